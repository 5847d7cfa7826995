//! Camera and projection (`docs/architecture.md` "Coordinates", "Projection",
//! "Viewport").
//!
//! * View matrix as `gluLookAt`, right-handed world.
//! * Everitt–Kilgard infinite-far projection
//!   `P = [[f/a,0,0,0],[0,f,0,0],[0,0,-1,-2n],[0,0,-1,0]]`, f = 1/tan(vfov/2), a = W/H.
//!   A point extruded to infinity (w = 0) gets z_clip = w_clip, i.e. window depth exactly 1
//!   (D24 0xFFFFFF).
//! * Render targets seen from a light ([`super::light_view`]) use a finite frustum instead,
//!   OpenGL's `glFrustum(l, r, b, t, n, f)` ([`Projection::frustum`]); window depth maps back
//!   to view depth (the distance along the view axis) by one rule for both
//!   ([`Projection::view_depth`]).
//! * Clip coordinates are computed as (P·V)·X in f64 and rounded once to f32 ([`ClipVertex`]).
//! * Viewport: `x_w = (x/w + 1)·W/2` and `y_gl = (y/w + 1)·H/2` in f32, OpenGL's y pointing up;
//!   image row j is GL row H−1−j (the flip is done exactly in fixed point, see [`super::fixed`]).
//!   `z_w = (z/w)·0.5 + 0.5` in f32.

use super::shader_float::ShaderFloat;
use crate::scene::{Camera, Scene};
use glam::{DMat4, DVec3, DVec4, Vec3};

/// A vertex in homogeneous clip space, f32 as a GPU's vertex stage would output it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClipVertex(pub [f32; 4]);

/// Default near distance when the scene gives none: 1/1000 of the distance from the eye to
/// the farthest corner of the scene bounds (light included), chosen so that D24 keeps
/// ~10 bits of depth resolution across a scene of that size with the infinite far plane —
/// but never more than half the view depth of the nearest geometry the camera sees
/// ([`nearest_visible_depth`]): a light or a mesh far away must not push the near plane past
/// the scene in view (a light at 1e30 once cleared the whole frame to background).
pub fn default_near(scene: &Scene) -> f64 {
    let camera = &scene.camera;
    let (lo, hi) = scene.bounds();
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let mut far = 0.0f64;
    for i in 0..8 {
        let c = DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        far = far.max((c - camera.eye).length());
    }
    let seen = nearest_visible_depth(scene).unwrap_or(f64::INFINITY);
    (far * 1e-3).min(seen * 0.5).max(1e-6)
}

/// The smallest view depth (distance along the view axis) of any mesh point inside the
/// camera's view pyramid (the frustum without its near and far planes), or `None` when no
/// triangle reaches into it. Each triangle is clipped against the pyramid's four sides and
/// the eye's plane in f64 view space (Sutherland–Hodgman); back faces count too, since the
/// near plane must not cut them either.
pub fn nearest_visible_depth(scene: &Scene) -> Option<f64> {
    let camera = &scene.camera;
    let view = DMat4::look_at_rh(camera.eye, camera.target, camera.up);
    let (tan_x, tan_y) = camera.view_half_tangents(scene.width, scene.height);
    // Inside ≥ 0; view space looks down −z, so the depth is −z.
    let planes: [fn(DVec3, f64, f64) -> f64; 5] = [
        |v, _, _| -v.z,
        |v, tx, _| -v.z * tx - v.x,
        |v, tx, _| -v.z * tx + v.x,
        |v, _, ty| -v.z * ty - v.y,
        |v, _, ty| -v.z * ty + v.y,
    ];
    let mut nearest: Option<f64> = None;
    for m in &scene.meshes {
        let pts: Vec<DVec3> = m
            .positions
            .iter()
            .map(|p| view.transform_point3(p.as_dvec3()))
            .collect();
        for t in &m.triangles {
            let mut poly: Vec<DVec3> = t.iter().map(|&i| pts[i as usize]).collect();
            for plane in planes {
                let d: Vec<f64> = poly.iter().map(|&v| plane(v, tan_x, tan_y)).collect();
                let mut out = Vec::with_capacity(poly.len() + 1);
                for i in 0..poly.len() {
                    let j = (i + 1) % poly.len();
                    if d[i] >= 0.0 {
                        out.push(poly[i]);
                    }
                    if (d[i] >= 0.0) != (d[j] >= 0.0) {
                        let s = d[i] / (d[i] - d[j]);
                        out.push(poly[i] + (poly[j] - poly[i]) * s);
                    }
                }
                poly = out;
                if poly.is_empty() {
                    break;
                }
            }
            for v in &poly {
                let depth = (-v.z).max(0.0);
                nearest = Some(nearest.map_or(depth, |n: f64| n.min(depth)));
            }
        }
    }
    nearest
}

/// The camera transform of one frame: view, projection and their product, in f64.
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Near-plane distance actually used.
    pub near: f64,
    /// Far-plane distance: `f64::INFINITY` for the infinite-far projection.
    pub far: f64,
    /// P·V.
    pub view_proj: DMat4,
    /// (P·V)⁻¹, for un-projecting depth-buffer points.
    pub inv_view_proj: DMat4,
}

impl Projection {
    /// The projection of `scene`'s camera at the scene's image size.
    pub fn for_scene(scene: &Scene) -> Self {
        let near = scene.camera.near.unwrap_or_else(|| default_near(scene));
        Self::new(&scene.camera, scene.width, scene.height, near)
    }

    /// The projection of `camera` for a `width`×`height` image with near plane `near`.
    pub fn new(camera: &Camera, width: u32, height: u32, near: f64) -> Self {
        let view = DMat4::look_at_rh(camera.eye, camera.target, camera.up);
        let f = 1.0 / camera.view_half_tangents(width, height).1;
        let a = width as f64 / height as f64;
        // Column-major: columns of P.
        let proj = DMat4::from_cols(
            DVec4::new(f / a, 0.0, 0.0, 0.0),
            DVec4::new(0.0, f, 0.0, 0.0),
            DVec4::new(0.0, 0.0, -1.0, -1.0),
            DVec4::new(0.0, 0.0, -2.0 * near, 0.0),
        );
        Self::from_matrices(width, height, near, f64::INFINITY, proj, view)
    }

    /// A finite perspective frustum for a `width`×`height` target, as `gluLookAt(eye,
    /// eye + forward, up)` followed by `glFrustum(l, r, b, t, near, far)` with the window
    /// `[l, r] × [b, t]` given as tangents at unit distance (`extent = [l, r, b, t]`, so the
    /// near-plane window is `extent · near`):
    /// `P = [[2n/(r−l),0,(r+l)/(r−l),0],[0,2n/(t−b),(t+b)/(t−b),0],[0,0,−(f+n)/(f−n),−2fn/(f−n)],[0,0,−1,0]]`.
    pub fn frustum(
        eye: DVec3,
        forward: DVec3,
        up: DVec3,
        extent: [f64; 4],
        near: f64,
        far: f64,
        size: [u32; 2],
    ) -> Self {
        let view = DMat4::look_at_rh(eye, eye + forward, up);
        let [l, r, b, t] = extent.map(|e| e * near);
        let (n, f) = (near, far);
        let proj = DMat4::from_cols(
            DVec4::new(2.0 * n / (r - l), 0.0, 0.0, 0.0),
            DVec4::new(0.0, 2.0 * n / (t - b), 0.0, 0.0),
            DVec4::new(
                (r + l) / (r - l),
                (t + b) / (t - b),
                -(f + n) / (f - n),
                -1.0,
            ),
            DVec4::new(0.0, 0.0, -2.0 * f * n / (f - n), 0.0),
        );
        Self::from_matrices(size[0], size[1], near, far, proj, view)
    }

    fn from_matrices(
        width: u32,
        height: u32,
        near: f64,
        far: f64,
        proj: DMat4,
        view: DMat4,
    ) -> Self {
        let view_proj = proj * view;
        Self {
            width,
            height,
            near,
            far,
            view_proj,
            inv_view_proj: view_proj.inverse(),
        }
    }

    /// The view depth (distance along the view axis, > 0 in front) that window depth `z_w`
    /// stands for, in f64 — the inverse of the projection's depth mapping: `n / (1 − z_w)`
    /// for the infinite far plane, `f·n / (f − z_w·(f − n))` for a finite frustum (Wyman &
    /// Hansen's `ConvertToWorldSpace`). Monotone in `z_w` (every step is a correctly rounded
    /// monotone operation), so window-depth order and view-depth order agree.
    pub fn view_depth(&self, z_w: f64) -> f64 {
        self.shader_view_depth::<f64>(z_w)
    }

    /// [`Projection::view_depth`] as a fragment program computes it in the shader precision
    /// `T` (`[options.gpu] shader`, [`crate::gpu::shader_float`]): `n`, `f` and `z_w` rounded
    /// to `T`, every operation rounded (Wyman & Hansen §3, pseudocode lines (5)–(6)). Whether
    /// the far plane is finite is the uniform's, decided before rounding.
    pub fn shader_view_depth<T: ShaderFloat>(&self, z_w: T) -> T {
        let (n, f) = (T::from_f64(self.near), T::from_f64(self.far));
        if self.far.is_finite() {
            f * n / (f - z_w * (f - n))
        } else {
            n / (T::one() - z_w)
        }
    }

    /// Clip coordinates of the world point `p` (w = 1), rounded once to f32.
    pub fn clip_point(&self, p: Vec3) -> ClipVertex {
        round_clip(self.view_proj * p.as_dvec3().extend(1.0))
    }

    /// Clip coordinates of the point at infinity in direction `d` (w = 0), rounded once to f32.
    pub fn clip_direction(&self, d: DVec3) -> ClipVertex {
        round_clip(self.view_proj * d.extend(0.0))
    }

    /// Window depth `(z/w)·0.5 + 0.5` of world point `p` in f64 (unclamped), or `None` when `p`
    /// is not in front of the eye (w ≤ 0). For conservative depth bounds (hierarchical-Z
    /// culling); rasterized depth comes from [`viewport`] in f32.
    pub fn window_depth(&self, p: DVec3) -> Option<f64> {
        let h = self.view_proj * p.extend(1.0);
        (h.w > 0.0).then(|| (h.z / h.w) * 0.5 + 0.5)
    }

    /// The world point seen at the center of pixel (`x`, `y`) (row 0 at the top) at window depth
    /// `z_w` in [0, 1]: the inverse of the viewport and projection, in f64.
    pub fn unproject(&self, x: u32, y: u32, z_w: f64) -> DVec3 {
        let ndc_x = (x as f64 + 0.5) / self.width as f64 * 2.0 - 1.0;
        let ndc_y = 1.0 - (y as f64 + 0.5) / self.height as f64 * 2.0;
        let ndc_z = z_w * 2.0 - 1.0;
        let h = self.inv_view_proj * DVec4::new(ndc_x, ndc_y, ndc_z, 1.0);
        h.truncate() / h.w
    }
}

/// A world-space plane carried into window coordinates: `f(x, y, z_w) = a·x + b·y + c·z_w + d`
/// for pixel column `x`, row `y` (row 0 at the top; the pixel center is at +½, folded into
/// `d`) and window depth `z_w`, with the sign of the world plane's equation at the point seen
/// there (for points in front of the eye). This is the plane a vertex program hands a fragment
/// program "transformed in viewport-space" (Forest et al. 2006 §4.2, Fig. 7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowPlane {
    /// Coefficient of the pixel column.
    pub a: f64,
    /// Coefficient of the pixel row.
    pub b: f64,
    /// Coefficient of the window depth.
    pub c: f64,
    /// Constant term (pixel centers included).
    pub d: f64,
}

impl WindowPlane {
    /// The plane's function at the center of pixel (`x`, `y`) and depth `z_w`.
    pub fn at(&self, x: u32, y: u32, z_w: f64) -> f64 {
        self.a * x as f64 + self.b * y as f64 + self.c * z_w + self.d
    }

    /// Whether the whole footprint of pixel (`x`, `y`) — the square of side 1 around its
    /// center, at depth `z_w` — is on the positive side (Fig. 7: "the rasterized fragment is
    /// rejected if its corresponding real-world fragment is outside any plane").
    pub fn footprint_outside(&self, x: u32, y: u32, z_w: f64) -> bool {
        self.at(x, y, z_w) - 0.5 * (self.a.abs() + self.b.abs()) > 0.0
    }
}

impl Projection {
    /// The world plane `normal · X − offset` in window coordinates ([`WindowPlane`]): the
    /// plane in clip space is `(P·V)⁻ᵀ·(normal, −offset)`, and `x_ndc = (x + ½)·2/W − 1`,
    /// `y_ndc = 1 − (y + ½)·2/H`, `z_ndc = 2·z_w − 1` (the viewport of [`Projection::unproject`]);
    /// its value there is the world equation divided by the clip w, which is positive in front
    /// of the eye.
    pub fn window_plane(&self, normal: DVec3, offset: f64) -> WindowPlane {
        let pc = self.inv_view_proj.transpose() * normal.extend(-offset);
        let (w, h) = (self.width as f64, self.height as f64);
        WindowPlane {
            a: pc.x * 2.0 / w,
            b: -pc.y * 2.0 / h,
            c: 2.0 * pc.z,
            d: pc.x * (1.0 / w - 1.0) + pc.y * (1.0 - 1.0 / h) - pc.z + pc.w,
        }
    }
}

fn round_clip(v: DVec4) -> ClipVertex {
    ClipVertex([v.x as f32, v.y as f32, v.z as f32, v.w as f32])
}

/// Window coordinates of a clip vertex with w > 0, in f32 and OpenGL orientation (y up):
/// `(x/w + 1)·W/2`, `(y/w + 1)·H/2`, `(z/w)·0.5 + 0.5`.
pub fn viewport(v: ClipVertex, width: u32, height: u32) -> [f32; 3] {
    let [x, y, z, w] = v.0;
    let xn = x / w;
    let yn = y / w;
    let zn = z / w;
    [
        (xn + 1.0) * (width as f32 * 0.5),
        (yn + 1.0) * (height as f32 * 0.5),
        zn * 0.5 + 0.5,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_plane_has_the_sign_and_zero_of_the_world_plane() {
        let proj = Projection::new(&cam(), 64, 48, 0.1);
        let normal = DVec3::new(0.3, -0.5, 0.8).normalize();
        let offset = 0.2;
        let wp = proj.window_plane(normal, offset);
        for (x, y, z) in [(3, 5, 0.97), (40, 20, 0.995), (63, 47, 0.9)] {
            let p = proj.unproject(x, y, z);
            let world = normal.dot(p) - offset;
            let win = wp.at(x, y, z);
            assert_eq!(world > 0.0, win > 0.0, "({x}, {y}, {z})");
            // The ratio is 1/w_clip, the same for every plane at that point.
            let h = proj.view_proj * p.extend(1.0);
            assert!((win - world / h.w).abs() < 1e-9 * (1.0 + world.abs() / h.w));
        }
    }

    fn cam() -> Camera {
        Camera {
            eye: DVec3::new(0.0, 0.0, 5.0),
            target: DVec3::ZERO,
            up: DVec3::Y,
            vfov_deg: 90.0,
            near: Some(0.5),
        }
    }

    /// The default near plane: 1/1000 of the farthest corner of the bounds where that is in
    /// front of all geometry in view (single-quad: unchanged by the cap), and at most half the
    /// nearest visible depth when a light far away stretches the bounds.
    #[test]
    fn default_near_stays_in_front_of_the_geometry_in_view() {
        let mut s = crate::scene::builtin::load("single-quad").unwrap();
        let seen = nearest_visible_depth(&s).unwrap();
        let near = default_near(&s);
        assert!(near < 0.5 * seen && near > 1e-4, "{near} vs {seen}");
        s.lights[0].center.y = 1e30;
        assert_eq!(nearest_visible_depth(&s), Some(seen));
        assert_eq!(default_near(&s), 0.5 * seen);
        // The floor passes under the eye: the nearest point in view is where the bottom of the
        // view pyramid meets it, not a vertex (the floor's corners are behind the camera or
        // outside the view).
        let mut low = crate::scene::builtin::load("single-quad").unwrap();
        low.camera.eye = DVec3::new(0.0, 0.5, 0.0);
        low.camera.target = DVec3::new(0.0, 0.5, -1.0);
        low.camera.vfov_deg = 90.0;
        low.width = 64;
        low.height = 64;
        let seen = nearest_visible_depth(&low).unwrap();
        // Bottom plane y = 0.5 − depth·tan(45°) meets the floor top y = 0 at depth 0.5.
        assert!((seen - 0.5).abs() < 1e-9, "{seen}");
        // Looking over every mesh (the floor would need a depth of 28 to enter the view).
        low.camera.eye = DVec3::new(0.0, 5.0, 0.0);
        low.camera.target = DVec3::new(10.0, 5.0, 0.0);
        low.camera.vfov_deg = 20.0;
        assert_eq!(nearest_visible_depth(&low), None);
    }

    #[test]
    fn point_at_infinity_has_depth_exactly_one() {
        let p = Projection::new(&cam(), 64, 64, 0.5);
        for d in [DVec3::new(0.1, 0.2, -1.0), DVec3::new(-3.0, 1.0, -0.5)] {
            let v = p.clip_direction(d);
            assert_eq!(v.0[2], v.0[3]);
            assert_eq!(viewport(v, 64, 64)[2], 1.0);
        }
    }

    #[test]
    fn near_plane_maps_to_depth_zero_and_center_to_middle() {
        let p = Projection::new(&cam(), 64, 32, 0.5);
        let v = p.clip_point(Vec3::new(0.0, 0.0, 4.5));
        let w = viewport(v, 64, 32);
        assert_eq!(w, [32.0, 16.0, 0.0]);
    }

    #[test]
    fn frustum_maps_near_and_far_and_view_depth_inverts_it() {
        // Looking down −z from the origin, window [−1, 1] × [−0.5, 0.5] at unit distance.
        let p = Projection::frustum(
            DVec3::ZERO,
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::Y,
            [-1.0, 1.0, -0.5, 0.5],
            2.0,
            10.0,
            [64, 32],
        );
        let near = viewport(p.clip_point(Vec3::new(0.0, 0.0, -2.0)), 64, 32);
        let far = viewport(p.clip_point(Vec3::new(0.0, 0.0, -10.0)), 64, 32);
        assert_eq!(near[2], 0.0);
        assert!((far[2] - 1.0).abs() < 1e-6, "{far:?}");
        // The corner of the window at distance 5 maps to the corner of the viewport.
        let corner = viewport(p.clip_point(Vec3::new(5.0, 2.5, -5.0)), 64, 32);
        assert!((corner[0] - 64.0).abs() < 1e-4 && (corner[1] - 32.0).abs() < 1e-4);
        for d in [2.0, 3.0, 7.5, 10.0] {
            let z = p.window_depth(DVec3::new(0.3, -0.1, -d)).unwrap();
            assert!((p.view_depth(z) - d).abs() < 1e-12 * d, "{d}");
        }
        // The infinite projection: the same rule with f = ∞.
        let q = Projection::new(&cam(), 64, 64, 0.5);
        let z = q.window_depth(DVec3::new(0.0, 0.0, 1.0)).unwrap();
        assert!((q.view_depth(z) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn unproject_inverts_projection() {
        let p = Projection::new(&cam(), 64, 64, 0.5);
        let x = Vec3::new(0.3, -0.7, 1.0);
        let w = viewport(p.clip_point(x), 64, 64);
        // Pixel containing the point, then un-project at its own depth: lands within a pixel.
        let px = w[0].floor() as u32;
        let py = 64 - 1 - w[1].floor() as u32;
        let back = p.unproject(px, py, w[2] as f64);
        assert!((back - x.as_dvec3()).length() < 0.1, "{back:?}");
    }
}
