//! Helpers shared by the integration tests: the `ssv` agreement check (`soft_shadow_volumes`,
//! `ssv_sphere`) and the horizon error and its checks (`horizon_clip`, `horizon_integrate`).

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

/// Mean |a − b| over the pixels where `mask` is set (NaN if the mask is empty, so a check on it
/// fails rather than passes).
pub fn mean_abs_over(a: &Visibility, b: &Visibility, mask: &[bool]) -> f64 {
    let idx: Vec<usize> = (0..mask.len()).filter(|&i| mask[i]).collect();
    idx.iter()
        .map(|&i| f64::from((a.gray(i) - b.gray(i)).abs()))
        .sum::<f64>()
        / idx.len() as f64
}

/// One method's horizon error before and after a horizon mode, the factor the mode must lower
/// it by (the check) and the measured values (the pins).
pub struct HorizonGain {
    /// The method's name.
    pub method: &'static str,
    /// `before ≥ factor · after` is required.
    pub factor: f64,
    /// The measured mean |e| before (e.g. `off`).
    pub before: f64,
    /// The measured mean |e| after (e.g. `clip`).
    pub after: f64,
    /// The pinned `before`, to 4 decimals.
    pub pin_before: f64,
    /// The pinned `after`, to 4 decimals.
    pub pin_after: f64,
}

/// Every gain reaches its factor, and the measured values equal their pins to 4 decimals.
/// `modes` names the two modes in the messages.
pub fn assert_horizon_gains(gains: &[HorizonGain], modes: (&str, &str)) {
    for g in gains {
        assert!(
            g.after * g.factor <= g.before,
            "{}: horizon error {} {}, {} {}",
            g.method,
            g.before,
            modes.0,
            g.after,
            modes.1
        );
        assert_eq!(
            (format!("{:.4}", g.before), format!("{:.4}", g.after)),
            (
                format!("{:.4}", g.pin_before),
                format!("{:.4}", g.pin_after)
            ),
            "{}: pins",
            g.method
        );
    }
}
