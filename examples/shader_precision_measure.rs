//! Where the shader precision's error concentrates (`[options.gpu] shader`, issue 11): every
//! (receiver, silhouette edge) pair inside the edge's wedge on a 256² frame, the edge's exact
//! coverage (Paper III §3.2.2, for a sphere §5.3 / Paper IV §4.2.1) at fp24 and fp16 against
//! f64, and Paper I's light intensity (eq. 1–3) at receivers inside a penumbra wedge, split by
//! the configuration of the pair:
//!
//! * **grazing**: the receiver's surface within 0.2 of parallel to the light direction
//!   (`n·l < 0.2`, about 78° or more from the light);
//! * **near edge**: the receiver closer to the edge than 5% of its distance from the light
//!   center (a point on the occluder itself, next to its silhouette);
//! * **edge ∥ light**: the edge within 25° of the light ray through its middle
//!   (`|dir·ray| > 0.9`);
//! * **near center**: the edge's projection onto the light (rectangle) or its chord (sphere)
//!   passing within 0.1 of the light's center (half-widths 1).
//!
//! `cargo run --release --example shader_precision_measure` (scenes `cube-of-spheres`, rect
//! light, and `cube-of-spheres-sphere`, sphere light).

use glam::DVec3;
use penumbra::frame::{Frame, GpuSettings};
use penumbra::geometry::penumbra_wedge::{
    build_wedges, far_distance, light_intensity, shader_light_intensity, wedge_radius, WedgeOptions,
};
use penumbra::geometry::silhouette::{light_facing, possible_silhouettes};
use penumbra::geometry::ssv_wedge::{SsvWedge, WedgeLight};
use penumbra::gpu::shader_float::{Fp16, Fp24, ShaderFloat};
use penumbra::gpu::shader_vec::SVec3;
use penumbra::light::coverage::{
    clip_to_light_cone, edge_coverage_exact, projected_edge_in_light, shader_edge_coverage,
    shader_sphere_edge_coverage, sphere_edge_coverage_exact,
};
use penumbra::scene::builtin;

/// The categories of a pair (module doc), in this order.
const CATEGORIES: [&str; 4] = ["grazing", "near edge", "edge ∥ light", "near center"];

/// Sums of |Δ| per category (in / not in it) over the pairs.
#[derive(Default)]
struct Tally {
    pairs: usize,
    total: f64,
    big: usize,
    in_pairs: [usize; 4],
    in_sum: [f64; 4],
    in_big: [usize; 4],
}

impl Tally {
    fn add(&mut self, flags: [bool; 4], err: f64) {
        let big = err > 1.0 / 255.0;
        self.pairs += 1;
        self.total += err;
        self.big += big as usize;
        for (k, _) in flags.iter().enumerate().filter(|(_, f)| **f) {
            self.in_pairs[k] += 1;
            self.in_sum[k] += err;
            self.in_big[k] += big as usize;
        }
    }

    fn print(&self, label: &str) {
        println!(
            "{label}: {} pairs, mean |Δ| {:.2e}, {} pairs with |Δ| > 1/255",
            self.pairs,
            self.total / self.pairs.max(1) as f64,
            self.big
        );
        for (k, name) in CATEGORIES.iter().enumerate() {
            let share = |a: f64, b: f64| 100.0 * a / b.max(1e-300);
            println!(
                "  {:12} {:5.1}% of pairs carry {:5.1}% of the summed |Δ| and {:5.1}% of the pairs > 1/255",
                name,
                share(self.in_pairs[k] as f64, self.pairs as f64),
                share(self.in_sum[k], self.total),
                share(self.in_big[k] as f64, self.big as f64),
            );
        }
    }
}

fn main() {
    for name in ["cube-of-spheres", "cube-of-spheres-sphere"] {
        let mut scene = builtin::load(name).expect("built-in scene");
        scene.resize(Some(256), Some(256));
        let frame = Frame::render(&scene, GpuSettings::default()).expect("frame");
        let light = WedgeLight::from_light(scene.light()).expect("rect or sphere light");
        let c = light.center();
        let mut edges = Vec::new();
        for (mesh, adj) in frame.caster_meshes() {
            let facing = light_facing(mesh, c.as_vec3());
            for e in possible_silhouettes(mesh, adj, &facing) {
                let (e0, e1) = (e.b.as_dvec3(), e.a.as_dvec3());
                if let Some(w) = SsvWedge::new(&light, e0, e1) {
                    edges.push((e0, e1, w));
                }
            }
        }
        let receivers: Vec<_> = frame.receivers().iter().flatten().copied().collect();
        let mut tallies = [Tally::default(), Tally::default()];
        for r in &receivers {
            let p = r.point.as_dvec3();
            let l = (c - p).normalize();
            let grazing = r.normal.as_dvec3().dot(l).abs() < 0.2;
            for (e0, e1, w) in &edges {
                if !w.contains(p) {
                    continue;
                }
                let flags = pair_flags(&light, p, *e0, *e1, grazing);
                let (exact, fp24, fp16) = match light {
                    WedgeLight::Rect(rl) => (
                        edge_coverage_exact(&rl, p, *e0, *e1),
                        shader_edge_coverage::<Fp24>(&rl, p, *e0, *e1).to_f64(),
                        shader_edge_coverage::<Fp16>(&rl, p, *e0, *e1).to_f64(),
                    ),
                    WedgeLight::Sphere { center, radius } => (
                        sphere_edge_coverage_exact(center, radius, p, *e0, *e1),
                        shader_sphere_edge_coverage::<Fp24>(center, radius, p, *e0, *e1).to_f64(),
                        shader_sphere_edge_coverage::<Fp16>(center, radius, p, *e0, *e1).to_f64(),
                    ),
                };
                tallies[0].add(flags, (fp24 - exact).abs());
                tallies[1].add(flags, (fp16 - exact).abs());
            }
        }
        tallies[0].print(&format!("{name}: edge coverage, fp24"));
        tallies[1].print(&format!("{name}: edge coverage, fp16"));
        if let WedgeLight::Sphere { radius, .. } = light {
            pw_intensity(&frame, c, radius, &receivers);
        }
    }
}

/// Paper I's light intensity (eq. 1–3) at every receiver inside a penumbra wedge.
fn pw_intensity(frame: &Frame, c: DVec3, radius: f64, receivers: &[penumbra::frame::Receiver]) {
    let far = far_distance(frame.scene, c);
    let opts = WedgeOptions {
        center: c,
        radius: wedge_radius(radius, far),
        far,
        extra_corner_wedges: true,
        parallel_rule: true,
    };
    let set = build_wedges(&frame.caster_meshes(), &opts).expect("wedges");
    let light = WedgeLight::Sphere { center: c, radius };
    let mut tallies = [Tally::default(), Tally::default()];
    for r in receivers {
        let p = r.point.as_dvec3();
        let grazing = r.normal.as_dvec3().dot((c - p).normalize()).abs() < 0.2;
        for w in &set.wedges {
            if !w.contains(p) || w.a == w.b {
                continue;
            }
            let flags = pair_flags(&light, p, w.a, w.b, grazing);
            let exact = light_intensity(w, p, false);
            let fp24 = shader_light_intensity(w, SVec3::<Fp24>::from_f64(p), false).to_f64();
            let fp16 = shader_light_intensity(w, SVec3::<Fp16>::from_f64(p), false).to_f64();
            tallies[0].add(flags, (fp24 - exact).abs());
            tallies[1].add(flags, (fp16 - exact).abs());
        }
    }
    tallies[0].print("cube-of-spheres-sphere: Paper I light intensity, fp24");
    tallies[1].print("cube-of-spheres-sphere: Paper I light intensity, fp16");
}

/// The categories (module doc) of receiver `p` and edge `e0 e1`.
fn pair_flags(light: &WedgeLight, p: DVec3, e0: DVec3, e1: DVec3, grazing: bool) -> [bool; 4] {
    let c = light.center();
    let d = e1 - e0;
    let t = ((p - e0).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    let near_edge = (p - (e0 + d * t)).length() < 0.05 * (p - c).length();
    let mid = 0.5 * (e0 + e1);
    let parallel = d.normalize().dot((mid - c).normalize()).abs() > 0.9;
    let chord = match light {
        WedgeLight::Rect(rl) => projected_edge_in_light(rl, p, e0, e1),
        WedgeLight::Sphere { center, radius } => clip_to_light_cone(*center, *radius, p, e0, e1),
    };
    let near_center = chord.is_some_and(|[a, b]| {
        let len = (b - a).length();
        len > 0.0 && a.perp_dot(b).abs() / len < 0.1
    });
    [grazing, near_edge, parallel, near_center]
}
