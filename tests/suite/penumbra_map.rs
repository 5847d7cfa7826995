//! Penumbra maps (Wyman & Hansen, EGSR 2003): the paper's own limits made visible and pinned
//! — outer penumbra only, an umbra that does not shrink as the light grows, hardening at
//! contact, shadow-map aliasing — the darkest-wins rule, the bias, the falloff and storage
//! formats, the stats' accounting, the hard cases (values checked before any clamp) and
//! thread-count independence.
//!
//! Geometry used by the bounds below: the `single-quad` occluder is a 1×1 square at y = 1
//! under a sphere light of radius r at height 3 above the floor y = 0. On the floor its hard
//! shadow (from the light center) is the square of half-width 0.75; the true umbra is the
//! square of half-width 0.75 − r/2 (rays from the light's far rim through the quad's edge),
//! gone at r = 1.5; the true penumbra reaches out to half-width 0.75 + r/2.

use penumbra::frame::{Frame, GpuSettings, Receiver};
use penumbra::limits::DEFAULT_HIZ_TILE_SIZE;
use penumbra::methods::penumbra_map::{self, PenumbraMapRender, PenumbraMapSettings};
use penumbra::scene::{LightShape, OptionValue, Scene};

use crate::sphere_hard_cases;
use sphere_hard_cases::{gray, small, with_sphere};

fn set(scene: &mut Scene, method: &str, key: &str, v: OptionValue) {
    scene
        .options
        .entry(method.into())
        .or_default()
        .insert(key.into(), v);
}

/// Everything a test looks at: the method's render, `raycast` with 256 samples (when asked),
/// and the depth-buffer receivers.
struct Run {
    pm: PenumbraMapRender,
    settings: PenumbraMapSettings,
    reference: Vec<f32>,
    receivers: Vec<Option<Receiver>>,
}

fn run(mut scene: Scene, tweak: impl Fn(&mut PenumbraMapSettings), reference: bool) -> Run {
    set(&mut scene, "raycast", "samples", OptionValue::Int(256));
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let mut settings = penumbra_map::read_settings(&frame).unwrap();
    tweak(&mut settings);
    let pm = penumbra_map::render(&frame, &settings).unwrap();
    let reference = if reference {
        gray(
            &penumbra::methods::run("raycast", &frame)
                .unwrap()
                .visibility,
        )
    } else {
        Vec::new()
    };
    Run {
        pm,
        settings,
        reference,
        receivers: frame.receivers().to_vec(),
    }
}

/// Indices of the pixels showing the floor (the top face y = 0).
fn floor_pixels(r: &Run) -> Vec<usize> {
    (0..r.receivers.len())
        .filter(|&i| r.receivers[i].is_some_and(|p| p.point.y.abs() < 1e-4))
        .collect()
}

fn f32_storage(s: &mut PenumbraMapSettings) {
    s.storage = penumbra::gpu::color::ColorFormat::F32;
}

/// §3: the penumbra map only shades the surfaces the shadow map sees, so the penumbra is
/// outer only: inside the hard shadow everything is black, although the true inner penumbra
/// covers 1 − (0.5/0.75)² = 55.6 % of the hard shadow for r = 0.5 (module doc).
#[test]
fn the_penumbra_is_outer_only() {
    let r = run(
        with_sphere(small("single-quad", 96), 0.5),
        f32_storage,
        true,
    );
    let vis = gray(&r.pm.visibility);
    let floor = floor_pixels(&r);
    let hard: Vec<usize> = floor.iter().copied().filter(|&i| vis[i] == 0.0).collect();
    let inner = hard.iter().filter(|&&i| r.reference[i] > 0.02).count();
    let true_umbra = floor.iter().filter(|&&i| r.reference[i] == 0.0).count();
    let outer = floor
        .iter()
        .filter(|&&i| vis[i] > 0.0 && vis[i] < 1.0)
        .count();
    let ratio = inner as f64 / hard.len() as f64;
    eprintln!(
        "hard shadow {} px, of which raycast > 0.02: {inner} ({ratio:.3}); raycast umbra {true_umbra} px; outer penumbra {outer} px",
        hard.len()
    );
    assert!(hard.len() > 500, "{}", hard.len());
    assert!((0.45..=0.65).contains(&ratio), "{ratio}");
    assert!(outer > 200, "the outer penumbra is drawn: {outer}");
    // Every black pixel is black because the shadow map says so: the umbra count of the
    // screen pass is the hard shadow (no penumbra-map value is exactly 0 here).
    assert_eq!(
        r.pm.screen.umbra as usize,
        vis.iter().filter(|v| **v == 0.0).count()
    );
}

/// §4.1 "approximating the umbra by a hard shadow ... as a shadow's umbra size shrinks, our
/// approximation leads to noticeably larger, darker shadows": a light-size sweep of the
/// `single-quad` occluder. The black area of `penumbra-map` stays the hard shadow for every
/// radius while `raycast`'s umbra shrinks as (1 − r/1.5)² of it and vanishes at r = 1.5.
#[test]
fn the_umbra_does_not_shrink_as_the_light_grows() {
    let mut pm_black = Vec::new();
    let mut rc_black = Vec::new();
    let mut umbra = Vec::new();
    for radius in [0.25f32, 0.5, 1.0, 1.5] {
        let r = run(
            with_sphere(small("single-quad", 96), radius),
            f32_storage,
            true,
        );
        let vis = gray(&r.pm.visibility);
        let floor = floor_pixels(&r);
        pm_black.push(floor.iter().filter(|&&i| vis[i] == 0.0).count());
        rc_black.push(floor.iter().filter(|&&i| r.reference[i] == 0.0).count());
        umbra.push(r.pm.screen.umbra);
    }
    eprintln!("penumbra-map black {pm_black:?}, raycast black {rc_black:?}");
    // Pin: the shadow map does not depend on the radius.
    assert!(umbra.iter().all(|u| *u == umbra[0]), "{umbra:?}");
    assert!(pm_black.iter().all(|b| *b == pm_black[0]), "{pm_black:?}");
    for (k, radius) in [0.25f64, 0.5, 1.0, 1.5].iter().enumerate() {
        let expected = (1.0 - radius / 1.5) * (1.0 - radius / 1.5);
        let got = rc_black[k] as f64 / pm_black[k] as f64;
        assert!(
            (got - expected).abs() < 0.1,
            "r {radius}: {got} vs {expected}"
        );
    }
    assert!(rc_black.windows(2).all(|w| w[1] < w[0]), "{rc_black:?}");
}

/// Shadows harden where occluder and receiver touch (§1): one column of `pw-columns` standing
/// on the floor, lit from behind so that its shadow falls toward the camera. Behind a point
/// of the column at height h the true penumbra on the floor is about as wide as h times the
/// light's angular diameter, so it vanishes at the base: there `penumbra-map` (hard shadow
/// plus outer penumbra) is right up to the shadow map's texel — its error vs `raycast` falls
/// as the map grows — while farther along the shadow the missing inner penumbra is an error
/// no map size removes.
#[test]
fn contact_shadows_are_hard_and_right() {
    let mut scene = small("pw-columns", 128);
    scene
        .meshes
        .retain(|m| m.name == "floor" || m.name == "column[1,1]");
    scene.lights[0].center = glam::Vec3::new(-1.5, 3.5, -1.5);
    let (bx, bz) = (-0.4f32, 0.5f32);
    // Mean |error| over the shadowed floor within 0.1 of the column, and 0.6–1.5 away.
    let errors = |map_size: u32| {
        let r = run(scene.clone(), |s| s.map_size = map_size, true);
        let vis = gray(&r.pm.visibility);
        let mut bins = [(0.0, 0); 2];
        for i in floor_pixels(&r) {
            if vis[i] >= 0.99 && r.reference[i] >= 0.99 {
                continue;
            }
            let p = r.receivers[i].unwrap().point;
            let d = (libm::hypotf(p.x - bx, p.z - bz) - 0.15).max(0.0);
            let k = match d {
                d if d < 0.1 => 0,
                d if (0.6..1.5).contains(&d) => 1,
                _ => continue,
            };
            bins[k].0 += (vis[i] - r.reference[i]).abs() as f64;
            bins[k].1 += 1;
        }
        assert!(bins.iter().all(|b| b.1 > 10), "{bins:?}");
        bins.map(|(e, n)| e / n as f64)
    };
    let (coarse, fine) = (errors(128), errors(1024));
    eprintln!(
        "mean |penumbra-map − raycast| on the shadowed floor, map 128 / 1024: within 0.1 of the base {:.4} / {:.4}, 0.6–1.5 away {:.4} / {:.4}",
        coarse[0], fine[0], coarse[1], fine[1]
    );
    assert!(fine[0] < coarse[0], "{coarse:?} {fine:?}");
    assert!(fine[0] < fine[1] / 3.0, "{fine:?}");
    assert!(
        (fine[1] - coarse[1]).abs() < 0.1 * coarse[1],
        "{coarse:?} {fine:?}"
    );
}

/// Shadow-map aliasing: the hard shadow's staircase is one shadow-map texel, so the floor
/// pixels of `cube-of-spheres-sphere` (round shadow outlines of every orientation) that the
/// shadow-map test classifies differently from the exact hard shadow (the segment to the light
/// center) fall with the texel size: about 2× per doubling of `map_size` from 256 to 2048,
/// 8× over the sweep; at least 4× is required. The shadow map alone decides this, so only it
/// is rendered (the method's light view and default bias).
#[test]
fn aliasing_falls_as_the_map_grows() {
    use penumbra::gpu::depth::{DepthFormat, PolygonOffset};
    use penumbra::gpu::light_view::LightView;
    use penumbra::gpu::tiling::Tiling;
    let scene = small("cube-of-spheres-sphere", 128);
    let light = scene.light().center;
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let receivers = frame.primary_ray_receivers();
    let offset = PolygonOffset {
        factor: penumbra_map::DEFAULT_SLOPE_BIAS,
        units: penumbra_map::DEFAULT_BIAS_UNITS,
    };
    let mut wrong = Vec::new();
    for n in [256u32, 512, 1024, 2048] {
        let tiling = Tiling::new(n, n, 8).unwrap();
        let view = LightView::fit(&scene, light, tiling, DepthFormat::D24, |_| true).unwrap();
        let (shadow_map, _) = view.render_depth(&scene, offset, Some(DEFAULT_HIZ_TILE_SIZE), None);
        let mut count = 0;
        for rcv in receivers.iter().flatten() {
            if rcv.point.y.abs() > 1e-4 {
                continue;
            }
            let p = rcv.point.as_dvec3() + glam::DVec3::Y * 1e-4;
            let blocked =
                penumbra::geometry::near_plane::segment_blocked(&scene, p, light.as_dvec3());
            let lit = view.lit(&shadow_map, view.window(rcv.point).unwrap());
            count += (blocked == lit) as usize;
        }
        wrong.push(count);
    }
    eprintln!("floor pixels off the exact hard shadow, map 256, 512, 1024, 2048: {wrong:?}");
    assert!(wrong.windows(2).all(|w| w[1] <= w[0]), "{wrong:?}");
    assert!(wrong[0] >= 4 * wrong[3].max(1), "{wrong:?}");
}

/// §3, Fig. 6: overlapping penumbrae are not summed or multiplied: the depth channel with
/// LESS keeps the darkest. On `pw-2002`, the penumbra map of every segment's cones and sheets
/// is, texel by texel, the minimum of the map of the even-numbered meshes' and the map of the
/// odd-numbered ones' (same light view, same shadow map; the segments of a digit touch, so
/// their penumbrae overlap), up to ties of the quantized depth channel (values within one D24
/// step keep the first drawn).
#[test]
fn overlapping_penumbrae_keep_the_darkest() {
    use penumbra::geometry::penumbra_cones::{cones_and_sheets, silhouettes};
    let scene = small("pw-2002", 64);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let mut s = penumbra_map::read_settings(&frame).unwrap();
    f32_storage(&mut s);
    let full = penumbra_map::render(&frame, &s).unwrap();
    let LightShape::Sphere { radius } = scene.light().shape else {
        unreachable!()
    };
    let light = penumbra_map::cone_light(&full.view, radius);
    let meshes = frame.caster_meshes();
    let sils = silhouettes(&meshes, scene.light().center).unwrap();
    let map_of = |parity: usize| {
        let (m, sl): (Vec<_>, Vec<_>) = scene
            .meshes
            .iter()
            .zip(&sils)
            .enumerate()
            .filter(|(k, _)| k % 2 == parity)
            .map(|(_, (m, sl))| (m, sl.clone()))
            .unzip();
        let g = cones_and_sheets(&m, &sl, &light, s.cone_segments);
        penumbra_map::render_penumbra_map::<f64>(&full.view, &full.shadow_map, &g, &s, false, None)
            .0
    };
    let (first, rest) = (map_of(0), map_of(1));
    let mut both = 0;
    for t in 0..full.penumbra_map.len() {
        for l in 0..full.penumbra_map[t].values.len() {
            let (a, b) = (first[t].value(l), rest[t].value(l));
            both += (a < 1.0 && b < 1.0) as usize;
            let all = full.penumbra_map[t].value(l);
            assert!(
                (all - a.min(b)).abs() < 1e-7,
                "texel {t}/{l}: {all} vs min({a}, {b})"
            );
        }
    }
    eprintln!("{both} texels in both penumbrae");
    assert!(both > 20, "the penumbrae overlap: {both}");
}

/// The falloff is applied to the winning intensity and the storage format only quantizes it:
/// the smoothstep map is smoothstep of the linear map (smoothstep is monotone, so the darkest
/// I gives the darkest I′), and the unorm8 and f16 maps are the f32 map converted.
#[test]
fn falloff_and_storage_formats_are_consistent() {
    use penumbra::gpu::color::ColorFormat;
    use penumbra_map::Falloff;
    let scene = small("pw-columns", 64);
    let map = |falloff, storage| {
        let r = run(
            scene.clone(),
            |s| {
                s.falloff = falloff;
                s.storage = storage;
            },
            false,
        )
        .pm;
        r.penumbra_map
            .iter()
            .flat_map(|t| t.values.iter().map(move |v| t.format.decode(*v)))
            .collect::<Vec<f32>>()
    };
    let linear = map(Falloff::Linear, ColorFormat::F32);
    let smooth = map(Falloff::Smoothstep, ColorFormat::F32);
    let unorm = map(Falloff::Smoothstep, ColorFormat::Unorm8);
    let half = map(Falloff::Smoothstep, ColorFormat::F16);
    let mut shaded = 0;
    for k in 0..linear.len() {
        let expected = Falloff::Smoothstep.apply(linear[k] as f64);
        assert!((smooth[k] as f64 - expected).abs() < 1e-6, "{k}");
        assert_eq!(
            unorm[k],
            ColorFormat::Unorm8.decode(ColorFormat::Unorm8.encode(smooth[k] as f64).0)
        );
        assert_eq!(
            half[k],
            ColorFormat::F16.decode(ColorFormat::F16.encode(smooth[k] as f64).0)
        );
        shaded += (linear[k] < 1.0) as usize;
    }
    assert!(shaded > 100, "{shaded}");
}

/// The slope-scaled bias is what the method needs (module doc, pass 1): the fitted light view
/// sees the floor slightly tilted, so without it a receiver lies behind the depth stored at
/// its texel's center whenever it sits on the far side of the center — half of the lit floor
/// comes out black (the receivers are spread evenly over their texels). With the default
/// bias only the hard shadow's staircase (aliasing) remains: under 2 % of the lit floor.
#[test]
fn the_slope_scaled_bias_removes_shadow_acne() {
    let scene = small("cube-of-spheres-sphere", 96);
    let light = scene.light().center.as_dvec3();
    let acne = |factor: f64| {
        let r = run(scene.clone(), |s| s.offset.factor = factor, false);
        let vis = gray(&r.pm.visibility);
        let mut lit = 0;
        let mut black = 0;
        for i in floor_pixels(&r) {
            let p = r.receivers[i].unwrap().point.as_dvec3() + glam::DVec3::Y * 1e-4;
            if !penumbra::geometry::near_plane::segment_blocked(&scene, p, light) {
                lit += 1;
                black += (vis[i] == 0.0) as usize;
            }
        }
        black as f64 / lit as f64
    };
    let (none, default) = (acne(0.0), acne(penumbra_map::DEFAULT_SLOPE_BIAS));
    eprintln!("lit floor black: {none:.4} without slope bias, {default:.4} with the default");
    assert!((0.4..=0.6).contains(&none), "{none}");
    assert!(default < 0.02, "{default}");
}

/// The stats show the three passes (and the silhouette stage), the map buffers and traffic
/// that adds up: every written penumbra-map fragment writes one colour sample, every lit
/// receiver reads one (nearest) or four (bilinear) penumbra-map samples, every fragment of
/// pass 2 reads one shadow-map sample.
#[test]
fn stats_account_for_the_passes_and_the_maps() {
    use penumbra::gpu::texture::Filter;
    for filter in [Filter::Nearest, Filter::Bilinear] {
        let r = run(small("cylinder", 48), |s| s.filter = filter, false);
        let names: Vec<&str> = r.pm.passes.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(
            names,
            ["shadow-map", "silhouettes", "penumbra-map", "screen"]
        );
        let [sm, _, pass2, screen] = [0, 1, 2, 3].map(|k| r.pm.passes[k].counters);
        let n = r.settings.map_size as u64;
        assert!(sm.depth_write_bytes > 0 && sm.depth_write_bytes <= 3 * 4 * n * n);
        let p = r.pm.program;
        let reached = p.fragments
            - p.discarded_behind_surface
            - p.discarded_surface_not_beyond_silhouette
            - p.discarded_in_front_of_silhouette;
        assert_eq!(pass2.fragments_shaded, p.fragments);
        assert_eq!(pass2.depth_passed, p.written);
        // D24: a shadow-map read per fragment, a depth-test read per fragment reaching it.
        assert_eq!(pass2.depth_read_bytes, 3 * (p.fragments + reached));
        assert_eq!(pass2.depth_write_bytes, 3 * p.written);
        assert_eq!(pass2.color_write_bytes, p.written);
        let st = r.pm.screen;
        let taps = if filter == Filter::Nearest { 1 } else { 4 };
        assert_eq!(
            screen.color_read_bytes,
            (st.receivers - st.umbra - st.behind_light) * taps
        );
        assert_eq!(
            screen.depth_read_bytes,
            3 * (st.receivers - st.behind_light)
        );
        assert!(st.umbra > 0 && st.penumbra > 0);
    }
    // Through the registry: the plan names the passes and the buffers.
    let scene = small("cylinder", 48);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let out = penumbra::methods::run("penumbra-map", &frame).unwrap();
    let plan = &out.stats.plan;
    let passes: Vec<&str> = plan["passes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap())
        .collect();
    assert_eq!(
        passes,
        [
            "scene-depth",
            "shadow-map",
            "silhouettes",
            "penumbra-map",
            "screen"
        ]
    );
    let buffers = plan["buffers"].to_string();
    assert!(buffers.contains("shadow-map 48x48") && buffers.contains("penumbra-map colour"));
}

/// The hard cases (`docs/architecture.md` "The hard cases") that apply to sphere lights
/// ([`sphere_hard_cases`]), at 32²: finite values in [0, 1] with the intensity I and the screen
/// values checked before any clamp (counted, must be zero), for the default map and for the float
/// storage formats with the linear falloff (which would let an out-of-range I through to the
/// visibility), in every depth format.
#[test]
fn hard_cases_stay_in_range_before_any_clamp() {
    use penumbra::gpu::color::ColorFormat;
    use penumbra::gpu::depth::DepthFormat;
    use penumbra_map::Falloff;
    // Every hard case, the two-light scene light by light (one map per light), and the
    // heavily overlapping penumbrae of `cube-of-spheres-sphere`.
    let mut cases = Vec::new();
    let mut two = None;
    for scene in sphere_hard_cases::scenes(32) {
        if scene.is_multi_light() {
            cases.extend((0..scene.lights.len()).map(|k| scene.with_only_light(k)));
            two = Some(scene);
        } else {
            cases.push(scene);
        }
    }
    cases.push(small("cube-of-spheres-sphere", 32));
    let two = two.expect("a multi-light hard case");
    let variants: [(Falloff, ColorFormat, DepthFormat); 4] = [
        (Falloff::Smoothstep, ColorFormat::Unorm8, DepthFormat::D24),
        (Falloff::Linear, ColorFormat::F32, DepthFormat::D24),
        (Falloff::Linear, ColorFormat::F16, DepthFormat::D16),
        (Falloff::Smoothstep, ColorFormat::F32, DepthFormat::D32F),
    ];
    for scene in cases {
        for (falloff, storage, depth) in variants {
            let r = run(
                scene.clone(),
                |s| {
                    s.falloff = falloff;
                    s.storage = storage;
                    s.depth = depth;
                },
                false,
            );
            let what = format!("{} {falloff:?} {storage:?} {depth:?}", scene.source);
            assert_eq!(r.pm.program.intensity_out_of_range, 0, "{what}");
            assert_eq!(r.pm.screen.out_of_range, 0, "{what}");
            assert_eq!(r.pm.screen.behind_light, 0, "{what}");
            let v = gray(&r.pm.visibility);
            assert!(
                v.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x)),
                "{what}"
            );
        }
    }
    // The registry averages the two lights.
    let frame = Frame::render(&two, GpuSettings::default()).unwrap();
    let v = gray(
        &penumbra::methods::run("penumbra-map", &frame)
            .unwrap()
            .visibility,
    );
    assert!(v.iter().all(|x| (0.0..=1.0).contains(x)));
}

#[test]
fn penumbra_maps_do_not_depend_on_thread_count() {
    let scene = small("pw-2002", 48);
    let render = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let r = run(scene.clone(), |_| {}, false).pm;
            let maps: Vec<u32> = r
                .penumbra_map
                .iter()
                .flat_map(|t| t.values.clone())
                .chain(r.shadow_map.iter().flat_map(|t| t.values.clone()))
                .collect();
            (gray(&r.visibility), maps, r.program, r.screen)
        })
    };
    assert_eq!(render(1), render(3));
}

/// `bias_stage` (module doc, pass 1): `lookup` leaves the shadow map exact and offsets the
/// receiver instead, by its own triangle's slope — which leaks light onto steep receivers
/// behind occluders (the sides of the `pw-2002` segments); `render` offsets the map. Counted
/// against `raycast`: pixels it sees dark (≤ 0.01) that come out above 0.5.
#[test]
fn bias_stages_trade_specks_for_leaks() {
    use penumbra::gpu::depth::PolygonOffset;
    use penumbra_map::BiasStage;
    let scene = small("pw-2002", 128);
    let mut leaks = Vec::new();
    for stage in [BiasStage::Render, BiasStage::Lookup] {
        let r = run(scene.clone(), |s| s.bias_stage = stage, true);
        let vis = gray(&r.pm.visibility);
        leaks.push(
            (0..vis.len())
                .filter(|&i| r.reference[i] <= 0.01 && vis[i] > 0.5)
                .count(),
        );
        let (exact, _) = r.pm.view.render_depth(
            &scene,
            PolygonOffset::NONE,
            Some(DEFAULT_HIZ_TILE_SIZE),
            None,
        );
        assert_eq!(r.pm.shadow_map == exact, stage == BiasStage::Lookup);
    }
    eprintln!("dark pixels lit: render {}, lookup {}", leaks[0], leaks[1]);
    // Pin (measured 256²: 16 vs 888).
    assert!(leaks[1] > 10 * leaks[0].max(1), "{leaks:?}");
}
