//! Golden outputs: every case of the catalog (`penumbra::golden::cases`: each method's
//! `GOLDENS`, its foundation scenes and its knobs), rendered small and compared bit for bit
//! with `golden/`, counters included (see `penumbra::golden`). Re-bless only with
//! `cargo run --release -- golden --bless`, and only when a change of output is intended:
//! nothing here writes a golden.

use std::collections::BTreeSet;
use std::path::Path;

fn golden_root() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("golden")
}

#[test]
fn goldens_match() {
    if let Err(e) = penumbra::golden::run_cases(&golden_root(), false) {
        panic!("{e}");
    }
}

/// Every case, rendered in a pool of 1 thread and in one of 3, matches its golden (which
/// [`goldens_match`] checks in the suite's own pool): no output bit depends on the thread
/// count. The cases checked cover every method of the registry and every variant.
#[test]
fn goldens_do_not_depend_on_thread_count() {
    let cases = penumbra::golden::cases::cases();
    let methods: BTreeSet<&str> = cases.iter().map(|c| c.method).collect();
    let registry: BTreeSet<&str> = penumbra::methods::names().collect();
    assert_eq!(methods, registry, "every method has goldens");
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let report = pool
            .install(|| penumbra::golden::run_cases(&golden_root(), false))
            .unwrap_or_else(|e| panic!("with {threads} threads:\n{e}"));
        assert_eq!(
            report.lines().filter(|l| l.starts_with("ok ")).count(),
            cases.len(),
            "with {threads} threads: {report}"
        );
    }
}
