//! What the criterion benchmark files share.

use criterion::Criterion;
use std::time::Duration;

/// 10 samples of 2 s after 0.5 s of warm-up per benchmark: small samples and short
/// measurement windows, at the price of wider confidence intervals, so that each file runs in
/// minutes on a shared two-core machine. The HTML report
/// (`target/criterion/report/index.html`) is drawn by plotters with the crate's embedded font.
pub fn config() -> Criterion {
    penumbra::drawing::register_font().expect("the embedded font");
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
}
