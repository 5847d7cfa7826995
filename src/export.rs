//! `penumbra export-scene`: a scene's geometry, camera, light and reference light samples as
//! one JSON document, for renderers outside the crate (the peers of issue 32, to come;
//! `docs/cli.md` "Subcommands").
//!
//! Everything is what the methods themselves use, not a re-derivation: the meshes in world
//! space as loaded (transforms applied, f32), their clip coordinates as the scene pass rounds
//! them ([`crate::gpu::transform::Projection::clip_point`]), the camera's `P·V` with the near plane actually used
//! (infinite far plane), the light, `raycast`'s stratified jittered samples
//! ([`sampling::stratified`] with the scene's `[options.raycast]` `samples` and `seed`), and
//! the clip-space shadow-volume triangles `hard-sv` draws from the light center, in its
//! submission order, with the counting direction it chooses (z-pass or z-fail,
//! [`crate::methods::hard_sv::shadow_test`]; Paper I §3, Paper II §5).
//!
//! A sphere light's samples depend on the receiver (the disk facing it, Paper IV §4.2.1):
//! `samples.unit_disk` then holds the samples' coordinates `(α, β)` on the unit disk in the
//! basis [`sampling::orthonormal_basis`] of that disk's normal, so that a peer maps sample i to
//! `center + radius·(α_i·b1 + β_i·b2)` with the basis of the disk facing its receiver;
//! `samples.positions` is then the disk facing the eye. Single-light scenes only.

use crate::error::InputError;
use crate::frame::Frame;
use crate::geometry::shadow_volume::{shadow_volume_triangles, Capping};
use crate::light::sampling::{self, Pattern};
use crate::methods::hard_sv::{shadow_test, HardSvOptions, ShadowTest};
use crate::methods::raycast::RaycastOptions;
use crate::options::OptionTable;
use crate::scene::{Light, LightShape, Scene};
use glam::{DVec3, Vec3};
use serde_json::{json, Value};

/// The `format` field of the document: bumped when a field changes meaning.
pub const FORMAT: &str = "penumbra-scene-export/1";

/// The export document of `scene` (module doc). Builds the scene's frame (adjacency and depth
/// pass) to get the casters, the near plane and `hard-sv`'s counting direction.
pub fn export_scene(scene: &Scene) -> Result<Value, InputError> {
    if scene.is_multi_light() {
        return Err(InputError::at(
            &scene.source,
            "lights",
            "export-scene exports single-light scenes only",
        ));
    }
    let frame = Frame::render(scene, crate::render::gpu_settings(scene)?)?;
    let proj = &frame.proj;
    let light = scene.light();
    let rc = RaycastOptions::read(scene)?;
    let eye = scene.camera.eye.as_vec3();
    let samples = sampling::stratified(light, rc.samples, Pattern::Jittered { seed: rc.seed }, eye)
        .map_err(|e| scene.option_error(RaycastOptions::NAME, "samples", e))?;
    let mut sample_doc = json!({
        "count": samples.len(),
        "seed": rc.seed,
        "pattern": "jittered",
        "positions": samples.iter().map(|s| s.position.to_array()).collect::<Vec<_>>(),
        "weights": samples.iter().map(|s| s.weight).collect::<Vec<_>>(),
    });
    if let LightShape::Sphere { .. } = light.shape {
        sample_doc["unit_disk"] = json!(unit_disk_coords(rc.samples, rc.seed)?);
    }
    let meshes: Vec<Value> = scene
        .meshes
        .iter()
        .map(|m| {
            json!({
                "name": m.name,
                "receiver_only": m.receiver_only,
                "positions": m.positions.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>(),
                "clip_positions": m.positions.iter().flat_map(|p| proj.clip_point(*p).0).collect::<Vec<_>>(),
                "triangles": m.triangles.iter().flatten().copied().collect::<Vec<_>>(),
            })
        })
        .collect();
    let test = HardSvOptions::read(scene)?.mode;
    let test = shadow_test(test, &frame, &[light.center]);
    let capping = match test {
        ShadowTest::ZPass => Capping::Open,
        ShadowTest::ZFail => Capping::Capped,
    };
    let volume = shadow_volume_triangles(&frame.caster_meshes(), light.center, proj, capping);
    let c = &scene.camera;
    Ok(json!({
        "format": FORMAT,
        "scene": scene.source,
        "width": scene.width,
        "height": scene.height,
        "camera": {
            "eye": c.eye.to_array(),
            "target": c.target.to_array(),
            "up": c.up.to_array(),
            "vfov_deg": c.vfov_deg,
            "near": proj.near,
            "far": Value::Null,
            "view_proj": proj.view_proj.to_cols_array(),
        },
        "light": light_doc(light),
        "samples": sample_doc,
        "meshes": meshes,
        "hard_sv": {
            "mode": match test { ShadowTest::ZPass => "zpass", ShadowTest::ZFail => "zfail" },
            "volume_triangles": volume.len(),
            "volume_clip": volume.iter().flatten().flat_map(|v| v.0).collect::<Vec<_>>(),
        },
    }))
}

/// The light's shape as in a scene file (`type` and its fields) plus its center.
fn light_doc(light: &Light) -> Value {
    let center = light.center.to_array();
    match &light.shape {
        LightShape::Point => json!({"type": "point", "center": center}),
        LightShape::Sphere { radius } => {
            json!({"type": "sphere", "center": center, "radius": radius})
        }
        LightShape::Disk { radius, normal } => json!({
            "type": "disk", "center": center, "radius": radius, "normal": normal.to_array()
        }),
        LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. } => json!({
            "type": light.shape.type_name(), "center": center, "u": u.to_array(), "v": v.to_array()
        }),
    }
}

/// The `(α, β)` coordinates of `raycast`'s samples on the unit disk (module doc): the samples
/// of a unit disk at the origin facing +z, expressed in the basis of its normal.
fn unit_disk_coords(n: u32, seed: u64) -> Result<Vec<[f64; 2]>, InputError> {
    let unit = Light {
        center: Vec3::ZERO,
        shape: LightShape::Disk {
            radius: 1.0,
            normal: Vec3::Z,
        },
    };
    let (b1, b2) = sampling::orthonormal_basis(DVec3::Z);
    let samples = sampling::stratified(&unit, n, Pattern::Jittered { seed }, Vec3::ZERO)
        .map_err(|e| InputError::at("raycast", "samples", e))?;
    Ok(samples
        .iter()
        .map(|s| {
            let p = s.position.as_dvec3();
            [p.dot(b1), p.dot(b2)]
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    fn floats(v: &Value) -> Vec<f64> {
        v.as_array()
            .expect("array")
            .iter()
            .map(|x| x.as_f64().expect("number"))
            .collect()
    }

    /// The document of `cube-of-spheres` holds every mesh triangle, the samples on the light
    /// rectangle (|s|, |t| ≤ 1 along u, v: the definition of a rect light), the shadow volume
    /// hard-sv draws, and clip coordinates that are `P·V` applied to the positions.
    #[test]
    fn cube_of_spheres_document() {
        let mut scene = builtin::load("cube-of-spheres").expect("built-in scene");
        scene.resize(Some(64), None);
        scene.set_cli_option("raycast.samples=16").expect("option");
        let doc = export_scene(&scene).expect("export");
        assert_eq!(doc["format"], FORMAT);
        assert_eq!(doc["width"], 64);
        let tris: usize = scene.meshes.iter().map(|m| m.triangles.len()).sum();
        let exported: usize = doc["meshes"]
            .as_array()
            .expect("meshes")
            .iter()
            .map(|m| m["triangles"].as_array().expect("triangles").len() / 3)
            .sum();
        assert_eq!(exported, tris);
        let light = scene.light();
        let LightShape::Rect { u, v } = light.shape else {
            panic!("cube-of-spheres has a rect light");
        };
        let positions = doc["samples"]["positions"].as_array().expect("positions");
        assert_eq!(positions.len(), 16);
        for p in positions {
            let p = Vec3::from_slice(&floats(p).iter().map(|x| *x as f32).collect::<Vec<_>>());
            let d = (p - light.center).as_dvec3();
            let s = d.dot(u.as_dvec3()) / u.as_dvec3().length_squared();
            let t = d.dot(v.as_dvec3()) / v.as_dvec3().length_squared();
            assert!(s.abs() <= 1.0 + 1e-6 && t.abs() <= 1.0 + 1e-6, "{s} {t}");
        }
        let m = &doc["meshes"][0];
        let pos = floats(&m["positions"]);
        let clip = floats(&m["clip_positions"]);
        let vp = glam::DMat4::from_cols_array(
            &floats(&doc["camera"]["view_proj"])
                .try_into()
                .expect("16 numbers"),
        );
        for (p, c) in pos.chunks(3).zip(clip.chunks(4)).take(50) {
            let want = vp * DVec3::new(p[0], p[1], p[2]).extend(1.0);
            for k in 0..4 {
                assert!((want[k] - c[k]).abs() <= 1e-5 * want[k].abs().max(1.0));
            }
        }
        let n_volume = doc["hard_sv"]["volume_triangles"].as_u64().expect("count") as usize;
        assert!(n_volume > 0);
        assert_eq!(floats(&doc["hard_sv"]["volume_clip"]).len(), n_volume * 12);
        assert!(matches!(
            doc["hard_sv"]["mode"].as_str(),
            Some("zpass") | Some("zfail")
        ));
        assert!(doc["samples"].get("unit_disk").is_none());
    }

    /// A sphere light's unit-disk coordinates lie in the unit disk, and mapped with the eye's
    /// basis they give back the exported positions.
    #[test]
    fn sphere_light_unit_disk() {
        let mut scene = builtin::load("cube-of-spheres-sphere").expect("built-in scene");
        scene.resize(Some(32), None);
        scene.set_cli_option("raycast.samples=16").expect("option");
        let doc = export_scene(&scene).expect("export");
        let light = scene.light();
        let LightShape::Sphere { radius } = light.shape else {
            panic!("sphere light expected");
        };
        let normal = (scene.camera.eye - light.center.as_dvec3()).normalize();
        let (b1, b2) = sampling::orthonormal_basis(normal);
        let disk = doc["samples"]["unit_disk"].as_array().expect("unit_disk");
        let positions = doc["samples"]["positions"].as_array().expect("positions");
        assert_eq!(disk.len(), 16);
        for (ab, p) in disk.iter().zip(positions) {
            let ab = floats(ab);
            assert!(ab[0] * ab[0] + ab[1] * ab[1] <= 1.0 + 2e-6);
            let want = light.center.as_dvec3() + f64::from(radius) * (ab[0] * b1 + ab[1] * b2);
            let got = floats(p);
            for k in 0..3 {
                assert!((want[k] - got[k]).abs() < 1e-4, "{want} {got:?}");
            }
        }
    }
}
