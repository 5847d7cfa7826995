//! The hard cases (`docs/architecture.md` "The hard cases") that apply to sphere lights, shared by
//! the tests of the sphere-light methods (`penumbra_wedges`, `penumbra_map`): a light so large
//! there is no umbra, the eye inside a shadow, overlapping boxes, zigzag silhouettes with high
//! vertex degrees, contact between occluder and receiver, two lights, acute silhouette corners,
//! silhouette edges nearly parallel to the light direction, geometry far from the origin — and the
//! scene and buffer helpers those tests share.

use penumbra::scene::{builtin, LightShape, Scene};
use penumbra::visibility::Visibility;

/// The values of a gray visibility buffer.
pub fn gray(v: &Visibility) -> Vec<f32> {
    match v {
        Visibility::Gray(g) => g.clone(),
        Visibility::Rgb(_) => panic!("gray expected"),
    }
}

/// The built-in scene `name` at `size`×`size`.
pub fn small(name: &str, size: u32) -> Scene {
    let mut s = builtin::load(name).expect("built-in scene");
    s.width = size;
    s.height = size;
    s
}

/// `s` with its first light made a sphere of radius `r`.
pub fn with_sphere(mut s: Scene, r: f32) -> Scene {
    s.lights[0].shape = LightShape::Sphere { radius: r };
    s
}

/// The hard-case scenes at `size`×`size` (module doc), in a fixed order.
pub fn scenes(size: u32) -> Vec<Scene> {
    let mut v = vec![
        with_sphere(small("single-quad", size), 1.5), // no umbra
        with_sphere(small("eye-in-shadow", size), 0.3), // eye inside shadow
        small("pw-2002", size),                       // overlapping boxes
        small("pw-fractal", size),                    // zigzag silhouettes, high vertex degrees
        small("pw-columns", size),                    // contact: columns stand on the floor
        small("two-lights", size),                    // two lights
    ];
    // Acute silhouette corners (Paper I Fig. 7 corner wedges) under a small sphere light.
    let mut s = penumbra::scene::file::load_scene_file(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/hard/acute-corner-sphere.toml"
    )))
    .expect("scenes/hard/acute-corner-sphere.toml");
    s.width = size;
    s.height = size;
    v.push(s);
    // Edges nearly parallel to the light: the cylinder's vertical edges under a light almost
    // straight above its rim.
    let mut s = small("cylinder", size);
    s.lights[0].center = glam::Vec3::new(0.35, 3.2, 0.0);
    v.push(s);
    // Far from the origin (depth precision).
    let mut s = small("cylinder", size);
    let off = glam::Vec3::new(1000.0, 0.0, -1000.0);
    for m in &mut s.meshes {
        for p in &mut m.positions {
            *p += off;
        }
    }
    s.lights[0].center += off;
    s.camera.eye += off.as_dvec3();
    s.camera.target += off.as_dvec3();
    v.push(s);
    v
}
