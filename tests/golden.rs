//! Golden outputs: every built-in foundation scene with every method, rendered at 64×64 and
//! compared bit for bit with `golden/` (see `penumbra::golden`). Re-bless with
//! `cargo run --release -- golden --bless` (or `PENUMBRA_BLESS=1 cargo test --test golden`)
//! only when a change of output is intended.

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
    let case = &penumbra::golden::cases()[0];
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let many = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    let a = one.install(|| penumbra::golden::render_case(case)).unwrap();
    let b = many
        .install(|| penumbra::golden::render_case(case))
        .unwrap();
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.method, y.method);
        assert_eq!(
            x.output.visibility, y.output.visibility,
            "{} differs between 1 and 3 threads",
            x.method
        );
        assert_eq!(x.output.raw_images, y.output.raw_images);
    }
}
