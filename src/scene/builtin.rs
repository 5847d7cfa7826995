//! Built-in scenes, generated in code so the default run needs no files.
//!
//! Every scene has a floor (a thin closed box whose top is the plane y = 0) as the receiver,
//! a light well clear of all geometry, a 256×256 image, ambient 0.15, `methods = None` (every
//! method that supports the light shape) and no options. World units are arbitrary; y is up.
//!
//! | name | occluders | light | triangles |
//! |---|---|---|---|
//! | `cube-of-spheres` | 3×3×3 spheres r 0.18, spacing 0.45 (8 stacks × 12 slices) | rect ½-extents 0.5 | 4548 |
//! | `single-quad` | one 1×1 two-sided quad at y = 1 | rect ½-extents 0.5 at y = 3 | 16 |
//! | `cylinder` | capped cylinder, 24 segments, r 0.35, h 1, floating at y = 0.4 | sphere r 0.3 | 108 |
//! | `eye-in-shadow` | a 4×3 slab above the camera + a floating box in the lit region | rect ½-extents 0.4 | 36 |
//! | `overlap-stress` | 300 stacked 1.2×1.2 two-sided quads, spacing 0.002 | point | 1212 |
//! | `cube-of-spheres-sphere` | as `cube-of-spheres` | sphere r 0.5 at the same center | 4548 |
//! | `pw-columns` | Paper II Fig. 9 analogue: 2×4 columns (16 segments, r 0.15, h 1.6) | sphere r 0.3 | 524 |
//! | `pw-fractal` | Paper II Fig. 10 analogue: closed 24×24 midpoint-displacement landscape | sphere r 0.4 | 1440 |
//! | `pw-2002` | Paper II Fig. 11 analogue: "2002" in seven-segment boxes at y = 0.9 | sphere r 0.25 | 276 |
//! | `two-lights` | Paper I Fig. 16 analogue: the `cylinder` occluder and a box | two spheres r 0.3, 0.25 | 120 |
//! | `forest-spheres` | Forest et al. 2006 Fig. 1: 3×3×3 spheres of 760 triangles (20 stacks × 20 slices), r 0.2, spacing 0.45 | rect ½-extents 0.6 | 20532 |
//! | `forest-spheres-1`, `-4`, `-9` | the cost series of Fig. 12: 1 sphere, 2×2 and 3×3 in one layer | as `forest-spheres` | 772, 3052, 6852 |
//! | `disk-block` | CGI 2004 Fig. 1/7: a 1×0.7×1 block floating at y = 0.9 straight below the light center (the silhouette from c is its top) | disk r 1.2 facing down | 24 |
//! | `disk-slab` | `disk-block` cut down to its top 0.1: the same silhouette from c, a different shadow | as `disk-block` | 24 |
//! | `disk-small-sphere` | CGI 2004 Fig. 8a / §4 case 2: a sphere r 0.25 of 224 triangles (16 slices × 8 stacks) under a larger disk: no umbra on the floor | disk r 0.8 | 236 |
//! | `disk-acute` | CGI 2004 §4 case 3: a flat triangular prism with a 14° tip | disk r 0.5 | 20 |
//! | `disk-torus` | CGI 2004 Fig. 8c: a tilted torus of 5760 triangles (60 × 48), concave and self-shadowing | disk r 0.6 | 5772 |

use super::procedural::{box_mesh, cylinder, prism, torus, transformed, two_sided_quad, uv_sphere};
use super::{Camera, Light, LightShape, Mesh, RawOptions, Scene};
use glam::{DVec3, Mat4, Vec3};

/// The scene `penumbra render` uses when none is given.
pub const DEFAULT: &str = "cube-of-spheres";

/// The scenes the default run (`cargo run --release`) renders after [`DEFAULT`], each into
/// `out/<name>`: [`DEFAULT`]'s sphere-light twin, for the methods that take only spheres
/// (Papers I–II, Wyman & Hansen 2003), and the disk-light pair's block, for the D-buffer
/// (CGI 2004).
pub const DEFAULT_COMPANIONS: &[&str] = &["cube-of-spheres-sphere", "disk-block"];

/// Names of the built-in scenes, in the order `penumbra list` prints them.
const NAMES: &[&str] = &[
    "cube-of-spheres",
    "single-quad",
    "cylinder",
    "eye-in-shadow",
    "overlap-stress",
    "cube-of-spheres-sphere",
    "pw-columns",
    "pw-fractal",
    "pw-2002",
    "two-lights",
    "forest-spheres",
    "forest-spheres-1",
    "forest-spheres-4",
    "forest-spheres-9",
    "disk-block",
    "disk-slab",
    "disk-small-sphere",
    "disk-acute",
    "disk-torus",
];

/// Names of all built-in scenes.
pub fn names() -> &'static [&'static str] {
    NAMES
}

/// The built-in scene `name` (its `source` is the name), or `None` if there is no such scene.
pub fn load(name: &str) -> Option<Scene> {
    let scene = match name {
        "cube-of-spheres" => cube_of_spheres(),
        "single-quad" => single_quad(),
        "cylinder" => cylinder_scene(),
        "eye-in-shadow" => eye_in_shadow(),
        "overlap-stress" => overlap_stress(),
        "cube-of-spheres-sphere" => cube_of_spheres_sphere(),
        "pw-columns" => pw_columns(),
        "pw-fractal" => pw_fractal(),
        "pw-2002" => pw_2002(),
        "two-lights" => two_lights(),
        "forest-spheres" => forest_spheres([3, 3, 3]),
        "forest-spheres-1" => forest_spheres([1, 1, 1]),
        "forest-spheres-4" => forest_spheres([2, 1, 2]),
        "forest-spheres-9" => forest_spheres([3, 1, 3]),
        "disk-block" => disk_pair("block", 0.9),
        "disk-slab" => disk_pair("slab", 1.5),
        "disk-small-sphere" => disk_small_sphere(),
        "disk-acute" => disk_acute(),
        "disk-torus" => disk_torus(),
        _ => return None,
    };
    Some(Scene {
        source: name.to_string(),
        ..scene
    })
}

/// Albedo of floors.
const FLOOR: [f32; 3] = [0.8, 0.8, 0.8];
/// Albedo of occluders.
const OCCLUDER: [f32; 3] = [0.85, 0.45, 0.3];

/// A floor slab of thickness 0.1 whose top face is y = 0, spanning x and z in the ranges.
fn floor(x: [f32; 2], z: [f32; 2]) -> Mesh {
    box_mesh(
        "floor",
        Vec3::new(x[0], -0.1, z[0]),
        Vec3::new(x[1], 0.0, z[1]),
        FLOOR,
    )
}

/// A camera with the default near plane.
fn camera(eye: [f64; 3], target: [f64; 3], vfov_deg: f64) -> Camera {
    Camera {
        eye: DVec3::from_array(eye),
        target: DVec3::from_array(target),
        up: DVec3::Y,
        vfov_deg,
        near: None,
    }
}

/// A downward-facing square light (u × v points to −y) of half extent `h`.
fn rect(h: f32) -> LightShape {
    LightShape::Rect {
        u: Vec3::new(h, 0.0, 0.0),
        v: Vec3::new(0.0, 0.0, h),
    }
}

/// The common defaults; `source` is filled in by [`load`].
fn scene(camera: Camera, light: Light, meshes: Vec<Mesh>) -> Scene {
    Scene {
        source: String::new(),
        width: 256,
        height: 256,
        camera,
        lights: vec![light],
        meshes,
        methods: None,
        options: RawOptions::new(),
        cli_options: Default::default(),
        ambient: 0.15,
    }
}

/// Forest et al. 2006 Fig. 1 / Paper III Fig. 15: a cube of 27 spheres above the floor whose
/// penumbrae overlap heavily.
fn cube_of_spheres() -> Scene {
    let mut meshes = vec![floor([-4.0, 4.0], [-4.0, 4.0])];
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                let c = Vec3::new(
                    0.45 * (i as f32 - 1.0),
                    1.2 + 0.45 * (j as f32 - 1.0),
                    0.45 * (k as f32 - 1.0),
                );
                let name = format!("sphere[{i},{j},{k}]");
                meshes.push(uv_sphere(&name, c, 0.18, 8, 12, OCCLUDER));
            }
        }
    }
    scene(
        camera([2.2, 3.0, 4.2], [-0.25, 0.4, -0.1], 50.0),
        Light {
            center: Vec3::new(0.3, 4.0, 0.2),
            shape: rect(0.5),
        },
        meshes,
    )
}

/// One two-sided 1×1 quad at y = 1 under a rectangular light at y = 3: the whole penumbra
/// (|x|, |z| ≤ 1) falls on the floor and is seen from in front without the quad hiding it.
fn single_quad() -> Scene {
    let q = [
        Vec3::new(-0.5, 1.0, 0.5),
        Vec3::new(0.5, 1.0, 0.5),
        Vec3::new(0.5, 1.0, -0.5),
        Vec3::new(-0.5, 1.0, -0.5),
    ];
    scene(
        camera([0.0, 2.2, 3.6], [0.0, 0.2, -0.2], 45.0),
        Light {
            center: Vec3::new(0.0, 3.0, 0.0),
            shape: rect(0.5),
        },
        vec![
            floor([-3.0, 3.0], [-3.0, 3.0]),
            two_sided_quad("quad", q, OCCLUDER),
        ],
    )
}

/// A standing capped cylinder floating 0.4 above the floor, lit from the side by a sphere
/// light so that its shadow falls sideways onto the floor.
fn cylinder_scene() -> Scene {
    scene(
        camera([1.0, 2.6, 4.0], [-0.3, 0.4, 0.0], 45.0),
        Light {
            center: Vec3::new(1.2, 3.2, 0.6),
            shape: LightShape::Sphere { radius: 0.3 },
        },
        vec![
            floor([-3.0, 3.0], [-3.0, 3.0]),
            cylinder(
                "cylinder",
                Vec3::new(0.0, 0.4, 0.0),
                0.35,
                1.0,
                24,
                OCCLUDER,
            ),
        ],
    )
}

/// The slab occluder of `eye-in-shadow` (min, max).
const SLAB: (Vec3, Vec3) = (Vec3::new(-2.0, 1.6, -2.0), Vec3::new(2.0, 1.7, 1.0));

/// The camera sits under a large horizontal slab, inside its hard shadow volume (the segment
/// from the eye to the light center crosses the slab), looking along +z at the shadowed floor
/// and beyond it into the lit region, where a small floating box casts its own shadow.
/// z-pass counts are wrong here; z-fail is right.
fn eye_in_shadow() -> Scene {
    scene(
        camera([0.0, 0.8, 0.5], [0.0, 0.0, 2.5], 60.0),
        Light {
            center: Vec3::new(0.0, 4.0, -0.5),
            shape: rect(0.4),
        },
        vec![
            floor([-6.0, 6.0], [-8.0, 8.0]),
            box_mesh("slab", SLAB.0, SLAB.1, OCCLUDER),
            box_mesh(
                "box",
                Vec3::new(-0.4, 0.3, 3.4),
                Vec3::new(0.4, 0.9, 4.2),
                OCCLUDER,
            ),
        ],
    )
}

/// Number of quads in `overlap-stress`.
const STRESS_QUADS: u32 = 300;

/// 300 two-sided quads (1.2×1.2) stacked 0.002 apart from y = 1 under a point light at y = 4:
/// floor points with |x|, |z| < 0.8 are inside all 300 shadow volumes (more than an 8-bit
/// stencil holds, so wrap and saturate differ), and the band 0.8 < |x| or |z| < 1.0 is inside
/// fewer, from 299 down to 1, because the higher quads cast larger shadows.
fn overlap_stress() -> Scene {
    overlap_stack(STRESS_QUADS, LightShape::Point)
}

/// `overlap-stress` generalized (issue 11's overflow study): `n` two-sided quads (1.2×1.2)
/// stacked 0.002 apart from y = 1 over the floor, under a light of `shape` centered at
/// y = 4. Floor points below the stack's middle are inside all `n` shadow volumes and, under
/// an area light, all `n` umbrae (a rectangle or sphere up to 0.5 across keeps the common
/// umbra at least |x|, |z| < 0.4 for `n` ≤ 512); the rim between the smallest and the largest
/// shadow is inside fewer volumes and many overlapping penumbrae.
pub fn overlap_stack(n: u32, shape: LightShape) -> Scene {
    let mut meshes = vec![floor([-3.0, 3.0], [-3.0, 3.0])];
    for i in 0..n {
        let y = (1.0 + 0.002 * f64::from(i)) as f32;
        let q = [
            Vec3::new(-0.6, y, 0.6),
            Vec3::new(0.6, y, 0.6),
            Vec3::new(0.6, y, -0.6),
            Vec3::new(-0.6, y, -0.6),
        ];
        meshes.push(two_sided_quad(&format!("quad[{i}]"), q, OCCLUDER));
    }
    scene(
        camera([0.0, 2.0, 3.5], [0.0, 0.3, -0.3], 45.0),
        Light {
            center: Vec3::new(0.0, 4.0, 0.0),
            shape,
        },
        meshes,
    )
}

/// Forest, Barthe & Paulin 2006 Fig. 1 and §5.2: spheres of 760 triangles ("each sphere is
/// discretized by 762 triangles"; 20 stacks × 20 slices is the nearest UV sphere) in a grid of
/// `n = [x, y, z]` spheres centered above the floor under a rectangular light, so that their
/// penumbrae overlap everywhere on the floor. `[3, 3, 3]` is the cube of the figure; fewer
/// spheres give the cost series of Fig. 12 (same light, camera and spacing).
fn forest_spheres(n: [u32; 3]) -> Scene {
    let mut meshes = vec![floor([-4.0, 4.0], [-4.0, 4.0])];
    let offset = |k: u32, count: u32| 0.45 * (k as f32 - 0.5 * (count - 1) as f32);
    for i in 0..n[0] {
        for j in 0..n[1] {
            for k in 0..n[2] {
                let c = Vec3::new(offset(i, n[0]), 1.2 + offset(j, n[1]), offset(k, n[2]));
                let name = format!("sphere[{i},{j},{k}]");
                meshes.push(uv_sphere(&name, c, 0.2, 20, 20, OCCLUDER));
            }
        }
    }
    scene(
        camera([2.2, 3.0, 4.2], [-0.25, 0.4, -0.1], 50.0),
        Light {
            center: Vec3::new(0.3, 4.0, 0.2),
            shape: rect(0.6),
        },
        meshes,
    )
}

/// `cube-of-spheres` under a sphere light of radius 0.5 at the same center: the sphere-light
/// twin that the penumbra-wedge methods (sphere lights only) render in the default run.
fn cube_of_spheres_sphere() -> Scene {
    let mut s = cube_of_spheres();
    s.lights[0].shape = LightShape::Sphere { radius: 0.5 };
    s
}

/// Paper I §7, Fig. 16 analogue: two sphere lights, one on each side, so that the floor shows
/// two overlapping soft shadows of a floating cylinder and of a box (visibility = the mean
/// over the lights).
fn two_lights() -> Scene {
    let mut s = cylinder_scene();
    s.camera = camera([0.0, 2.8, 4.2], [0.0, 0.3, 0.4], 50.0);
    s.meshes.push(box_mesh(
        "box",
        Vec3::new(-1.3, 0.3, 0.3),
        Vec3::new(-0.8, 0.8, 0.8),
        OCCLUDER,
    ));
    s.lights = vec![
        Light {
            center: Vec3::new(-1.8, 2.6, -1.6),
            shape: LightShape::Sphere { radius: 0.3 },
        },
        Light {
            center: Vec3::new(2.0, 2.2, -1.2),
            shape: LightShape::Sphere { radius: 0.25 },
        },
    ];
    s
}

/// A disk light of `radius` at `center` facing straight down (CGI 2004: one circular light).
fn disk_down(center: Vec3, radius: f32) -> Light {
    Light {
        center,
        shape: LightShape::Disk {
            radius,
            normal: Vec3::NEG_Y,
        },
    }
}

/// CGI 2004 Fig. 1 and Fig. 7: a box `name` (x, z ∈ ±0.5, y from `bottom` to 1.6) under a
/// disk light large enough that its sides are silhouette faces, with the light center straight
/// above it, so that from c only its top is seen: the silhouette from c is the top square,
/// whatever the bottom. `disk-block` (bottom 0.9: a tall block floating above the floor, whose
/// umbra is bounded by its bottom edges) and `disk-slab` (bottom 1.5: the block cut down to its
/// top 0.1) cast different true shadows although a method working from the silhouette seen from
/// c shades them alike. The camera is low enough to see the floor under the occluder.
fn disk_pair(name: &str, bottom: f32) -> Scene {
    scene(
        camera([0.0, 1.4, 3.6], [0.0, 0.25, 0.0], 55.0),
        disk_down(Vec3::new(0.0, 3.8, 0.0), 1.2),
        vec![
            floor([-4.0, 4.0], [-4.0, 4.0]),
            box_mesh(
                name,
                Vec3::new(-0.5, bottom, -0.5),
                Vec3::new(0.5, 1.6, 0.5),
                OCCLUDER,
            ),
        ],
    )
}

/// CGI 2004 Fig. 8a and §4 case 2: a small sphere (224 triangles, Table 1's first row) under
/// a larger disk, so that its umbra ends above the floor.
fn disk_small_sphere() -> Scene {
    scene(
        camera([0.0, 2.6, 3.2], [0.0, 0.3, 0.0], 45.0),
        disk_down(Vec3::new(0.0, 3.6, 0.0), 0.8),
        vec![
            floor([-3.0, 3.0], [-3.0, 3.0]),
            uv_sphere("sphere", Vec3::new(0.0, 1.8, 0.0), 0.25, 8, 16, OCCLUDER),
        ],
    )
}

/// CGI 2004 §4 case 3: a flat triangular prism whose tip is a 14° silhouette corner.
fn disk_acute() -> Scene {
    let base = [[0.9, 0.0], [-0.7, 0.2], [-0.7, -0.2]];
    scene(
        camera([0.0, 2.8, 3.4], [0.2, 0.2, 0.0], 45.0),
        disk_down(Vec3::new(0.2, 3.0, 0.0), 0.5),
        vec![
            floor([-3.0, 3.0], [-3.0, 3.0]),
            prism("wedge", &base, [1.0, 1.08], OCCLUDER),
        ],
    )
}

/// CGI 2004 Fig. 8c: a complex, concave occluder — a torus of 5760 triangles (Table 1's
/// third row) tilted 30° about x, shadowing itself and the floor.
fn disk_torus() -> Scene {
    let t = torus("torus", Vec3::ZERO, 0.5, 0.16, [60, 48], OCCLUDER);
    let m = Mat4::from_translation(Vec3::new(0.0, 1.1, 0.0))
        * Mat4::from_rotation_x(std::f32::consts::FRAC_PI_6);
    scene(
        camera([0.6, 2.8, 3.6], [0.0, 0.5, 0.0], 45.0),
        disk_down(Vec3::new(0.3, 3.4, 0.2), 0.6),
        vec![floor([-3.0, 3.0], [-3.0, 3.0]), transformed(&t, m)],
    )
}

/// Paper II Fig. 9 analogue ("column scene"): two rows of four columns on a floor, lit from
/// above and to the side so their long shadows and penumbrae overlap on the floor.
fn pw_columns() -> Scene {
    let mut meshes = vec![floor([-4.0, 4.0], [-4.0, 4.0])];
    for row in 0..2 {
        for i in 0..4 {
            let base = Vec3::new(-1.2 + 0.8 * i as f32, 0.0, -0.5 + 1.0 * row as f32);
            let name = format!("column[{row},{i}]");
            meshes.push(cylinder(&name, base, 0.15, 1.6, 16, OCCLUDER));
        }
    }
    scene(
        camera([0.5, 3.2, 5.0], [0.0, 0.4, -0.3], 50.0),
        Light {
            center: Vec3::new(2.5, 4.0, 1.5),
            shape: LightShape::Sphere { radius: 0.3 },
        },
        meshes,
    )
}

/// Side of the `pw-fractal` height grid (cells).
const FRACTAL_N: usize = 24;

/// Paper II Fig. 10 analogue ("fractal scene"): a closed heightfield landscape made by
/// midpoint displacement (deterministic LCG, roughness 0.55) on a central massif, lit from
/// low on one side so that it shadows itself.
fn pw_fractal() -> Scene {
    let n = 32; // power-of-two grid for midpoint displacement, sampled down to FRACTAL_N
    let mut h = vec![vec![0.0f64; n + 1]; n + 1];
    let mut seed = 0x2002_u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let mut step = n;
    let mut amp = 1.3;
    while step > 1 {
        let half = step / 2;
        for y in (0..n).step_by(step) {
            for x in (0..n).step_by(step) {
                let avg = (h[y][x] + h[y][x + step] + h[y + step][x] + h[y + step][x + step]) / 4.0;
                h[y + half][x + half] = avg + amp * rnd();
            }
        }
        for y in (0..=n).step_by(half) {
            let x0 = if (y / half) % 2 == 0 { half } else { 0 };
            for x in (x0..=n).step_by(step) {
                let mut sum = 0.0;
                let mut k = 0.0;
                for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                    let (xx, yy) = (x as i64 + dx * half as i64, y as i64 + dy * half as i64);
                    if (0..=n as i64).contains(&xx) && (0..=n as i64).contains(&yy) {
                        sum += h[yy as usize][xx as usize];
                        k += 1.0;
                    }
                }
                h[y][x] = sum / k + amp * rnd();
            }
        }
        step = half;
        amp *= 0.55;
    }
    let m = FRACTAL_N;
    let heights: Vec<Vec<f64>> = (0..=m)
        .map(|j| {
            (0..=m)
                .map(|i| {
                    // A central massif so that peaks shadow the valleys around them.
                    let (u, v) = (i as f64 / m as f64 - 0.5, j as f64 / m as f64 - 0.5);
                    let massif = 0.9 * libm::exp(-(u * u + v * v) / 0.05);
                    0.3 + h[j * n / m][i * n / m].max(-0.25) + massif
                })
                .collect()
        })
        .collect();
    scene(
        camera([0.0, 3.0, 4.6], [0.0, 0.2, 0.0], 50.0),
        Light {
            center: Vec3::new(-3.2, 2.4, -2.2),
            shape: LightShape::Sphere { radius: 0.4 },
        },
        vec![heightfield("landscape", &heights, 4.0, -0.1)],
    )
}

/// A closed heightfield over the square [−size/2, size/2]² (x, z): the top grid of
/// `heights[row][col]`, vertical side walls down to `base_y` and a flat bottom fanned from its
/// center. Every triangle is oriented outward (top +y, sides away from the center, bottom −y).
fn heightfield(name: &str, heights: &[Vec<f64>], size: f64, base_y: f64) -> Mesh {
    let m = heights.len() - 1;
    let coord = |i: usize| -size / 2.0 + size * i as f64 / m as f64;
    let mut pos: Vec<DVec3> = Vec::new();
    for (j, row) in heights.iter().enumerate() {
        for (i, y) in row.iter().enumerate() {
            pos.push(DVec3::new(coord(i), *y, coord(j)));
        }
    }
    let top = |i: usize, j: usize| (j * (m + 1) + i) as u32;
    let mut tris: Vec<([u32; 3], DVec3)> = Vec::new();
    for j in 0..m {
        for i in 0..m {
            let (a, b, c, d) = (top(i, j), top(i + 1, j), top(i + 1, j + 1), top(i, j + 1));
            tris.push(([a, b, c], DVec3::Y));
            tris.push(([a, c, d], DVec3::Y));
        }
    }
    // Boundary ring of top vertices, counter-clockwise seen from above.
    let mut ring = Vec::new();
    ring.extend((0..m).map(|i| (i, 0)));
    ring.extend((0..m).map(|j| (m, j)));
    ring.extend((0..m).map(|i| (m - i, m)));
    ring.extend((0..m).map(|j| (0, m - j)));
    let bottom0 = pos.len() as u32;
    for &(i, j) in &ring {
        pos.push(DVec3::new(coord(i), base_y, coord(j)));
    }
    let center = pos.len() as u32;
    pos.push(DVec3::new(0.0, base_y, 0.0));
    let k = ring.len();
    for r in 0..k {
        let (t0, t1) = (
            top(ring[r].0, ring[r].1),
            top(ring[(r + 1) % k].0, ring[(r + 1) % k].1),
        );
        let (b0, b1) = (bottom0 + r as u32, bottom0 + ((r + 1) % k) as u32);
        let mid = (pos[t0 as usize] + pos[t1 as usize]) * 0.5;
        let out = DVec3::new(mid.x, 0.0, mid.z);
        tris.push(([t0, b0, b1], out));
        tris.push(([t0, b1, t1], out));
        tris.push(([center, b1, b0], -DVec3::Y));
    }
    let triangles = tris
        .into_iter()
        .map(|([a, b, c], out)| {
            let (pa, pb, pc) = (pos[a as usize], pos[b as usize], pos[c as usize]);
            if (pb - pa).cross(pc - pa).dot(out) < 0.0 {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
        .collect();
    Mesh {
        name: name.to_string(),
        positions: pos.iter().map(|p| p.as_vec3()).collect(),
        triangles,
        color: OCCLUDER,
        receiver_only: false,
        repairs: Default::default(),
    }
}

/// Paper II Fig. 11 analogue ("2002 scene"): the digits 2, 0, 0, 2 as seven-segment boxes
/// lying flat at y = 0.9, casting a soft "2002" onto the floor.
fn pw_2002() -> Scene {
    // Segments a..g as (x0, z0, x1, z1) in a 0.5 × 0.9 digit cell (z grows toward the camera).
    let seg = |k: usize| -> [f32; 4] {
        let (w, t, h) = (0.5f32, 0.09f32, 0.9f32);
        match k {
            0 => [0.0, 0.0, w, t],                       // a: top
            1 => [w - t, 0.0, w, h / 2.0],               // b: top right
            2 => [w - t, h / 2.0, w, h],                 // c: bottom right
            3 => [0.0, h - t, w, h],                     // d: bottom
            4 => [0.0, h / 2.0, t, h],                   // e: bottom left
            5 => [0.0, 0.0, t, h / 2.0],                 // f: top left
            _ => [0.0, (h - t) / 2.0, w, (h + t) / 2.0], // g: middle
        }
    };
    let two = [0, 1, 6, 4, 3];
    let zero = [0, 1, 2, 3, 4, 5];
    let digits: [&[usize]; 4] = [&two, &zero, &zero, &two];
    let mut meshes = vec![floor([-3.0, 3.0], [-3.0, 3.0])];
    for (d, segs) in digits.iter().enumerate() {
        let x0 = -1.3 + 0.7 * d as f32;
        for &k in segs.iter() {
            let [a, b, c, e] = seg(k);
            meshes.push(box_mesh(
                &format!("digit[{d}].segment[{k}]"),
                Vec3::new(x0 + a, 0.9, -0.45 + b),
                Vec3::new(x0 + c, 0.98, -0.45 + e),
                OCCLUDER,
            ));
        }
    }
    scene(
        camera([0.0, 3.0, 3.2], [0.0, 0.2, 0.0], 50.0),
        Light {
            center: Vec3::new(0.4, 3.2, -0.6),
            shape: LightShape::Sphere { radius: 0.25 },
        },
        meshes,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::validate::validate;

    #[test]
    fn every_builtin_validates() {
        assert!(names().contains(&DEFAULT));
        for &name in names() {
            let s = load(name).unwrap();
            assert_eq!(s.source, name);
            validate(&s).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!((s.width, s.height), (256, 256));
        }
        assert!(load("no-such-scene").is_none());
    }

    #[test]
    fn triangle_counts() {
        let count = |n: &str| {
            load(n)
                .unwrap()
                .meshes
                .iter()
                .map(|m| m.triangles.len())
                .sum::<usize>()
        };
        assert_eq!(count("cube-of-spheres"), 12 + 27 * 168);
        assert_eq!(count("single-quad"), 12 + 4);
        assert_eq!(count("cylinder"), 12 + 96);
        assert_eq!(count("eye-in-shadow"), 36);
        assert_eq!(count("overlap-stress"), 12 + 300 * 4);
        assert_eq!(count("cube-of-spheres-sphere"), 12 + 27 * 168);
        assert_eq!(count("pw-columns"), 12 + 8 * 64);
        assert_eq!(count("pw-fractal"), 24 * 24 * 2 + 96 * 3);
        assert_eq!(count("pw-2002"), 12 + 22 * 12);
        assert_eq!(count("two-lights"), 12 + 96 + 12);
        assert_eq!(load("two-lights").unwrap().lights.len(), 2);
        assert_eq!(count("disk-block"), 24);
        assert_eq!(count("disk-slab"), 24);
        assert_eq!(count("disk-small-sphere"), 12 + 224);
        assert_eq!(count("disk-acute"), 12 + 8);
        assert_eq!(count("disk-torus"), 12 + 5760);
    }

    /// The light's extent (a bounding sphere of its shape) clears every mesh's bounding box.
    #[test]
    fn lights_clear_geometry() {
        for &name in names() {
            let s = load(name).unwrap();
            for light in &s.lights {
                let r = match &light.shape {
                    LightShape::Point => 0.0,
                    LightShape::Sphere { radius } | LightShape::Disk { radius, .. } => *radius,
                    LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. } => {
                        u.length() + v.length()
                    }
                };
                for m in &s.meshes {
                    let (lo, hi) = m
                        .positions
                        .iter()
                        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| {
                            (l.min(*p), h.max(*p))
                        });
                    let d = light.center.clamp(lo, hi).distance(light.center);
                    assert!(d > r + 0.5, "{name}: light {r} within {d} of {}", m.name);
                }
            }
        }
    }

    /// Where the segment from `p` to `light` crosses the plane y = `y`.
    fn cross_at(p: Vec3, light: Vec3, y: f32) -> Vec3 {
        let t = (y - p.y) / (light.y - p.y);
        p + (light - p) * t
    }

    #[test]
    fn eye_is_strictly_inside_the_slab_shadow_volume() {
        let s = load("eye-in-shadow").unwrap();
        let eye = s.camera.eye.as_vec3();
        for y in [SLAB.0.y, SLAB.1.y] {
            let c = cross_at(eye, s.light().center, y);
            let margin = (c.x - SLAB.0.x)
                .min(SLAB.1.x - c.x)
                .min(c.z - SLAB.0.z)
                .min(SLAB.1.z - c.z);
            assert!(margin > 0.5, "eye only {margin} inside the shadow volume");
        }
        assert!(eye.y < SLAB.0.y && eye.y > 0.0);
    }

    #[test]
    fn overlap_stress_counts() {
        let s = load("overlap-stress").unwrap();
        // Number of quads the segment from a floor point to the light crosses.
        let count = |x: f32| {
            let p = Vec3::new(x, 0.0, 0.0);
            s.meshes[1..]
                .iter()
                .filter(|m| {
                    let y = m.positions[0].y;
                    let c = cross_at(p, s.light().center, y);
                    c.x.abs() < 0.6 && c.z.abs() < 0.6
                })
                .count()
        };
        assert_eq!(count(0.0), 300);
        assert_eq!(count(0.79), 300);
        let band = count(0.9);
        assert!(band > 0 && band < 255, "{band}");
        assert_eq!(count(1.01), 0);
    }
}
