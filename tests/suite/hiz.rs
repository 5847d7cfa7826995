//! The hierarchical-Z unit (`[options.gpu] hiz`, `penumbra::gpu::hiz`, issue 13): on and off
//! give the same output bits for every method on scenes that exercise z-pass, z-fail, every
//! light shape and several lights, and the counters show what it saved: fewer fragments
//! rasterized and shaded, the same overflow events and clamped pixels (a rejected tile held no
//! fragment that would have changed a buffer), and rejections where the passes use it.

use penumbra::gpu::counters::Counters;
use penumbra::methods;
use penumbra::render::{render_scene, MethodRun};
use penumbra::scene::builtin;
use penumbra::visibility::Visibility;

/// Every method `scene` (built-in, at 48²) supports, rendered with `hiz = on|off`.
fn runs(scene: &str, hiz: &str) -> Vec<MethodRun> {
    runs_with(scene, 48, &[format!("gpu.hiz={hiz}")])
}

/// Every method `scene` (built-in, at `size`²) supports, rendered with the `--opt` options
/// `opts`.
fn runs_with(scene: &str, size: u32, opts: &[String]) -> Vec<MethodRun> {
    let mut s = builtin::load(scene).unwrap();
    s.resize(Some(size), Some(size));
    s.methods = Some(
        methods::names()
            .filter(|m| methods::supports_scene(m, &s))
            .map(|m| m.to_string())
            .collect(),
    );
    for o in opts {
        s.set_cli_option(o).unwrap();
    }
    render_scene(&s).unwrap()
}

/// The bits of a visibility.
fn bits(v: &Visibility) -> Vec<u32> {
    match v {
        Visibility::Gray(v) => v.iter().map(|x| x.to_bits()).collect(),
        Visibility::Rgb(v) => v.iter().flatten().map(|x| x.to_bits()).collect(),
    }
}

/// The counters of every pass after the scene pass, summed.
fn method_passes(run: &MethodRun) -> Counters {
    let mut c = Counters::default();
    for p in run.output.stats.passes.iter().skip(1) {
        c += p.counters;
    }
    c
}

/// How many of the plan's buffers are the hierarchical-Z unit's ("tile zmin/zmax", "tile
/// receiver bounds"), those of its per-light plans included (a method run once per light).
fn hiz_buffers(run: &MethodRun) -> usize {
    let plan = &run.output.stats.plan;
    let per_light = plan["settings"]["per_light"]
        .as_array()
        .into_iter()
        .flatten();
    std::iter::once(plan)
        .chain(per_light)
        .flat_map(|p| p["buffers"].as_array().expect("plan.buffers"))
        .filter(|b| b["name"].as_str().is_some_and(|n| n.starts_with("tile ")))
        .count()
}

/// Scenes: z-pass on rectangle and sphere lights, the eye in shadow (z-fail), overlapping
/// occluders, two lights, Paper I's scene and the D-buffer's disk.
const SCENES: &[&str] = &[
    "cube-of-spheres",
    "cube-of-spheres-sphere",
    "eye-in-shadow",
    "overlap-stress",
    "two-lights",
    "pw-2002",
    "disk-block",
];

#[test]
fn hiz_on_and_off_give_the_same_bits_for_every_method() {
    for scene in SCENES {
        let (on, off) = (runs(scene, "on"), runs(scene, "off"));
        assert_eq!(on.len(), off.len(), "{scene}");
        for (a, b) in on.iter().zip(&off) {
            let at = format!("{scene}/{}", a.method);
            assert_eq!(a.method, b.method, "{at}");
            assert!(
                bits(&a.output.visibility) == bits(&b.output.visibility),
                "{at}: hiz changed the image"
            );
            assert_eq!(
                a.output.stats.clamped_pixels, b.output.stats.clamped_pixels,
                "{at}"
            );
            let (c_on, c_off) = (method_passes(a), method_passes(b));
            assert!(
                c_on.fragments_rasterized <= c_off.fragments_rasterized,
                "{at}: {} fragments with hiz, {} without",
                c_on.fragments_rasterized,
                c_off.fragments_rasterized
            );
            // pw-restructured's fragment program runs on every wedge fragment, inside or not;
            // a rejected tile holds only fragments outside (or behind every receiver).
            assert!(c_on.fragments_shaded <= c_off.fragments_shaded, "{at}");
            assert_eq!(c_on.overflow_events, c_off.overflow_events, "{at}");
            assert_eq!(
                (c_off.tiles_culled_hiz, c_off.hiz_read_bytes),
                (0, 0),
                "{at}: off"
            );
            // A pass reads the unit's bounds only when the plan lists them, and a plan
            // without the unit lists none.
            assert!(
                hiz_buffers(a) > 0 || c_on.hiz_read_bytes == 0,
                "{at}: reads unlisted"
            );
            assert_eq!(
                hiz_buffers(b),
                0,
                "{at}: plan lists HiZ buffers with hiz = off"
            );
        }
    }
}

/// The passes that consult the unit reject tiles on the default scene, and every rejection
/// saves fragments: a (tile, triangle) pair is rejected only where the triangle has some.
#[test]
fn hiz_rejects_tiles_in_the_passes_that_use_it() {
    let (on, off) = (
        runs("cube-of-spheres", "on"),
        runs("cube-of-spheres", "off"),
    );
    for method in [
        "hard-sv",
        "nsample",
        "ssv",
        "ssv-optimized",
        "wedge-blending",
    ] {
        let find =
            |rs: &[MethodRun]| method_passes(rs.iter().find(|r| r.method == method).expect("ran"));
        let (c_on, c_off) = (find(&on), find(&off));
        assert!(c_on.tiles_culled_hiz > 0, "{method}: nothing rejected");
        assert!(c_on.hiz_read_bytes > 0, "{method}: HiZ reads not counted");
        assert!(
            c_on.fragments_rasterized < c_off.fragments_rasterized,
            "{method}: {} fragments with hiz, {} without",
            c_on.fragments_rasterized,
            c_off.fragments_rasterized
        );
        assert_eq!(
            c_on.tiles_visited + c_on.tiles_culled_hiz,
            c_off.tiles_visited,
            "{method}: a rejected pair is a pair not visited"
        );
    }
}

/// `pw2002` uses the unit only when asked (`[options.pw2002] hiz = on`; Paper I ran without
/// it): the same bits, fewer fragments, rejections counted, and the zmin/zmax in its plan.
#[test]
fn pw2002_rejects_tiles_only_when_asked() {
    for scene in ["pw-2002", "cube-of-spheres-sphere"] {
        let render = |hiz: &str| {
            let mut s = builtin::load(scene).unwrap();
            s.resize(Some(48), Some(48));
            s.methods = Some(vec!["pw2002".into()]);
            s.set_cli_option(&format!("pw2002.hiz={hiz}")).unwrap();
            render_scene(&s).unwrap().remove(0)
        };
        let (on, off) = (render("on"), render("off"));
        assert!(
            bits(&on.output.visibility) == bits(&off.output.visibility),
            "{scene}"
        );
        let (c_on, c_off) = (method_passes(&on), method_passes(&off));
        assert_eq!(
            (c_off.tiles_culled_hiz, c_off.hiz_read_bytes),
            (0, 0),
            "{scene}"
        );
        assert_eq!(hiz_buffers(&off), 0, "{scene}");
        assert!(c_on.tiles_culled_hiz > 0 && hiz_buffers(&on) > 0, "{scene}");
        assert!(
            c_on.fragments_rasterized < c_off.fragments_rasterized,
            "{scene}"
        );
        assert_eq!(c_on.depth_passed, c_off.depth_passed, "{scene}");
    }
}

/// `wedge-blending`'s half-wedge pass skips depth-tested faces where LESS fails at every
/// sample of a tile: fewer fragments there, and the same image (checked above).
#[test]
fn wedge_blending_half_wedges_use_the_unit() {
    let (on, off) = (
        runs("cube-of-spheres", "on"),
        runs("cube-of-spheres", "off"),
    );
    let pass = |rs: &[MethodRun]| {
        let run = rs
            .iter()
            .find(|r| r.method == "wedge-blending")
            .expect("ran");
        run.output
            .stats
            .passes
            .iter()
            .find(|p| p.name == "wb-half-wedges")
            .expect("half-wedge pass")
            .counters
    };
    let (c_on, c_off) = (pass(&on), pass(&off));
    assert!(c_on.tiles_culled_hiz > 0, "nothing rejected");
    assert!(c_on.fragments_rasterized < c_off.fragments_rasterized);
    assert_eq!(c_on.fragments_shaded, c_off.fragments_shaded);
    assert_eq!(
        c_on.tiles_visited + c_on.tiles_culled_hiz,
        c_off.tiles_visited
    );
}

/// HiZ tiles finer than the raster tile (`[options.gpu] hiz-tile-size`, 32×32 raster tiles):
/// the same bits as the unit off, for every method; and, since a finer HiZ tile's bounds lie
/// inside the coarser one's, every pass rasterizes at most the fragments the coarser unit
/// lets through (a pair is drawn only over the HiZ tiles that keep it), and the stencil
/// passes that only test the scene depth reject at least the (tile, triangle) pairs it
/// rejects.
#[test]
fn finer_hiz_tiles_change_no_bit_and_reject_at_least_as_much() {
    let (mut decided_more, mut drew_less) = (Vec::new(), Vec::new());
    for scene in ["cube-of-spheres", "eye-in-shadow", "two-lights"] {
        let render = |hiz: &str, hiz_tile: u32| {
            let opts = [
                format!("gpu.hiz={hiz}"),
                "gpu.tile-size=32".into(),
                format!("gpu.hiz-tile-size={hiz_tile}"),
            ];
            runs_with(scene, 96, &opts)
        };
        let off = render("off", 32);
        let by_size = [32, 8, 4].map(|h| render("on", h));
        for (i, runs) in by_size.iter().enumerate() {
            for (r, o) in runs.iter().zip(&off) {
                let at = format!("{scene}/{} at HiZ size index {i}", r.method);
                assert!(
                    bits(&r.output.visibility) == bits(&o.output.visibility),
                    "{at}"
                );
            }
        }
        for pair in by_size.windows(2) {
            for (coarse, fine) in pair[0].iter().zip(&pair[1]) {
                let at = format!("{scene}/{}", coarse.method);
                let (c, f) = (method_passes(coarse), method_passes(fine));
                assert!(
                    f.fragments_rasterized <= c.fragments_rasterized,
                    "{at}: {} fragments with finer HiZ tiles, {} with coarser",
                    f.fragments_rasterized,
                    c.fragments_rasterized
                );
                if ["hard-sv", "nsample"].contains(&coarse.method.as_str()) {
                    assert!(f.tiles_culled_hiz >= c.tiles_culled_hiz, "{at}");
                }
            }
        }
        let hard = |runs: &[MethodRun]| {
            method_passes(runs.iter().find(|r| r.method == "hard-sv").expect("ran"))
        };
        let (fine, coarse) = (hard(&by_size[2]), hard(&by_size[0]));
        if fine.tiles_culled_hiz > coarse.tiles_culled_hiz {
            decided_more.push(scene);
        }
        if fine.fragments_rasterized < coarse.fragments_rasterized {
            drew_less.push(scene);
        }
    }
    // Somewhere the finer tiles decide pairs the coarse ones could not, and skip the part of
    // a raster tile where they reject a triangle they keep elsewhere.
    assert!(!decided_more.is_empty());
    assert!(!drew_less.is_empty());
}
