//! The GPU profiles of the cost model (`docs/gpu-model.md` "Profiles"): each GPU's figures,
//! read from `profiles.toml` (built into the program), each either **published** — a value and
//! the page or paper that prints it — or an **assumption** — a low and a high value and why, a
//! range the model carries into its low and high estimates. A profile that lacks a figure, has
//! a figure with neither a source nor an assumption, or a value that is not a positive finite
//! number is refused with the profile and the figure named.

use crate::options::{Accepted, OptionType};
use serde::Deserialize;
use std::sync::OnceLock;

/// The profiles built into the program.
pub const PROFILES_TOML: &str = include_str!("profiles.toml");

/// The profile the model uses when none is chosen (`[options.gpu] model`): the GeForce FX 5900
/// Ultra, the thesis' "latest available commodity graphics hardware" (Preface), the family
/// Paper III's shaders ran on (thesis §2.5.2), and the chip of the D-buffer paper's QuadroFX
/// 3000 (CGI 2004 §5) — one profile for every method, so that a table's modeled times compare.
pub const DEFAULT_PROFILE: &str = "geforce-fx-5900-ultra";

/// One figure of a profile: published, or an assumed range (module doc).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged, deny_unknown_fields)]
pub enum Figure {
    /// A value printed by `source`.
    Published {
        /// The value.
        value: f64,
        /// Where it is printed (a URL or a paper section, with the quoted words).
        source: String,
    },
    /// A value no source here prints: the range the model assumes.
    Assumed {
        /// The lowest plausible value.
        low: f64,
        /// The highest plausible value.
        high: f64,
        /// Why this range.
        assumption: String,
    },
}

impl Figure {
    /// The figure as a range `(low, high)` (a published value is both).
    pub fn range(&self) -> (f64, f64) {
        match self {
            Figure::Published { value, .. } => (*value, *value),
            Figure::Assumed { low, high, .. } => (*low, *high),
        }
    }

    /// Its source, or its assumption prefixed with "assumed:".
    pub fn provenance(&self) -> String {
        match self {
            Figure::Published { source, .. } => source.clone(),
            Figure::Assumed { assumption, .. } => format!("assumed: {assumption}"),
        }
    }

    fn check(&self, what: &str) -> Result<(), String> {
        let (low, high) = self.range();
        let text = match self {
            Figure::Published { source, .. } => source,
            Figure::Assumed { assumption, .. } => assumption,
        };
        if !(low.is_finite() && high.is_finite() && low > 0.0 && low <= high) {
            return Err(format!(
                "{what}: {low}..{high} is not a positive finite range"
            ));
        }
        if text.trim().is_empty() {
            return Err(format!("{what}: the source or assumption is empty"));
        }
        Ok(())
    }
}

/// One GPU's figures (units in `profiles.toml`'s header).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GpuProfile {
    /// The name `[options.gpu] model` and `penumbra list --gpus` use.
    pub id: String,
    /// The product, chip and year.
    pub name: String,
    /// Which of the reproduced papers ran on it (or none).
    pub papers: String,
    /// Core clock, MHz.
    pub core_clock_mhz: Figure,
    /// Fragment-program pipes (lanes on a current GPU).
    pub pixel_pipes: Figure,
    /// Colour pixels the ROPs write per clock.
    pub rops: Figure,
    /// Z/stencil-only pixels per clock.
    pub zstencil_per_clock: Figure,
    /// Fragment-program arithmetic operations per pipe per clock.
    pub alu_ops_per_pipe_per_clock: Figure,
    /// Peak memory bandwidth, GB/s (10⁹ bytes).
    pub memory_bandwidth_gbs: Figure,
    /// Triangle setup rate, millions per second.
    pub triangle_setup_mtris: Figure,
    /// Side of a hierarchical-Z tile in pixels.
    pub hiz_tile: Figure,
}

impl GpuProfile {
    /// Every figure with its name, in the order of the file.
    pub fn figures(&self) -> [(&'static str, &Figure); 8] {
        [
            ("core_clock_mhz", &self.core_clock_mhz),
            ("pixel_pipes", &self.pixel_pipes),
            ("rops", &self.rops),
            ("zstencil_per_clock", &self.zstencil_per_clock),
            (
                "alu_ops_per_pipe_per_clock",
                &self.alu_ops_per_pipe_per_clock,
            ),
            ("memory_bandwidth_gbs", &self.memory_bandwidth_gbs),
            ("triangle_setup_mtris", &self.triangle_setup_mtris),
            ("hiz_tile", &self.hiz_tile),
        ]
    }
}

/// The constants no vendor publishes, shared by every profile (`docs/gpu-model.md`
/// "Assumptions"): each an [`Figure::Assumed`] range.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Assumptions {
    /// The fraction of peak bandwidth a pass reaches.
    pub memory_efficiency: Figure,
    /// Fixed cost of a pass, µs.
    pub pass_overhead_us: Figure,
    /// Depth/stencil traffic is divided by this.
    pub z_compression: Figure,
    /// Coarse tiles the hierarchical Z tests per clock.
    pub hiz_tests_per_clock: Figure,
    /// Instruction slots of one transcendental function (`atan2`, `acos`, `tan`).
    pub transcendental_slots: Figure,
}

impl Assumptions {
    fn figures(&self) -> [(&'static str, &Figure); 5] {
        [
            ("memory_efficiency", &self.memory_efficiency),
            ("pass_overhead_us", &self.pass_overhead_us),
            ("z_compression", &self.z_compression),
            ("hiz_tests_per_clock", &self.hiz_tests_per_clock),
            ("transcendental_slots", &self.transcendental_slots),
        ]
    }
}

/// The profiles and the shared assumptions.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Profiles {
    /// The GPUs, in the file's order (oldest first).
    pub gpu: Vec<GpuProfile>,
    /// The shared assumptions.
    pub assumptions: Assumptions,
}

impl Profiles {
    /// The profile named `id`.
    pub fn get(&self, id: &str) -> Option<&GpuProfile> {
        self.gpu.iter().find(|g| g.id == id)
    }
}

/// Reads and checks profiles written as in `profiles.toml`; the error names the profile and
/// the figure.
pub fn parse_profiles(text: &str) -> Result<Profiles, String> {
    let profiles: Profiles = toml::from_str(text).map_err(|e| format!("GPU profiles: {e}"))?;
    for g in &profiles.gpu {
        for (what, f) in g.figures() {
            f.check(what)
                .map_err(|e| format!("GPU profile {:?}: {e}", g.id))?;
        }
    }
    for (what, f) in profiles.assumptions.figures() {
        if !matches!(f, Figure::Assumed { .. }) {
            return Err(format!(
                "GPU profiles: assumption {what} must be a range (low, high, assumption)"
            ));
        }
        f.check(what).map_err(|e| format!("GPU profiles: {e}"))?;
    }
    let mut ids: Vec<&str> = profiles.gpu.iter().map(|g| g.id.as_str()).collect();
    ids.sort_unstable();
    if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
        return Err(format!("GPU profiles: {:?} is listed twice", w[0]));
    }
    Ok(profiles)
}

/// The built-in profiles ([`PROFILES_TOML`]), read once. The file is part of the program and
/// checked by a test, so a failure here is a bug of the build, not of the user's input.
pub fn profiles() -> &'static Profiles {
    static PROFILES: OnceLock<Profiles> = OnceLock::new();
    PROFILES.get_or_init(|| {
        parse_profiles(PROFILES_TOML).expect("the built-in profiles.toml is valid (tested)")
    })
}

/// `penumbra list --gpus`: every profile, its figures with their sources or assumptions (the
/// default marked), then the shared assumptions.
pub fn listing() -> String {
    use std::fmt::Write as _;
    let p = profiles();
    let mut out = String::new();
    let range = |f: &Figure| match f.range() {
        (l, h) if l == h => format!("{l}"),
        (l, h) => format!("{l}–{h}"),
    };
    for g in &p.gpu {
        let default = if g.id == DEFAULT_PROFILE {
            " (default)"
        } else {
            ""
        };
        let _ = writeln!(out, "# {}{default}: {}", g.id, g.name);
        let _ = writeln!(out, "  papers: {}", g.papers);
        for (what, f) in g.figures() {
            let _ = writeln!(out, "  {what} = {}  [{}]", range(f), f.provenance());
        }
    }
    let _ = writeln!(out, "# assumptions shared by every profile");
    for (what, f) in p.assumptions.figures() {
        let _ = writeln!(out, "  {what} = {}  [{}]", range(f), f.provenance());
    }
    out
}

/// A chosen profile (`[options.gpu] model`, `--opt gpu.model=NAME`): its index in the built-in
/// [`profiles`], an [`OptionType`] whose spellings are the profiles' ids.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GpuModel(usize);

impl GpuModel {
    /// The profile.
    pub fn profile(self) -> &'static GpuProfile {
        &profiles().gpu[self.0]
    }

    /// The profile named `id`, if it is built in.
    pub fn named(id: &str) -> Option<Self> {
        profiles().gpu.iter().position(|g| g.id == id).map(GpuModel)
    }
}

impl Default for GpuModel {
    /// [`DEFAULT_PROFILE`].
    fn default() -> Self {
        GpuModel::named(DEFAULT_PROFILE).expect("the default profile is built in (tested)")
    }
}

impl serde::Serialize for GpuModel {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.profile().id)
    }
}

impl OptionType for GpuModel {
    type Allowed = ();
    fn everything() -> Self::Allowed {}
    fn read(text: &str, _: &Self::Allowed) -> Option<Self> {
        GpuModel::named(text)
    }
    fn accepted(_: &Self::Allowed) -> Accepted {
        Accepted::OneOf(profiles().gpu.iter().map(|g| g.id.clone()).collect())
    }
    fn written(self) -> String {
        self.profile().id.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The built-in file loads: the six GPUs (and the FX 5800 Ultra Paper III ran on),
    /// every figure with a source or an assumption, and the default among them.
    #[test]
    fn the_built_in_profiles_load_with_their_sources() {
        let p = parse_profiles(PROFILES_TOML).unwrap();
        for id in [
            "geforce3",
            "geforce-fx-5800-ultra",
            "geforce-fx-5900-ultra",
            "radeon-9700-pro",
            "geforce-6800-ultra",
            "geforce-7800-gtx",
            "rtx-4090",
        ] {
            let g = p.get(id).unwrap_or_else(|| panic!("{id} missing"));
            for (what, f) in g.figures() {
                assert!(!f.provenance().is_empty(), "{id}.{what}");
            }
        }
        assert!(p.get(DEFAULT_PROFILE).is_some());
        // Published figures the model's claims rest on (the issue: 2× z/stencil-only rate on
        // NV3x/NV4x, not on R300).
        let z = |id: &str| p.get(id).unwrap().zstencil_per_clock.range().0;
        let rop = |id: &str| p.get(id).unwrap().rops.range().0;
        assert_eq!(
            z("geforce-fx-5900-ultra"),
            2.0 * rop("geforce-fx-5900-ultra")
        );
        assert_eq!(z("geforce-6800-ultra"), 2.0 * rop("geforce-6800-ultra"));
        assert_eq!(z("radeon-9700-pro"), rop("radeon-9700-pro"));
    }

    fn without_line(starting: &str) -> String {
        PROFILES_TOML
            .lines()
            .filter(|l| !l.starts_with(starting))
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// A profile missing a figure is refused, naming the figure.
    #[test]
    fn a_profile_with_a_missing_figure_is_refused() {
        let text = PROFILES_TOML.replacen(
            "rops = { value = 4, source = \"https://comparegpus.com",
            "# rops removed = { value = 4, source = \"https://comparegpus.com",
            1,
        );
        assert_ne!(text, PROFILES_TOML);
        let e = parse_profiles(&text).unwrap_err();
        assert!(e.contains("rops"), "{e}");
        let e = parse_profiles(&without_line("memory_efficiency")).unwrap_err();
        assert!(e.contains("memory_efficiency"), "{e}");
    }

    /// A figure with neither a source nor an assumption, an empty source, a zero or a reversed
    /// range, and a published "assumption" are refused.
    #[test]
    fn figures_without_provenance_or_with_bad_values_are_refused() {
        let clock = "core_clock_mhz = { value = 200, source = \"https://www1.sharkyextreme.com";
        assert!(PROFILES_TOML.contains(clock));
        for bad in [
            "core_clock_mhz = { value = 200 }",
            "core_clock_mhz = { value = 200, source = \" \" }",
            "core_clock_mhz = { value = 0, source = \"x\" }",
            "core_clock_mhz = { low = 300, high = 200, assumption = \"x\" }",
            "core_clock_mhz = { value = nan, source = \"x\" }",
        ] {
            let text: String = PROFILES_TOML
                .lines()
                .map(|l| if l.starts_with(clock) { bad } else { l })
                .collect::<Vec<_>>()
                .join("\n");
            assert!(parse_profiles(&text).is_err(), "{bad}");
        }
        let published = PROFILES_TOML.replacen(
            "memory_efficiency = { low = 0.5, high = 0.85, assumption = \"the fraction",
            "memory_efficiency = { value = 0.7, source = \"the fraction",
            1,
        );
        let published = published.replacen("peak DRAM bandwidth a pass's access pattern reaches (page misses, read/write turnarounds)\" }", "peak\" }", 1);
        assert!(parse_profiles(&published).is_err());
    }
}
