//! `penumbra probe`: explain one pixel (`docs/architecture.md` "Probing one pixel").
//!
//! [`probe_pixel`] renders the scene pass, attaches a [`Probe`] to the frame and runs one
//! method: its own passes record every event at the pixel ([`crate::gpu::probe`]). The trace
//! ends with the method's resolve, whose value is the rendered pixel bit for bit; then comes
//! the reference — `raycast` with the scene's options, evaluated at that pixel alone — and the
//! method's error there. [`ProbeReport::text`] lists the events one per line in aligned
//! columns; the report serializes to JSON as the same content.
//!
//! Light samples (`nsample`'s renders, `raycast`'s rays) give thousands of events: unless
//! `verbose`, only the first [`SAMPLES_SHOWN`] samples' events are listed, and the resolve
//! summarizes all of them.

use crate::error::InputError;
use crate::gpu::probe::{check_chains, Probe, ProbeEvent};
use crate::methods;
use crate::scene::Scene;
use serde::Serialize;
use std::fmt::Write as _;
use std::sync::Arc;

/// How many light samples' events a listing shows without `verbose`.
pub const SAMPLES_SHOWN: u32 = 4;

/// Everything `penumbra probe` found at one pixel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProbeReport {
    /// The scene (built-in name or file).
    pub scene: String,
    /// Image width and height.
    pub size: [u32; 2],
    /// The method.
    pub method: String,
    /// The pixel (column, row; row 0 at the top).
    pub pixel: [u32; 2],
    /// The events listed (all, or those of the first [`SAMPLES_SHOWN`] light samples).
    pub events: Vec<ProbeEvent>,
    /// Events of further light samples left out of `events`.
    pub omitted_events: usize,
    /// For methods that sample the light (`nsample`, `raycast`): how many light samples the
    /// pixel has and how many of them light it (events with a `lit` value), over the whole
    /// trace.
    pub light_samples: Option<SampleCount>,
    /// The first event of the whole trace whose buffer value before differs from its value
    /// after the previous event ([`check_chains`]); `None` when every one chains.
    pub chain_break: Option<String>,
    /// The method's visibility at the pixel, per stored channel.
    pub visibility: Vec<f32>,
    /// The reference's visibility there (`raycast` with the scene's options).
    pub reference: Vec<f32>,
    /// The reference's sample count.
    pub reference_samples: u32,
    /// Method − reference, per channel.
    pub error: Vec<f32>,
}

/// Light samples of a pixel: all of them and those that light it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SampleCount {
    /// Light samples (summed over lights).
    pub total: usize,
    /// Samples that light the pixel.
    pub lit: usize,
}

/// Probe pixel (`x`, `y`) of `scene` rendered with `method` (module doc); `verbose` keeps every
/// light sample's events. Errors: a pixel outside the image (naming `--pixel`), an unknown
/// method or one that cannot render the scene's lights, and every error of a render.
pub fn probe_pixel(
    scene: &Scene,
    method: &str,
    [x, y]: [u32; 2],
    verbose: bool,
) -> Result<ProbeReport, InputError> {
    if x >= scene.width || y >= scene.height {
        return Err(InputError::at(
            "--pixel",
            format!("{x},{y}"),
            format!(
                "outside the {}×{} image (columns 0…{}, rows 0…{})",
                scene.width,
                scene.height,
                scene.width - 1,
                scene.height - 1
            ),
        ));
    }
    methods::check_option_tables(scene)?;
    methods::check_method(method, scene)?;
    let mut frame = crate::render::checked_frame(scene)?;
    let i = (y * scene.width + x) as usize;
    let mut mask = vec![false; frame.pixel_count()];
    mask[i] = true;
    let reference = methods::raycast::raycast_where(&frame, &mask, 0)?.channels(i);
    let probe = Arc::new(Probe::new(x, y));
    frame.probe = Some(probe.clone());
    let visibility = methods::run(method, &frame)?.visibility.channels(i);
    let all = probe.events();
    let shown: Vec<ProbeEvent> = all
        .iter()
        .filter(|e| verbose || e.scope.sample.is_none_or(|s| s < SAMPLES_SHOWN))
        .cloned()
        .collect();
    let verdicts: Vec<bool> = all
        .iter()
        .filter(|e| e.scope.sample.is_some())
        .flat_map(|e| e.values.iter().filter(|v| v.name == "lit"))
        .map(|v| v.value == 1.0)
        .collect();
    let light_samples = (!verdicts.is_empty()).then(|| SampleCount {
        total: verdicts.len(),
        lit: verdicts.iter().filter(|l| **l).count(),
    });
    let error = visibility
        .iter()
        .zip(reference.iter().cycle())
        .map(|(v, r)| v - r)
        .collect();
    Ok(ProbeReport {
        scene: scene.source.clone(),
        size: [scene.width, scene.height],
        method: method.into(),
        pixel: [x, y],
        omitted_events: all.len() - shown.len(),
        light_samples,
        chain_break: check_chains(&all).err(),
        events: shown,
        visibility,
        reference,
        reference_samples: methods::raycast::reference_samples(&frame)?,
        error,
    })
}

/// A computed value as the listing shows it: integers as such, others to 6 decimals (or in
/// scientific notation when small or large); the JSON keeps every bit.
fn short(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v}")
    } else if (1e-4..1e6).contains(&v.abs()) {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').to_string()
    } else {
        format!("{v:.4e}")
    }
}

/// The columns of one event line.
fn columns(k: usize, e: &ProbeEvent) -> [String; 8] {
    let s = &e.scope;
    let mut scope = Vec::new();
    for (name, v) in [
        ("light", s.light),
        ("sample", s.sample),
        ("piece", s.piece),
        ("loop", s.group),
    ] {
        if let Some(v) = v {
            scope.push(format!("{name} {v}"));
        }
    }
    let pass = if e.texel {
        format!("{} @texel({}, {})", e.pass, e.at[0], e.at[1])
    } else {
        e.pass.clone()
    };
    let primitive = e.primitive.as_ref().map_or(String::new(), |p| {
        let facing = match p.front_facing {
            Some(true) => " front",
            Some(false) => " back",
            None => "",
        };
        let detail = if p.detail.is_empty() {
            String::new()
        } else {
            format!(" ({})", p.detail)
        };
        format!("{} {}{detail}{facing}", p.kind.name(), p.index)
    });
    let depth = e.depth.map_or(String::new(), |d| {
        format!(
            "{:#x} {:?} {:#x} {}",
            d.fragment,
            d.func,
            d.stored,
            if d.pass { "pass" } else { "fail" }
        )
    });
    let values = e
        .values
        .iter()
        .map(|v| format!("{} {}", v.name, short(v.value)))
        .collect::<Vec<_>>()
        .join(", ");
    let buffer = e.buffer.as_ref().map_or(String::new(), |b| {
        let change = match &b.before {
            None => format!("{} := {}", b.buffer, b.after),
            Some(before) if *before == b.after => format!("{} = {}", b.buffer, b.after),
            Some(before) => format!("{} {} → {}", b.buffer, before, b.after),
        };
        match b.overflow {
            Some((kind, n)) => format!("{change} [{n}× {kind:?}]"),
            None => change,
        }
    });
    let note = match &e.resolve {
        Some(r) => format!(
            "visibility {}{}{}{}",
            r.visibility
                .iter()
                .map(f32::to_string)
                .collect::<Vec<_>>()
                .join(" "),
            if r.clamped { " (clamped)" } else { "" },
            if e.note.is_empty() { "" } else { "; " },
            e.note
        ),
        None => e.note.clone(),
    };
    [
        k.to_string(),
        scope.join(" "),
        pass,
        primitive,
        depth,
        values,
        buffer,
        note,
    ]
}

impl ProbeReport {
    /// The listing `penumbra probe` prints (module doc): a header, one line per event in
    /// aligned columns, then the reference and the error.
    pub fn text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "probe {} ({}×{}), pixel ({}, {}), method {}",
            self.scene, self.size[0], self.size[1], self.pixel[0], self.pixel[1], self.method
        );
        let header = [
            "#",
            "scope",
            "pass",
            "primitive",
            "depth test (fragment FUNC stored)",
            "computed",
            "buffer before → after",
            "result",
        ]
        .map(String::from);
        let rows: Vec<[String; 8]> = std::iter::once(header)
            .chain(self.events.iter().enumerate().map(|(k, e)| columns(k, e)))
            .collect();
        let widths: Vec<usize> = (0..8)
            .map(|c| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0))
            .collect();
        for r in &rows {
            let line: Vec<String> = r
                .iter()
                .zip(&widths)
                .map(|(cell, w)| format!("{cell:<w$}"))
                .collect();
            let _ = writeln!(s, "{}", line.join("  ").trim_end());
        }
        if self.omitted_events > 0 {
            let _ = writeln!(
                s,
                "… {} events of light samples {SAMPLES_SHOWN} and later not listed (--verbose \
                 lists them)",
                self.omitted_events
            );
        }
        if let Some(n) = self.light_samples {
            let _ = writeln!(
                s,
                "light samples: {}, lighting the pixel {}, occluded {}",
                n.total,
                n.lit,
                n.total - n.lit
            );
        }
        let join = |v: &[f32]| v.iter().map(f32::to_string).collect::<Vec<_>>().join(" ");
        let _ = writeln!(
            s,
            "{}: {}   reference (raycast, {} samples): {}   error: {}",
            self.method,
            join(&self.visibility),
            self.reference_samples,
            join(&self.reference),
            join(&self.error)
        );
        let _ = match &self.chain_break {
            None => writeln!(
                s,
                "trace: every buffer's value before each event equals its value after the one before"
            ),
            Some(e) => writeln!(s, "trace: INCONSISTENT: {e}"),
        };
        s
    }
}
