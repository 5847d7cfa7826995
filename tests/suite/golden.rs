//! Golden outputs: every case of the catalog (`penumbra::golden::cases`: every method on the
//! foundation scenes and the knobs), rendered small and compared bit for bit with `golden/`,
//! counters included (see `penumbra::golden`). Re-bless with
//! `cargo run --release -- golden --bless` (or, this module only,
//! `PENUMBRA_BLESS=1 cargo test --test suite golden::`) only when a change of output is intended.

use std::path::Path;

#[test]
fn goldens_match() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("golden");
    let bless = std::env::var(penumbra::golden::BLESS_ENV).is_ok_and(|v| v == "1");
    if let Err(e) = penumbra::golden::run_cases(&root, bless) {
        panic!("{e}");
    }
}

#[test]
fn goldens_do_not_depend_on_thread_count() {
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    let group = &penumbra::golden::cases::groups()[0];
    let render = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| penumbra::golden::cases::render_group(base, group))
            .unwrap()
    };
    let (a, b) = (render(1), render(3));
    for ((case, x), (_, y)) in a.iter().zip(&b) {
        assert_eq!(
            x.visibility, y.visibility,
            "{} differs between 1 and 3 threads",
            case.method
        );
        assert_eq!(x.dumps, y.dumps);
        assert_eq!(x.stats.totals, y.stats.totals);
    }
}
