//! Buffer dumps (issue 14 item 2): the buffers that make a method what it is, handed back as
//! they were when the method resolved them, with what each holds, its size, its element
//! format, the raw values and, where the format can overflow or the resolve clamps, a
//! per-pixel event map counted in the renderer where the events happened.
//!
//! A method always hands back the dumps that are part of its ordinary outputs (`hard-sv`'s
//! `stencil`, `wedge-blending`'s `penumbrae`); every other dump, and every event map, only
//! when the frame asks for them ([`Frame::dump_buffers`], `--dump-buffers`), so a normal run
//! keeps and counts nothing extra. How a dump becomes files is [`crate::output::dump`];
//! `docs/buffer-dumps.md` lists every method's dumps.
//!
//! Values are row-major, row 0 at the top, channels interleaved, like every image here; a
//! light-view map has its own size ([`BufferDump::width`], [`BufferDump::height`]).

use crate::frame::Frame;
use crate::gpu::color::ColorFormat;
use crate::gpu::depth::DepthFormat;
use crate::gpu::li_buffer::LiFormat;
use crate::gpu::split_blend::SplitFormat;
use crate::gpu::tiling::Tiling;
use crate::gpu::vbuffer::{
    VBuffer8Tile, VBufferF16Tile, VBufferF32Tile, VBufferFormat, VBufferRgbTile, VBufferTile,
};
use half::f16;

/// How one element of a dump is stored: its numpy dtype in the raw file
/// ([`Storage::dtype`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Storage {
    /// Unsigned 8-bit.
    U8,
    /// Signed 16-bit.
    I16,
    /// Signed 32-bit.
    I32,
    /// Unsigned 16-bit.
    U16,
    /// Unsigned 32-bit (also raw 32-bit words).
    U32,
    /// IEEE binary16.
    F16,
    /// IEEE binary32.
    F32,
    /// IEEE binary64.
    F64,
}

impl Storage {
    /// The numpy dtype of the raw file (little-endian).
    pub fn dtype(self) -> &'static str {
        match self {
            Storage::U8 => "|u1",
            Storage::I16 => "<i2",
            Storage::I32 => "<i4",
            Storage::U16 => "<u2",
            Storage::U32 => "<u4",
            Storage::F16 => "<f2",
            Storage::F32 => "<f4",
            Storage::F64 => "<f8",
        }
    }
}

/// The values of a dump, row-major, channels interleaved, in their [`Storage`].
#[derive(Debug, Clone)]
pub enum DumpValues {
    /// Unsigned 8-bit.
    U8(Vec<u8>),
    /// Signed 16-bit.
    I16(Vec<i16>),
    /// Signed 32-bit.
    I32(Vec<i32>),
    /// Unsigned 16-bit.
    U16(Vec<u16>),
    /// Unsigned 32-bit.
    U32(Vec<u32>),
    /// binary16.
    F16(Vec<f16>),
    /// binary32.
    F32(Vec<f32>),
    /// binary64.
    F64(Vec<f64>),
}

impl DumpValues {
    /// The storage of the values.
    pub fn storage(&self) -> Storage {
        match self {
            DumpValues::U8(_) => Storage::U8,
            DumpValues::I16(_) => Storage::I16,
            DumpValues::I32(_) => Storage::I32,
            DumpValues::U16(_) => Storage::U16,
            DumpValues::U32(_) => Storage::U32,
            DumpValues::F16(_) => Storage::F16,
            DumpValues::F32(_) => Storage::F32,
            DumpValues::F64(_) => Storage::F64,
        }
    }

    /// Number of elements (pixels × channels).
    pub fn len(&self) -> usize {
        match self {
            DumpValues::U8(v) => v.len(),
            DumpValues::I16(v) => v.len(),
            DumpValues::I32(v) => v.len(),
            DumpValues::U16(v) => v.len(),
            DumpValues::U32(v) => v.len(),
            DumpValues::F16(v) => v.len(),
            DumpValues::F32(v) => v.len(),
            DumpValues::F64(v) => v.len(),
        }
    }

    /// True when there are no elements.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Element `i` as a number (exact for every storage but `U32` words above 2^53, which
    /// no dump holds as numbers).
    pub fn get(&self, i: usize) -> f64 {
        match self {
            DumpValues::U8(v) => v[i].into(),
            DumpValues::I16(v) => v[i].into(),
            DumpValues::I32(v) => v[i].into(),
            DumpValues::U16(v) => v[i].into(),
            DumpValues::U32(v) => v[i].into(),
            DumpValues::F16(v) => v[i].to_f64(),
            DumpValues::F32(v) => v[i].into(),
            DumpValues::F64(v) => v[i],
        }
    }

    /// Element `i` as raw bits (zero-extended): what [`DumpValues::le_bytes`] writes.
    pub fn bits(&self, i: usize) -> u64 {
        match self {
            DumpValues::U8(v) => v[i].into(),
            DumpValues::I16(v) => v[i] as u16 as u64,
            DumpValues::I32(v) => v[i] as u32 as u64,
            DumpValues::U16(v) => v[i].into(),
            DumpValues::U32(v) => v[i].into(),
            DumpValues::F16(v) => v[i].to_bits().into(),
            DumpValues::F32(v) => v[i].to_bits().into(),
            DumpValues::F64(v) => v[i].to_bits(),
        }
    }

    /// The values as little-endian bytes, element after element: the raw file's contents.
    pub fn le_bytes(&self) -> Vec<u8> {
        match self {
            DumpValues::U8(v) => v.clone(),
            DumpValues::I16(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            DumpValues::I32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            DumpValues::U16(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            DumpValues::U32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            DumpValues::F16(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            DumpValues::F32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            DumpValues::F64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
        }
    }
}

/// Equal when the storage and every bit are equal (a NaN equals the same NaN: dumps are
/// compared for determinism).
impl PartialEq for DumpValues {
    fn eq(&self, o: &Self) -> bool {
        self.storage() == o.storage()
            && self.len() == o.len()
            && (0..self.len()).all(|i| self.bits(i) == o.bits(i))
    }
}

/// What one element of a dump is (`docs/buffer-dumps.md` lists the formats): its storage,
/// its channels, and how its viewable image shows it ([`BufferDump::panels`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElementFormat {
    /// An 8-bit stencil value (`gpu::stencil`), u8.
    Stencil8,
    /// An LI buffer value (Paper I §4, Paper II §2): i16 for the 16- and 12-bit formats, u8
    /// for the 8-bit one.
    Li(LiFormat),
    /// A V-buffer of Paper III in its format (§4.1: f32, f16, RGB f32; §4.2: the 8-bit
    /// version's R (add) and G (subtract) channels, u8 × 2).
    VBuffer(VBufferFormat),
    /// One RGBA8 buffer of Paper IV §4.3's split V-buffer, u8 × 4, R the most significant
    /// channel, each channel's upper `reserved_bits` holding carries.
    SplitRgba8(SplitFormat),
    /// Forest et al. 2006 §4.3: an RGBA32F target of four `PK4UB` words (one per radial part,
    /// u32 × 4), each word the bounding rectangle (top, bottom, left, right; top in the lowest
    /// byte).
    Pk4ubRects,
    /// Forest et al. 2006 §4.3: an RGBA32F target of four `PK4UB` words (u32 × 4), each word
    /// (occlusion, max X, max Y, free; occlusion in the lowest byte).
    Pk4ubOcclusion,
    /// Forest et al.'s final vBuffer unpacked (`packing = f32`): per radial part occlusion,
    /// left, bottom, right, top (f32 × 20).
    PartsF32,
    /// A depth buffer as stored: D16 u16 and D24 u32 unorm values, D32F f32.
    Depth(DepthFormat),
    /// A colour target with `channels` channels in a colour format (unorm8 u8, f16, f32).
    Color(ColorFormat, u32),
    /// A count per pixel, u8.
    Count8,
    /// A signed count per pixel, i32.
    CountI32,
    /// A sum in f64, with `channels` channels.
    SumF64(u32),
    /// A scalar in f64 (NaN where the pixel has none).
    ScalarF64,
}

impl ElementFormat {
    /// The storage of one element.
    pub fn storage(self) -> Storage {
        match self {
            ElementFormat::Stencil8 | ElementFormat::Count8 => Storage::U8,
            ElementFormat::Li(LiFormat::Li8) => Storage::U8,
            ElementFormat::Li(_) => Storage::I16,
            ElementFormat::VBuffer(VBufferFormat::F16) => Storage::F16,
            ElementFormat::VBuffer(VBufferFormat::Split8) => Storage::U8,
            ElementFormat::VBuffer(_) => Storage::F32,
            ElementFormat::SplitRgba8(_) => Storage::U8,
            ElementFormat::Pk4ubRects | ElementFormat::Pk4ubOcclusion => Storage::U32,
            ElementFormat::PartsF32 => Storage::F32,
            ElementFormat::ScalarF64 => Storage::F64,
            ElementFormat::Depth(DepthFormat::D16) => Storage::U16,
            ElementFormat::Depth(DepthFormat::D24) => Storage::U32,
            ElementFormat::Depth(DepthFormat::D32F) => Storage::F32,
            ElementFormat::Color(ColorFormat::Unorm8, _) => Storage::U8,
            ElementFormat::Color(ColorFormat::F16, _) => Storage::F16,
            ElementFormat::Color(ColorFormat::F32, _) => Storage::F32,
            ElementFormat::CountI32 => Storage::I32,
            ElementFormat::SumF64(_) => Storage::F64,
        }
    }

    /// Channels per pixel.
    pub fn channels(self) -> u32 {
        match self {
            ElementFormat::VBuffer(VBufferFormat::RgbF32) => 3,
            ElementFormat::VBuffer(VBufferFormat::Split8) => 2,
            ElementFormat::SplitRgba8(_)
            | ElementFormat::Pk4ubRects
            | ElementFormat::Pk4ubOcclusion => 4,
            ElementFormat::PartsF32 => 20,
            ElementFormat::Color(_, n) | ElementFormat::SumF64(n) => n,
            _ => 1,
        }
    }

    /// A short name of the format, for the sidecar and the legend.
    pub fn name(self) -> String {
        match self {
            ElementFormat::Stencil8 => "stencil8".into(),
            ElementFormat::Li(f) => format!("LI{}", f.bits()),
            ElementFormat::VBuffer(VBufferFormat::F32) => "vbuffer-f32".into(),
            ElementFormat::VBuffer(VBufferFormat::F16) => "vbuffer-f16".into(),
            ElementFormat::VBuffer(VBufferFormat::RgbF32) => "vbuffer-rgb-f32".into(),
            ElementFormat::VBuffer(VBufferFormat::Split8) => "vbuffer-8bit-rg".into(),
            ElementFormat::SplitRgba8(f) => format!("split-rgba8-r{}", f.reserved_bits),
            ElementFormat::Pk4ubRects => "pk4ub-rects".into(),
            ElementFormat::Pk4ubOcclusion => "pk4ub-occlusion".into(),
            ElementFormat::PartsF32 => "parts-f32".into(),
            ElementFormat::Depth(d) => format!("{d:?}").to_lowercase(),
            ElementFormat::Color(c, n) => {
                format!("{}x{n}", crate::options::OptionType::written(c))
            }
            ElementFormat::Count8 => "count8".into(),
            ElementFormat::CountI32 => "count-i32".into(),
            ElementFormat::SumF64(n) => format!("sum-f64x{n}"),
            ElementFormat::ScalarF64 => "scalar-f64".into(),
        }
    }

    /// The default names of the channels (a dump may name them itself,
    /// [`BufferDump::with_channels`]).
    fn channel_names(self) -> Vec<String> {
        let list: &[&str] = match self {
            ElementFormat::VBuffer(VBufferFormat::RgbF32) => &["R", "G", "B"],
            ElementFormat::VBuffer(VBufferFormat::Split8) => &["R (add)", "G (subtract)"],
            ElementFormat::SplitRgba8(_) => &["R", "G", "B", "A"],
            ElementFormat::Pk4ubRects | ElementFormat::Pk4ubOcclusion => {
                &["part 0", "part 1", "part 2", "part 3"]
            }
            _ => &[],
        };
        match (list.is_empty(), self.channels()) {
            (false, _) => list.iter().map(|s| s.to_string()).collect(),
            (true, 1) => vec!["value".into()],
            (true, n) => (0..n).map(|k| format!("channel {k}")).collect(),
        }
    }

    /// What the viewable image shows of pixel values `px` (its channels' raw elements): one
    /// number per panel, with the panel's label. Single-channel formats show the value;
    /// multi-channel ones each channel, except where a channel alone means nothing: the split
    /// V-buffer shows its reconstructed value over the full value (carries included, Paper IV
    /// §4.3), the PK4UB targets the mean over the four parts of the rectangle's area or of the
    /// occlusion, the unpacked parts the mean occlusion.
    fn panel_labels(self, names: &[String]) -> Vec<String> {
        match self {
            ElementFormat::SplitRgba8(_) => vec!["value / full (carries included)".into()],
            ElementFormat::Pk4ubRects => vec!["mean rectangle area over the parts".into()],
            ElementFormat::Pk4ubOcclusion | ElementFormat::PartsF32 => {
                vec!["mean occlusion over the parts".into()]
            }
            _ => names.to_vec(),
        }
    }

    /// The panel values of one pixel whose elements are `px` ([`ElementFormat::panel_labels`]).
    fn panel_values(self, px: &[f64], bits: &[u64]) -> Vec<f64> {
        let mean = |f: &dyn Fn(usize) -> f64| (0..4).map(f).sum::<f64>() / 4.0;
        let byte = |w: u64, k: u32| ((w >> (8 * k)) & 0xFF) as f64 / 255.0;
        match self {
            ElementFormat::SplitRgba8(f) => {
                let rgba = [0, 1, 2, 3].map(|k| bits[k] as u8);
                vec![f.reconstruct(rgba) as f64 / f.full() as f64]
            }
            ElementFormat::Pk4ubRects => vec![mean(&|k| {
                let w = bits[k];
                let (top, bottom, left, right) = (byte(w, 0), byte(w, 1), byte(w, 2), byte(w, 3));
                ((right - left).max(0.0)) * ((top - bottom).max(0.0))
            })],
            ElementFormat::Pk4ubOcclusion => vec![mean(&|k| byte(bits[k], 0))],
            ElementFormat::PartsF32 => vec![mean(&|k| px[5 * k])],
            _ => px.to_vec(),
        }
    }
}

/// What an overflow event is in a buffer's format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    /// An add left the format's range and wrapped (stencil INCR_WRAP/DECR_WRAP, an LI buffer
    /// with `overflow = wrap`).
    Wrap,
    /// An add or a write left the format's range and was clamped to it (stencil INCR/DECR,
    /// saturating blending, an LI buffer with `overflow = saturate`, a unorm8 or `PK4UB`
    /// conversion).
    Saturate,
    /// A float result that is not finite (f16 V-buffer and colour targets).
    NonFinite,
    /// A `PK4UB` word that is not an ordinary float (denormal, NaN or infinity) was written to
    /// an RGBA32F target (`gpu::pack4ub`).
    SpecialFloat,
}

impl EventKind {
    /// The name in the sidecar and the legend.
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Wrap => "wrap",
            EventKind::Saturate => "saturate",
            EventKind::NonFinite => "non-finite",
            EventKind::SpecialFloat => "special-float",
        }
    }
}

/// Per pixel, the events of one buffer: the overflow events of each kind counted where the
/// renderer made them, and whether the method's resolve clamped what it read there into
/// [0, 1] (the pixels of [`MethodStats::clamped_pixels`](super::output::MethodStats)).
#[derive(Debug, Clone, PartialEq)]
pub struct EventMap {
    /// Per kind, the events per pixel (row-major).
    pub overflows: Vec<(EventKind, Vec<u32>)>,
    /// Per pixel, whether the resolve clamped it (empty when the buffer is not resolved
    /// directly).
    pub clamped: Vec<bool>,
}

impl EventMap {
    /// An event map of one kind of overflow and the clamps.
    pub fn new(kind: EventKind, overflows: Vec<u32>, clamped: Vec<bool>) -> Self {
        Self {
            overflows: vec![(kind, overflows)],
            clamped,
        }
    }

    /// An event map of the resolve's clamps only (the format cannot overflow).
    pub fn clamps(clamped: Vec<bool>) -> Self {
        Self {
            overflows: Vec::new(),
            clamped,
        }
    }

    /// Total events of each kind.
    pub fn totals(&self) -> Vec<(EventKind, u64)> {
        self.overflows
            .iter()
            .map(|(k, v)| (*k, v.iter().map(|&n| u64::from(n)).sum()))
            .collect()
    }

    /// Pixels with at least one overflow event.
    pub fn overflowed_pixels(&self) -> u64 {
        let n = self.overflows.first().map_or(0, |(_, v)| v.len());
        (0..n)
            .filter(|&i| self.overflows.iter().any(|(_, v)| v[i] > 0))
            .count() as u64
    }

    /// Pixels the resolve clamped.
    pub fn clamped_pixels(&self) -> u64 {
        self.clamped.iter().filter(|&&c| c).count() as u64
    }
}

/// One dumped buffer (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct BufferDump {
    /// File stem, e.g. `stencil` or `li` (ASCII letters, digits, `-`, `_`).
    pub name: String,
    /// What the buffer is and holds, with the paper section, one or two sentences.
    pub about: String,
    /// Width in pixels (a light-view map: its own size).
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The element format.
    pub format: ElementFormat,
    /// The names of the channels, as many as the format has.
    pub channels: Vec<String>,
    /// The raw values, row-major, channels interleaved.
    pub values: DumpValues,
    /// The per-pixel events, where the format can overflow or the resolve clamps.
    pub events: Option<EventMap>,
}

impl BufferDump {
    /// A dump of `values` in `format` at `width`×`height`.
    ///
    /// # Panics
    /// If the values' storage or count does not match the format and size (a method's bug).
    pub fn new(
        name: &str,
        about: &str,
        (width, height): (u32, u32),
        format: ElementFormat,
        values: DumpValues,
    ) -> Self {
        assert_eq!(values.storage(), format.storage(), "dump {name}: storage");
        assert_eq!(
            values.len(),
            width as usize * height as usize * format.channels() as usize,
            "dump {name}: element count"
        );
        Self {
            name: name.into(),
            about: about.into(),
            width,
            height,
            format,
            channels: format.channel_names(),
            values,
            events: None,
        }
    }

    /// This dump with its event map.
    ///
    /// # Panics
    /// If the map's size is not the dump's.
    pub fn with_events(mut self, events: EventMap) -> Self {
        let n = self.width as usize * self.height as usize;
        assert!(
            events.overflows.iter().all(|(_, v)| v.len() == n)
                && (events.clamped.is_empty() || events.clamped.len() == n),
            "dump {}: event map size",
            self.name
        );
        self.events = Some(events);
        self
    }

    /// This dump with its own channel names.
    ///
    /// # Panics
    /// If there are not as many names as the format has channels.
    pub fn with_channels(mut self, names: &[&str]) -> Self {
        assert_eq!(names.len(), self.format.channels() as usize);
        self.channels = names.iter().map(|s| s.to_string()).collect();
        self
    }

    /// Pixels.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The panels of the viewable image: per panel its label and one number per pixel
    /// ([`ElementFormat`]'s rule).
    pub fn panels(&self) -> Vec<(String, Vec<f64>)> {
        let c = self.format.channels() as usize;
        let labels = self.format.panel_labels(&self.channels);
        let mut panels: Vec<(String, Vec<f64>)> = labels
            .into_iter()
            .map(|l| (l, Vec::with_capacity(self.pixels())))
            .collect();
        for i in 0..self.pixels() {
            let px: Vec<f64> = (0..c).map(|k| self.values.get(i * c + k)).collect();
            let bits: Vec<u64> = (0..c).map(|k| self.values.bits(i * c + k)).collect();
            for (p, v) in panels.iter_mut().zip(self.format.panel_values(&px, &bits)) {
                p.1.push(v);
            }
        }
        panels
    }
}

/// Row-major values of a tiled buffer: `field(tile)` is one tile's tile-major storage
/// (`docs/architecture.md` "Rasterization").
pub fn row_major<T: Copy, U>(tiling: &Tiling, tiles: &[U], field: impl Fn(&U) -> &[T]) -> Vec<T> {
    tiling.gather_row_major(|t| field(&tiles[t]))
}

/// Per pixel (row-major), whether it shows geometry (not background): the pixels whose
/// resolve can clamp.
pub fn receiver_pixels(frame: &Frame) -> Vec<bool> {
    frame
        .prim_ids()
        .iter()
        .map(|&p| p != crate::frame::BACKGROUND)
        .collect()
}

/// The element format of a colour target's single channel or its four channels, with the
/// values converted from the target's `u32` storage to the dump's.
pub fn color_values(format: ColorFormat, stored: impl Iterator<Item = u32>) -> DumpValues {
    match format {
        ColorFormat::Unorm8 => DumpValues::U8(stored.map(|v| v as u8).collect()),
        ColorFormat::F16 => DumpValues::F16(stored.map(|v| f16::from_bits(v as u16)).collect()),
        ColorFormat::F32 => DumpValues::F32(stored.map(f32::from_bits).collect()),
    }
}

/// Depth values as a dump stores them (D16 u16, D24 u32, D32F f32), from the depth buffer's
/// `u32` storage.
pub fn depth_values(format: DepthFormat, stored: impl Iterator<Item = u32>) -> DumpValues {
    match format {
        DepthFormat::D16 => DumpValues::U16(stored.map(|v| v as u16).collect()),
        DepthFormat::D24 => DumpValues::U32(stored.collect()),
        DepthFormat::D32F => DumpValues::F32(stored.map(f32::from_bits).collect()),
    }
}

/// The LI values of an LI buffer as a dump stores them (i16, or u8 for `Li8`).
pub fn li_values(format: LiFormat, li: &[i32]) -> DumpValues {
    match format {
        LiFormat::Li8 => DumpValues::U8(li.iter().map(|&v| v as u8).collect()),
        _ => DumpValues::I16(li.iter().map(|&v| v as i16).collect()),
    }
}

/// A V-buffer storage whose stored values a dump holds exactly (Paper III §4.1, §4.2).
pub trait VBufferDump: VBufferTile + Sized {
    /// The stored values of `tiles` (tiled by `tiling`), row-major, in the dump storage of
    /// [`ElementFormat::VBuffer`] of this format.
    fn dump_values(tiling: &Tiling, tiles: &[Self]) -> DumpValues;
}

impl VBufferDump for VBufferF32Tile {
    fn dump_values(tiling: &Tiling, tiles: &[Self]) -> DumpValues {
        DumpValues::F32(row_major(tiling, tiles, |t| &t.values))
    }
}

impl VBufferDump for VBufferF16Tile {
    fn dump_values(tiling: &Tiling, tiles: &[Self]) -> DumpValues {
        DumpValues::F16(row_major(tiling, tiles, |t| &t.values))
    }
}

impl VBufferDump for VBufferRgbTile {
    fn dump_values(tiling: &Tiling, tiles: &[Self]) -> DumpValues {
        DumpValues::F32(row_major(tiling, tiles, |t| &t.values).concat())
    }
}

impl VBufferDump for VBuffer8Tile {
    fn dump_values(tiling: &Tiling, tiles: &[Self]) -> DumpValues {
        let r = row_major(tiling, tiles, |t| &t.add);
        let g = row_major(tiling, tiles, |t| &t.sub);
        DumpValues::U8(r.iter().zip(&g).flat_map(|(r, g)| [*r, *g]).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn storage_matches_the_format_and_bytes_are_little_endian() {
        let d = BufferDump::new(
            "li",
            "test",
            (2, 1),
            ElementFormat::Li(LiFormat::Li16),
            DumpValues::I16(vec![-2, 300]),
        );
        assert_eq!(d.values.le_bytes(), vec![0xFE, 0xFF, 0x2C, 0x01]);
        assert_eq!(d.panels(), vec![("value".to_string(), vec![-2.0, 300.0])]);
        assert_eq!(Storage::I16.dtype(), "<i2");
    }

    #[test]
    #[should_panic(expected = "storage")]
    fn a_wrong_storage_is_a_bug() {
        BufferDump::new(
            "x",
            "",
            (1, 1),
            ElementFormat::Stencil8,
            DumpValues::I16(vec![0]),
        );
    }

    #[test]
    fn split_panel_is_the_reconstructed_value() {
        let f = SplitFormat::default();
        let rgba = f.split(0o1234);
        let d = BufferDump::new(
            "add",
            "",
            (1, 1),
            ElementFormat::SplitRgba8(f),
            DumpValues::U8(rgba.to_vec()),
        );
        assert_eq!(d.panels()[0].1, vec![0o1234 as f64 / 4095.0]);
    }

    #[test]
    fn nan_dumps_compare_by_bits() {
        let a = DumpValues::F32(vec![f32::NAN, 1.0]);
        assert_eq!(a, a.clone());
        assert_ne!(a, DumpValues::F32(vec![f32::NAN, -1.0]));
        assert_ne!(DumpValues::U8(vec![1]), DumpValues::I16(vec![1]));
    }
}
