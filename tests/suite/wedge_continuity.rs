//! C0 continuity of the soft-shadow-volume sums across wedge boundaries (Paper III §3.1,
//! Paper IV §4.1): `ssv`, `ssv-optimized` and `wedge-blending` add an edge's coverage only
//! inside its wedge, so the sum over a silhouette is continuous where a receiver crosses a wedge
//! boundary exactly when the coverage the wedge leaves out is zero. Tested for random edges and
//! receivers between the edge and the floor, rectangular and spherical lights: outside the
//! wedge (beyond a margin of 1e-9 of the scene size), the edge's exact coverage is 0 within
//! 1e-12.

use glam::DVec3;
use penumbra::geometry::ssv_wedge::{SsvWedge, WedgeLight};
use penumbra::geometry::tight_wedge::{
    halves_from_planes, polyhedron_from_planes, sphere_wedge_halfspaces, wedge_halves_and_planes,
    whole_wedge, DEFAULT_SPHERE_SIDES,
};
use penumbra::light::coverage::{edge_coverage_exact, sphere_edge_coverage_exact, RectLight};
use proptest::prelude::*;

fn rect() -> RectLight {
    RectLight::new(
        DVec3::new(0.2, 3.0, -0.1),
        DVec3::new(0.6, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 0.4),
    )
}

const SPHERE_CENTER: DVec3 = DVec3::new(-0.3, 3.0, 0.2);
const SPHERE_RADIUS: f64 = 0.5;

fn point() -> impl Strategy<Value = DVec3> {
    (-2.5f64..2.5, 0.0f64..0.8, -2.5f64..2.5).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

fn edge() -> impl Strategy<Value = (DVec3, DVec3)> {
    (
        (-1.5f64..1.5, 1.0f64..2.2, -1.5f64..1.5),
        (-1.5f64..1.5, 1.0f64..2.2, -1.5f64..1.5),
    )
        .prop_map(|(a, b)| (DVec3::from(a), DVec3::from(b)))
        .prop_filter("a real edge", |(a, b)| (*a - *b).length() > 0.05)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Paper III's wedge (`ssv`), rectangle and sphere.
    #[test]
    fn ssv_wedges_hold_all_coverage((a, b) in edge(), p in point()) {
        let l = rect();
        if let Some(w) = SsvWedge::new(&WedgeLight::Rect(l), b, a) {
            if !w.contains_within(p, -1e-9) {
                let c = edge_coverage_exact(&l, p, b, a);
                prop_assert!(c.abs() <= 1e-12, "rect: coverage {c} outside the wedge");
            }
        }
        let light = WedgeLight::Sphere { center: SPHERE_CENTER, radius: SPHERE_RADIUS };
        if let Some(w) = SsvWedge::new(&light, b, a) {
            if !w.contains_within(p, -1e-9) {
                let c = sphere_edge_coverage_exact(SPHERE_CENTER, SPHERE_RADIUS, p, b, a);
                prop_assert!(c.abs() <= 1e-12, "sphere: coverage {c} outside the wedge");
            }
        }
    }

    /// Paper IV's tight wedge (`ssv-optimized`, and split in halves by `wedge-blending`).
    #[test]
    fn tight_wedges_hold_all_coverage((a, b) in edge(), p in point()) {
        let l = rect();
        let corners = l.corners();
        let (lo, hi) = (DVec3::splat(-4.0), DVec3::splat(4.0));
        let wedge = whole_wedge(l.center, &corners, a, b, lo, hi);
        if !wedge.is_empty() && !wedge.contains(p, 1e-9) {
            let c = edge_coverage_exact(&l, p, b, a);
            prop_assert!(c.abs() <= 1e-12, "coverage {c} outside the tight wedge");
        }
        let ([inner, outer], _) = wedge_halves_and_planes(l.center, &corners, a, b, lo, hi);
        let in_half = inner.contains(p, 1e-9) || outer.contains(p, 1e-9);
        if !in_half {
            let c = edge_coverage_exact(&l, p, b, a);
            prop_assert!(c.abs() <= 1e-12, "coverage {c} outside both halves");
        }
    }

    /// Paper IV's tight wedge of a sphere (`ssv-optimized`, the hull of the end pyramids over
    /// the circumscribed polygons of the silhouette disks, cut by Paper III's planes), with
    /// the default and the smallest polygon: outside the wedge and outside both halves the
    /// sphere's exact coverage is 0, and the wedge lies within Paper III's wedge.
    #[test]
    fn tight_sphere_wedges_hold_all_coverage((a, b) in edge(), p in point()) {
        let (lo, hi) = (DVec3::splat(-4.0), DVec3::splat(4.0));
        let c = SPHERE_CENTER;
        for sides in [DEFAULT_SPHERE_SIDES, 3] {
            let planes = sphere_wedge_halfspaces(c, SPHERE_RADIUS, sides, a, b);
            let wedge = polyhedron_from_planes(&planes, lo, hi);
            let cov = sphere_edge_coverage_exact(c, SPHERE_RADIUS, p, b, a);
            if !wedge.contains(p, 1e-9) {
                prop_assert!(cov.abs() <= 1e-12, "{sides} sides: coverage {cov} outside the wedge");
            }
            let [inner, outer] = halves_from_planes(&planes, c, a, b, lo, hi);
            if !(inner.contains(p, 1e-9) || outer.contains(p, 1e-9)) {
                prop_assert!(cov.abs() <= 1e-12, "{sides} sides: coverage {cov} outside both halves");
            }
            let light = WedgeLight::Sphere { center: c, radius: SPHERE_RADIUS };
            if let Some(w) = SsvWedge::new(&light, a, b) {
                if wedge.contains(p, -1e-9) {
                    prop_assert!(w.contains_within(p, 1e-9), "{sides} sides: {p} beyond Paper III's wedge");
                }
            }
        }
    }
}
