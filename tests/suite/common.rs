//! Helpers shared by the `ssv` integration tests (`soft_shadow_volumes`, `ssv_sphere`).

use penumbra::render::render_scene;
use penumbra::scene::Scene;
use penumbra::visibility::Visibility;

/// Jittered strata per side of the `raycast` reference (1024 samples).
pub const K: f64 = 32.0;

/// One value per pixel (the red channel of an RGB visibility).
pub fn gray(v: &Visibility) -> Vec<f32> {
    match v {
        Visibility::Gray(v) => v.clone(),
        Visibility::Rgb(v) => v.iter().map(|c| c[0]).collect(),
    }
}

/// Render `scene` with `raycast` and `ssv` and check the planar-occluder agreement of Paper
/// III §5.3: max |ssv − raycast| ≤ `max_tol` (derived by the caller) and mean ≤ 1/(2k); the
/// shadow must have a penumbra (> 50 pixels strictly between 0.05 and 0.95) and an umbra.
pub fn assert_ssv_agrees_with_raycast(mut scene: Scene, max_tol: f64, label: &str) {
    scene.methods = Some(vec!["raycast".into(), "ssv".into()]);
    let runs = render_scene(&scene).unwrap();
    let ssv = runs.iter().find(|r| r.method == "ssv").unwrap();
    let e = ssv.error.as_ref().expect("error vs the reference").all;
    eprintln!("{label}: ssv exact vs raycast {e:?}");
    assert!(e.max_abs <= max_tol, "max {} > {max_tol}", e.max_abs);
    assert!(
        e.mean_abs <= 1.0 / (2.0 * K),
        "mean {} > 1/(2k)",
        e.mean_abs
    );
    let vis = gray(&ssv.output.visibility);
    assert!(vis.iter().filter(|v| **v > 0.05 && **v < 0.95).count() > 50);
    assert!(vis.contains(&0.0), "the quad has an umbra");
}
