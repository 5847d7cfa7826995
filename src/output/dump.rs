//! The files of a buffer dump ([`crate::methods::dump`]; `docs/buffer-dumps.md`), in the
//! method's folder `DIR/METHOD/`, for a dump named `NAME`:
//!
//! | file | contents |
//! |---|---|
//! | `NAME.png` | the raw values of a single-channel 8-bit buffer, 8-bit grayscale PNG, exact |
//! | `NAME.bin` | the raw values of every other buffer: little-endian, row-major (row 0 at the top), channels interleaved, no header |
//! | `NAME.json` | the sidecar: what it is, width, height, format, numpy dtype and shape, the numpy line that loads it, the used range, the event totals |
//! | `NAME.view.png` | a viewable image: one panel per channel (or per derived value), scaled to its used range, with a colour bar and its min / 0 / max labels drawn in |
//! | `NAME.events.bin` | the event map, `<u4`, shape (height, width, K + 1): per kind of overflow its events per pixel, then 1 where the resolve clamped |
//! | `NAME.events.png` | the event map viewable: the buffer dimmed in gray, overflowed pixels in the kind's colour, clamped pixels blue, both yellow, with a legend |
//!
//! Only the raw file is written for the dumps of a normal run (`hard-sv`'s `stencil.png`,
//! `wedge-blending`'s `penumbrae.png`, as before dumps existed); the others only with
//! `--dump-buffers` ([`dump_files`]'s `full`).
//!
//! Colour maps: a panel whose values have both signs is drawn with a diverging map, blue
//! through white to red, symmetric about zero (zero white, in the middle of the bar); any
//! other with a sequential map (viridis, dark = min, yellow = max). Values that are not
//! finite are magenta; a panel whose values are all equal is drawn in the map's middle
//! colour and labelled as constant.

use crate::methods::dump::{BufferDump, DumpValues, EventKind, Storage};
use plotters::prelude::*;
use std::io;

/// The raw file's name: `NAME.png` for a single-channel 8-bit dump, else `NAME.bin`
/// (module table). The name must be a plain, non-hidden file stem (ASCII letters, digits,
/// `-`, `_`, not starting with `-`).
pub fn raw_file_name(d: &BufferDump) -> io::Result<String> {
    let ok = !d.name.is_empty()
        && !d.name.starts_with('-')
        && d.name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_');
    if !ok {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("buffer dump name {:?} is not a plain file stem", d.name),
        ));
    }
    Ok(if is_gray8(d) {
        format!("{}.png", d.name)
    } else {
        format!("{}.bin", d.name)
    })
}

/// Whether the dump's raw file is an 8-bit grayscale PNG.
fn is_gray8(d: &BufferDump) -> bool {
    d.values.storage() == Storage::U8 && d.format.channels() == 1
}

/// The viewable image's file name.
pub fn view_file_name(d: &BufferDump) -> String {
    format!("{}.view.png", d.name)
}

/// The viewable event map's file name (when the dump has one).
pub fn events_view_file_name(d: &BufferDump) -> String {
    format!("{}.events.png", d.name)
}

/// The files of dump `d` (module table): only the raw file, or with `full` every file.
pub fn dump_files(d: &BufferDump, full: bool) -> io::Result<Vec<(String, Vec<u8>)>> {
    let raw = raw_file_name(d)?;
    let expected = d.pixels() * d.format.channels() as usize;
    if d.values.len() != expected || d.values.storage() != d.format.storage() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "buffer dump {:?} has {} {:?} values, expected {expected} {:?} for {}x{}",
                d.name,
                d.values.len(),
                d.values.storage(),
                d.format.storage(),
                d.width,
                d.height
            ),
        ));
    }
    let bytes = match &d.values {
        DumpValues::U8(v) if is_gray8(d) => super::encode_gray8_png(v, d.width, d.height)?,
        values => values.le_bytes(),
    };
    let mut files = vec![(raw.clone(), bytes)];
    if !full {
        return Ok(files);
    }
    let panels = d.panels();
    let ranges: Vec<Range> = panels.iter().map(|(_, v)| Range::of(v)).collect();
    files.push((view_file_name(d), view_png(d, &panels, &ranges)?));
    let mut events_json = serde_json::Value::Null;
    if let Some(ev) = &d.events {
        let n = d.pixels();
        let k = ev.overflows.len() + 1;
        let mut words = Vec::with_capacity(n * k * 4);
        for i in 0..n {
            for (_, v) in &ev.overflows {
                words.extend_from_slice(&v[i].to_le_bytes());
            }
            let clamped = ev.clamped.get(i).copied().unwrap_or(false);
            words.extend_from_slice(&(clamped as u32).to_le_bytes());
        }
        let bin = format!("{}.events.bin", d.name);
        files.push((bin.clone(), words));
        files.push((
            events_view_file_name(d),
            events_png(d, &panels[0].1, &ranges[0])?,
        ));
        let mut channels: Vec<String> = ev
            .overflows
            .iter()
            .map(|(kind, _)| format!("{} events", kind.name()))
            .collect();
        channels.push("clamped by the resolve (0/1)".into());
        let totals: serde_json::Map<String, serde_json::Value> = ev
            .totals()
            .into_iter()
            .map(|(kind, t)| (kind.name().to_string(), t.into()))
            .collect();
        events_json = serde_json::json!({
            "raw": bin,
            "view": events_view_file_name(d),
            "dtype": "<u4",
            "shape": [d.height, d.width, k],
            "channels": channels,
            "numpy": format!("numpy.fromfile({bin:?}, dtype='<u4').reshape({}, {}, {k})", d.height, d.width),
            "event_totals": totals,
            "overflowed_pixels": ev.overflowed_pixels(),
            "clamped_pixels": ev.clamped_pixels(),
        });
    }
    let c = d.format.channels();
    let shape: Vec<u32> = if c == 1 {
        vec![d.height, d.width]
    } else {
        vec![d.height, d.width, c]
    };
    let dtype = d.format.storage().dtype();
    let numpy = if is_gray8(d) {
        format!("numpy.asarray(PIL.Image.open({raw:?}))")
    } else {
        let dims: Vec<String> = shape.iter().map(|s| s.to_string()).collect();
        format!(
            "numpy.fromfile({raw:?}, dtype='{dtype}').reshape({})",
            dims.join(", ")
        )
    };
    let panels_json: Vec<serde_json::Value> = panels
        .iter()
        .zip(&ranges)
        .map(|((label, _), r)| {
            serde_json::json!({
                "label": label,
                "min": r.finite.map(|(lo, _)| lo),
                "max": r.finite.map(|(_, hi)| hi),
                "non_finite_pixels": r.non_finite,
            })
        })
        .collect();
    let sidecar = serde_json::json!({
        "name": d.name,
        "about": d.about,
        "width": d.width,
        "height": d.height,
        "format": d.format.name(),
        "dtype": dtype,
        "channels": d.channels,
        "shape": shape,
        "layout": "row-major, row 0 at the top, channels interleaved, little-endian",
        "raw": raw,
        "numpy": numpy,
        "view": view_file_name(d),
        "view_panels": panels_json,
        "events": events_json,
    });
    let mut json = serde_json::to_vec_pretty(&sidecar)
        .map_err(|e| io::Error::other(format!("encoding {}.json: {e}", d.name)))?;
    json.push(b'\n');
    files.push((format!("{}.json", d.name), json));
    Ok(files)
}

/// The used range of a panel's values.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Range {
    /// Smallest and largest finite value, `None` if none is finite.
    finite: Option<(f64, f64)>,
    /// Values that are NaN or infinite.
    non_finite: u64,
}

impl Range {
    fn of(v: &[f64]) -> Self {
        let mut finite: Option<(f64, f64)> = None;
        let mut non_finite = 0;
        for &x in v {
            if !x.is_finite() {
                non_finite += 1;
                continue;
            }
            finite = Some(match finite {
                None => (x, x),
                Some((lo, hi)) => (lo.min(x), hi.max(x)),
            });
        }
        Self { finite, non_finite }
    }

    /// Whether the panel uses the diverging map (values of both signs).
    fn diverging(&self) -> bool {
        self.finite.is_some_and(|(lo, hi)| lo < 0.0 && hi > 0.0)
    }

    /// The position of `x` on the colour bar, 0…1 (module doc), `None` if not finite.
    fn position(&self, x: f64) -> Option<f64> {
        let (lo, hi) = self.finite?;
        if !x.is_finite() {
            return None;
        }
        Some(if self.diverging() {
            let m = lo.abs().max(hi.abs());
            0.5 + 0.5 * x / m
        } else if hi > lo {
            (x - lo) / (hi - lo)
        } else {
            0.5
        })
    }

    /// The colour of `x`.
    fn colour(&self, x: f64) -> [u8; 3] {
        match self.position(x) {
            None => NON_FINITE,
            Some(t) if self.diverging() => ramp(&DIVERGING, t),
            Some(t) => ramp(&SEQUENTIAL, t),
        }
    }
}

/// The colour of values that are not finite.
const NON_FINITE: [u8; 3] = [255, 0, 255];

/// Viridis at five stops.
const SEQUENTIAL: [[u8; 3]; 5] = [
    [68, 1, 84],
    [59, 82, 139],
    [33, 145, 140],
    [94, 201, 98],
    [253, 231, 37],
];

/// Blue, white, red (the ends of "coolwarm").
const DIVERGING: [[u8; 3]; 3] = [[59, 76, 192], [242, 242, 242], [180, 4, 38]];

/// Linear interpolation through `stops` at `t` in [0, 1].
fn ramp(stops: &[[u8; 3]], t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0) * (stops.len() - 1) as f64;
    let k = (t.floor() as usize).min(stops.len() - 2);
    let f = t - k as f64;
    std::array::from_fn(|c| {
        let (a, b) = (stops[k][c] as f64, stops[k + 1][c] as f64);
        (a + (b - a) * f).round() as u8
    })
}

/// A value for a label: integers as such, others with four significant digits.
fn label(x: f64) -> String {
    if x == x.trunc() && x.abs() < 1e9 {
        format!("{x:.0}")
    } else if (1e-3..1e6).contains(&x.abs()) {
        let s = format!("{x:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{x:.3e}")
    }
}

/// The smallest width of a panel in the viewable images, so that its labels fit.
const MIN_PANEL_WIDTH: u32 = 256;

/// Pixels of text lines and bars.
const TITLE_HEIGHT: u32 = 22;
const LEGEND_HEIGHT: u32 = 62;
const GAP: u32 = 8;

/// A drawing: an RGB canvas, its texts drawn last with the embedded font.
struct Canvas {
    width: u32,
    height: u32,
    rgb: Vec<u8>,
    texts: Vec<(String, (i32, i32))>,
}

impl Canvas {
    fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            rgb: vec![255; width as usize * height as usize * 3],
            texts: Vec::new(),
        }
    }

    fn set(&mut self, x: u32, y: u32, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y as usize * self.width as usize + x as usize);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    fn rect(&mut self, x0: u32, y0: u32, w: u32, h: u32, c: [u8; 3]) {
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                self.set(x, y, c);
            }
        }
    }

    /// `w`×`h` pixel colours (row-major) at (`x0`, `y0`), each `zoom`² canvas pixels.
    fn image(&mut self, x0: u32, y0: u32, (w, h, zoom): (u32, u32, u32), c: &[[u8; 3]]) {
        for y in 0..h * zoom {
            for x in 0..w * zoom {
                let p = c[(y / zoom) as usize * w as usize + (x / zoom) as usize];
                self.set(x0 + x, y0 + y, p);
            }
        }
    }

    fn text(&mut self, s: impl Into<String>, x: u32, y: u32) {
        self.texts.push((s.into(), (x as i32, y as i32)));
    }

    /// The PNG of the canvas with its texts.
    fn png(mut self) -> io::Result<Vec<u8>> {
        crate::drawing::register_font().map_err(io::Error::other)?;
        {
            let root = BitMapBackend::with_buffer(&mut self.rgb, (self.width, self.height))
                .into_drawing_area();
            let style = TextStyle::from(("sans-serif", 13).into_font()).color(&BLACK);
            for (s, pos) in &self.texts {
                root.draw_text(s, &style, *pos)
                    .map_err(|e| io::Error::other(format!("drawing a legend: {e}")))?;
            }
            root.present()
                .map_err(|e| io::Error::other(format!("drawing a legend: {e}")))?;
        }
        let pixels: Vec<[u8; 3]> = self
            .rgb
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        super::encode_rgb8_png(&pixels, self.width, self.height)
    }
}

/// The zoom of a dump's panels: the smallest integer that makes a panel at least
/// [`MIN_PANEL_WIDTH`] wide (1 for wide buffers).
fn zoom(d: &BufferDump) -> u32 {
    MIN_PANEL_WIDTH.div_ceil(d.width.max(1)).max(1)
}

/// The viewable image (module doc): per panel a title, the image and its colour bar.
fn view_png(
    d: &BufferDump,
    panels: &[(String, Vec<f64>)],
    ranges: &[Range],
) -> io::Result<Vec<u8>> {
    let z = zoom(d);
    let (pw, ph) = (d.width * z, d.height * z);
    let cell = pw.max(MIN_PANEL_WIDTH);
    let count = panels.len() as u32;
    let width = count * cell + (count + 1) * GAP;
    let height = TITLE_HEIGHT + ph + LEGEND_HEIGHT + 2 * GAP;
    let mut cv = Canvas::new(width, height);
    for (k, ((name, values), r)) in panels.iter().zip(ranges).enumerate() {
        let x0 = GAP + k as u32 * (cell + GAP);
        cv.text(format!("{} — {name} ({})", d.name, d.format.name()), x0, 4);
        let colours: Vec<[u8; 3]> = values.iter().map(|&v| r.colour(v)).collect();
        cv.image(x0, TITLE_HEIGHT, (d.width, d.height, z), &colours);
        colour_bar(&mut cv, x0, TITLE_HEIGHT + ph + GAP, cell, r);
    }
    cv.png()
}

/// A colour bar of `width` at (`x0`, `y0`) with its labels (module doc).
fn colour_bar(cv: &mut Canvas, x0: u32, y0: u32, width: u32, r: &Range) {
    let bar_h = 14;
    let Some((lo, hi)) = r.finite else {
        cv.text("no finite value", x0, y0);
        return;
    };
    if lo == hi {
        cv.rect(x0, y0, width, bar_h, r.colour(lo));
        cv.text(format!("constant {}", label(lo)), x0, y0 + bar_h + 4);
    } else {
        for x in 0..width {
            let t = x as f64 / (width - 1) as f64;
            let c = if r.diverging() {
                ramp(&DIVERGING, t)
            } else {
                ramp(&SEQUENTIAL, t)
            };
            cv.rect(x0 + x, y0, 1, bar_h, c);
        }
        let ty = y0 + bar_h + 4;
        if r.diverging() {
            let m = lo.abs().max(hi.abs());
            cv.text(format!("−{}", label(m)), x0, ty);
            cv.text("0", x0 + width / 2 - 3, ty);
            cv.text(label(m), x0 + width - 8 * label(m).len() as u32, ty);
            cv.text(format!("used: {} … {}", label(lo), label(hi)), x0, ty + 16);
        } else {
            cv.text(label(lo), x0, ty);
            let hl = label(hi);
            cv.text(&hl, x0 + width.saturating_sub(8 * hl.len() as u32), ty);
            cv.text("min … max of the used range", x0, ty + 16);
        }
    }
    if r.non_finite > 0 {
        cv.rect(x0 + width - 12, y0 + bar_h + 36, 10, 10, NON_FINITE);
        cv.text(
            format!("{} NaN/inf", r.non_finite),
            x0 + width.saturating_sub(110),
            y0 + bar_h + 34,
        );
    }
}

/// The colour of a kind of overflow in the event view.
fn event_colour(kind: EventKind) -> [u8; 3] {
    match kind {
        EventKind::Wrap => [230, 25, 25],
        EventKind::Saturate => [255, 140, 0],
        EventKind::NonFinite => [230, 0, 230],
        EventKind::SpecialFloat => [0, 170, 0],
    }
}

/// Clamped by the resolve.
const CLAMPED: [u8; 3] = [30, 90, 255];
/// Overflowed and clamped.
const BOTH: [u8; 3] = [255, 220, 0];

/// The viewable event map (module doc): `base` (the first panel, range `r`) dimmed in gray
/// under the marked pixels, and a legend of the marks with their counts.
fn events_png(d: &BufferDump, base: &[f64], r: &Range) -> io::Result<Vec<u8>> {
    let ev = d.events.as_ref().expect("events_png needs an event map");
    let z = zoom(d);
    let (pw, ph) = (d.width * z, d.height * z);
    let cell = pw.max(MIN_PANEL_WIDTH + 100);
    let entries = ev.overflows.len() as u32 + 2;
    let width = cell + 2 * GAP;
    let height = TITLE_HEIGHT + ph + GAP + entries * 18 + GAP;
    let mut cv = Canvas::new(width, height);
    cv.text(format!("{} — events ({})", d.name, d.format.name()), GAP, 4);
    let colours: Vec<[u8; 3]> = (0..d.pixels())
        .map(|i| {
            let over = ev.overflows.iter().find(|(_, v)| v[i] > 0).map(|(k, _)| *k);
            let clamped = ev.clamped.get(i).copied().unwrap_or(false);
            match (over, clamped) {
                (Some(_), true) => BOTH,
                (Some(k), false) => event_colour(k),
                (None, true) => CLAMPED,
                (None, false) => {
                    let g = (40.0 + 100.0 * r.position(base[i]).unwrap_or(0.0)).round() as u8;
                    [g; 3]
                }
            }
        })
        .collect();
    cv.image(GAP, TITLE_HEIGHT, (d.width, d.height, z), &colours);
    let mut y = TITLE_HEIGHT + ph + GAP;
    for (kind, v) in &ev.overflows {
        let pixels = v.iter().filter(|&&n| n > 0).count();
        let events: u64 = v.iter().map(|&n| u64::from(n)).sum();
        cv.rect(GAP, y + 2, 12, 12, event_colour(*kind));
        cv.text(
            format!("{}: {events} events at {pixels} pixels", kind.name()),
            GAP + 18,
            y,
        );
        y += 18;
    }
    let both = (0..d.pixels())
        .filter(|&i| {
            ev.clamped.get(i).copied().unwrap_or(false)
                && ev.overflows.iter().any(|(_, v)| v[i] > 0)
        })
        .count();
    cv.rect(GAP, y + 2, 12, 12, CLAMPED);
    cv.text(
        format!("clamped by the resolve: {} pixels", ev.clamped_pixels()),
        GAP + 18,
        y,
    );
    y += 18;
    cv.rect(GAP, y + 2, 12, 12, BOTH);
    cv.text(
        format!("overflowed and clamped: {both} pixels (gray: the buffer, no event)"),
        GAP + 18,
        y,
    );
    cv.png()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::li_buffer::LiFormat;
    use crate::methods::dump::{ElementFormat, EventMap};

    fn li_dump() -> BufferDump {
        BufferDump::new(
            "li",
            "an LI buffer",
            (3, 2),
            ElementFormat::Li(LiFormat::Li16),
            DumpValues::I16(vec![255, 0, -255, 510, 255, 128]),
        )
        .with_events(EventMap::new(
            EventKind::Wrap,
            vec![0, 0, 1, 0, 0, 0],
            vec![false, false, true, true, false, false],
        ))
    }

    #[test]
    fn raw_only_without_full_and_every_file_with_it() {
        let d = li_dump();
        let names = |full| -> Vec<String> {
            dump_files(&d, full)
                .unwrap()
                .into_iter()
                .map(|(n, _)| n)
                .collect()
        };
        assert_eq!(names(false), ["li.bin"]);
        assert_eq!(
            names(true),
            [
                "li.bin",
                "li.view.png",
                "li.events.bin",
                "li.events.png",
                "li.json"
            ]
        );
        let files = dump_files(&d, true).unwrap();
        let raw: Vec<i16> = files[0]
            .1
            .chunks_exact(2)
            .map(|b| i16::from_le_bytes([b[0], b[1]]))
            .collect();
        assert_eq!(raw, [255, 0, -255, 510, 255, 128]);
        let ev: Vec<u32> = files[2]
            .1
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(ev, [0, 0, 0, 0, 1, 1, 0, 1, 0, 0, 0, 0]);
        let json: serde_json::Value = serde_json::from_slice(&files[4].1).unwrap();
        assert_eq!(json["dtype"], "<i2");
        assert_eq!(json["shape"], serde_json::json!([2, 3]));
        assert_eq!(json["view_panels"][0]["min"], -255.0);
        assert_eq!(json["events"]["clamped_pixels"], 2);
        assert_eq!(json["events"]["event_totals"]["wrap"], 1);
        let view = image::load_from_memory(&files[1].1).unwrap().to_rgb8();
        assert!(view.width() >= MIN_PANEL_WIDTH);
    }

    #[test]
    fn signed_values_diverge_about_zero() {
        let r = Range::of(&[-2.0, 1.0, f64::NAN]);
        assert!(r.diverging());
        assert_eq!(r.position(0.0), Some(0.5));
        assert_eq!(r.position(-2.0), Some(0.0));
        assert_eq!(r.position(1.0), Some(0.75));
        assert_eq!(r.non_finite, 1);
        assert_eq!(r.colour(f64::NAN), NON_FINITE);
        let s = Range::of(&[3.0, 5.0]);
        assert!(!s.diverging());
        assert_eq!(s.position(4.0), Some(0.5));
    }

    #[test]
    fn names_must_be_plain_stems() {
        let mut d = li_dump();
        d.name = "../x".into();
        assert!(dump_files(&d, false).is_err());
    }
}
