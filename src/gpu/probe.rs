//! One-pixel probes: what every pass did to one pixel, recorded by the passes themselves
//! (`penumbra probe`, `docs/architecture.md` "Probing one pixel").
//!
//! A [`Probe`] is attached to a frame ([`crate::frame::Frame::probe`]); every method's passes
//! then record, as they run, an ordered list of [`ProbeEvent`]s for the watched sample: which
//! primitive covered it, its depth test, the value the fragment program computed, the buffer
//! before and after as raw bits ([`Raw`]), overflow, wrap, saturation and clamp events, and the
//! final resolve. There is no second implementation of any pass: the same fragment programs
//! push events when the fragment they process is the watched one.
//!
//! # Where a pass watches
//!
//! A [`PassProbe`] names a pass and the samples of its render target it watches, as
//! (tile, index in the tile) of that target's tiling: the probed pixel for camera passes and
//! screen passes, the texels the screen pass will read for passes into maps seen from the
//! light. [`super::raster::draw`] compares the tile index once per tile and only in
//! the watched tile compares each fragment's sample; it hands the fragment program a [`Tap`]
//! for the watched fragment and `None` for every other one. With no probe attached nothing is
//! recorded and the output bits are the same (tested for every method).
//!
//! # Order and scope
//!
//! Events are appended in the order the renderer applied them: within a pass the watched
//! sample belongs to one tile, whose triangles run in submission order on one thread, and
//! passes run one after the other. Each event carries its [`Scope`]: the light (several
//! lights), the light sample (`nsample`), the light piece and the silhouette loop
//! (`ssv-optimized`), set by the code that runs those loops ([`Probe::enter`]).
//!
//! # Buffers
//!
//! An event that reads or changes a buffer carries a [`BufferChange`]: the buffer's name, its
//! value before (`None` for a clear, which starts the buffer) and after. For every buffer — one
//! name at one sample, whatever the scope: a buffer the lights share is written in each
//! light's scope, and a buffer used again is cleared first — each event's "before" equals the
//! previous event's "after" ([`check_chains`]).

use super::depth::{DepthFormat, DepthFunc};
use super::setup::RasterTriangle;
use super::tiling::{TileRect, Tiling};
use serde::Serialize;
use std::fmt;
use std::sync::Mutex;

/// A raw stored value, as the buffer holds its bits (module doc, "Buffers"). Displayed as the
/// integer, or for floats as the value and (f32, f16) its bits in hexadecimal.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Raw {
    /// An 8-bit unsigned value (stencil, unorm8 colour).
    U8(u8),
    /// A signed integer (the LI buffer, in its format's range).
    Int(i32),
    /// The bits of an f32.
    F32(u32),
    /// The bits of an IEEE binary16.
    F16(u16),
    /// The bits of an f64.
    F64(u64),
    /// A stored depth ([`DepthFormat::quantize`]).
    Depth(u32),
    /// The R and G channels of the 8-bit V-buffer (additive, subtractive).
    Rg8([u8; 2]),
    /// An RGBA8 pixel.
    Rgba8([u8; 4]),
    /// A 32-bit word of packed bytes (PK4UB).
    Word(u32),
    /// Several channels.
    Channels(Vec<Raw>),
}

impl fmt::Display for Raw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Raw::U8(v) => write!(f, "{v}"),
            Raw::Int(v) => write!(f, "{v}"),
            Raw::F32(b) => write!(f, "{} [{b:08x}]", f32::from_bits(*b)),
            Raw::F16(b) => write!(f, "{} [{b:04x}]", half::f16::from_bits(*b)),
            Raw::F64(b) => write!(f, "{}", f64::from_bits(*b)),
            Raw::Depth(v) => write!(f, "{v:#x}"),
            Raw::Rg8([r, g]) => write!(f, "R{r} G{g}"),
            Raw::Rgba8(c) => write!(f, "[{} {} {} {}]", c[0], c[1], c[2], c[3]),
            Raw::Word(w) => write!(f, "{w:08x}"),
            Raw::Channels(cs) => {
                let parts: Vec<String> = cs.iter().map(Raw::to_string).collect();
                write!(f, "({})", parts.join(", "))
            }
        }
    }
}

impl Raw {
    /// An f32 value's bits.
    pub fn f32(v: f32) -> Self {
        Raw::F32(v.to_bits())
    }
}

/// What happened to a value that did not fit its storage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Overflow {
    /// Wrapped modulo 2^bits (`GL_INCR_WRAP`, an LI buffer with `overflow = wrap`).
    Wrap,
    /// Stuck at the end of the range (`GL_INCR`, saturating blending, `overflow = saturate`).
    Saturate,
    /// A float result that is not finite.
    NonFinite,
    /// Clamped by a conversion (unorm8, PK4UB).
    Clamp,
}

/// A buffer write at the watched sample (module doc, "Buffers").
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BufferChange {
    /// The buffer, e.g. `stencil`, `li`, `vbuffer`, `split-add`.
    pub buffer: String,
    /// The value before; `None` for a clear.
    pub before: Option<Raw>,
    /// The value after.
    pub after: Raw,
    /// Overflow events of this write: their kind and number (e.g. saturated channels).
    pub overflow: Option<(Overflow, u64)>,
}

/// A depth test at the watched sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct DepthTest {
    /// The fragment's quantized depth.
    pub fragment: u32,
    /// The stored depth it was compared with.
    pub stored: u32,
    /// The comparison, `fragment FUNC stored`.
    pub func: DepthFunc,
    /// The storage format of both.
    pub format: DepthFormat,
    /// Whether it passed.
    pub pass: bool,
}

/// The kind of primitive a fragment came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PrimitiveKind {
    /// A triangle of a hard shadow-volume quad (`detail`: its silhouette edge).
    ShadowQuad,
    /// A front-cap triangle of a z-fail shadow volume.
    FrontCap,
    /// A triangle of a hard shadow volume, quad or cap (`detail`: whose volume).
    VolumeTriangle,
    /// A back-cap triangle (at infinity) of a z-fail shadow volume.
    BackCap,
    /// A face triangle of a penumbra wedge or soft-shadow-volume wedge.
    Wedge,
    /// A face triangle of half a wedge (Paper IV §4.4, Forest et al. §4.2).
    HalfWedge,
    /// A top or bottom cap of the penumbra-wedge volumes (Paper II §5).
    WedgeCap,
    /// The umbra quad of a degenerate penumbra wedge.
    UmbraQuad,
    /// A full-screen triangle drawn for a volume around the eye.
    FullScreen,
    /// A penumbra-map cone triangle.
    Cone,
    /// A penumbra-map sheet triangle.
    Sheet,
    /// A scene triangle drawn into a map seen from the light.
    SceneTriangle,
    /// An umbra-volume triangle of the D-buffer.
    UmbraVolume,
    /// A penumbra-volume triangle of the D-buffer.
    PenumbraVolume,
    /// A silhouette (a whole silhouette's buffer, wedge blending).
    Silhouette,
    /// A light sample (a shadow ray or one hard-shadow render).
    LightSample,
}

impl PrimitiveKind {
    /// The kebab-case name the listing prints.
    pub fn name(self) -> &'static str {
        match self {
            PrimitiveKind::ShadowQuad => "shadow-quad",
            PrimitiveKind::FrontCap => "front-cap",
            PrimitiveKind::VolumeTriangle => "volume-triangle",
            PrimitiveKind::BackCap => "back-cap",
            PrimitiveKind::Wedge => "wedge",
            PrimitiveKind::HalfWedge => "half-wedge",
            PrimitiveKind::WedgeCap => "wedge-cap",
            PrimitiveKind::UmbraQuad => "umbra-quad",
            PrimitiveKind::FullScreen => "full-screen",
            PrimitiveKind::Cone => "cone",
            PrimitiveKind::Sheet => "sheet",
            PrimitiveKind::SceneTriangle => "scene-triangle",
            PrimitiveKind::UmbraVolume => "umbra-volume",
            PrimitiveKind::PenumbraVolume => "penumbra-volume",
            PrimitiveKind::Silhouette => "silhouette",
            PrimitiveKind::LightSample => "light-sample",
        }
    }
}

/// The primitive a fragment came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Primitive {
    /// What it is.
    pub kind: PrimitiveKind,
    /// Its index in the pass's submission order (a triangle, wedge, silhouette or sample).
    pub index: u32,
    /// What it belongs to, e.g. `edge 4 of caster 1` or `wedge 12 front`.
    pub detail: String,
    /// Its facing, for rasterized triangles.
    pub front_facing: Option<bool>,
}

/// A value a fragment program computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Value {
    /// Its name, e.g. `coverage`, `delta`, `I`, `t`.
    pub name: String,
    /// The value.
    pub value: f64,
}

/// The resolve of the watched pixel: a buffer's value turned into a visibility. The last
/// resolve of a trace is the method's output for the pixel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Resolve {
    /// The visibility per channel (one value for gray), as f32.
    pub visibility: Vec<f32>,
    /// Whether the value was clamped into [0, 1].
    pub clamped: bool,
}

/// Where an event happened (module doc, "Order and scope").
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Scope {
    /// The light (scenes with several lights).
    pub light: Option<u32>,
    /// The light sample (`nsample`'s renders, `raycast`'s rays).
    pub sample: Option<u32>,
    /// The light piece (`ssv-optimized`'s light splitting).
    pub piece: Option<u32>,
    /// The silhouette loop rendered into its own buffer (`ssv-optimized`'s overlap mode).
    pub group: Option<u32>,
}

/// One thing a pass did at the watched sample.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProbeEvent {
    /// Light, sample, piece and group.
    pub scope: Scope,
    /// The pass.
    pub pass: String,
    /// The watched sample: the pixel, or a texel of a map seen from the light.
    pub at: [u32; 2],
    /// Whether `at` is a texel of a light-view map rather than the pixel.
    pub texel: bool,
    /// The primitive, for rasterized passes.
    pub primitive: Option<Primitive>,
    /// The depth test, where there is one.
    pub depth: Option<DepthTest>,
    /// What the fragment program computed.
    pub values: Vec<Value>,
    /// The buffer write.
    pub buffer: Option<BufferChange>,
    /// The resolve, for the last pass.
    pub resolve: Option<Resolve>,
    /// What happened, in a few words (e.g. `outside the wedge: discarded`).
    pub note: String,
}

impl ProbeEvent {
    /// Set the primitive.
    pub fn primitive(
        mut self,
        kind: PrimitiveKind,
        index: u32,
        detail: impl Into<String>,
        front_facing: Option<bool>,
    ) -> Self {
        self.primitive = Some(Primitive {
            kind,
            index,
            detail: detail.into(),
            front_facing,
        });
        self
    }

    /// Set the depth test.
    pub fn depth(
        mut self,
        format: DepthFormat,
        func: DepthFunc,
        fragment: u32,
        stored: u32,
        pass: bool,
    ) -> Self {
        self.depth = Some(DepthTest {
            fragment,
            stored,
            func,
            format,
            pass,
        });
        self
    }

    /// Add a computed value.
    pub fn value(mut self, name: &str, value: f64) -> Self {
        self.values.push(Value {
            name: name.into(),
            value,
        });
        self
    }

    /// Set the buffer write: `buffer` went from `before` to `after` with `overflows` overflow
    /// events of `kind` (none when 0).
    pub fn write(
        mut self,
        buffer: &str,
        before: Raw,
        after: Raw,
        kind: Overflow,
        overflows: u64,
    ) -> Self {
        self.buffer = Some(BufferChange {
            buffer: buffer.into(),
            before: Some(before),
            after,
            overflow: (overflows > 0).then_some((kind, overflows)),
        });
        self
    }

    /// Set a clear of `buffer` to `value`.
    pub fn clear(mut self, buffer: &str, value: Raw) -> Self {
        self.buffer = Some(BufferChange {
            buffer: buffer.into(),
            before: None,
            after: value,
            overflow: None,
        });
        self
    }

    /// Set the resolve to `visibility`.
    pub fn resolve(mut self, visibility: &[f32], clamped: bool) -> Self {
        self.resolve = Some(Resolve {
            visibility: visibility.to_vec(),
            clamped,
        });
        self
    }

    /// Set the note.
    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.note = note.into();
        self
    }

    /// Set a read of `buffer`, which holds `value` (before and after are the same).
    pub fn read(mut self, buffer: &str, value: Raw) -> Self {
        self.buffer = Some(BufferChange {
            buffer: buffer.into(),
            before: Some(value.clone()),
            after: value,
            overflow: None,
        });
        self
    }

    /// Set the light of the scope (a primitive of one light in a buffer shared by all).
    pub fn light(mut self, light: u32) -> Self {
        self.scope.light = Some(light);
        self
    }

    /// Set the light sample of the scope.
    pub fn sample(mut self, sample: u32) -> Self {
        self.scope.sample = Some(sample);
        self
    }
}

/// The recorder of one probed pixel (module doc).
#[derive(Debug)]
pub struct Probe {
    pixel: [u32; 2],
    state: Mutex<State>,
}

#[derive(Debug, Default)]
struct State {
    scope: Scope,
    events: Vec<ProbeEvent>,
}

impl Probe {
    /// A probe of pixel (x, y) (column, row; row 0 at the top).
    pub fn new(x: u32, y: u32) -> Self {
        Self {
            pixel: [x, y],
            state: Mutex::new(State::default()),
        }
    }

    /// The probed pixel (column, row).
    pub fn pixel(&self) -> [u32; 2] {
        self.pixel
    }

    fn state(&self) -> std::sync::MutexGuard<'_, State> {
        // A panic while recording cannot leave the log half-written: every push is one call.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Set the scope for what follows until the guard is dropped (module doc, "Order and
    /// scope").
    pub fn enter(&self, set: impl FnOnce(&mut Scope)) -> ScopeGuard<'_> {
        let mut st = self.state();
        let previous = st.scope;
        set(&mut st.scope);
        ScopeGuard {
            probe: self,
            previous,
        }
    }

    /// The pass `name` watching the probed pixel of a camera pass tiled by `tiling`.
    pub fn pass(&self, name: &str, tiling: &Tiling) -> PassProbe<'_> {
        self.pass_at(name, tiling, &[self.pixel], false)
    }

    /// The pass `name` watching the samples `at` (column, row) of a render target tiled by
    /// `tiling`; `texel` says whether they are texels of a light-view map.
    pub fn pass_at(
        &self,
        name: &str,
        tiling: &Tiling,
        at: &[[u32; 2]],
        texel: bool,
    ) -> PassProbe<'_> {
        PassProbe {
            probe: self,
            pass: name.into(),
            texel,
            targets: at
                .iter()
                .map(|&[x, y]| Target {
                    at: [x, y],
                    tile: tiling.tile_of(x, y),
                    local: tiling.local(x, y),
                })
                .collect(),
        }
    }

    fn push(&self, mut e: ProbeEvent) {
        let mut st = self.state();
        let (own, scope) = (e.scope, st.scope);
        e.scope = Scope {
            light: own.light.or(scope.light),
            sample: own.sample.or(scope.sample),
            piece: own.piece.or(scope.piece),
            group: own.group.or(scope.group),
        };
        st.events.push(e);
    }

    /// The events recorded so far, in order.
    pub fn events(&self) -> Vec<ProbeEvent> {
        self.state().events.clone()
    }
}

/// Restores the previous scope when dropped ([`Probe::enter`]).
#[derive(Debug)]
pub struct ScopeGuard<'a> {
    probe: &'a Probe,
    previous: Scope,
}

impl Drop for ScopeGuard<'_> {
    fn drop(&mut self) {
        self.probe.state().scope = self.previous;
    }
}

/// One watched sample of a pass's render target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Target {
    at: [u32; 2],
    tile: usize,
    local: usize,
}

/// A pass and the samples it watches (module doc, "Where a pass watches").
#[derive(Debug)]
pub struct PassProbe<'a> {
    probe: &'a Probe,
    pass: String,
    texel: bool,
    targets: Vec<Target>,
}

impl PassProbe<'_> {
    /// Whether tile `t` holds a watched sample.
    #[inline]
    pub fn watches_tile(&self, t: usize) -> bool {
        self.targets.iter().any(|x| x.tile == t)
    }

    /// The tap of sample `local` of tile `t`, if it is watched.
    #[inline]
    pub fn tap(&self, t: usize, local: usize) -> Option<Tap<'_>> {
        self.targets
            .iter()
            .find(|x| x.tile == t && x.local == local)
            .map(|x| Tap {
                pass: self,
                at: x.at,
            })
    }

    /// The tap of sample (x, y), if it is watched.
    #[inline]
    pub fn tap_at(&self, x: u32, y: u32) -> Option<Tap<'_>> {
        self.targets.iter().find(|t| t.at == [x, y]).map(|t| Tap {
            pass: self,
            at: t.at,
        })
    }

    /// Whether row `y` holds a watched sample.
    #[inline]
    pub fn watches_row(&self, y: u32) -> bool {
        self.targets.iter().any(|t| t.at[1] == y)
    }

    /// The probe this pass records into.
    pub fn probe(&self) -> &Probe {
        self.probe
    }
}

/// The handle a fragment program gets for the watched fragment: it makes and records events.
#[derive(Debug, Clone, Copy)]
pub struct Tap<'a> {
    pass: &'a PassProbe<'a>,
    at: [u32; 2],
}

impl Tap<'_> {
    /// A new event of this pass at this sample.
    pub fn event(&self) -> ProbeEvent {
        ProbeEvent {
            scope: Scope::default(),
            pass: self.pass.pass.clone(),
            at: self.at,
            texel: self.pass.texel,
            primitive: None,
            depth: None,
            values: Vec::new(),
            buffer: None,
            resolve: None,
            note: String::new(),
        }
    }

    /// Record `event` (its scope completed from the probe's).
    pub fn push(&self, event: ProbeEvent) {
        self.pass.probe.push(event);
    }

    /// The watched sample (column, row).
    pub fn at(&self) -> [u32; 2] {
        self.at
    }
}

impl PassProbe<'_> {
    /// Record one event at the first watched sample (the probed pixel of a camera pass).
    pub fn record(&self, event: impl FnOnce(Tap) -> ProbeEvent) {
        if let Some(t) = self.targets.first() {
            let tap = Tap {
                pass: self,
                at: t.at,
            };
            tap.push(event(tap));
        }
    }

    /// Record, at each watched sample of tile `t` that `tri` covers outside the rectangle
    /// `drawn` (where the triangle is still rasterized; `None`: nowhere), that the triangle
    /// was rejected there before rasterization ([`super::hiz`]): `event` builds the
    /// primitive's event, `why` says by what.
    pub fn record_culled(
        &self,
        t: usize,
        tri: &RasterTriangle,
        drawn: Option<TileRect>,
        why: &str,
        event: impl Fn(Tap) -> ProbeEvent,
    ) {
        for x in self.targets.iter().filter(|x| x.tile == t) {
            let [px, py] = x.at;
            if tri.covers(px, py) && !drawn.is_some_and(|r| r.contains(px, py)) {
                let tap = Tap {
                    pass: self,
                    at: x.at,
                };
                tap.push(event(tap).note(why));
            }
        }
    }

    /// Record one event at every watched sample (e.g. the clear of a map).
    pub fn record_each(&self, event: impl Fn(Tap) -> ProbeEvent) {
        for t in &self.targets {
            let tap = Tap {
                pass: self,
                at: t.at,
            };
            tap.push(event(tap));
        }
    }
}

/// Check that every buffer's writes chain (module doc, "Buffers"): per buffer name and
/// sample, the first event is a clear and every later event's `before` equals the previous
/// `after` (a clear starts the chain again). Returns the first break as a message.
pub fn check_chains(events: &[ProbeEvent]) -> Result<(), String> {
    // Per buffer (name, sample, whether a texel): the last event that left a value, and it.
    type Buffer<'a> = (&'a str, [u32; 2], bool);
    let mut last: Vec<(Buffer, (usize, &Raw))> = Vec::new();
    for (k, e) in events.iter().enumerate() {
        let Some(b) = &e.buffer else { continue };
        let key = (b.buffer.as_str(), e.at, e.texel);
        let slot = last.iter().position(|(kk, _)| *kk == key);
        match (&b.before, slot) {
            (None, Some(s)) => last[s].1 = (k, &b.after),
            (None, None) => last.push((key, (k, &b.after))),
            (Some(before), Some(s)) => {
                let (j, after) = last[s].1;
                if before != after {
                    return Err(format!(
                        "event {k} ({}): {} before {before} but event {j} left {after}",
                        e.pass, b.buffer
                    ));
                }
                last[s].1 = (k, &b.after);
            }
            (Some(_), None) => {
                return Err(format!(
                    "event {k} ({}): {} written before it was cleared",
                    e.pass, b.buffer
                ))
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taps_only_the_watched_sample_and_scopes_nest() {
        let tiling = Tiling::new(16, 16, 8).unwrap();
        let probe = Probe::new(9, 3);
        let pass = probe.pass("p", &tiling);
        assert!(pass.watches_tile(1) && !pass.watches_tile(0));
        assert!(pass.tap(1, tiling.local(9, 3)).is_some());
        assert!(pass.tap(1, tiling.local(10, 3)).is_none());
        let tap = pass.tap_at(9, 3).unwrap();
        {
            let _light = probe.enter(|s| s.light = Some(1));
            let _sample = probe.enter(|s| s.sample = Some(4));
            tap.push(tap.event().clear("stencil", Raw::U8(0)).sample(7));
        }
        let write = |buffer, before, after| {
            tap.event()
                .write(buffer, Raw::U8(before), Raw::U8(after), Overflow::Wrap, 0)
        };
        tap.push(write("stencil", 0, 1));
        tap.push(write("li", 0, 1));
        let events = probe.events();
        assert_eq!(events[0].scope.light, Some(1));
        assert_eq!(events[0].scope.sample, Some(7));
        assert_eq!(events[1].scope, Scope::default());
        // The stencil chains across scopes; the LI buffer was never cleared.
        let e = check_chains(&events).unwrap_err();
        assert!(e.starts_with("event 2 (p): li written before"), "{e}");
    }

    #[test]
    fn chains_follow_before_and_after() {
        let tiling = Tiling::new(8, 8, 8).unwrap();
        let probe = Probe::new(1, 1);
        let pass = probe.pass("p", &tiling);
        let tap = pass.tap_at(1, 1).unwrap();
        tap.push(tap.event().clear("li", Raw::Int(255)));
        tap.push(
            tap.event()
                .write("li", Raw::Int(255), Raw::Int(0), Overflow::Wrap, 0),
        );
        assert_eq!(check_chains(&probe.events()), Ok(()));
        tap.push(
            tap.event()
                .write("li", Raw::Int(255), Raw::Int(0), Overflow::Wrap, 0),
        );
        let e = check_chains(&probe.events()).unwrap_err();
        assert!(e.contains("li before 255 but event 1 left 0"), "{e}");
    }
}
