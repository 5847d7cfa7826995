//! Rendering from a light (`docs/architecture.md` "Projection": render targets seen from the
//! light go through the same rasterizer): a camera at the light center with a render target of
//! its own resolution and depth format, the shadow map drawn into it, and the one rule for
//! reading such a map at a point ([`LightView::sample`]).
//!
//! # The light-view camera
//!
//! A square `map-size`×`map-size` target (Wyman & Hansen §5 render their maps at the image
//! size; the penumbra-map method defaults `map-size` to the frame's larger side) seen through
//! one perspective frustum ([`Projection::frustum`], finite far plane) from the light center.
//! The frustum covers the receivers by covering the scene: every mesh vertex is inside it,
//! hence every triangle (the frustum is convex), every receiver and every occluder between a
//! receiver and the light. It is fitted as follows ([`LightView::fit`]):
//!
//! * the view axis is the axis of the narrowest cone from the light center around every mesh
//!   vertex: the center of the smallest ball enclosing the unit directions to the vertices,
//!   approximated by [`AXIS_ITERATIONS`] Bădoiu–Clarkson steps (start at the direction to the
//!   first vertex; step k moves the center 1/(k + 2) of the way toward the farthest
//!   direction), in f64, in vertex order; the up vector is the world axis least aligned with
//!   it (X, Y, Z on ties);
//! * every vertex must lie within [`MAX_LIGHT_VIEW_HALF_ANGLE_DEG`] of the axis, else the
//!   scene cannot be covered by one frustum (geometry beside or behind the light) and
//!   [`LightView::fit`] fails naming the vertex farthest from the axis, its mesh and its angle
//!   — rather than render a map that silently misses receivers;
//! * the window `[l, r] × [b, t]` is the bounding rectangle of the vertices' tangents
//!   (x/d, y/d) at view depth d, widened by [`FRUSTUM_MARGIN`] of its span on each side
//!   (at least 1e-6), so that no vertex lies on a side plane; the frustum is asymmetric, so
//!   the map's texels are spent on the scene only;
//! * near = (1 − [`FRUSTUM_MARGIN`]) · the smallest vertex view depth and far =
//!   (1 + [`FRUSTUM_MARGIN`]) · the largest: the tightest depth range, which is what D16 and
//!   D24 precision depend on.
//!
//! # Distance as depth (the D-buffer, CGI 2004 §3.2)
//!
//! "Instead of using standard matrix multiplication to transform the vertices from world space
//! to light source view space, the z-coordinate of the vertices is calculated as the distance
//! between the vertex and c": [`LightView::distance_clip_point`] keeps x, y and w of the
//! view's projection (so the vertex lands on the same texel) and replaces z by
//! `w·(2·|p − c|/range − 1)`, so that the window depth is `|p − c|/range` for distances in
//! [0, `range`]; the rasterizer then interpolates it linearly in window space like any depth
//! and the depth format quantizes it. Clipping against z keeps exactly the distances in
//! [0, `range`].
//!
//! # The shadow map
//!
//! [`LightView::render_depth`]: every mesh in file order, triangles in order, through the
//! same setup (back faces culled, as the scene pass: for closed meshes the nearest surface
//! seen from the light is front-facing), binning and tile traversal as every pass, depth LESS
//! with writes, cleared to 1.0, with a polygon offset ([`PolygonOffset`], the shadow-map bias)
//! added to each fragment's depth before it is quantized.

use super::buffers::{alloc_tiles, DepthTile};
use super::counters::Counters;
use super::depth::{DepthFormat, DepthState, PolygonOffset};
use super::probe::{Overflow, PassProbe, PrimitiveKind, Raw};
use super::raster::{bin, draw, Fragment, TileDraw};
use super::setup::{setup_all, CullMode};
use super::texture::{nearest, sample_2d, Filter, Wrap};
use super::tiling::Tiling;
use super::transform::{viewport, ClipVertex, Projection};
use crate::scene::Scene;
use glam::{DVec3, Vec3};

/// The largest angle between the light's view axis and a mesh vertex that one frustum
/// covers (module doc). A frustum of half-angle 80° spends a texel on 5.7 times the tangent
/// range of one on the axis; beyond it the map degenerates toward the 90° limit.
pub const MAX_LIGHT_VIEW_HALF_ANGLE_DEG: f64 = 80.0;

/// Relative margin of the fitted frustum's window and depth range (module doc).
pub const FRUSTUM_MARGIN: f64 = 0.01;

/// Bădoiu–Clarkson steps of the view-axis fit (module doc): after k steps the enclosing ball
/// is within a factor 1 + 1/√k of the smallest, so the cone's half-angle is within a few
/// percent of the narrowest possible.
pub const AXIS_ITERATIONS: usize = 400;

/// The axis of the narrowest cone around the unit `directions` (module doc).
fn enclosing_cone_axis(directions: &[DVec3]) -> DVec3 {
    let Some(&first) = directions.first() else {
        return DVec3::NEG_Y;
    };
    let mut center = first;
    for k in 0..AXIS_ITERATIONS {
        let mut far = first;
        let mut far_d = -1.0;
        for &d in directions {
            let dist = d.distance_squared(center);
            if dist > far_d {
                far_d = dist;
                far = d;
            }
        }
        center += (far - center) / (k as f64 + 2.0);
    }
    center.try_normalize().unwrap_or(DVec3::NEG_Y)
}

/// Why no single frustum covers a scene from a light point.
#[derive(Debug, Clone, PartialEq)]
pub struct UncoveredVertex {
    /// Index of the mesh in the scene.
    pub mesh: usize,
    /// Index of the vertex in the mesh.
    pub vertex: usize,
    /// The vertex position.
    pub position: Vec3,
    /// Its angle from the fitted view axis, in degrees.
    pub angle_deg: f64,
}

/// A camera at a light center with its own square render target (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct LightView {
    /// The light center (the eye of this view).
    pub center: DVec3,
    /// Unit view direction.
    pub axis: DVec3,
    /// The frustum: `proj.near`, `proj.far` and the map size in `proj.width`/`proj.height`.
    pub proj: Projection,
    /// The depth format of the target.
    pub depth: DepthFormat,
    /// The target's tiling (same tile size as the frame).
    pub tiling: Tiling,
}

impl LightView {
    /// Fit a view from `center` covering every vertex of the meshes of `scene` that `covers`
    /// accepts (by index; module doc), rendering into a square target of format `depth` tiled
    /// by `tiling` (its width is the map size). The methods leave out the meshes whose shadow
    /// reaches no receiver ([`crate::frame::Frame::within_light_influence`]): they are still
    /// rendered, and clipped.
    ///
    /// Errors: the first vertex (mesh order, vertex order) farther than
    /// [`MAX_LIGHT_VIEW_HALF_ANGLE_DEG`] from the axis.
    pub fn fit(
        scene: &Scene,
        center: Vec3,
        tiling: Tiling,
        depth: DepthFormat,
        covers: impl Fn(usize) -> bool,
    ) -> Result<Self, UncoveredVertex> {
        let c = center.as_dvec3();
        let covered = || {
            scene
                .meshes
                .iter()
                .enumerate()
                .filter(|(mi, _)| covers(*mi))
        };
        let directions: Vec<DVec3> = covered()
            .flat_map(|(_, m)| m.positions.iter())
            .map(|p| (p.as_dvec3() - c).normalize_or_zero())
            .collect();
        let axis = enclosing_cone_axis(&directions);
        let up = [DVec3::X, DVec3::Y, DVec3::Z]
            .into_iter()
            .min_by(|a, b| a.dot(axis).abs().total_cmp(&b.dot(axis).abs()))
            .unwrap_or(DVec3::Y);
        let right = axis.cross(up).normalize();
        let true_up = right.cross(axis);
        let max_angle = MAX_LIGHT_VIEW_HALF_ANGLE_DEG.to_radians();
        let mut ext = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let (mut near, mut far) = (f64::INFINITY, 0.0f64);
        let mut worst: Option<UncoveredVertex> = None;
        for (mi, m) in covered() {
            for (vi, p) in m.positions.iter().enumerate() {
                let v = p.as_dvec3() - c;
                let d = v.dot(axis);
                let (x, y) = (v.dot(right), v.dot(true_up));
                let angle = libm::atan2(libm::hypot(x, y), d);
                if angle > max_angle {
                    if worst
                        .as_ref()
                        .is_none_or(|w| angle.to_degrees() > w.angle_deg)
                    {
                        worst = Some(UncoveredVertex {
                            mesh: mi,
                            vertex: vi,
                            position: *p,
                            angle_deg: angle.to_degrees(),
                        });
                    }
                    continue;
                }
                let (tx, ty) = (x / d, y / d);
                ext = [
                    ext[0].min(tx),
                    ext[1].max(tx),
                    ext[2].min(ty),
                    ext[3].max(ty),
                ];
                near = near.min(d);
                far = far.max(d);
            }
        }
        if let Some(w) = worst {
            return Err(w);
        }
        for k in [0, 2] {
            let pad = (FRUSTUM_MARGIN * (ext[k + 1] - ext[k])).max(1e-6);
            ext[k] -= pad;
            ext[k + 1] += pad;
        }
        let proj = Projection::frustum(
            c,
            axis,
            true_up,
            ext,
            near * (1.0 - FRUSTUM_MARGIN),
            far * (1.0 + FRUSTUM_MARGIN),
            [tiling.width, tiling.width],
        );
        Ok(Self {
            center: c,
            axis,
            proj,
            depth,
            tiling,
        })
    }

    /// The map's edge in texels.
    pub fn size(&self) -> u32 {
        self.proj.width
    }

    /// The view depth (distance along the axis) of world point `p`.
    pub fn depth_of(&self, p: DVec3) -> f64 {
        (p - self.center).dot(self.axis)
    }

    /// Clip coordinates of world point `p` in this view (f64, rounded once to f32).
    pub fn clip_point(&self, p: DVec3) -> ClipVertex {
        let h = self.proj.view_proj * p.extend(1.0);
        ClipVertex([h.x as f32, h.y as f32, h.z as f32, h.w as f32])
    }

    /// Window coordinates (x, y in texels with y up as OpenGL, z the window depth) of the
    /// world point `p`, as a vertex stage and the viewport would compute them (f32), or `None`
    /// when `p` is not in front of the light (w ≤ 0).
    pub fn window(&self, p: Vec3) -> Option<[f32; 3]> {
        let clip = self.clip_point(p.as_dvec3());
        (clip.0[3] > 0.0).then(|| viewport(clip, self.size(), self.size()))
    }

    /// The D-buffer's vertex stage (module doc, "Distance as depth"): clip coordinates of
    /// world point `p` with the distance to the light center as depth over [0, `range`]
    /// (f64, rounded once to f32).
    pub fn distance_clip_point(&self, p: DVec3, range: f64) -> ClipVertex {
        let h = self.proj.view_proj * p.extend(1.0);
        let z = h.w * (2.0 * (p - self.center).length() / range - 1.0);
        ClipVertex([h.x as f32, h.y as f32, z as f32, h.w as f32])
    }

    /// The texel of a map of this view that nearest sampling reads at window coordinates
    /// (x, y), clamped to the edge, as (tile, index in the tile) — the texel
    /// [`LightView::sample`] reads with [`Filter::Nearest`].
    pub fn nearest_texel(&self, x: f32, y: f32) -> (usize, usize) {
        let n = self.size();
        let i = nearest(x as f64, n, Wrap::ClampToEdge);
        let row = n - 1 - nearest(y as f64, n, Wrap::ClampToEdge);
        (self.tiling.tile_of(i, row), self.tiling.local(i, row))
    }

    /// Sample a map of this view stored tile-major (one value per texel, read with
    /// `texel(tile, local)`) at window coordinates (x, y) with `filter`, clamped to the edge
    /// ([`super::texture`]; window y points up, so texel row j is image row size − 1 − j).
    pub fn sample(
        &self,
        x: f32,
        y: f32,
        filter: Filter,
        texel: impl Fn(usize, usize) -> f64,
    ) -> f64 {
        super::shader_ops::fetch();
        self.sample_texels(x, y, filter, texel)
    }

    /// [`LightView::sample`] without counting a fetch (what a probe replays).
    fn sample_texels(
        &self,
        x: f32,
        y: f32,
        filter: Filter,
        texel: impl Fn(usize, usize) -> f64,
    ) -> f64 {
        let n = self.size();
        sample_2d(
            x as f64,
            y as f64,
            [n, n],
            Wrap::ClampToEdge,
            filter,
            |i, j| {
                let row = n - 1 - j;
                texel(self.tiling.tile_of(i, row), self.tiling.local(i, row))
            },
        )
    }

    /// The texels (column, image row) [`LightView::sample`] reads at window coordinates (x, y)
    /// with `filter`, in the order it reads them: what a probe of a map lookup watches
    /// ([`super::probe`]).
    pub fn texels_read(&self, x: f32, y: f32, filter: Filter) -> Vec<[u32; 2]> {
        let read = std::cell::RefCell::new(Vec::new());
        self.sample_texels(x, y, filter, |t, l| {
            read.borrow_mut().push(self.tiling.position(t, l));
            0.0
        });
        let mut texels = read.into_inner();
        let mut seen = Vec::new();
        texels.retain(|t| {
            let new = !seen.contains(t);
            seen.push(*t);
            new
        });
        texels
    }

    /// The clip coordinates of the triangles of `scene` in this view, meshes in file order,
    /// triangles in order: of every mesh (the primitive ids of the scene pass), or with
    /// `casters_only` of the meshes that cast shadows (not the receiver-only ones).
    fn scene_triangles(&self, scene: &Scene, casters_only: bool) -> Vec<[ClipVertex; 3]> {
        let mut prims = Vec::new();
        for m in scene
            .meshes
            .iter()
            .filter(|m| !(casters_only && m.receiver_only))
        {
            let clip: Vec<ClipVertex> = m
                .positions
                .iter()
                .map(|p| self.clip_point(p.as_dvec3()))
                .collect();
            prims.extend(m.triangles.iter().map(|t| t.map(|i| clip[i as usize])));
        }
        prims
    }

    /// Per scene triangle (primitive id order), the largest window-depth slope per texel and
    /// the largest vertex depth it has in this view, as triangle setup computes them for
    /// [`PolygonOffset`] — for a depth offset applied when a map is read rather than when it
    /// is rendered. A triangle setup drops (seen edge-on) gets slope 0 and depth 1.
    pub fn depth_slopes(&self, scene: &Scene) -> Vec<(f64, f32)> {
        let (tris, _) = setup_all(
            &self.scene_triangles(scene, false),
            CullMode::None,
            &self.tiling,
        );
        let mut out = vec![(0.0, 1.0); scene.meshes.iter().map(|m| m.triangles.len()).sum()];
        for t in tris.iter().rev() {
            out[t.prim as usize] = (t.max_depth_slope(), t.z_range[1]);
        }
        out
    }

    /// The shadow-map test (`GL_TEXTURE_COMPARE_MODE` with `GL_LEQUAL`, nearest): whether a
    /// point at window coordinates `(x, y, z)` of this view is lit by the light center —
    /// its quantized depth is at most the stored depth of the nearest texel of
    /// `shadow_map`. The stored value is read from the tile storage (the caller counts it).
    pub fn lit(&self, shadow_map: &[DepthTile], [x, y, z]: [f32; 3]) -> bool {
        let stored = self.sample(x, y, Filter::Nearest, |t, l| shadow_map[t].values[l] as f64);
        self.depth.quantize(z) as f64 <= stored
    }

    /// Render the depth of every mesh of `scene` that casts shadows (receiver-only meshes
    /// cast none) from the light with polygon `offset` (module doc, "The shadow map"): the
    /// tile-major depth target and the pass counters. The hierarchical-Z unit is on with HiZ
    /// tiles of edge `hiz` (`Some`, e.g.
    /// [`DEFAULT_HIZ_TILE_SIZE`](crate::limits::DEFAULT_HIZ_TILE_SIZE)), or off (`None`) (early Z
    /// as in the scene pass: [`crate::gpu::hiz`]): a triangle whose offset depth is at or
    /// behind a tile's zmax at its nearest vertex fails LESS at every texel there and is not
    /// drawn in it ([`super::setup::RasterTriangle::nearest_offset_depth`]); the same bits on
    /// and off (unit test). With a probe, the clear and every fragment at the texels `probe`
    /// watches are recorded ([`super::probe`]).
    pub fn render_depth(
        &self,
        scene: &Scene,
        offset: PolygonOffset,
        hiz: Option<u32>,
        probe: Option<&PassProbe>,
    ) -> (Vec<DepthTile>, Counters) {
        let prims = self.scene_triangles(scene, true);
        let (tris, mut counters) = setup_all(&prims, CullMode::Back, &self.tiling);
        let bins = bin(&self.tiling, &tris);
        let mut tiles = alloc_tiles(&self.tiling, |t, _| {
            let hiz_tile = hiz.unwrap_or(self.tiling.tile);
            DepthTile::cleared_in(self.depth, &self.tiling, t, hiz_tile)
        });
        if let Some(p) = probe {
            p.record_each(|tap| {
                tap.event()
                    .clear("shadow-map", Raw::Depth(self.depth.far()))
            });
        }
        let state = DepthState::LESS_WRITE;
        let format = self.depth;
        counters += draw(
            &self.tiling,
            &mut tiles,
            &tris,
            &bins,
            probe,
            |t, tile, tri, c| match hiz {
                Some(_) => {
                    let near = tri.nearest_offset_depth(offset, format);
                    tile.early_z(&self.tiling, t, tri.bbox, near, c)
                }
                None => TileDraw::Whole,
            },
            |_, tile, tri, f, c, tap| {
                let z = tri.offset_depth(offset, format, f.z);
                let before = tile.values[f.local];
                let pass = tile.test_and_write(&state, &Fragment { z, ..f }, c);
                if let Some(tap) = tap {
                    let e = tap.event().primitive(
                        PrimitiveKind::SceneTriangle,
                        tri.prim,
                        "",
                        Some(tri.front_facing),
                    );
                    let e = e.value("offset", z as f64 - f.z as f64).depth(
                        format,
                        state.func,
                        format.quantize(z),
                        before,
                        pass,
                    );
                    let after = Raw::Depth(tile.values[f.local]);
                    tap.push(e.write("shadow-map", Raw::Depth(before), after, Overflow::Clamp, 0));
                }
            },
        );
        (tiles, counters)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::DEFAULT_HIZ_TILE_SIZE;
    use crate::scene::builtin;

    fn tiling(size: u32) -> Tiling {
        Tiling::new(size, size, 8).unwrap()
    }

    #[test]
    fn fitted_frustum_covers_every_vertex_inside_the_window_and_depth_range() {
        for name in [
            "cube-of-spheres-sphere",
            "pw-fractal",
            "cylinder",
            "two-lights",
        ] {
            let scene = builtin::load(name).unwrap();
            for light in &scene.lights {
                let view =
                    LightView::fit(&scene, light.center, tiling(128), DepthFormat::D24, |_| {
                        true
                    })
                    .unwrap_or_else(|e| panic!("{name}: {e:?}"));
                for m in &scene.meshes {
                    for p in &m.positions {
                        let [x, y, z] = view.window(*p).unwrap();
                        assert!((0.0..128.0).contains(&x) && (0.0..128.0).contains(&y));
                        assert!(z > 0.0 && z < 1.0, "{name}: {z}");
                    }
                }
            }
        }
    }

    #[test]
    fn geometry_above_and_below_the_light_is_reported() {
        let mut scene = builtin::load("cylinder").unwrap();
        // A slab just above the light and the floor below: no cone narrower than 90° holds
        // both.
        let c = scene.light().center;
        scene.meshes.push(crate::scene::procedural::box_mesh(
            "ceiling",
            c + Vec3::new(-1.0, 0.5, -1.0),
            c + Vec3::new(1.0, 0.6, 1.0),
            [0.5; 3],
        ));
        let e = LightView::fit(&scene, c, tiling(64), DepthFormat::D24, |_| true).unwrap_err();
        assert!(e.angle_deg > MAX_LIGHT_VIEW_HALF_ANGLE_DEG, "{e:?}");
        let p = scene.meshes[e.mesh].positions[e.vertex];
        assert_eq!(p, e.position);
        // Without the slab the scene is covered.
        scene.meshes.pop();
        LightView::fit(&scene, c, tiling(64), DepthFormat::D24, |_| true).unwrap();
    }

    #[test]
    fn the_axis_is_the_narrowest_cone_around_the_vertices() {
        // Directions spread over a 60° cap around (1, 1, 0)/√2 plus one inside it.
        let axis = DVec3::new(1.0, 1.0, 0.0).normalize();
        let (u, v) = (DVec3::Z, DVec3::new(1.0, -1.0, 0.0).normalize());
        let t = 30f64.to_radians();
        let mut dirs: Vec<DVec3> = (0..12)
            .map(|k| {
                let a = k as f64 / 12.0 * std::f64::consts::TAU;
                axis * libm::cos(t) + (u * libm::cos(a) + v * libm::sin(a)) * libm::sin(t)
            })
            .collect();
        dirs.insert(0, (axis + u * 0.1).normalize());
        let got = enclosing_cone_axis(&dirs);
        assert!(got.angle_between(axis) < 0.02, "{got:?}");
    }

    #[test]
    fn nearest_texel_is_the_texel_nearest_sampling_reads_and_distance_is_depth() {
        let scene = builtin::load("single-quad").unwrap();
        let view = LightView::fit(
            &scene,
            scene.light().center,
            tiling(16),
            DepthFormat::D24,
            |_| true,
        )
        .unwrap();
        let id = |t: usize, l: usize| (t * 1000 + l) as f64;
        for (x, y) in [(0.2f32, 0.3f32), (7.5, 9.99), (15.9, 0.0), (-3.0, 20.0)] {
            let (t, l) = view.nearest_texel(x, y);
            assert_eq!(
                view.sample(x, y, Filter::Nearest, id),
                id(t, l),
                "({x}, {y})"
            );
        }
        // The distance vertex stage: same window x, y; window depth = distance / range.
        let p = DVec3::new(0.3, 1.0, -0.2);
        let d = (p - view.center).length();
        let clip = view.distance_clip_point(p, 4.0 * d);
        let [x, y, z] = viewport(clip, 16, 16);
        let [x0, y0, _] = view.window(p.as_vec3()).unwrap();
        assert!((x - x0).abs() < 1e-4 && (y - y0).abs() < 1e-4);
        assert!((z - 0.25).abs() < 1e-6, "{z}");
    }

    /// Early Z in the shadow-map pass changes no texel, in every depth format, with no
    /// offset, a positive one and a negative one; the counters show it at work.
    #[test]
    fn early_z_in_the_shadow_map_changes_no_texel() {
        let offsets = PolygonOffset::EARLY_Z_TEST_CASES;
        let mut culled = 0;
        for name in [
            "cube-of-spheres",
            "forest-spheres",
            "pw-fractal",
            "cylinder",
        ] {
            let scene = builtin::load(name).unwrap();
            for format in [DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F] {
                let view =
                    LightView::fit(&scene, scene.light().center, tiling(128), format, |_| true)
                        .unwrap();
                for offset in offsets {
                    let (on, c_on) = view.render_depth(&scene, offset, Some(8), None);
                    let (off, c_off) = view.render_depth(&scene, offset, None, None);
                    let values = |tiles: &[DepthTile]| -> Vec<u32> {
                        tiles.iter().flat_map(|t| t.values.clone()).collect()
                    };
                    assert!(values(&on) == values(&off), "{name} {format:?} {offset:?}");
                    assert_eq!(c_off.tiles_culled_hiz, 0);
                    assert!(c_on.fragments_rasterized <= c_off.fragments_rasterized);
                    culled += c_on.tiles_culled_hiz;
                }
            }
        }
        assert!(culled > 0, "early Z never rejected a (tile, triangle) pair");
    }

    #[test]
    fn shadow_map_stores_the_nearest_surface_and_the_offset_moves_it_back() {
        let scene = builtin::load("single-quad").unwrap();
        let view = LightView::fit(
            &scene,
            scene.light().center,
            tiling(64),
            DepthFormat::D24,
            |_| true,
        )
        .unwrap();
        let (plain, c) = view.render_depth(
            &scene,
            PolygonOffset::NONE,
            Some(DEFAULT_HIZ_TILE_SIZE),
            None,
        );
        assert!(c.depth_write_bytes > 0);
        // The texel under the light center sees the quad's top at y = 1 (view depth 2).
        let [x, y, _] = view.window(Vec3::new(0.0, 1.0, 0.0)).unwrap();
        let stored = view.sample(x, y, Filter::Nearest, |t, l| plain[t].values[l] as f64);
        let d = view.proj.view_depth(view.depth.to_window(stored as u32));
        // The texel center is within half a texel (6/64 world units) of the point, on a quad
        // the fitted axis sees at a tilt of well under a degree.
        let expected = view.depth_of(glam::DVec3::new(0.0, 1.0, 0.0));
        assert!((d - expected).abs() < 1e-3 && (d - 2.0).abs() < 1e-3, "{d}");
        let units = PolygonOffset {
            factor: 0.0,
            units: 8.0,
        };
        let (biased, _) = view.render_depth(&scene, units, Some(DEFAULT_HIZ_TILE_SIZE), None);
        let moved = view.sample(x, y, Filter::Nearest, |t, l| biased[t].values[l] as f64);
        assert_eq!(moved, stored + 8.0);
    }
}
