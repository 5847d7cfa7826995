//! Labelled image grids: renders of several methods side by side, each with its name and a
//! caption under it (the README picture, `examples/readme_picture.rs`). The images are copied
//! pixel for pixel; only the labels are drawn, with `plotters` and the embedded font of
//! [`crate::experiment::plotting`].

use plotters::prelude::*;

/// One panel: an sRGB image (row 0 at the top, `width × height` of the grid) and its label
/// lines (the first in bold type size, the rest smaller).
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Row-major 8-bit sRGB pixels.
    pub pixels: Vec<[u8; 3]>,
    /// The title (e.g. the method name).
    pub title: String,
    /// A caption line under the title (e.g. time and error).
    pub caption: String,
}

/// Space between panels and around the grid, in pixels.
const GAP: u32 = 6;
/// Height of the label area under each image, in pixels.
const LABEL_HEIGHT: u32 = 42;

/// Lays `panels` of `width × height` pixels out in rows of `columns`, each image with its
/// title and caption under it, on a white background; returns the PNG bytes. An error when a
/// panel has the wrong number of pixels or there is nothing to draw.
pub fn labelled_grid_png(
    panels: &[Panel],
    (width, height): (u32, u32),
    columns: u32,
) -> Result<Vec<u8>, String> {
    let n = (width as usize) * (height as usize);
    if panels.is_empty() || columns == 0 || n == 0 {
        return Err("nothing to draw: no panels or an empty image".into());
    }
    if let Some(p) = panels.iter().find(|p| p.pixels.len() != n) {
        return Err(format!(
            "panel {:?} has {} pixels, expected {width}×{height}",
            p.title,
            p.pixels.len()
        ));
    }
    let columns = columns.min(panels.len() as u32);
    let rows = (panels.len() as u32).div_ceil(columns);
    let cell = (width + GAP, height + LABEL_HEIGHT + GAP);
    let total = (GAP + columns * cell.0, GAP + rows * cell.1);
    let origin = |k: usize| {
        let (c, r) = (k as u32 % columns, k as u32 / columns);
        (GAP + c * cell.0, GAP + r * cell.1)
    };
    let mut rgb = vec![255u8; total.0 as usize * total.1 as usize * 3];
    for (k, p) in panels.iter().enumerate() {
        let (x0, y0) = origin(k);
        for y in 0..height {
            let row = (y0 + y) as usize * total.0 as usize;
            let dst = (row + x0 as usize) * 3;
            let src = &p.pixels[(y * width) as usize..((y + 1) * width) as usize];
            for (i, px) in src.iter().enumerate() {
                rgb[dst + 3 * i..dst + 3 * i + 3].copy_from_slice(px);
            }
        }
    }
    crate::drawing::register_font()?;
    {
        let root = BitMapBackend::with_buffer(&mut rgb, total).into_drawing_area();
        let title = TextStyle::from(("sans-serif", 17)).color(&BLACK);
        let caption = TextStyle::from(("sans-serif", 13)).color(&RGBColor(70, 70, 70));
        for (k, p) in panels.iter().enumerate() {
            let (x0, y0) = origin(k);
            let (x, y) = (x0 as i32 + 2, (y0 + height) as i32 + 4);
            root.draw_text(&p.title, &title, (x, y))
                .map_err(|e| e.to_string())?;
            root.draw_text(&p.caption, &caption, (x, y + 21))
                .map_err(|e| e.to_string())?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    let pixels: Vec<[u8; 3]> = rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    crate::output::encode_rgb8_png(&pixels, total.0, total.1).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn panel(title: &str, c: u8) -> Panel {
        Panel {
            pixels: vec![[c, 0, 0]; 16 * 8],
            title: title.into(),
            caption: "1 ms".into(),
        }
    }

    /// The images are copied unchanged to their cells, labels land under them (some
    /// non-white, non-image pixels there), and the grid has the stated size.
    #[test]
    fn images_are_copied_and_labelled() {
        let png = labelled_grid_png(
            &[panel("a", 10), panel("b", 20), panel("c", 30)],
            (16, 8),
            2,
        )
        .unwrap();
        let img = image::load_from_memory(&png).unwrap().into_rgb8();
        assert_eq!(
            img.dimensions(),
            (GAP + 2 * (16 + GAP), GAP + 2 * (8 + LABEL_HEIGHT + GAP))
        );
        assert_eq!(img.get_pixel(GAP, GAP).0, [10, 0, 0]);
        assert_eq!(img.get_pixel(GAP + 16 + GAP + 15, GAP + 7).0, [20, 0, 0]);
        let second_row = GAP + 8 + LABEL_HEIGHT + GAP;
        assert_eq!(img.get_pixel(GAP, second_row).0, [30, 0, 0]);
        let label_ink = (GAP..GAP + 16)
            .flat_map(|x| (GAP + 8..GAP + 8 + LABEL_HEIGHT).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0 != [255, 255, 255])
            .count();
        assert!(label_ink > 0, "no label drawn");
    }

    #[test]
    fn wrong_sizes_are_errors() {
        let mut p = panel("a", 1);
        p.pixels.pop();
        assert!(labelled_grid_png(&[p], (16, 8), 1).is_err());
        assert!(labelled_grid_png(&[], (16, 8), 1).is_err());
    }
}
