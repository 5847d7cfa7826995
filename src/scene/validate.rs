//! Scene validation: everything a renderer relies on is checked once, here, and reported as
//! one [`InputError`] naming the scene, the object and the problem
//! (`docs/architecture.md` "Bad input").
//!
//! Checked: image size in `1..=MAX_IMAGE_SIZE`; every number finite (camera, light, every
//! vertex, colours); camera with `vfov_deg` from [`MIN_VFOV_DEG`] up to (not including) 180, `eye ≠ target`, `up` not parallel to
//! the view direction, `near > 0` if given; 1 to [`MAX_LIGHTS`] lights, each of positive size (radius > 0; `u`, `v`
//! non-zero, not parallel, the light at least [`MIN_RECT_LIGHT_WIDTH`] of its length wide;
//! disk normal non-zero; a non-empty texture of `width·height`
//! texels in `[0, 1]`, emitting in every channel); at least one mesh, each a closed, consistently wound two-manifold
//! ([`crate::scene::adjacency::build`], the message names the offending edge) that is not
//! inside out (signed volume not negative; flat two-sided meshes have volume 0); every light
//! centre strictly outside every mesh (bounding box, then ray parity), and every light's
//! shape (sphere, disk, rectangle) apart from every mesh ([`light_shape_touches`]); `ambient` in `[0, 1]`;
//! a `methods` list, if given, not empty (the names are checked by the methods registry).

use super::{Camera, Light, LightShape, Mesh, Scene};
use crate::error::InputError;
use crate::limits::{MAX_IMAGE_SIZE, MAX_LIGHTS, MIN_RECT_LIGHT_WIDTH, MIN_VFOV_DEG};
use crate::primitives::polygon_clip::clip_polygon_to_box;
use crate::primitives::ray_triangle::line_triangle;
use crate::scene::adjacency;
use glam::{DVec2, DVec3, Vec3};

/// Checks every invariant a [`Scene`] promises (see the module docs); the first violation is
/// returned, in the order image size, camera, light, ambient, methods, meshes, light placement.
pub fn validate(scene: &Scene) -> Result<(), InputError> {
    let err = |object: &str, message: String| InputError::at(&scene.source, object, message);
    for (what, v) in [("width", scene.width), ("height", scene.height)] {
        if v == 0 || v > MAX_IMAGE_SIZE {
            return Err(err(what, format!("{v} is outside 1..={MAX_IMAGE_SIZE}")));
        }
    }
    validate_camera(&scene.camera).map_err(|(o, m)| err(o, m))?;
    if scene.lights.is_empty() || scene.lights.len() > MAX_LIGHTS {
        return Err(err(
            "lights",
            format!("has {} lights, needs 1..={MAX_LIGHTS}", scene.lights.len()),
        ));
    }
    for (k, light) in scene.lights.iter().enumerate() {
        validate_light(light).map_err(|(o, m)| err(&scene.light_object(k, o), m))?;
    }
    if !(scene.ambient.is_finite() && (0.0..=1.0).contains(&scene.ambient)) {
        return Err(err(
            "ambient",
            format!("{} is outside [0,1]", scene.ambient),
        ));
    }
    if let Some(methods) = &scene.methods {
        if methods.is_empty() {
            return Err(err(
                "methods",
                "empty list (omit `methods` to run every method)".into(),
            ));
        }
    }
    if scene.meshes.is_empty() {
        return Err(InputError::new(&scene.source, "the scene has no meshes"));
    }
    for (i, mesh) in scene.meshes.iter().enumerate() {
        let object = format!("meshes[{i}] ({})", mesh.name);
        validate_mesh(mesh).map_err(|m| err(&object, m))?;
    }
    for (k, light) in scene.lights.iter().enumerate() {
        for (i, mesh) in scene.meshes.iter().enumerate() {
            if let Some(why) = point_touches(mesh, light.center) {
                return Err(err(
                    &scene.light_object(k, "light"),
                    format!(
                        "light intersects geometry: the light center {} is {why} meshes[{i}] ({})",
                        fmt_f32v(light.center),
                        mesh.name
                    ),
                ));
            }
        }
    }
    for (k, light) in scene.lights.iter().enumerate() {
        for (i, mesh) in scene.meshes.iter().enumerate() {
            if let Some(t) = light_shape_touches(mesh, light) {
                return Err(err(
                    &scene.light_object(k, "light"),
                    format!(
                        "light intersects geometry: the {} light around {} overlaps meshes[{i}] \
                         ({}): its triangle {t} touches or crosses the light",
                        light.shape.type_name(),
                        fmt_f32v(light.center),
                        mesh.name
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The first triangle of the closed mesh `m` that the light's shape touches or crosses, for a
/// light whose center is outside `m` ([`point_touches`]): a triangle within `radius` of a
/// sphere's center, a triangle meeting a disk or a rectangle (its plane section, or the
/// triangle itself when it lies in the light's plane, overlaps the light). A shape whose
/// center is outside the mesh and which meets no triangle is outside the mesh. `None` for a
/// point light and for a shape apart from the mesh.
pub fn light_shape_touches(m: &Mesh, light: &Light) -> Option<usize> {
    let c = light.center.as_dvec3();
    let (shape, reach): (LightRegion, DVec3) = match &light.shape {
        LightShape::Point => return None,
        LightShape::Sphere { radius } => {
            let r = f64::from(*radius);
            (LightRegion::Ball(r), DVec3::splat(r))
        }
        LightShape::Disk { radius, normal } => {
            let r = f64::from(*radius);
            let n = normal.as_dvec3().normalize();
            (LightRegion::Disk(r, n), DVec3::splat(r))
        }
        LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. } => {
            let (u, v) = (u.as_dvec3(), v.as_dvec3());
            (LightRegion::Rect(u, v), u.abs() + v.abs())
        }
    };
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for p in &m.positions {
        lo = lo.min(p.as_dvec3());
        hi = hi.max(p.as_dvec3());
    }
    if (c + reach).cmplt(lo).any() || (c - reach).cmpgt(hi).any() {
        return None;
    }
    m.triangles.iter().position(|t| {
        let tri = t.map(|i| m.positions[i as usize].as_dvec3());
        shape.meets(c, tri)
    })
}

/// The extent of a light around its center, for [`light_shape_touches`].
enum LightRegion {
    /// A ball of this radius.
    Ball(f64),
    /// A disk of this radius facing along the unit normal.
    Disk(f64, DVec3),
    /// The parallelogram spanned by these half-extent vectors.
    Rect(DVec3, DVec3),
}

impl LightRegion {
    /// Whether the region around `c` shares a point with the triangle `tri`.
    fn meets(&self, c: DVec3, tri: [DVec3; 3]) -> bool {
        let [a, b, p] = tri;
        match self {
            LightRegion::Ball(r) => closest_point_on_triangle(c, a, b, p).distance(c) <= *r,
            LightRegion::Disk(r, n) => {
                let closest = match plane_section(c, *n, tri).as_slice() {
                    [] => return false,
                    [q] => *q,
                    [q0, q1] => closest_point_on_segment(c, *q0, *q1),
                    _ => closest_point_on_triangle(c, a, b, p),
                };
                closest.distance(c) <= *r
            }
            LightRegion::Rect(u, v) => {
                // Coordinates (s, t) with x − c = s·u + t·v + k·normal; the light is |s|, |t| ≤ 1.
                let normal = u.cross(*v);
                let (du, dv) = (v.cross(normal), normal.cross(*u));
                let (su, tv) = (u.dot(du), v.dot(dv));
                let st: Vec<DVec2> = plane_section(c, normal, tri)
                    .iter()
                    .map(|q| DVec2::new((*q - c).dot(du) / su, (*q - c).dot(dv) / tv))
                    .collect();
                !clip_polygon_to_box(&st, DVec2::splat(-1.0), DVec2::ONE).is_empty()
            }
        }
    }
}

/// The points where triangle `tri` meets the plane through `c` with normal `n`: none, one
/// point, the two ends of a segment, or the three corners when the triangle lies in the plane.
fn plane_section(c: DVec3, n: DVec3, tri: [DVec3; 3]) -> Vec<DVec3> {
    let d = tri.map(|x| n.dot(x - c));
    if d.iter().all(|&x| x == 0.0) {
        return tri.to_vec();
    }
    let mut pts = Vec::with_capacity(2);
    for i in 0..3 {
        let j = (i + 1) % 3;
        if d[i] == 0.0 {
            pts.push(tri[i]);
        } else if (d[i] < 0.0) != (d[j] < 0.0) && d[j] != 0.0 {
            pts.push(tri[i] + (tri[j] - tri[i]) * (d[i] / (d[i] - d[j])));
        }
    }
    pts
}

/// Closest point to `p` on the segment `ab`.
fn closest_point_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let d = b - a;
    let l2 = d.length_squared();
    if l2 == 0.0 {
        a
    } else {
        a + d * ((p - a).dot(d) / l2).clamp(0.0, 1.0)
    }
}

/// Largest f32 rounding of a stored coordinate that passes without a warning, as a fraction
/// of the scene's size (the diagonal of [`Scene::bounds`]): 10⁻⁴, a tenth of a pixel of a
/// 1024-pixel view of the whole scene.
pub const F32_ROUNDING_WARN_FRACTION: f64 = 1e-4;

/// A warning (not an error) for a scene whose coordinates lie so far from the origin that
/// storing them as f32 (vertices and light centers are f32, as on a GPU) can move a point by
/// more than [`F32_ROUNDING_WARN_FRACTION`] of the scene's size: half an f32 step at the
/// largest coordinate. `None` when the rounding is below that.
pub fn f32_rounding_warning(scene: &Scene) -> Option<String> {
    let (lo, hi) = scene.bounds();
    let size = (hi.as_dvec3() - lo.as_dvec3()).length();
    let largest = lo.abs().max(hi.abs()).max_element();
    let rounding = f64::from(f32::from_bits(largest.to_bits() + 1) - largest) / 2.0;
    (rounding > F32_ROUNDING_WARN_FRACTION * size).then(|| {
        format!(
            "{}: warning: coordinates up to {largest} are stored as f32 and rounded by up to \
             {rounding}, {:.1e} of the scene's size {size:.4} (warned above \
             {F32_ROUNDING_WARN_FRACTION:e}); move the scene toward the origin",
            crate::error::shortened(&scene.source),
            rounding / size
        )
    })
}

/// Formats a vector as `(x, y, z)` with Rust's shortest round-trip digits.
fn fmt_v3(v: DVec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

/// Formats an f32 vector as `(x, y, z)` with f32's shortest round-trip digits.
fn fmt_f32v(v: Vec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

fn finite3(v: DVec3) -> bool {
    v.is_finite()
}

/// Camera checks; the error is (object, message).
fn validate_camera(c: &Camera) -> Result<(), (&'static str, String)> {
    for (what, v) in [
        ("camera.eye", c.eye),
        ("camera.target", c.target),
        ("camera.up", c.up),
    ] {
        if !finite3(v) {
            return Err((what, format!("{} is not finite", fmt_v3(v))));
        }
    }
    if !(c.vfov_deg.is_finite() && c.vfov_deg >= MIN_VFOV_DEG && c.vfov_deg < 180.0) {
        return Err((
            "camera.vfov_deg",
            format!(
                "{} is outside [{MIN_VFOV_DEG}, 180) (narrower views leave less than an f32 \
                 step of the coordinates per pixel)",
                c.vfov_deg
            ),
        ));
    }
    if let Some(n) = c.near {
        if !(n.is_finite() && n > 0.0) {
            return Err(("camera.near", format!("{n} must be a finite number > 0")));
        }
    }
    let dir = c.target - c.eye;
    if dir == DVec3::ZERO {
        return Err((
            "camera.target",
            "equals camera.eye (no view direction)".into(),
        ));
    }
    if !dir.is_finite() {
        return Err(("camera.target", "too far from camera.eye (overflow)".into()));
    }
    if c.up == DVec3::ZERO {
        return Err(("camera.up", "is the zero vector".into()));
    }
    // Relative test on normalized vectors: sin(angle) below 1e-9 counts as parallel.
    if dir.normalize().cross(c.up.normalize()).length() <= 1e-9 {
        return Err((
            "camera.up",
            format!("{} is parallel to the view direction", fmt_v3(c.up)),
        ));
    }
    Ok(())
}

/// The checks of one light on its own (module doc: finite numbers, positive size, a usable
/// texture), as [`validate`] runs them; the error is the field it names (`light.radius`, …)
/// and the message. Public so that code building lights outside a scene (the fuzz targets of
/// wedge construction and coverage) can feed exactly the lights a validated scene holds.
pub fn validate_light(l: &Light) -> Result<(), (&'static str, String)> {
    let v3 = fmt_f32v;
    if !l.center.is_finite() {
        return Err(("light.center", format!("{} is not finite", v3(l.center))));
    }
    let radius = |r: f32| {
        if r.is_finite() && r > 0.0 {
            Ok(())
        } else {
            Err((
                "light.radius",
                format!("{r} must be a finite number > 0 (zero-size light)"),
            ))
        }
    };
    let rect = |u: Vec3, v: Vec3| {
        for (what, x) in [("light.u", u), ("light.v", v)] {
            if !x.is_finite() {
                return Err((what, format!("{} is not finite", v3(x))));
            }
            if x == Vec3::ZERO {
                return Err((what, "is the zero vector (zero-size light)".to_string()));
            }
        }
        let (ud, vd) = (u.as_dvec3(), v.as_dvec3());
        if ud.normalize().cross(vd.normalize()).length() <= 1e-6 {
            return Err((
                "light.v",
                format!(
                    "{} is parallel to light.u {} (zero-area light)",
                    v3(v),
                    v3(u)
                ),
            ));
        }
        let long = ud.length().max(vd.length());
        let wide = ud.cross(vd).length() / long;
        if wide < MIN_RECT_LIGHT_WIDTH * long {
            return Err((
                "light.v",
                format!(
                    "{} and light.u {} make a light {:e} wide and {:e} long: thinner than \
                     {MIN_RECT_LIGHT_WIDTH:e} of its length, its corners are not apart in f32",
                    v3(v),
                    v3(u),
                    2.0 * wide,
                    2.0 * long
                ),
            ));
        }
        Ok(())
    };
    match &l.shape {
        LightShape::Point => Ok(()),
        LightShape::Sphere { radius: r } => radius(*r),
        LightShape::Disk { radius: r, normal } => {
            radius(*r)?;
            if !normal.is_finite() {
                return Err(("light.normal", format!("{} is not finite", v3(*normal))));
            }
            if *normal == Vec3::ZERO {
                return Err(("light.normal", "is the zero vector".into()));
            }
            Ok(())
        }
        LightShape::Rect { u, v } => rect(*u, *v),
        LightShape::TexturedRect { u, v, texture } => {
            rect(*u, *v)?;
            let (w, h) = (texture.width as usize, texture.height as usize);
            if w == 0 || h == 0 {
                return Err((
                    "light.texture",
                    format!("{} is empty ({w}×{h})", texture.source),
                ));
            }
            if texture.texels.len() != w * h {
                return Err((
                    "light.texture",
                    format!(
                        "{}: {} texels for {w}×{h}",
                        texture.source,
                        texture.texels.len()
                    ),
                ));
            }
            if let Some(i) = texture
                .texels
                .iter()
                .position(|t| t.iter().any(|c| !(0.0..=1.0).contains(c)))
            {
                return Err((
                    "light.texture",
                    format!(
                        "{}: texel {i} is {:?}, outside [0,1]",
                        texture.source, texture.texels[i]
                    ),
                ));
            }
            // Visibility per channel is the light seen over the light emitted: 0/0 for a
            // channel no texel emits in.
            for (c, name) in ["red", "green", "blue"].into_iter().enumerate() {
                if texture.texels.iter().all(|t| t[c] == 0.0) {
                    return Err((
                        "light.texture",
                        format!(
                            "{}: every texel's {name} is 0: the light emits no {name}, so its \
                             {name} visibility (light seen / light emitted) would be 0/0",
                            texture.source
                        ),
                    ));
                }
            }
            Ok(())
        }
    }
}

/// Mesh checks: finite vertices, a colour in [0, 1], at least one triangle, closed two-manifold.
fn validate_mesh(m: &Mesh) -> Result<(), String> {
    if let Some(i) = m.positions.iter().position(|p| !p.is_finite()) {
        let p = m.positions[i];
        return Err(format!(
            "vertex {i} is not finite: ({}, {}, {})",
            p.x, p.y, p.z
        ));
    }
    if m.color.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Err(format!("color {:?} is outside [0,1]", m.color));
    }
    if m.triangles.is_empty() {
        return Err("the mesh has no triangles".into());
    }
    if m.receiver_only {
        // It casts nothing, so it needs no silhouettes and may be open (a floor plane).
        return Ok(());
    }
    adjacency::build(m).map_err(|e| e.to_string())?;
    if let Some(volume) = inside_out_volume(&m.positions, &m.triangles) {
        return Err(format!(
            "inside out: negative volume {volume} (triangles must be counter-clockwise seen \
             from outside)"
        ));
    }
    Ok(())
}

/// The signed volume of the closed surface `triangles` when it is inside out, `None` when it
/// is not: outward winding means the signed volume (relative to the first vertex, to limit
/// cancellation) is not negative beyond rounding, −10⁻⁹ of the cube of the largest extent;
/// flat closed meshes such as two-sided quads have volume ≈ 0 and pass. The one rule of
/// [`validate`] and of mesh repair ([`super::repair`]), which turns such parts right side out.
pub fn inside_out_volume(positions: &[Vec3], triangles: &[[u32; 3]]) -> Option<f64> {
    let o = positions[triangles.first()?[0] as usize].as_dvec3();
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let mut volume6 = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3() - o);
        volume6 += a.dot(b.cross(c));
        for p in [a, b, c] {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let extent = (hi - lo).max_element();
    (volume6 < -1e-9 * extent * extent * extent).then_some(volume6 / 6.0)
}

/// Whether the point `c` is on or inside the closed mesh `m` (on, for a receiver-only mesh,
/// which may be open): `None` when strictly outside, else the words for the message
/// ("inside", "on the surface of").
///
/// Outside the mesh's bounding box is outside. Otherwise a point within 1e-6 of the box
/// diagonal of a triangle is on the surface, and else the parity of ray crossings decides.
/// A ray passing within 1e-9 (barycentric) of an edge is ambiguous and another fixed,
/// non-axis-aligned direction is tried. Two-sided quads have even parity everywhere off
/// their plane, as they should.
pub fn point_touches(m: &Mesh, c: Vec3) -> Option<&'static str> {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in &m.positions {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if c.cmplt(lo).any() || c.cmpgt(hi).any() {
        return None;
    }
    let cd = c.as_dvec3();
    let tol = 1e-6 * (hi - lo).as_dvec3().length().max(f64::MIN_POSITIVE);
    let tri = |t: &[u32; 3]| t.map(|i| m.positions[i as usize].as_dvec3());
    if m.triangles.iter().any(|t| {
        let [a, b, p] = tri(t);
        closest_point_on_triangle(cd, a, b, p).distance(cd) <= tol
    }) {
        return Some("on the surface of");
    }
    if m.receiver_only {
        // An open mesh has no inside.
        return None;
    }
    const DIRS: [DVec3; 3] = [
        DVec3::new(0.431_752_3, 0.810_293_7, 0.396_122_1),
        DVec3::new(-0.622_341_9, 0.213_457_7, 0.753_118_3),
        DVec3::new(0.158_832_4, -0.701_225_6, 0.695_119_8),
    ];
    let mut inside = false;
    for dir in DIRS {
        let mut crossings = 0u32;
        let mut ambiguous = false;
        for t in &m.triangles {
            let [a, b, p] = tri(t);
            match ray_hits(cd, dir, a, b, p) {
                Hit::No => {}
                Hit::Yes => crossings += 1,
                Hit::Ambiguous => {
                    ambiguous = true;
                    break;
                }
            }
        }
        inside = crossings % 2 == 1;
        if !ambiguous {
            break;
        }
    }
    inside.then_some("inside")
}

enum Hit {
    No,
    Yes,
    Ambiguous,
}

/// The ray `o + t·d`, `t > 0`, against triangle `abc` ([`line_triangle`], widened by 10⁻⁹ in
/// barycentric coordinates), flagging grazing hits near an edge or a vertex as ambiguous; a
/// ray within 10⁻¹² (relative) of the triangle's plane misses.
fn ray_hits(o: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Hit {
    const EPS: f64 = 1e-9;
    let (e1, e2) = (b - a, c - a);
    let Some(h) = line_triangle(o, d, a, e1, e2, EPS) else {
        return Hit::No;
    };
    if h.det.abs() <= 1e-12 * e1.length() * e2.length() || h.t <= 0.0 {
        return Hit::No; // parallel to the plane (or a degenerate triangle), or behind
    }
    if h.u <= EPS || h.v <= EPS || 1.0 - h.u - h.v <= EPS {
        return Hit::Ambiguous;
    }
    Hit::Yes
}

/// Closest point to `p` on triangle `abc` (Ericson, Real-Time Collision Detection §5.1.5).
fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom == 0.0 {
        // Degenerate (zero-area) triangle: fall back to its longest edge's closest point.
        let seg = |x: DVec3, y: DVec3| {
            let d = y - x;
            let l2 = d.length_squared();
            if l2 == 0.0 {
                x
            } else {
                x + d * ((p - x).dot(d) / l2).clamp(0.0, 1.0)
            }
        };
        let cands = [seg(a, b), seg(b, c), seg(c, a)];
        return cands
            .into_iter()
            .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
            .unwrap_or(a);
    }
    let v = vb / denom;
    let w = vc / denom;
    a + ab * v + ac * w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::procedural::{box_mesh, two_sided_quad, uv_sphere};
    use crate::scene::RgbTexture;

    fn scene() -> Scene {
        Scene {
            source: "test-scene".into(),
            width: 64,
            height: 48,
            camera: Camera {
                eye: DVec3::new(0.0, 2.0, 5.0),
                target: DVec3::ZERO,
                up: DVec3::Y,
                vfov_deg: 45.0,
                near: None,
            },
            lights: vec![Light {
                center: Vec3::new(0.0, 4.0, 0.0),
                shape: LightShape::Rect {
                    u: Vec3::X * 0.5,
                    v: Vec3::Z * 0.5,
                },
            }],
            meshes: vec![
                box_mesh(
                    "floor",
                    Vec3::new(-3.0, -0.1, -3.0),
                    Vec3::new(3.0, 0.0, 3.0),
                    [0.8; 3],
                ),
                uv_sphere("ball", Vec3::new(0.0, 1.0, 0.0), 0.5, 8, 12, [0.8; 3]),
            ],
            methods: None,
            options: Default::default(),
            cli_options: Default::default(),
            ambient: 0.15,
        }
    }

    fn msg(s: &Scene) -> String {
        validate(s).unwrap_err().to_string()
    }

    #[test]
    fn good_scene_passes() {
        validate(&scene()).unwrap();
    }

    #[test]
    fn image_size() {
        let mut s = scene();
        s.width = 0;
        assert_eq!(msg(&s), "test-scene: width: 0 is outside 1..=16384");
        s.width = 1;
        s.height = MAX_IMAGE_SIZE + 1;
        assert!(msg(&s).contains("height"));
    }

    #[test]
    fn camera_errors() {
        let mut s = scene();
        s.camera.eye.x = f64::NAN;
        assert!(
            msg(&s).contains("camera.eye: (NaN, 2, 5) is not finite"),
            "{}",
            msg(&s)
        );
        let mut s = scene();
        s.camera.target = s.camera.eye;
        assert!(msg(&s).contains("camera.target: equals camera.eye"));
        let mut s = scene();
        s.camera.up = s.camera.target - s.camera.eye;
        assert!(msg(&s).contains("camera.up") && msg(&s).contains("parallel"));
        let mut s = scene();
        s.camera.vfov_deg = 180.0;
        assert!(msg(&s).contains("camera.vfov_deg"));
        s.camera.vfov_deg = 1e-30;
        assert_eq!(
            msg(&s),
            "test-scene: camera.vfov_deg: 0.000000000000000000000000000001 is outside \
             [0.1, 180) (narrower views leave less than an f32 step of the coordinates per pixel)"
        );
        s.camera.vfov_deg = MIN_VFOV_DEG;
        validate(&s).unwrap();
        let mut s = scene();
        s.camera.near = Some(0.0);
        assert!(msg(&s).contains("camera.near"));
    }

    #[test]
    fn light_errors() {
        let mut s = scene();
        s.lights[0].shape = LightShape::Sphere { radius: 0.0 };
        assert!(msg(&s).contains("light.radius: 0 must be a finite number > 0 (zero-size light)"));
        s.lights[0].shape = LightShape::Rect {
            u: Vec3::ZERO,
            v: Vec3::Z,
        };
        assert!(msg(&s).contains("light.u: is the zero vector"));
        s.lights[0].shape = LightShape::Rect {
            u: Vec3::X,
            v: Vec3::X * -2.0,
        };
        assert!(msg(&s).contains("light.v") && msg(&s).contains("parallel"));
        // A light 2·10⁷ long and 2 wide: thinner than 10⁻⁶ of its length (MIN_RECT_LIGHT_WIDTH);
        // 2·10⁵ long is accepted.
        s.lights[0].shape = LightShape::Rect {
            u: Vec3::X * 1e7,
            v: Vec3::Z,
        };
        assert_eq!(
            msg(&s),
            "test-scene: light.v: (0, 0, 1) and light.u (10000000, 0, 0) make a light 2e0 wide \
             and 2e7 long: thinner than 1e-6 of its length, its corners are not apart in f32"
        );
        s.lights[0].shape = LightShape::Rect {
            u: Vec3::X * 1e5,
            v: Vec3::Z,
        };
        assert!(validate_light(&s.lights[0]).is_ok());
        s.lights[0].shape = LightShape::Disk {
            radius: 1.0,
            normal: Vec3::ZERO,
        };
        assert!(msg(&s).contains("light.normal"));
        s.lights[0].shape = LightShape::TexturedRect {
            u: Vec3::X,
            v: Vec3::Z,
            texture: RgbTexture {
                width: 0,
                height: 0,
                texels: vec![],
                source: "t.png".into(),
            },
        };
        assert!(msg(&s).contains("light.texture: t.png is empty"));
        s.lights[0].shape = LightShape::TexturedRect {
            u: Vec3::X,
            v: Vec3::Z,
            texture: RgbTexture {
                width: 2,
                height: 1,
                texels: vec![[1.0, 0.0, 0.5], [0.25, 0.0, 0.0]],
                source: "t.png".into(),
            },
        };
        assert_eq!(
            msg(&s),
            "test-scene: light.texture: t.png: every texel's green is 0: the light emits no \
             green, so its green visibility (light seen / light emitted) would be 0/0"
        );
        s.lights[0].shape = LightShape::Point;
        s.lights[0].center.y = f32::INFINITY;
        assert!(msg(&s).contains("light.center"));
    }

    #[test]
    fn mesh_errors() {
        let mut s = scene();
        s.meshes[1].positions[5] = Vec3::new(0.25, 1.0, f32::NAN);
        assert_eq!(
            msg(&s),
            "test-scene: meshes[1] (ball): vertex 5 is not finite: (0.25, 1, NaN)"
        );
        let mut s = scene();
        s.meshes[0].triangles.pop();
        let m = msg(&s);
        assert!(
            m.starts_with("test-scene: meshes[0] (floor): open mesh: edge "),
            "{m}"
        );
        let mut s = scene();
        for t in &mut s.meshes[1].triangles {
            t.swap(0, 1);
        }
        assert!(msg(&s).starts_with("test-scene: meshes[1] (ball): inside out: negative volume"));
        let mut s = scene();
        s.meshes.clear();
        assert!(msg(&s).contains("no meshes"));
        let mut s = scene();
        s.ambient = 1.5;
        assert!(msg(&s).contains("ambient"));
    }

    #[test]
    fn several_lights_are_each_checked_and_named() {
        let mut s = scene();
        let second = Light {
            center: Vec3::new(2.0, 4.0, 0.0),
            shape: LightShape::Sphere { radius: 0.0 },
        };
        s.lights.push(second.clone());
        assert!(
            msg(&s).starts_with("test-scene: lights[1].radius: 0 must be a finite number > 0"),
            "{}",
            msg(&s)
        );
        s.lights[1].shape = LightShape::Sphere { radius: 0.2 };
        validate(&s).unwrap();
        s.lights[1].center = Vec3::new(0.1, 1.05, -0.02);
        assert!(
            msg(&s).starts_with("test-scene: lights[1]: light intersects geometry"),
            "{}",
            msg(&s)
        );
        s.lights = vec![second; MAX_LIGHTS + 1];
        assert_eq!(msg(&s), "test-scene: lights: has 256 lights, needs 1..=255");
        s.lights.clear();
        assert_eq!(msg(&s), "test-scene: lights: has 0 lights, needs 1..=255");
    }

    #[test]
    fn light_inside_geometry() {
        let mut s = scene();
        // A point light: only its center counts (area lights: `area_light_overlapping_geometry`).
        s.lights[0].shape = LightShape::Point;
        s.lights[0].center = Vec3::new(0.1, 1.05, -0.02);
        let m = msg(&s);
        assert!(
            m.contains("light intersects geometry") && m.contains("inside meshes[1] (ball)"),
            "{m}"
        );
        // Inside the bounding box of the sphere but outside the sphere itself: fine.
        s.lights[0].center = Vec3::new(0.45, 1.45, 0.45);
        validate(&s).unwrap();
        // On the floor's top surface.
        s.lights[0].center = Vec3::new(1.0, 0.0, 1.0);
        assert!(msg(&s).contains("on the surface of meshes[0] (floor)"));
        // Next to a two-sided quad, inside its (flat) bounding box only when on its plane.
        let q = [
            Vec3::new(-1.0, 2.0, 1.0),
            Vec3::new(1.0, 2.0, 1.0),
            Vec3::new(1.0, 2.0, -1.0),
            Vec3::new(-1.0, 2.0, -1.0),
        ];
        s.meshes[1] = two_sided_quad("quad", q, [0.5; 3]);
        s.lights[0].center = Vec3::new(0.3, 2.0, 0.2);
        assert!(msg(&s).contains("on the surface of meshes[1] (quad)"));
        s.lights[0].center = Vec3::new(0.3, 3.0, 0.2);
        validate(&s).unwrap();
    }

    #[test]
    fn area_light_overlapping_geometry() {
        // The ball (centre (0, 1, 0), radius 0.5) and the floor (top face y = 0).
        let mut s = scene();
        let overlaps = |s: &Scene, mesh: &str| {
            let m = msg(s);
            assert!(
                m.starts_with("test-scene: light: light intersects geometry: the ")
                    && m.contains(&format!("overlaps {mesh}: its triangle ")),
                "{m}"
            );
        };
        let light = |c: [f32; 3], shape: LightShape| Light {
            center: Vec3::from_array(c),
            shape,
        };
        let rect = |u: Vec3, v: Vec3| LightShape::Rect { u, v };
        let disk = |radius: f32, normal: Vec3| LightShape::Disk { radius, normal };
        // (a light touching the mesh, the same light moved or shrunk clear of it, the mesh)
        let cases = [
            (
                light([0.0, 1.9, 0.0], LightShape::Sphere { radius: 0.5 }),
                light([0.0, 1.9, 0.0], LightShape::Sphere { radius: 0.35 }),
                "meshes[1] (ball)",
            ),
            // A rectangle whose centre is clear of the ball but whose corner cuts into it.
            (
                light([0.7, 1.2, 0.0], rect(Vec3::X * 0.4, Vec3::Z * 0.4)),
                light([1.0, 1.2, 0.0], rect(Vec3::X * 0.4, Vec3::Z * 0.4)),
                "meshes[1] (ball)",
            ),
            // A vertical rectangle reaching down through the floor.
            (
                light([2.0, 0.3, 2.0], rect(Vec3::X * 0.2, Vec3::Y * 0.5)),
                light([2.0, 0.6, 2.0], rect(Vec3::X * 0.2, Vec3::Y * 0.5)),
                "meshes[0] (floor)",
            ),
            // A disk in the plane of the floor's top face, its centre just beyond the edge.
            (
                light([3.2, 0.0, 0.0], disk(0.5, Vec3::Y)),
                light([3.2, 0.0, 0.0], disk(0.1, Vec3::Y)),
                "meshes[0] (floor)",
            ),
            // A tilted disk dipping into the ball.
            (
                light([0.0, 1.7, 0.0], disk(0.6, Vec3::new(1.0, 1.0, 0.0))),
                light([0.0, 1.7, 0.0], disk(0.1, Vec3::new(1.0, 1.0, 0.0))),
                "meshes[1] (ball)",
            ),
        ];
        for (touching, clear, mesh) in cases {
            s.lights[0] = touching;
            overlaps(&s, mesh);
            s.lights[0] = clear;
            validate(&s).unwrap();
        }
    }

    #[test]
    fn far_coordinates_warn() {
        let mut s = scene();
        assert_eq!(f32_rounding_warning(&s), None);
        let far = Vec3::new(30000.0, 0.0, 0.0);
        for m in &mut s.meshes {
            for p in &mut m.positions {
                *p += far;
            }
        }
        s.lights[0].center += far;
        let w = f32_rounding_warning(&s).unwrap();
        assert!(
            w.starts_with(
                "test-scene: warning: coordinates up to 30003 are stored as f32 and rounded by \
                 up to 0.0009765625, 1.0e-4 of the scene's size 9.42"
            ),
            "{w}"
        );
    }

    #[test]
    fn closest_point_cases() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let near = |p: DVec3, q: DVec3| assert!(p.distance(q) < 1e-12, "{p} vs {q}");
        near(
            closest_point_on_triangle(DVec3::new(0.2, 0.2, 1.0), a, b, c),
            DVec3::new(0.2, 0.2, 0.0),
        );
        near(
            closest_point_on_triangle(DVec3::new(-1.0, -1.0, 0.0), a, b, c),
            a,
        );
        near(
            closest_point_on_triangle(DVec3::new(2.0, -1.0, 0.0), a, b, c),
            b,
        );
        near(
            closest_point_on_triangle(DVec3::new(0.5, -1.0, 0.0), a, b, c),
            DVec3::new(0.5, 0.0, 0.0),
        );
        near(
            closest_point_on_triangle(DVec3::new(1.0, 1.0, 0.0), a, b, c),
            DVec3::new(0.5, 0.5, 0.0),
        );
        // Zero-area triangle.
        near(
            closest_point_on_triangle(DVec3::new(0.5, 1.0, 0.0), a, b, DVec3::X * 2.0),
            DVec3::X * 0.5,
        );
    }
}
