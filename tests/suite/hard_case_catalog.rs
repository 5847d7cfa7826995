//! The hard-case catalog (issue 15): every `scenes/hard/*.toml`, read from the directory in
//! sorted order so that a new scene is picked up without editing this file, rendered at 64²
//! (whatever size the file asks for) with every method that supports its light — whatever the
//! scene's `methods` list says — and the file's options (the stack scenes lower `nsample.n`).
//!
//! For every (scene, method):
//! * the method returns no error and does not panic;
//! * every visibility value is finite and in [0, 1];
//! * the methods that count values clamped to [0, 1] before the resolve (`clamped_pixels`:
//!   `pw2002`, `pw-restructured`, `ssv`, `ssv-optimized`, `wedge-blending`, and `dbuffer`'s
//!   clamp of t) clamp no pixel, unless [`CLAMPED`] pins a count;
//! * the output is the same bits with 1 and 2 worker threads (visibility, raw images, counters);
//! * the fraction of pixels that differ from the reference (`raycast`) by more than
//!   [`THRESHOLD`] is within the bound of [`TABLE`]. The count skips the pixels whose receiver
//!   plane cuts the light (the library's horizon receivers, `penumbra::metrics::horizon`, a
//!   sphere light taken as its disk facing the receiver; a face partly turned away from the
//!   light: the reference's rays to the part of the light behind the plane hit the receiver's
//!   own mesh, while the rasterized methods count only the shadow volumes of silhouettes; the
//!   shaded image multiplies those pixels by a small n·l); their number is printed, with the
//!   mean |e| over the whole-light and the horizon receivers. [`THRESHOLD`] = 0.05 is four
//!   times the largest difference the reference shows against itself with another seed on
//!   these scenes (0.0127), so a pixel over it is the method's, not the reference's noise.
//!
//! The count is taken on at least [`MIN_CONSIDERED`] of the scene's receiver pixels, so the
//! horizon exclusion cannot leave a bound to hold on a handful of pixels or on none.
//!
//! A bound is [`Bound::Correct`] when it follows from the math or a paper (a point light: the
//! hard shadow volume computes the reference's function; an exact method on single convex
//! occluders; a known limit of a paper such as Paper I's z-pass-only wedges) — as a fraction,
//! or ([`Bound::CorrectWhere`]) as the set of pixels where the arithmetic allows an error
//! (next to the reference's penumbra; on faces grazing the light), and
//! [`Bound::Pin`] when it is the code's measured output at the time the entry was written —
//! a regression fence, not a claim that the output is right; its `why` says what is wrong or
//! unexplained. A scene or method without an entry fails the test with a message naming it.
//! Findings: `docs/hard-cases.md`.

use penumbra::frame::Frame;
use penumbra::methods;
use penumbra::methods::output::MethodOutput;
use penumbra::metrics::error_report::error_report;
use penumbra::metrics::horizon::{receiver_classes, ReceiverClass};
use penumbra::scene::Scene;
use penumbra::visibility::Visibility;
use std::path::{Path, PathBuf};

/// A pixel differs from the reference when |method − raycast| exceeds this (module doc).
const THRESHOLD: f32 = 0.05;

/// The least share of a scene's receiver pixels (pixels with a receiver, horizon or not)
/// that the fraction over [`THRESHOLD`] is measured on, for every (scene, method): the horizon
/// exclusion may take the minority of them, never so many that a bound holds on a handful of
/// pixels (or vacuously on none). Every hard scene aims its light at a receiver that faces it
/// (each file's header), so more than half of the receivers see the whole light.
const MIN_CONSIDERED: f64 = 0.5;

/// The bound on the (non-straddling) pixels over [`THRESHOLD`].
#[derive(Debug, Clone, Copy)]
enum Bound {
    /// Follows from the math or a paper: a fraction.
    Correct { max_frac: f64, why: &'static str },
    /// Follows from the math: every pixel over the threshold is one of the [`Allowed`] pixels
    /// (so the fraction is at most theirs, whatever it is at this size).
    CorrectWhere { allowed: Allowed, why: &'static str },
    /// The code's current output, pinned (a fence against regressions).
    Pin { max_frac: f64, why: &'static str },
}

/// The pixels where a [`Bound::CorrectWhere`] allows a method to be off the reference.
#[derive(Debug, Clone, Copy)]
enum Allowed {
    /// Within this many pixels (rows and columns) of one where the reference is strictly
    /// between 0 and 1: umbra and lit regions agree with the reference, errors only in and
    /// next to its penumbra.
    NearPenumbra(usize),
    /// On a receiver whose plane holds the light's direction to within [`GRAZING`] (the cosine
    /// between the normal and the direction to the light center).
    Grazing,
}

/// The `|cos|` between a receiver's normal and the direction to the light under which
/// [`Allowed::Grazing`] counts it as grazing: f32 normals and points are rounded by a few
/// 10⁻⁸ relative, so a face parallel to the light to rounding has `|cos|` ≲ 3·10⁻⁷
/// (`far-point-light`'s side faces: `tests/suite/reference_agreement.rs`); 10⁻⁶ is three times that.
const GRAZING: f64 = 1e-6;

impl Bound {
    /// The fraction bound, for the entries that state one.
    fn max_frac(&self) -> Option<f64> {
        match *self {
            Bound::Correct { max_frac, .. } | Bound::Pin { max_frac, .. } => Some(max_frac),
            Bound::CorrectWhere { .. } => None,
        }
    }

    fn describe(&self) -> String {
        match *self {
            Bound::Correct { max_frac, why } => format!("correct ≤ {max_frac}: {why}"),
            Bound::CorrectWhere { allowed, why } => format!("correct, only {allowed:?}: {why}"),
            Bound::Pin { max_frac, why } => format!("PIN ≤ {max_frac}: {why}"),
        }
    }
}

/// Per pixel, whether it is one of the `allowed` pixels of `reference` (frame `receivers`,
/// light center `light`, image `width`).
fn allowed_pixels(
    allowed: Allowed,
    reference: &Visibility,
    receivers: &[Option<penumbra::frame::Receiver>],
    light: glam::DVec3,
    width: usize,
) -> Vec<bool> {
    let n = reference.len();
    match allowed {
        Allowed::NearPenumbra(r) => {
            let soft: Vec<bool> = (0..n)
                .map(|i| reference.rgb(i).iter().any(|&v| v > 0.0 && v < 1.0))
                .collect();
            let height = n / width;
            (0..n)
                .map(|i| {
                    let (x, y) = ((i % width) as i64, (i / width) as i64);
                    let r = r as i64;
                    (y - r..=y + r).any(|yy| {
                        (x - r..=x + r).any(|xx| {
                            (0..width as i64).contains(&xx)
                                && (0..height as i64).contains(&yy)
                                && soft[(yy * width as i64 + xx) as usize]
                        })
                    })
                })
                .collect()
        }
        Allowed::Grazing => receivers
            .iter()
            .map(|r| {
                r.as_ref().is_some_and(|r| {
                    let to_light = (light - r.point.as_dvec3()).normalize();
                    r.normal.as_dvec3().normalize().dot(to_light).abs() < GRAZING
                })
            })
            .collect(),
    }
}

use Bound::{Correct, CorrectWhere, Pin};

/// Exact methods on one convex occluder and the light in front of every receiver plane: only
/// the reference's jitter remains, below [`THRESHOLD`] everywhere — a few pixels along
/// silhouettes where rasterization and the receiver point differ are allowed.
const EXACT: Bound = Correct {
    max_frac: 0.002,
    why: "exact coverage of one convex occluder (Paper III §3; Forest et al. §4): noise only",
};

/// `nsample` takes N hard shadows; with N ≥ 64 its error is ≤ 1/(2√N)·(edges crossing the
/// light) ≤ 0.0625 per edge at N = 64 and 0.016 at N = 1024 (tests/suite/reference_agreement.rs).
const NSAMPLE: Bound = Correct {
    max_frac: 0.002,
    why: "N-sample average: sampling error below the threshold at N = 1024",
};

/// A point light: every method that runs computes the reference's function (the hard shadow
/// from one point), up to the rasterization of shadow-quad edges.
const POINT: Bound = Correct {
    max_frac: 0.001,
    why: "a point light: the hard shadow volume is the reference's function",
};

/// `far-origin-rect`: the box, floor and light stored as f32 at 10⁵ are rounded by at most
/// half an ulp, 0.0039, per coordinate (≤ 0.0055 horizontally), and every method's vertex
/// stage works on those rounded positions, as the reference does. A shadow boundary on the
/// floor moves with the occluder's edge magnified by h_light/(h_light − h_box) = 3/2.4 and
/// with the light by h_box/(h_light − h_box) = 0.25: at most 0.0055·1.5 ≈ 0.008 world units,
/// plus the f32 clip-space transform of coordinates of 10⁵ (an ulp of 0.0078, moving an edge
/// by about as much). A pixel at 64² with vfov 45° at ~3.5 from the eye is ~0.05 world units,
/// so umbra and lit stay where the reference has them, and an error can only be within a
/// pixel of the reference's penumbra ("the same contact shadow, no speckles on lit faces").
const FAR_ORIGIN: Bound = CorrectWhere {
    allowed: Allowed::NearPenumbra(1),
    why: "f32 rounding at 1e5 (≤ 0.0039 per coordinate) moves shadow boundaries by ≲ 0.02 world units, under a pixel (~0.05): errors only within a pixel of the penumbra",
};

/// `far-point-light`: a point light, so every method that runs computes the reference's
/// function (the hard shadow from one point; nsample's samples are all that point) —
/// except on receivers whose plane holds the light's direction to rounding (the block's
/// side faces, the light 10³⁰ straight above: |cos| ≤ 3·10⁻⁷), where the side quads of the
/// block's shadow volume lie in the face's plane and the depth test between them and the
/// face decides ([`GRAZING`]).
const FAR_POINT: Bound = CorrectWhere {
    allowed: Allowed::Grazing,
    why: "a point light: the hard shadow volume is the reference's function except on faces parallel to the light to rounding, where its side quads lie in the face",
};

/// `near-plane-1e-5`: the receivers are put on their triangle's plane, so the reference and
/// every method evaluate exact floor points; what D24 still rounds is the shadow volumes'
/// depth test against the floor, by a depth step of ~0.1 world units along the view ray at
/// the floor (the file's header: d²/(near·2²⁴)). That decides wrongly only where a shadow
/// quad passes within a step of the floor, i.e. next to where the quads meet it — the
/// shadow's boundaries, inside the reference's penumbra — within ~0.1 world units of them,
/// under two pixels (a pixel on the floor is ~0.06 across at ~4.7 from the eye).
const NEAR_PLANE: Bound = CorrectWhere {
    allowed: Allowed::NearPenumbra(2),
    why: "D24 misjudges the volumes' depth test only within a depth step (~0.1 world units, < 2 px) of where the shadow quads meet the floor: errors only next to the penumbra",
};

/// `stack-256-*` with `ssv`: the f32 V-buffer holds any count, and the visibility is
/// 1 − Σ (the fraction of the light each plate hides), clamped. Where no plate hides any of
/// the light the sum is 0 (lit, as the reference); where every plate hides all of it the
/// sum is 256 and clamps to 0 (umbra). Only where some plate hides part of the light — the
/// penumbra — can the sum exceed the union (Paper III §5.3, over-dark); a pixel the
/// reference's samples show lit or dark there (a sliver of the light its 1024 samples miss)
/// is next to the penumbra it does show.
const STACK_SSV: Bound = CorrectWhere {
    allowed: Allowed::NearPenumbra(1),
    why: "f32 V-buffer: 256 plates sum to 0 where lit and ≥ 1 where all hide the light, so umbra and lit are right; the summed penumbrae err only in (and next to) the penumbra",
};

/// `box-near-disk` with `dbuffer`: for one convex occluder the umbra volume holds exactly the
/// points that see none of the disk and the penumbra volume those that see part of it (CGI
/// 2004 §2–3: the volumes are bounded by the planes tangent to the disk and the occluder's
/// silhouette), so the D-buffer's lit and umbra regions are the reference's; V(t) only
/// approximates the visible fraction inside the penumbra. The volumes are rasterized into a
/// D-buffer whose texel covers less floor than a screen pixel, so a pixel can be misclassified
/// only where a volume's boundary passes within a texel of it: next to the reference's
/// penumbra.
const DBUFFER_CONVEX: Bound = CorrectWhere {
    allowed: Allowed::NearPenumbra(1),
    why: "one convex occluder: the umbra and penumbra volumes are exact (CGI 2004 §2–3), so lit and umbra agree with the reference; V(t) errs only in (and a texel next to) the penumbra",
};

/// `hard-sv` where the reference is lit or in umbra: a point that sees the whole light sees
/// its center, one that sees none of it does not, so the hard shadow from the center is the
/// reference's function outside the penumbra (and a pixel next to it, where the shadow quads'
/// rasterization and the receiver point differ).
const HARD_OUTSIDE_PENUMBRA: Bound = CorrectWhere {
    allowed: Allowed::NearPenumbra(1),
    why: "the hard shadow from the light center is right wherever the reference sees all or none of the light",
};

/// (scene file stem, method, bound).
const TABLE: &[(&str, &str, Bound)] = &[
    ("acute-corner-sphere", "nsample", NSAMPLE),
    ("acute-corner-sphere", "hard-sv", Pin { max_frac: 0.0312, why: "the hard shadow from the light center has no penumbra" }), // 125 px
    ("acute-corner-sphere", "pw2002", Pin { max_frac: 0.0237, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 95 px
    ("acute-corner-sphere", "pw-restructured", Pin { max_frac: 0.014, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 56 px
    ("acute-corner-sphere", "ssv-optimized", EXACT),
    ("acute-corner-sphere", "ssv", EXACT),
    ("acute-corner-sphere", "penumbra-map", Pin { max_frac: 0.0334, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 134 px
    ("acute-corners-sphere", "nsample", NSAMPLE),
    ("acute-corners-sphere", "hard-sv", Pin { max_frac: 0.1373, why: "the hard shadow from the light center has no penumbra" }), // 518 px
    ("acute-corners-sphere", "pw2002", Pin { max_frac: 0.0745, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 281 px
    ("acute-corners-sphere", "pw-restructured", Pin { max_frac: 0.0737, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 278 px
    ("acute-corners-sphere", "ssv-optimized", Pin { max_frac: 0.0385, why: "5° and 1° prisms 0.06 thick: silhouette from the light center only; not separated from the corner wedges" }), // 145 px
    ("acute-corners-sphere", "ssv", Pin { max_frac: 0.0382, why: "5° and 1° prisms 0.06 thick: silhouette from the light center only; not separated from the corner wedges" }), // 144 px
    ("acute-corners-sphere", "penumbra-map", Pin { max_frac: 0.1545, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 583 px
    ("bob-hole-rect", "nsample", NSAMPLE),
    ("bob-hole-rect", "hard-sv", Pin { max_frac: 0.0347, why: "the hard shadow from the light center has no penumbra" }), // 140 px
    ("bob-hole-rect", "ssv-optimized", Pin { max_frac: 0.0033, why: "genus 1: two loops of hundreds of small edges, wedges of neighbouring edges overlap (Paper III §5.3)" }), // 13 px
    ("bob-hole-rect", "ssv", Pin { max_frac: 0.0033, why: "genus 1: two loops of hundreds of small edges, wedges of neighbouring edges overlap (Paper III §5.3)" }), // 13 px
    ("bob-hole-rect", "wedge-blending", Pin { max_frac: 0.0048, why: "5 loops blended with ε; the floor through the hole is lit, as in raycast (torus-hole-rect's dark hole does not appear: not investigated why)" }), // 19 px
    ("box-near-disk", "nsample", NSAMPLE),
    ("box-near-disk", "hard-sv", HARD_OUTSIDE_PENUMBRA),
    ("box-near-disk", "dbuffer", DBUFFER_CONVEX),
    ("box-on-floor-rect", "nsample", NSAMPLE),
    ("box-on-floor-rect", "hard-sv", Pin { max_frac: 0.0262, why: "the hard shadow from the light center has no penumbra" }), // 105 px
    ("box-on-floor-rect", "ssv-optimized", EXACT),
    ("box-on-floor-rect", "ssv", EXACT),
    ("box-on-floor-rect", "wedge-blending", EXACT),
    ("eye-in-shadow-sphere", "nsample", NSAMPLE),
    ("eye-in-shadow-sphere", "hard-sv", Pin { max_frac: 0.0987, why: "the hard shadow from the light center has no penumbra" }), // 396 px
    ("eye-in-shadow-sphere", "pw2002", Pin { max_frac: 0.4936, why: "Paper I counts wedges z-pass only: wrong where the eye's shadow volumes are (warned)" }), // 1982 px
    ("eye-in-shadow-sphere", "pw-restructured", Pin { max_frac: 0.0429, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate; z-fail (Paper II §5)" }), // 172 px
    ("eye-in-shadow-sphere", "ssv-optimized", EXACT),
    ("eye-in-shadow-sphere", "ssv", EXACT),
    ("eye-in-shadow-sphere", "penumbra-map", Pin { max_frac: 0.1022, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 410 px
    ("eye-in-wedge-rect", "nsample", NSAMPLE),
    ("eye-in-wedge-rect", "hard-sv", Pin { max_frac: 0.1275, why: "the hard shadow from the light center has no penumbra" }), // 512 px
    ("eye-in-wedge-rect", "ssv-optimized", EXACT),
    ("eye-in-wedge-rect", "ssv", EXACT),
    ("eye-in-wedge-rect", "wedge-blending", EXACT),
    ("far-origin-rect", "nsample", FAR_ORIGIN),
    ("far-origin-rect", "nsample", Pin { max_frac: 0.013, why: "f32 vertices at 1e5 rounded by ≤ 0.0039: nsample, ssv, wedge-blending all differ from raycast along the shadow edge" }), // 52 px
    ("far-origin-rect", "hard-sv", Pin { max_frac: 0.0242, why: "the hard shadow from the light center has no penumbra" }), // 97 px
    ("far-origin-rect", "ssv-optimized", FAR_ORIGIN),
    ("far-origin-rect", "ssv-optimized", Pin { max_frac: 0.013, why: "f32 vertices at 1e5 rounded by ≤ 0.0039: every method differs from raycast along the shadow edge (nsample too)" }), // 52 px
    ("far-origin-rect", "ssv", FAR_ORIGIN),
    ("far-origin-rect", "ssv", Pin { max_frac: 0.0152, why: "f32 vertices at 1e5 rounded by ≤ 0.0039: every method differs from raycast along the shadow edge (nsample too)" }), // 61 px
    ("far-origin-rect", "wedge-blending", FAR_ORIGIN),
    ("far-origin-rect", "wedge-blending", Pin { max_frac: 0.016, why: "f32 vertices at 1e5 rounded by ≤ 0.0039: every method differs from raycast along the shadow edge (nsample too)" }), // 64 px
    ("far-point-light", "nsample", FAR_POINT),
    ("far-point-light", "nsample", Pin { max_frac: 0.0033, why: "as hard-sv: 13 px on faces parallel to the light within 3e-7 (tests/suite/reference_agreement.rs)" }), // 13 px
    ("far-point-light", "hard-sv", FAR_POINT),
    ("far-point-light", "hard-sv", Pin { max_frac: 0.0033, why: "13 px on faces parallel to the light within 3e-7: side quad fights in depth (tests/suite/reference_agreement.rs)" }), // 13 px
    ("far-sun-sphere", "nsample", NSAMPLE),
    ("far-sun-sphere", "hard-sv", Pin { max_frac: 0.0003, why: "the hard shadow from the light center has no penumbra" }), // 1 px
    ("far-sun-sphere", "pw2002", Pin { max_frac: 0.0003, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 1 px
    ("far-sun-sphere", "pw-restructured", Pin { max_frac: 0.0003, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 1 px
    ("far-sun-sphere", "ssv-optimized", EXACT),
    ("far-sun-sphere", "ssv", EXACT),
    ("far-sun-sphere", "penumbra-map", Pin { max_frac: 0.0038, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 15 px
    ("hand-close-rect", "nsample", NSAMPLE),
    ("hand-close-rect", "hard-sv", Pin { max_frac: 0.1961, why: "the hard shadow from the light center has no penumbra" }), // 799 px
    ("hand-close-rect", "ssv-optimized", Pin { max_frac: 0.0015, why: "real non-convex mesh (fingers): wedges of neighbouring silhouette edges overlap (Paper III §5.3)" }), // 6 px
    ("hand-close-rect", "ssv", Pin { max_frac: 0.0015, why: "real non-convex mesh (fingers): wedges of neighbouring silhouette edges overlap (Paper III §5.3)" }), // 6 px
    ("hand-close-rect", "wedge-blending", Pin { max_frac: 0.0381, why: "the silhouette from the light center is several loops of one mesh (6), blended with the ε of independent occluders (Forest et al. §5); not separated per pixel" }), // 155 px
    ("hand-close-sphere", "nsample", NSAMPLE),
    ("hand-close-sphere", "hard-sv", Pin { max_frac: 0.2046, why: "the hard shadow from the light center has no penumbra" }), // 834 px
    ("hand-close-sphere", "pw2002", Pin { max_frac: 0.3049, why: "penumbra wedges fail on real meshes (issue 28): the fingers' short silhouette edges, wedges overlapping; Paper I/II's falloff approximate" }), // 1243 px
    ("hand-close-sphere", "pw-restructured", Pin { max_frac: 0.198, why: "penumbra wedges fail on real meshes (issue 28): the fingers' short silhouette edges, wedges overlapping; Paper I/II's falloff approximate" }), // 807 px
    ("hand-close-sphere", "ssv-optimized", Pin { max_frac: 0.001, why: "real non-convex mesh (fingers): wedges of neighbouring silhouette edges overlap (Paper III §5.3)" }), // 4 px
    ("hand-close-sphere", "ssv", Pin { max_frac: 0.001, why: "real non-convex mesh (fingers): wedges of neighbouring silhouette edges overlap (Paper III §5.3)" }), // 4 px
    ("hand-close-sphere", "penumbra-map", Pin { max_frac: 0.2279, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 929 px
    ("hand-shell-rect", "nsample", Correct { max_frac: 0.002, why: "a shell counts 2 behind both sheets, still nonzero (Bergeron 1986), so each hard shadow is exact; N = 1024 sampling error below the threshold" }),
    ("hand-shell-rect", "hard-sv", Pin { max_frac: 0.1961, why: "the hard shadow from the light center has no penumbra; the same 799 px as hand-close-rect (counts of 2 read shadowed)" }), // 799 px
    ("hand-shell-rect", "ssv-optimized", Pin { max_frac: 0.1956, why: "shell: every silhouette edge has a twin on the back sheet, so every penumbra is summed twice, then clamped (docs/mesh-repair.md); 6 px closed" }), // 797 px
    ("hand-shell-rect", "ssv", Pin { max_frac: 0.1956, why: "shell: every silhouette edge has a twin on the back sheet, so every penumbra is summed twice, then clamped (docs/mesh-repair.md); 6 px closed" }), // 797 px
    ("hand-shell-rect", "wedge-blending", Pin { max_frac: 0.0874, why: "shell: twin silhouette edges on the two sheets (11 loops against 6 closed), each penumbra counted twice; 155 px closed" }), // 356 px
    ("hand-shell-sphere", "nsample", Correct { max_frac: 0.002, why: "a shell counts 2 behind both sheets, still nonzero (Bergeron 1986), so each hard shadow is exact; N = 1024 sampling error below the threshold" }),
    ("hand-shell-sphere", "hard-sv", Pin { max_frac: 0.2046, why: "the hard shadow from the light center has no penumbra" }), // 834 px
    ("hand-shell-sphere", "pw2002", Pin { max_frac: 0.2895, why: "fails closed too (issue 28; 1243 px on hand-close-sphere); as a shell every wedge has a twin on the back sheet, the LI buffer sums both (mean |e| 0.164 vs 0.114 closed, 128²)" }), // 1180 px
    ("hand-shell-sphere", "pw-restructured", Pin { max_frac: 0.2233, why: "fails closed too (issue 28; 807 px on hand-close-sphere); as a shell every wedge has a twin on the back sheet, the LI buffer sums both (mean |e| 0.121 vs 0.068 closed, 128²)" }), // 910 px
    ("hand-shell-sphere", "ssv-optimized", Pin { max_frac: 0.2053, why: "shell: every silhouette edge has a twin on the back sheet, so every penumbra is summed twice, then clamped (docs/mesh-repair.md); 4 px closed" }), // 837 px
    ("hand-shell-sphere", "ssv", Pin { max_frac: 0.2051, why: "shell: every silhouette edge has a twin on the back sheet, so every penumbra is summed twice, then clamped (docs/mesh-repair.md); 4 px closed" }), // 836 px
    ("hand-shell-sphere", "penumbra-map", Pin { max_frac: 0.2279, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation); a shadow map, the two sheets at one depth: the same 929 px as closed" }), // 929 px
    ("huge-light-rect", "nsample", NSAMPLE),
    ("huge-light-rect", "hard-sv", Pin { max_frac: 0.0438, why: "the hard shadow from the light center has no penumbra" }), // 175 px
    ("huge-light-rect", "ssv-optimized", Pin { max_frac: 0.0105, why: "light 100× the box: the silhouette from the light center is not the one most of the light sees" }), // 42 px
    ("huge-light-rect", "ssv", Pin { max_frac: 0.0103, why: "light 100× the box: the silhouette from the light center is not the one most of the light sees" }), // 41 px
    ("huge-light-rect", "wedge-blending", Pin { max_frac: 0.0108, why: "light 100× the box: the silhouette from the light center is not the one most of the light sees" }), // 43 px
    ("huge-light-sphere", "nsample", NSAMPLE),
    ("huge-light-sphere", "hard-sv", Pin { max_frac: 0.037, why: "the hard shadow from the light center has no penumbra" }), // 148 px
    ("huge-light-sphere", "pw2002", Pin { max_frac: 0.078, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 312 px
    ("huge-light-sphere", "pw-restructured", Pin { max_frac: 0.078, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 312 px
    ("huge-light-sphere", "ssv-optimized", Pin { max_frac: 0.0166, why: "light 100× the box: the silhouette from the light center is not the one most of the light sees" }), // 66 px
    ("huge-light-sphere", "ssv", Pin { max_frac: 0.0168, why: "light 100× the box: the silhouette from the light center is not the one most of the light sees" }), // 67 px
    ("huge-light-sphere", "penumbra-map", Pin { max_frac: 0.0681, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 272 px
    ("light-below-floor", "nsample", Correct { max_frac: 0.0, why: "every visible point is in the floor's umbra (light under it): visibility 0 everywhere" }),
    ("light-below-floor", "hard-sv", Correct { max_frac: 0.0, why: "every visible point is in the floor's umbra (light under it): visibility 0 everywhere" }),
    ("light-below-floor", "pw2002", Pin { max_frac: 0.6465, why: "Paper I counts wedges z-pass only: wrong where the eye's shadow volumes are (warned)" }), // 2516 px
    ("light-below-floor", "pw-restructured", Correct { max_frac: 0.0, why: "every visible point is in the floor's umbra (light under it): visibility 0 everywhere" }),
    ("light-below-floor", "ssv-optimized", Correct { max_frac: 0.0, why: "every visible point is in the floor's umbra (light under it): visibility 0 everywhere" }),
    ("light-below-floor", "ssv", Correct { max_frac: 0.0, why: "every visible point is in the floor's umbra (light under it): visibility 0 everywhere" }),
    ("light-below-floor", "penumbra-map", Correct { max_frac: 0.0, why: "every visible point is in the floor's umbra (light under it): visibility 0 everywhere" }),
    ("light-on-box-rect", "nsample", NSAMPLE),
    ("light-on-box-rect", "hard-sv", Pin { max_frac: 0.6442, why: "the hard shadow from the light center has no penumbra" }), // 2411 px
    ("light-on-box-rect", "ssv-optimized", Pin { max_frac: 0.6442, why: "silhouette from the light center only (Paper III/IV): box sides hiding the overhang missed" }), // 2411 px
    ("light-on-box-rect", "ssv", Pin { max_frac: 0.6442, why: "silhouette from the light center only (Paper III): the box sides hiding the overhang are missed, 0.64 vs 0.39" }), // 2411 px
    ("light-on-box-rect", "wedge-blending", Pin { max_frac: 0.6442, why: "silhouette from the light center only: the box sides hiding the overhang are missed" }), // 2411 px
    ("near-plane-1e-5", "nsample", NEAR_PLANE),
    ("near-plane-1e-5", "nsample", Pin { max_frac: 0.019, why: "D24 cannot hold the floor: receivers are snapped to their planes, the rasterized volumes still test D24 depths" }), // 76 px
    ("near-plane-1e-5", "hard-sv", NEAR_PLANE),
    ("near-plane-1e-5", "hard-sv", Pin { max_frac: 0.02, why: "the hard shadow from the light center has no penumbra" }), // 80 px
    ("near-plane-1e-5", "ssv-optimized", NEAR_PLANE),
    ("near-plane-1e-5", "ssv-optimized", Pin { max_frac: 0.0153, why: "D24 cannot hold the floor: receivers are snapped to their planes, the rasterized volumes still test D24 depths" }), // 61 px
    ("near-plane-1e-5", "ssv", NEAR_PLANE),
    ("near-plane-1e-5", "ssv", Pin { max_frac: 0.0075, why: "D24 cannot hold the floor: receivers are snapped to their planes, the rasterized volumes still test D24 depths" }), // 30 px
    ("near-plane-1e-5", "wedge-blending", NEAR_PLANE),
    ("near-plane-1e-5", "wedge-blending", Pin { max_frac: 0.0088, why: "D24 cannot hold the floor: receivers are snapped to their planes, the rasterized volumes still test D24 depths" }), // 35 px
    ("near-plane-cuts-volume-rect", "nsample", NSAMPLE),
    ("near-plane-cuts-volume-rect", "hard-sv", Pin { max_frac: 0.0088, why: "the hard shadow from the light center has no penumbra" }), // 35 px
    ("near-plane-cuts-volume-rect", "ssv-optimized", Pin { max_frac: 0.0033, why: "13 px, the same in ssv and wedge-blending: not investigated" }), // 13 px
    ("near-plane-cuts-volume-rect", "ssv", Pin { max_frac: 0.0033, why: "13 px, the same in ssv-optimized and wedge-blending: not investigated" }), // 13 px
    ("near-plane-cuts-volume-rect", "wedge-blending", Pin { max_frac: 0.0033, why: "13 px, the same in ssv and ssv-optimized: not investigated" }), // 13 px
    ("parallel-edge-point", "nsample", POINT),
    ("parallel-edge-point", "hard-sv", POINT),
    ("parallel-edge-rect", "nsample", NSAMPLE),
    ("parallel-edge-rect", "hard-sv", Pin { max_frac: 0.0302, why: "the hard shadow from the light center has no penumbra" }), // 121 px
    ("parallel-edge-rect", "ssv-optimized", Pin { max_frac: 0.0115, why: "faces at the edge are edge-on from the light center: its silhouette is not the light's (same 46 px in all three)" }), // 46 px
    ("parallel-edge-rect", "ssv", Pin { max_frac: 0.0115, why: "faces at the edge are edge-on from the light center: its silhouette is not the light's (same 46 px in all three)" }), // 46 px
    ("parallel-edge-rect", "wedge-blending", Pin { max_frac: 0.0115, why: "faces at the edge are edge-on from the light center: its silhouette is not the light's (same 46 px in all three)" }), // 46 px
    ("parallel-edge-sphere", "nsample", NSAMPLE),
    ("parallel-edge-sphere", "hard-sv", Pin { max_frac: 0.0274, why: "the hard shadow from the light center has no penumbra" }), // 110 px
    ("parallel-edge-sphere", "pw2002", Pin { max_frac: 0.0327, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 131 px
    ("parallel-edge-sphere", "pw-restructured", Pin { max_frac: 0.0254, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 102 px
    ("parallel-edge-sphere", "ssv-optimized", Pin { max_frac: 0.0103, why: "faces at the edge are edge-on from the light center: its silhouette is not the light's (as the rect light)" }), // 41 px
    ("parallel-edge-sphere", "ssv", Pin { max_frac: 0.0103, why: "faces at the edge are edge-on from the light center: its silhouette is not the light's (as the rect light)" }), // 41 px
    ("parallel-edge-sphere", "penumbra-map", Pin { max_frac: 0.0287, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 115 px
    ("quad-plane-receiver", "nsample", NSAMPLE),
    ("quad-plane-receiver", "hard-sv", Pin { max_frac: 0.1895, why: "the hard shadow from the light center has no penumbra" }), // 665 px
    ("quad-plane-receiver", "ssv-optimized", Pin { max_frac: 0.0285, why: "receivers on a hard shadow quad's plane (Paper IV §4.4) and the slab's overhang; not separated" }), // 100 px
    ("quad-plane-receiver", "ssv", Pin { max_frac: 0.0285, why: "receivers on a hard shadow quad's plane and the slab's overhang; not separated" }), // 100 px
    ("quad-plane-receiver", "wedge-blending", Pin { max_frac: 0.026, why: "receivers on a hard shadow quad's plane and the slab's overhang; not separated" }), // 91 px
    ("scorpion-legs-disk", "nsample", NSAMPLE),
    ("scorpion-legs-disk", "hard-sv", Pin { max_frac: 0.036, why: "the hard shadow from the light center has no penumbra" }), // 146 px
    ("scorpion-legs-disk", "dbuffer", Pin { max_frac: 0.0525, why: "concave occluder: the D-buffer keeps the farthest crossing, inner penumbra read as umbra (CGI 2004 §4 case 1), legs narrower than the light have no umbra (§4 case 2); not separated per pixel" }), // 213 px
    ("sliver-triangles-rect", "nsample", NSAMPLE),
    ("sliver-triangles-rect", "hard-sv", Pin { max_frac: 0.0892, why: "the hard shadow from the light center has no penumbra" }), // 358 px
    ("sliver-triangles-rect", "ssv-optimized", EXACT),
    ("sliver-triangles-rect", "ssv", EXACT),
    ("sliver-triangles-rect", "wedge-blending", EXACT),
    ("sliver-triangles-sphere", "nsample", NSAMPLE),
    ("sliver-triangles-sphere", "hard-sv", Pin { max_frac: 0.081, why: "the hard shadow from the light center has no penumbra" }), // 325 px
    ("sliver-triangles-sphere", "pw2002", Pin { max_frac: 0.0409, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 164 px
    ("sliver-triangles-sphere", "pw-restructured", Pin { max_frac: 0.0409, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 164 px
    ("sliver-triangles-sphere", "ssv-optimized", EXACT),
    ("sliver-triangles-sphere", "ssv", EXACT),
    ("sliver-triangles-sphere", "penumbra-map", Pin { max_frac: 0.0807, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 324 px
    ("spot-thin-sphere", "nsample", NSAMPLE),
    ("spot-thin-sphere", "hard-sv", Pin { max_frac: 0.0375, why: "the hard shadow from the light center has no penumbra" }), // 152 px
    ("spot-thin-sphere", "pw2002", Pin { max_frac: 0.0659, why: "penumbra wedges fail on real meshes (issue 28: short silhouette edges, wedges overlapping along the horns and ears); Paper I/II's falloff approximate" }), // 267 px
    ("spot-thin-sphere", "pw-restructured", Pin { max_frac: 0.0353, why: "penumbra wedges fail on real meshes (issue 28: short silhouette edges, wedges overlapping along the horns and ears); Paper I/II's falloff approximate" }), // 143 px
    ("spot-thin-sphere", "ssv-optimized", Pin { max_frac: 0.0111, why: "thin parts: silhouette loops of tiny edges whose wedges overlap (Paper III §5.3), and the silhouette from the light center only" }), // 45 px
    ("spot-thin-sphere", "ssv", Pin { max_frac: 0.0111, why: "thin parts: silhouette loops of tiny edges whose wedges overlap (Paper III §5.3), and the silhouette from the light center only" }), // 45 px
    ("spot-thin-sphere", "penumbra-map", Pin { max_frac: 0.0587, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 238 px
    ("stack-256-rect", "nsample", Pin { max_frac: 0.1066, why: "N hard renders with an 8-bit wrapping stencil: 256 volumes count 0, the umbra reads lit" }), // 428 px
    ("stack-256-rect", "hard-sv", Pin { max_frac: 0.1661, why: "8-bit stencil INCR_WRAP: 256 volumes count 0, the umbra under the stack reads lit" }), // 667 px
    ("stack-256-rect", "ssv-optimized", Pin { max_frac: 0.1437, why: "8-bit stencil umbra wraps at 256 and the split RGBA8 V-buffer saturates past 36 full adds" }), // 577 px
    ("stack-256-rect", "ssv", STACK_SSV),
    ("stack-256-rect", "ssv", Pin { max_frac: 0.1007, why: "f32 V-buffer holds the counts; Paper III §5.3: 256 penumbrae summed, overlap over-darkens" }), // 404 px
    ("stack-256-rect", "wedge-blending", Pin { max_frac: 0.0, why: "one silhouette per plate, blended (ε): overlap handled; transient per-loop stencil wraps cancel" }), // 0 px
    ("stack-256-sphere", "nsample", Pin { max_frac: 0.0909, why: "N hard renders with an 8-bit wrapping stencil: 256 volumes count 0, the umbra reads lit" }), // 365 px
    ("stack-256-sphere", "hard-sv", Pin { max_frac: 0.1592, why: "8-bit stencil INCR_WRAP: 256 volumes count 0, the umbra under the stack reads lit" }), // 639 px
    ("stack-256-sphere", "pw2002", Pin { max_frac: 0.216, why: "LI16 wrap: 255 − 255·n leaves [−32768, 32767] for n ≥ 130 umbrae and wraps to lit" }), // 867 px
    ("stack-256-sphere", "pw-restructured", Pin { max_frac: 0.216, why: "LI16 wrap as pw2002 (±255 umbra adds, single pass): n ≥ 130 umbrae wrap to lit" }), // 867 px
    ("stack-256-sphere", "ssv-optimized", Pin { max_frac: 0.1412, why: "8-bit stencil umbra wraps at 256 and the split RGBA8 V-buffer saturates past 36 full adds" }), // 567 px
    ("stack-256-sphere", "ssv", STACK_SSV),
    ("stack-256-sphere", "ssv", Pin { max_frac: 0.0982, why: "f32 V-buffer holds the counts; Paper III §5.3: 256 penumbrae summed, overlap over-darkens" }), // 394 px
    ("stack-256-sphere", "penumbra-map", Pin { max_frac: 0.1031, why: "a shadow map, no counts, no overflow; penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 414 px
    ("tiny-sphere-light", "nsample", NSAMPLE),
    ("tiny-sphere-light", "hard-sv", Pin { max_frac: 0.0003, why: "the hard shadow from the light center has no penumbra" }), // 1 px
    ("tiny-sphere-light", "pw2002", Pin { max_frac: 0.0003, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 1 px
    ("tiny-sphere-light", "pw-restructured", Pin { max_frac: 0.0003, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 1 px
    ("tiny-sphere-light", "ssv-optimized", EXACT),
    ("tiny-sphere-light", "ssv", EXACT),
    ("tiny-sphere-light", "penumbra-map", Pin { max_frac: 0.0122, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 49 px
    ("torus-hole-rect", "nsample", NSAMPLE),
    ("torus-hole-rect", "hard-sv", Pin { max_frac: 0.1319, why: "the hard shadow from the light center has no penumbra" }), // 524 px
    ("torus-hole-rect", "ssv-optimized", Pin { max_frac: 0.0005, why: "non-convex (two loops): 2 px measured" }), // 2 px
    ("torus-hole-rect", "ssv", Pin { max_frac: 0.0, why: "non-convex (two loops): measured exact, not derived" }), // 0 px
    ("torus-hole-rect", "wedge-blending", Pin { max_frac: 0.0831, why: "8-bit packing clamps the hole loop's −1 to 0: the hole stays dark (docs/wedge-blending.md)" }), // 330 px
    ("vertex-degree-sphere", "nsample", NSAMPLE),
    ("vertex-degree-sphere", "hard-sv", Pin { max_frac: 0.0852, why: "the hard shadow from the light center has no penumbra" }), // 333 px
    ("vertex-degree-sphere", "pw2002", Pin { max_frac: 0.0823, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 322 px
    ("vertex-degree-sphere", "pw-restructured", Pin { max_frac: 0.0591, why: "penumbra wedges: Paper I/II's linear-in-angle falloff and summed wedges, approximate" }), // 231 px
    ("vertex-degree-sphere", "ssv-optimized", Pin { max_frac: 0.0208, why: "silhouette vertices of degree > 2 (Paper V) and three overlapping crowns; not separated" }), // 82 px (81 with the bounding cube's wedges)
    ("vertex-degree-sphere", "ssv", Pin { max_frac: 0.0208, why: "silhouette vertices of degree > 2 (Paper V) and three overlapping crowns; not separated" }), // 81 px
    ("vertex-degree-sphere", "penumbra-map", Pin { max_frac: 0.111, why: "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen's approximation)" }), // 434 px
    ("zigzag-star-rect", "nsample", NSAMPLE),
    ("zigzag-star-rect", "hard-sv", Pin { max_frac: 0.1913, why: "the hard shadow from the light center has no penumbra" }), // 768 px
    ("zigzag-star-rect", "ssv-optimized", Pin { max_frac: 0.0302, why: "concave star: wedges of neighbouring silhouette edges overlap (Paper III §5.3)" }), // 121 px
    ("zigzag-star-rect", "ssv", Pin { max_frac: 0.0304, why: "concave star: wedges of neighbouring silhouette edges overlap (Paper III §5.3)" }), // 122 px
    ("zigzag-star-rect", "wedge-blending", Pin { max_frac: 0.0429, why: "concave star: blending per loop cannot fix one loop's own overlapping wedges" }), // 172 px
];

/// (scene file stem, method, pinned maximum of `clamped_pixels`): PINS, the counts measured when
/// the entry was written (over- and under-counts where occluders' or wedges' contributions
/// overlap: Paper III §5.3, Paper I §5); every other pair must clamp nothing.
const CLAMPED: &[(&str, &str, u64)] = &[
    ("acute-corner-sphere", "pw2002", 3),
    ("acute-corners-sphere", "pw2002", 104),
    ("acute-corners-sphere", "pw-restructured", 99),
    ("acute-corners-sphere", "ssv-optimized", 143),
    ("acute-corners-sphere", "ssv", 142),
    ("bob-hole-rect", "ssv-optimized", 11),
    ("bob-hole-rect", "ssv", 12),
    ("box-on-floor-rect", "ssv-optimized", 1),
    ("eye-in-shadow-sphere", "pw2002", 1616),
    ("far-origin-rect", "ssv", 1),
    ("hand-close-rect", "ssv-optimized", 29),
    ("hand-close-rect", "ssv", 31),
    ("hand-close-sphere", "pw2002", 471),
    ("hand-close-sphere", "pw-restructured", 187),
    ("hand-close-sphere", "ssv-optimized", 23),
    ("hand-close-sphere", "ssv", 30),
    ("hand-shell-rect", "ssv-optimized", 579),
    ("hand-shell-rect", "ssv", 579),
    ("hand-shell-sphere", "pw2002", 1107),
    ("hand-shell-sphere", "pw-restructured", 952),
    ("hand-shell-sphere", "ssv-optimized", 584),
    ("hand-shell-sphere", "ssv", 585),
    ("huge-light-rect", "ssv-optimized", 2),
    ("huge-light-sphere", "ssv-optimized", 2),
    ("light-below-floor", "pw-restructured", 165),
    ("light-below-floor", "ssv-optimized", 165),
    ("light-below-floor", "ssv", 165),
    ("light-on-box-rect", "ssv-optimized", 4),
    ("light-on-box-rect", "ssv", 4),
    ("near-plane-1e-5", "ssv-optimized", 2),
    ("near-plane-1e-5", "ssv", 24),
    ("parallel-edge-rect", "ssv-optimized", 1),
    ("parallel-edge-rect", "ssv", 1),
    ("parallel-edge-sphere", "ssv-optimized", 1),
    ("quad-plane-receiver", "ssv-optimized", 177),
    ("quad-plane-receiver", "ssv", 207),
    ("scorpion-legs-disk", "dbuffer", 1),
    ("spot-thin-sphere", "pw2002", 387),
    ("spot-thin-sphere", "pw-restructured", 226),
    ("spot-thin-sphere", "ssv-optimized", 197),
    ("spot-thin-sphere", "ssv", 200),
    ("stack-256-rect", "ssv-optimized", 770),
    ("stack-256-rect", "ssv", 963),
    ("stack-256-sphere", "pw2002", 978),
    ("stack-256-sphere", "pw-restructured", 978),
    ("stack-256-sphere", "ssv-optimized", 808),
    ("stack-256-sphere", "ssv", 954),
    ("tiny-sphere-light", "pw2002", 1),
    ("torus-hole-rect", "ssv-optimized", 1),
    ("vertex-degree-sphere", "pw2002", 460),
    ("vertex-degree-sphere", "pw-restructured", 328),
    // 326 with the bounding cube's wedges; the sphere's tight wedges (Paper IV §4.1) moved one
    // receiver 1.7e-5 from a hard-quad plane (coverage 0.4998) into the other half (§4.4).
    ("vertex-degree-sphere", "ssv-optimized", 327),
    ("vertex-degree-sphere", "ssv", 328),
    ("zigzag-star-rect", "ssv-optimized", 44),
    ("zigzag-star-rect", "ssv", 44),
];

fn hard_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hard")
}

fn scene_files() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(hard_dir())
        .expect("scenes/hard")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

fn stem(p: &Path) -> String {
    p.file_stem().unwrap().to_string_lossy().into_owned()
}

/// Render `scene` with `method` in a pool of `threads` workers.
fn render(scene: &Scene, method: &str, threads: usize) -> MethodOutput {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let gpu = penumbra::render::gpu_settings(scene).unwrap_or_else(|e| panic!("{e}"));
        let frame = Frame::render(scene, gpu).unwrap_or_else(|e| panic!("{e}"));
        methods::run(method, &frame).unwrap_or_else(|e| panic!("{method}: {e}"))
    })
}

/// Per pixel: whether the receiver's plane cuts the light (module doc): the library's
/// horizon receivers (`penumbra::metrics::horizon`, a sphere light as its disk facing the
/// receiver), and the class of every pixel for the printed split.
fn horizon_classes(
    scene: &Scene,
) -> (
    Vec<Option<ReceiverClass>>,
    Vec<Option<penumbra::frame::Receiver>>,
) {
    let frame = Frame::render(scene, penumbra::render::gpu_settings(scene).unwrap()).unwrap();
    (
        receiver_classes(&scene.lights, frame.receivers()),
        frame.receivers().to_vec(),
    )
}

fn check_values(v: &Visibility) -> Result<(), String> {
    for i in 0..v.len() {
        for x in v.rgb(i) {
            if !x.is_finite() || !(0.0..=1.0).contains(&x) {
                return Err(format!("pixel {i}: visibility {x}"));
            }
        }
    }
    Ok(())
}

#[test]
fn every_hard_scene_renders_with_every_method_within_its_bound() {
    let files = scene_files();
    assert!(files.len() >= 18, "{} scenes in scenes/hard", files.len());
    let mut failures = Vec::new();
    let mut seen = Vec::new();
    eprintln!(
        "{:<28} {:<16} {:>8} {:>6} {:>8} {:>9} {:>7} {:>10} {:>10}  bound",
        "scene",
        "method",
        "frac",
        "over",
        "straddle",
        "rec. used",
        "clamped",
        "whole |e|",
        "horizon|e|"
    );
    for path in &files {
        let name = stem(path);
        let mut scene = penumbra::scene::file::load_scene_file(path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        scene.width = 64;
        scene.height = 64;
        let (classes, receivers_of_pixels) = horizon_classes(&scene);
        let light = scene.lights[0].center.as_dvec3();
        let straddle: Vec<bool> = classes
            .iter()
            .map(|c| *c == Some(ReceiverClass::Horizon))
            .collect();
        let mut outputs: Vec<(String, MethodOutput)> = Vec::new();
        for m in methods::names() {
            if !methods::supports_scene(m, &scene) {
                continue;
            }
            let one = render(&scene, m, 1);
            let two = render(&scene, m, 2);
            if one.visibility != two.visibility
                || one.dumps != two.dumps
                || one.stats.totals != two.stats.totals
            {
                failures.push(format!("{name} {m}: differs between 1 and 2 threads"));
            }
            if let Err(e) = check_values(&one.visibility) {
                failures.push(format!("{name} {m}: {e}"));
            }
            let pinned = CLAMPED
                .iter()
                .find(|(s, mm, _)| *s == name && *mm == m)
                .map_or(0, |e| e.2);
            if one.stats.clamped_pixels > pinned {
                failures.push(format!(
                    "{name} {m}: clamped_pixels {} > {pinned} (add or update CLAMPED)",
                    one.stats.clamped_pixels
                ));
            }
            outputs.push((m.to_string(), one));
        }
        let reference = &outputs
            .iter()
            .find(|(m, _)| m == methods::REFERENCE)
            .expect("raycast runs on every scene")
            .1
            .visibility;
        for (m, out) in &outputs {
            if m == methods::REFERENCE {
                continue;
            }
            seen.push((name.clone(), m.clone()));
            let v = &out.visibility;
            let considered: Vec<usize> = (0..v.len()).filter(|&i| !straddle[i]).collect();
            // Not vacuous: the receivers counted are at least [`MIN_CONSIDERED`] of all.
            let receivers = classes.iter().filter(|c| c.is_some()).count();
            let considered_receivers = considered.iter().filter(|&&i| classes[i].is_some()).count();
            if (considered_receivers as f64) < MIN_CONSIDERED * receivers as f64 || receivers == 0 {
                failures.push(format!(
                    "{name} {m}: {considered_receivers} of {receivers} receiver pixels considered \
                     (< {MIN_CONSIDERED} of them: the horizon exclusion leaves too little)"
                ));
            }
            let over = considered
                .iter()
                .filter(|&&i| {
                    let (a, b) = (v.rgb(i), reference.rgb(i));
                    (0..3).any(|c| (a[c] - b[c]).abs() > THRESHOLD)
                })
                .count();
            let frac = over as f64 / considered.len().max(1) as f64;
            let entries: Vec<&Bound> = TABLE
                .iter()
                .filter(|(s, mm, _)| *s == name && mm == m)
                .map(|e| &e.2)
                .collect();
            let kind = if entries.is_empty() {
                "MISSING".to_string()
            } else {
                entries
                    .iter()
                    .map(|b| b.describe())
                    .collect::<Vec<_>>()
                    .join(" & ")
            };
            let is_over = |i: usize| {
                let (a, b) = (v.rgb(i), reference.rgb(i));
                (0..3).any(|c| (a[c] - b[c]).abs() > THRESHOLD)
            };
            // Diagnostics for choosing and checking `CorrectWhere` entries: the pixels over
            // the threshold outside each allowed set.
            let outside = |allowed| {
                let ok = allowed_pixels(
                    allowed,
                    reference,
                    &receivers_of_pixels,
                    light,
                    scene.width as usize,
                );
                considered.iter().filter(|&&i| is_over(i) && !ok[i]).count()
            };
            let outside_sets = [
                Allowed::NearPenumbra(0),
                Allowed::NearPenumbra(1),
                Allowed::NearPenumbra(2),
                Allowed::NearPenumbra(3),
                Allowed::Grazing,
            ]
            .map(outside);
            let split = error_report(v, reference, methods::REFERENCE, &classes).horizon_split;
            eprintln!(
                "{name:<28} {m:<16} {frac:>8.5} {over:>6} {:>8} {:>9} {:>7} {:>10.5} {:>10.5}  {kind}",
                v.len() - considered.len(),
                format!("{considered_receivers}/{receivers}"),
                out.stats.clamped_pixels,
                split.whole_light.mean_abs,
                split.horizon.mean_abs
            );
            eprintln!("    over outside near-penumbra 0..3 px, grazing: {outside_sets:?}");
            if entries.is_empty() {
                failures.push(format!(
                    "{name} {m}: no entry in TABLE (measured fraction {frac:.5} over \
                     {THRESHOLD}): add one to tests/suite/hard_case_catalog.rs — Correct if the bound \
                     follows from the math or a paper, else Pin with the reason"
                ));
            }
            for b in entries {
                match (b.max_frac(), b) {
                    (Some(max), _) if frac > max => failures.push(format!(
                        "{name} {m}: fraction {frac:.5} of pixels over {THRESHOLD} > {}",
                        b.describe()
                    )),
                    (None, CorrectWhere { allowed, .. }) => {
                        let n = outside(*allowed);
                        if n > 0 {
                            failures.push(format!(
                                "{name} {m}: {n} pixels over {THRESHOLD} outside the allowed \
                                 ones: {}",
                                b.describe()
                            ));
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    for (s, m, _) in TABLE {
        if !seen.iter().any(|(ss, mm)| ss == s && mm == m) {
            failures.push(format!(
                "TABLE entry ({s}, {m}) matches no scene and method"
            ));
        }
    }
    for (s, m, _) in CLAMPED {
        if !seen.iter().any(|(ss, mm)| ss == s && mm == m) {
            failures.push(format!(
                "CLAMPED entry ({s}, {m}) matches no scene and method"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Methods the hard-case catalog has no entry for yet, each with the reason: the list may only
/// shrink (the test below fails when a listed method gains an entry).
const NOT_IN_CATALOG: &[(&str, &str)] = &[(
    "raycast",
    "the reference every other method's bound is measured against",
)];

/// Every method of the registry (`methods::ALL`, "How to add a method" in
/// docs/architecture.md) is wired into everything that pins or measures methods: golden cases
/// and accuracy–time configurations (declared in the method's module, `Method::goldens` and
/// `Method::sweep`), and a hard-case catalog entry (or a reason in [`NOT_IN_CATALOG`]). The
/// criterion benchmarks of `benches/pipeline.rs` iterate the registry, so every method has one.
#[test]
fn every_method_has_goldens_catalog_entries_and_sweep_configurations() {
    let golden = penumbra::golden::cases::cases();
    let sweep = penumbra::experiment::accuracy_time::configurations();
    let mut missing = Vec::new();
    for m in methods::names() {
        if !golden.iter().any(|c| c.method == m) {
            missing.push(format!("{m}: no golden case (Method::goldens)"));
        }
        let listed = NOT_IN_CATALOG.iter().any(|(n, _)| *n == m);
        let in_catalog = TABLE.iter().any(|(_, method, _)| *method == m);
        match (in_catalog, listed) {
            (false, false) => missing.push(format!("{m}: no hard-case catalog entry (TABLE)")),
            (true, true) => missing.push(format!(
                "{m}: in the catalog now, remove it from NOT_IN_CATALOG"
            )),
            _ => {}
        }
        if !sweep.iter().any(|(method, _)| *method == m) {
            missing.push(format!(
                "{m}: no accuracy-time configuration (Method::sweep)"
            ));
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

/// Every scene of `scenes/hard/` has at least one entry whose bound comes from the math or a
/// paper ([`Bound::Correct`] or [`Bound::CorrectWhere`], e.g. `raycast`'s own noise), so that
/// no scene is held only by pins taken from the code's output; and every entry names a scene
/// that exists.
#[test]
fn every_hard_scene_has_a_derived_bound() {
    let scenes: Vec<String> = scene_files().iter().map(|p| stem(p)).collect();
    assert!(scenes.len() >= 30, "{} hard scenes", scenes.len());
    let only_pins: Vec<&String> = scenes
        .iter()
        .filter(|s| {
            !TABLE
                .iter()
                .any(|(scene, _, b)| scene == s && !matches!(b, Pin { .. }))
        })
        .collect();
    assert!(only_pins.is_empty(), "scenes with pins only: {only_pins:?}");
    let unknown: Vec<&str> = TABLE
        .iter()
        .map(|(scene, _, _)| *scene)
        .filter(|scene| !scenes.iter().any(|s| s == scene))
        .collect();
    assert!(unknown.is_empty(), "entries of no scene: {unknown:?}");
}
