//! What every method hands back first: the visibility of the light per pixel, in [0, 1]
//! (`docs/architecture.md` "Methods": all methods are compared on the same footing), gray or
//! RGB for textured lights. Below the frame and the methods, so that the error metrics and
//! the outputs read it without depending on either.

/// Per-pixel visibility of the light, row 0 at the top, row-major.
#[derive(Debug, Clone, PartialEq)]
pub enum Visibility {
    /// One value per pixel in [0, 1].
    Gray(Vec<f32>),
    /// One value per pixel and RGB channel in [0, 1] (textured/coloured lights).
    Rgb(Vec<[f32; 3]>),
}

impl Visibility {
    /// Number of pixels.
    pub fn len(&self) -> usize {
        match self {
            Visibility::Gray(v) => v.len(),
            Visibility::Rgb(v) => v.len(),
        }
    }

    /// True when there are no pixels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The visibility of pixel `i` as RGB (gray replicated).
    pub fn rgb(&self, i: usize) -> [f32; 3] {
        match self {
            Visibility::Gray(v) => [v[i]; 3],
            Visibility::Rgb(v) => v[i],
        }
    }

    /// The visibility of pixel `i` per stored channel: one value for gray, three for RGB.
    pub fn channels(&self, i: usize) -> Vec<f32> {
        match self {
            Visibility::Gray(v) => vec![v[i]],
            Visibility::Rgb(v) => v[i].to_vec(),
        }
    }

    /// The visibility of pixel `i` as one value (RGB averaged with equal weights).
    pub fn gray(&self, i: usize) -> f32 {
        match self {
            Visibility::Gray(v) => v[i],
            Visibility::Rgb(v) => (v[i][0] + v[i][1] + v[i][2]) / 3.0,
        }
    }
}
