use glam::DVec3;
use penumbra::geometry::ssv_wedge::*;
use penumbra::light::coverage::*;

#[test]
fn scratch() {
    let l = RectLight::new(
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, 0.0025107860565185547),
        DVec3::new(17.5, 9.775161743164063e-6, 0.0021437406539916992),
    );
    let e0 = DVec3::new(0.0, 0.0000000004656612873077393, 71932.0);
    let e1 = DVec3::new(0.0, 0.0000000004656612873077393, -87384.0);
    let p = DVec3::new(-21.5, 0.0, 0.000000029763516096181775);
    let w = SsvWedge::new(&WedgeLight::Rect(l), e0, e1).unwrap();
    println!("top {:?}", w.top);
    for h in &w.planes {
        println!("{:?} dist {:e}", h, h.distance(p));
    }
    println!("cov {}", edge_coverage_exact(&l, p, e0, e1));
    println!(
        "local p {} e0 {} e1 {}",
        l.local(p),
        l.local(e0),
        l.local(e1)
    );
    for c in l.corners() {
        println!("corner {c}");
    }
}
