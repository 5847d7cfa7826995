//! The shared first pass of every frame: the scene rendered into the depth buffer (D24 by
//! default, LESS, back faces culled) with the id of the visible triangle per pixel, the
//! per-tile hierarchical-Z bounds, and the receiver point and normal each pixel shows (the
//! normals also as the receiver-normal buffer of `horizon = clip`, [`Frame::receiver_normals`]).
//!
//! Every method reads this depth buffer (Paper III §3.2.2: "p = point(x, y, z); z is the depth
//! buffer value") and never writes it. Scene triangles are submitted mesh by mesh in file order;
//! primitive id = running triangle index over all meshes.

use crate::error::InputError;
use crate::gpu::buffers::{alloc_tiles, DepthTile};
use crate::gpu::counters::{count, Counters};
use crate::gpu::depth::{DepthFormat, DepthFunc, DepthState};
use crate::gpu::hiz::{TileReceiverBounds, HIZ_CULLED};
use crate::gpu::probe::{PassProbe, Probe, ProbeEvent, Tap};
use crate::gpu::raster::{bin, draw, TileDraw};
pub use crate::gpu::setup::setup_all;
use crate::gpu::setup::{CullMode, RasterTriangle};
use crate::gpu::shader_float::ShaderPrecision;
use crate::gpu::tiling::Tiling;
use crate::gpu::transform::{ClipVertex, Projection};
use crate::gpu_model::GpuModel;
use crate::options::{option_names, option_table, OptionTable, PowerOfTwo, Switch};
use crate::pass::PassStats;
use crate::scene::adjacency::{self, Adjacency};
use crate::scene::{Mesh, Scene};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::sync::{Arc, OnceLock};
use std::time::Instant;

/// How far off its triangle's plane a depth-buffer receiver may lie, relative to the scene's
/// diagonal, before [`Frame::receivers`] puts it on the plane: half the ray-origin offset of
/// the `raycast` reference (`methods::raycast::ORIGIN_OFFSET` is defined as twice this), so
/// that a receiver the depth buffer holds well enough is never below the surface its shadow
/// rays start from.
pub const RECEIVER_PLANE_TOLERANCE: f64 = 0.5e-4;

/// The pixel at which no geometry was drawn.
pub const BACKGROUND: u32 = u32::MAX;

/// Two front-facing triangles covering the viewport at the near plane: what a method draws for
/// a volume it cannot rasterize by its faces (the eye inside or near it), so that every pixel
/// runs its fragment program and the program's own inside test decides.
pub const FULL_SCREEN: [[ClipVertex; 3]; 2] = [
    [
        ClipVertex([-1.0, -1.0, 0.0, 1.0]),
        ClipVertex([1.0, -1.0, 0.0, 1.0]),
        ClipVertex([1.0, 1.0, 0.0, 1.0]),
    ],
    [
        ClipVertex([-1.0, -1.0, 0.0, 1.0]),
        ClipVertex([1.0, 1.0, 0.0, 1.0]),
        ClipVertex([-1.0, 1.0, 0.0, 1.0]),
    ],
];

/// Pipeline settings shared by every pass of a frame (`[options.gpu]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct GpuSettings {
    /// Tile edge in pixels.
    pub tile_size: u32,
    /// Depth buffer format.
    pub depth: DepthFormat,
    /// Arithmetic of the fragment programs ([`crate::gpu::shader_float`]).
    pub shader: ShaderPrecision,
    /// Whether passes consult the hierarchical-Z unit ([`crate::gpu::hiz`]) to reject
    /// (tile, triangle) pairs before rasterizing them; the output bits are the same either way.
    pub hiz: bool,
    /// Edge of a hierarchical-Z tile in pixels (zmin/zmax are kept per HiZ tile): the
    /// option's value, or the raster tile's edge when that is smaller. A HiZ tile never spans
    /// raster tiles, because the tiles are drawn in parallel and each keeps its own bounds
    /// as it writes depth (`docs/architecture.md`, "Hierarchical Z").
    pub hiz_tile_size: u32,
    /// The GPU profile of the cost model ([`crate::gpu_model`]); no pass reads it.
    pub model: GpuModel,
}

impl GpuSettings {
    /// The HiZ tile edge with the hierarchical-Z unit on, `None` with it off: what a pass with
    /// early Z starts its depth tiles with and its plan lists.
    pub fn hiz_tile(&self) -> Option<u32> {
        self.hiz.then_some(self.hiz_tile_size)
    }
}

impl Default for GpuSettings {
    fn default() -> Self {
        GpuOptions::default().settings()
    }
}

option_names!(DepthFormat {
    D16 = "d16",
    D24 = "d24",
    D32F = "d32f",
});

option_names!(ShaderPrecision {
    F64 = "f64",
    Fp32 = "fp32",
    Fp24 = "fp24",
    Fp16 = "fp16",
});

option_table! {
    /// `[options.gpu]`: the pipeline settings of every pass ([`GpuSettings`]).
    pub struct GpuOptions["gpu"] {
        /// edge of a screen tile in pixels (binning, traversal; the unit of the receiver bounds and of pw-restructured's culling)
        tile_size: PowerOfTwo [2..=256] = PowerOfTwo(crate::limits::DEFAULT_TILE_SIZE);
        /// depth format of every pass (the maps seen from a light default to it too)
        depth: DepthFormat = DepthFormat::D24;
        /// arithmetic of the fragment programs, every operation rounded: f64, IEEE fp32, ATI R300 fp24 (7-bit exponent, 16-bit mantissa, no denormals) or IEEE fp16 (half)
        shader: ShaderPrecision = ShaderPrecision::F64;
        /// hierarchical Z: passes reject whole tiles of a triangle with the tiles' zmin/zmax and receiver bounds before rasterizing (same output bits on and off; counters show the work saved)
        hiz: Switch = Switch::On;
        /// edge of a hierarchical-Z tile in pixels, whose zmin/zmax the unit keeps (at most the raster tile: a larger value is taken as the raster tile's edge)
        hiz_tile_size: PowerOfTwo [2..=256] = PowerOfTwo(crate::limits::DEFAULT_HIZ_TILE_SIZE);
        /// the GPU profile whose modeled time stats.json (gpu_model), the tables and the report show (docs/gpu-model.md; penumbra list --gpus): it changes no computed bit
        model: GpuModel = GpuModel::default();
    }
}

impl GpuOptions {
    /// The pipeline settings these options ask for.
    pub fn settings(&self) -> GpuSettings {
        GpuSettings {
            tile_size: self.tile_size.0,
            depth: self.depth,
            shader: self.shader,
            hiz: self.hiz == Switch::On,
            hiz_tile_size: self.hiz_tile_size.0.min(self.tile_size.0),
            model: self.model,
        }
    }
}

/// A surface point seen at a pixel, with its geometric normal (facing the camera).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Receiver {
    /// World-space point.
    pub point: Vec3,
    /// Unit normal.
    pub normal: Vec3,
}

/// Per-tile storage of the scene pass.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneTile {
    /// Depth.
    pub depth: DepthTile,
    /// Visible primitive id per sample, [`BACKGROUND`] where nothing was drawn.
    pub prim: Vec<u32>,
}

/// The result of the scene pass, shared read-only by all methods.
#[derive(Debug, Clone)]
pub struct Frame<'s> {
    /// The scene.
    pub scene: &'s Scene,
    /// Camera transform.
    pub proj: Projection,
    /// Pipeline settings.
    pub gpu: GpuSettings,
    /// Tiling of the image.
    pub tiling: Tiling,
    /// The meshes that cast shadows (all but the receiver-only ones), in scene order: each
    /// mesh's index in the scene and its edge adjacency.
    pub casters: Vec<(usize, Adjacency)>,
    /// Scene depth and primitive ids, tile-major, hierarchical Z built.
    pub tiles: Vec<SceneTile>,
    /// Mesh index and triangle index of each primitive id.
    pub prim_owner: Vec<(u32, u32)>,
    /// Stats of the scene pass.
    pub pass: PassStats,
    /// Row-major visible primitive ids, computed on first use ([`Frame::prim_ids`]).
    prim_rows: OnceLock<Vec<u32>>,
    /// The unit normal and a vertex of each primitive's triangle, computed on first use
    /// ([`Frame::plane_of`]).
    prim_planes: OnceLock<Vec<(DVec3, DVec3)>>,
    /// Row-major depth-buffer receivers, computed on first use ([`Frame::receivers`]).
    depth_receivers: OnceLock<(Vec<Option<Receiver>>, usize)>,
    /// Per-tile bounds of [`Frame::receivers`], computed on first use
    /// ([`Frame::receiver_bounds`]).
    receiver_bounds: OnceLock<TileReceiverBounds>,
    /// The receiver-normal buffer, row-major, computed on first use
    /// ([`Frame::receiver_normals`]).
    receiver_normals: OnceLock<Vec<DVec3>>,
    /// Each mesh's axis-aligned box and the box of every receiver point, computed on first
    /// use ([`Frame::within_light_influence`]).
    influence_boxes: OnceLock<InfluenceBoxes>,
    /// Whether methods hand back every buffer they resolved, with its event map
    /// ([`crate::methods::dump`], `--dump-buffers`); false after [`Frame::render`], set with
    /// [`Frame::dumping`].
    pub dump_buffers: bool,
    /// The probe the methods' passes record into ([`crate::gpu::probe`]), if one is attached.
    pub probe: Option<Arc<Probe>>,
}

/// What [`Frame::within_light_influence`] compares: each mesh's axis-aligned box, and the box
/// of every receiver point of the frame (`None` when no pixel shows a surface).
#[derive(Debug, Clone)]
struct InfluenceBoxes {
    meshes: Vec<(DVec3, DVec3)>,
    receivers: Option<(DVec3, DVec3)>,
}

impl InfluenceBoxes {
    fn new(frame: &Frame) -> Self {
        let bounds = |points: &mut dyn Iterator<Item = DVec3>| {
            let first = points.next()?;
            Some(points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
        };
        let empty = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        Self {
            meshes: frame
                .scene
                .meshes
                .iter()
                .map(|m| bounds(&mut m.positions.iter().map(|p| p.as_dvec3())).unwrap_or(empty))
                .collect(),
            receivers: bounds(
                &mut frame
                    .receivers()
                    .iter()
                    .flatten()
                    .map(|r| r.point.as_dvec3()),
            ),
        }
    }
}

impl<'s> Frame<'s> {
    /// Build adjacency and render the scene depth pass.
    pub fn render(scene: &'s Scene, gpu: GpuSettings) -> Result<Self, InputError> {
        let casters = scene
            .meshes
            .iter()
            .enumerate()
            .filter(|(_, m)| !m.receiver_only)
            .map(|(k, m)| {
                let adjacency = adjacency::build(m).map_err(|e| {
                    InputError::at(
                        &scene.source,
                        format!("meshes[{k}] ({})", m.name),
                        e.to_string(),
                    )
                })?;
                Ok((k, adjacency))
            })
            .collect::<Result<Vec<_>, InputError>>()?;
        let tiling = Tiling::new(scene.width, scene.height, gpu.tile_size)
            .map_err(|e| scene.option_error(GpuOptions::NAME, "tile-size", e))?;
        let proj = Projection::for_scene(scene);
        check_camera_outside_geometry(scene, proj.near)?;
        let start = Instant::now();
        let mut prims = Vec::new();
        let mut prim_owner = Vec::new();
        for (mi, m) in scene.meshes.iter().enumerate() {
            let clip: Vec<ClipVertex> = m.positions.iter().map(|p| proj.clip_point(*p)).collect();
            for (ti, t) in m.triangles.iter().enumerate() {
                prims.push(t.map(|i| clip[i as usize]));
                prim_owner.push((mi as u32, ti as u32));
            }
        }
        let (tris, mut counters) = setup_all(&prims, CullMode::Back, &tiling);
        let bins = bin(&tiling, &tris);
        let mut tiles = alloc_tiles(&tiling, |t, len| SceneTile {
            depth: DepthTile::cleared_in(gpu.depth, &tiling, t, gpu.hiz_tile_size),
            prim: vec![BACKGROUND; len],
        });
        let state = DepthState::LESS_WRITE;
        // Early Z (crate::gpu::hiz): a triangle at or behind the tile's zmax fails LESS at
        // every sample. The writes keep the bounds (zmax tightened when a test needs it).
        counters += draw(
            &tiling,
            &mut tiles,
            &tris,
            &bins,
            None,
            |t, tile, tri, c| {
                if !gpu.hiz {
                    return TileDraw::Whole;
                }
                tile.depth.early_z(&tiling, t, tri.bbox, tri.z_range[0], c)
            },
            |_, tile, tri, f, c, _| {
                if tile.depth.test_and_write(&state, &f, c) {
                    tile.prim[f.local] = tri.prim;
                }
            },
        );
        if tiles
            .iter()
            .all(|t| t.prim.iter().all(|&p| p == BACKGROUND))
        {
            let c = &scene.camera;
            return Err(InputError::at(
                &scene.source,
                "camera",
                format!(
                    "no geometry in view: every pixel would be background (the eye at ({}, {}, \
                     {}) looking at ({}, {}, {}) with vfov {}° sees none of the meshes, or \
                     they are smaller than a pixel)",
                    c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.vfov_deg
                ),
            ));
        }
        tiles
            .par_iter_mut()
            .enumerate()
            .for_each(|(t, tile)| tile.depth.finish_hiz(&tiling, t));
        let pass = PassStats {
            name: "scene-depth".into(),
            wall_seconds: start.elapsed().as_secs_f64(),
            runs: 1,
            counters,
        };
        Ok(Self {
            scene,
            proj,
            gpu,
            tiling,
            casters,
            tiles,
            prim_owner,
            pass,
            prim_rows: OnceLock::new(),
            prim_planes: OnceLock::new(),
            depth_receivers: OnceLock::new(),
            receiver_bounds: OnceLock::new(),
            receiver_normals: OnceLock::new(),
            influence_boxes: OnceLock::new(),
            dump_buffers: false,
            probe: None,
        })
    }

    /// This frame with [`Frame::dump_buffers`] set to `on`.
    pub fn dumping(mut self, on: bool) -> Self {
        self.dump_buffers = on;
        self
    }

    /// The meshes that cast shadows ([`Frame::casters`]) within the light's influence
    /// ([`Frame::within_light_influence`]), with their adjacency, in scene order: what every
    /// method builds silhouettes, volumes and wedges from. A caster whose shadow reaches no
    /// receiver of the frame submits nothing.
    pub fn caster_meshes(&self) -> Vec<(&'s Mesh, &Adjacency)> {
        self.influencing_casters()
            .map(|(k, adj)| (&self.scene.meshes[k], adj))
            .collect()
    }

    /// The scene index of the `k`-th mesh of [`Frame::caster_meshes`].
    pub fn caster_mesh_index(&self, k: usize) -> usize {
        self.influencing_casters()
            .nth(k)
            .map(|(i, _)| i)
            .expect("a caster index of caster_meshes")
    }

    /// `meshes[i] (name)`, the object an error names, for the `k`-th of
    /// [`Frame::caster_meshes`].
    pub fn caster_object(&self, k: usize) -> String {
        let i = self.caster_mesh_index(k);
        format!("meshes[{i}] ({})", self.scene.meshes[i].name)
    }

    fn influencing_casters(&self) -> impl Iterator<Item = (usize, &Adjacency)> + '_ {
        self.casters
            .iter()
            .filter(|(k, _)| self.within_light_influence(*k))
            .map(|(k, adj)| (*k, adj))
    }

    /// Whether mesh `mesh` of the scene can change the light of a receiver this frame shows:
    /// `false` only where, for every light, some axis direction `d` (±x, ±y, ±z) separates
    /// the mesh from both. The mesh's box lies beyond the light's box along `d` (its least
    /// `d·x` at least the light's greatest), and every receiver point lies short of the mesh
    /// along `d` by more than a tolerance. Every shadow point of the mesh is `l + t(b − l)`
    /// with `l` on the light, `b` on the mesh and `t ≥ 1`, so `d·x ≥ d·b ≥` the mesh's least
    /// `d·x` there: its shadow volume, umbra and penumbra lie wholly beyond every receiver,
    /// and no pixel's visibility depends on it. The tolerance is 10⁻³ of the diagonal of the
    /// receivers' and the mesh's boxes, so that the receivers' positions, rebuilt from the
    /// depth buffer, cannot reach it by rounding. A frame that shows no receiver keeps every
    /// mesh.
    pub fn within_light_influence(&self, mesh: usize) -> bool {
        let boxes = self
            .influence_boxes
            .get_or_init(|| InfluenceBoxes::new(self));
        let Some((rlo, rhi)) = boxes.receivers else {
            return true;
        };
        let (blo, bhi) = boxes.meshes[mesh];
        let tol = 1e-3 * (rhi.max(bhi) - rlo.min(blo)).length();
        !self.scene.lights.iter().all(|light| {
            let (llo, lhi) = light.bounds();
            (0..3).any(|k| {
                (blo[k] >= lhi[k] && rhi[k] < blo[k] - tol)
                    || (bhi[k] <= llo[k] && rlo[k] > bhi[k] + tol)
            })
        })
    }

    /// The axis-aligned bounds (min, max) of the vertices of the meshes within the light's
    /// influence ([`Frame::within_light_influence`]), and with `lights` every light center
    /// too: [`Scene::mesh_bounds`]' and [`Scene::bounds`]' points without the meshes that
    /// change no pixel. With no point, the first light's center.
    pub fn influence_bounds(&self, lights: bool) -> (Vec3, Vec3) {
        self.scene
            .bounds_of(lights, |k| self.within_light_influence(k))
    }

    /// This frame for `scene`, a scene that differs from this frame's only in its lights
    /// ([`Scene::with_only_light`]): the scene pass does not depend on the lights, so its
    /// buffers are re-used instead of rendered again.
    pub fn lit_by<'a>(&self, scene: &'a Scene) -> Frame<'a> {
        debug_assert!(
            scene.meshes == self.scene.meshes
                && scene.camera == self.scene.camera
                && (scene.width, scene.height) == (self.scene.width, self.scene.height),
            "Frame::lit_by needs the same meshes, camera and size"
        );
        Frame {
            scene,
            proj: self.proj.clone(),
            gpu: self.gpu,
            tiling: self.tiling,
            casters: self.casters.clone(),
            tiles: self.tiles.clone(),
            prim_owner: self.prim_owner.clone(),
            pass: self.pass.clone(),
            prim_rows: self.prim_rows.clone(),
            prim_planes: self.prim_planes.clone(),
            depth_receivers: self.depth_receivers.clone(),
            receiver_bounds: self.receiver_bounds.clone(),
            receiver_normals: self.receiver_normals.clone(),
            influence_boxes: self.influence_boxes.clone(),
            dump_buffers: self.dump_buffers,
            probe: self.probe.clone(),
        }
    }

    /// The pass `name` watching the probed pixel, when a probe is attached
    /// ([`Frame::probe`]).
    pub fn probe_pass(&self, name: &str) -> Option<PassProbe<'_>> {
        self.probe.as_ref().map(|p| p.pass(name, &self.tiling))
    }

    /// Record one event of pass `name` at the probed pixel, when a probe is attached: `event`
    /// gets the tap and the pixel's row-major index.
    pub fn probe_record(&self, name: &str, event: impl FnOnce(Tap, usize) -> ProbeEvent) {
        if let Some(p) = self.probe_pass(name) {
            let [x, y] = p.probe().pixel();
            p.record(|tap| event(tap, (y * self.scene.width + x) as usize));
        }
    }

    /// The distance from the eye to the corners of the near-plane rectangle: a volume whose
    /// faces come closer to the eye than this may be clipped by the near plane (methods then
    /// draw it as [`FULL_SCREEN`]).
    pub fn near_plane_radius(&self) -> f64 {
        let cam = &self.scene.camera;
        let (tan_x, tan_y) = cam.view_half_tangents(self.scene.width, self.scene.height);
        self.proj.near * (1.0 + tan_x * tan_x + tan_y * tan_y).sqrt()
    }

    /// Number of pixels.
    pub fn pixel_count(&self) -> usize {
        (self.scene.width * self.scene.height) as usize
    }

    /// Visible primitive per pixel, row-major (computed once per frame).
    pub fn prim_ids(&self) -> &[u32] {
        self.prim_rows
            .get_or_init(|| self.tiling.gather_row_major(|t| &self.tiles[t].prim))
    }

    /// Stored depth per pixel, row-major.
    pub fn depth_values(&self) -> Vec<u32> {
        self.tiling
            .gather_row_major(|t| &self.tiles[t].depth.values)
    }

    /// Geometric unit normal of primitive `prim` (outward; visible faces face the camera
    /// because back faces are culled).
    pub fn normal_of(&self, prim: u32) -> Vec3 {
        self.plane_of(prim).0.as_vec3()
    }

    /// The receiver of every pixel, row-major; `None` for background: the depth-buffer point,
    /// i.e. the pixel center un-projected at its stored depth — the point the rasterized
    /// methods see (computed once per frame). Where the depth format cannot hold the surface
    /// — the un-projected point lies farther than [`RECEIVER_PLANE_TOLERANCE`] of the meshes'
    /// diagonal ([`Scene::mesh_bounds`]) off the visible triangle's plane (a near plane far too close for the depth
    /// format, geometry far away) — the receiver is the exact hit of the pixel ray with that
    /// plane instead, as [`Frame::primary_ray_receivers`] computes it: a reference evaluated
    /// below the surface it should see shadows itself, and every method's error against it
    /// would be the reference's ([`Frame::snapped_receivers`] counts these pixels).
    pub fn receivers(&self) -> &[Option<Receiver>] {
        &self.depth_receivers_and_snaps().0
    }

    /// What the hierarchical-Z unit ([`crate::gpu::hiz`], on with `[options.gpu] hiz`) lets
    /// the draw loop rasterize of `tri` in tile `t` ([`TileDraw`]), for a pass that tests the
    /// scene depth with `idle.0` (without writing it) and leaves every buffer alone for a
    /// fragment whose test outcome is `idle.1` (z-pass volume counting does nothing where the
    /// test fails: `false`; z-fail nothing where it passes: `true`): nothing
    /// when every HiZ tile under the triangle decides `idle` for all its fragments, else the
    /// HiZ tiles that do not ([`crate::gpu::buffers::DepthTile::hiz_draw`]). The zmin/zmax
    /// reads and a rejection of the whole pair are counted in `c`; the watched samples of
    /// `probe` the triangle covers outside what is drawn record the rejection, as `event`
    /// describes the primitive, with the note [`HIZ_CULLED`].
    pub fn hiz_depth_draw(
        &self,
        t: usize,
        tri: &RasterTriangle,
        idle: (DepthFunc, bool),
        c: &mut Counters,
        probe: Option<&PassProbe>,
        event: impl Fn(Tap) -> ProbeEvent,
    ) -> TileDraw {
        if !self.gpu.hiz {
            return TileDraw::Whole;
        }
        let draw = self.tiles[t].depth.hiz_draw(&self.tiling, t, idle, tri, c);
        count!(c.tiles_culled_hiz += (draw == TileDraw::Skip) as u64);
        if let Some(probe) = probe {
            match draw {
                TileDraw::Skip => probe.record_culled(t, tri, None, HIZ_CULLED, event),
                TileDraw::Within(r) => probe.record_culled(t, tri, Some(r), HIZ_CULLED, event),
                TileDraw::Whole => {}
            }
        }
        draw
    }

    /// The hierarchical-Z unit's per-tile bounds of [`Frame::receivers`]
    /// ([`crate::gpu::hiz`]), computed once per frame.
    pub fn receiver_bounds(&self) -> &TileReceiverBounds {
        self.receiver_bounds.get_or_init(|| {
            let receivers = self.receivers();
            TileReceiverBounds::new(&self.tiling, |x, y| {
                receivers[(y * self.scene.width + x) as usize].map(|r| r.point.as_dvec3())
            })
        })
    }

    /// The receiver-normal buffer ([`crate::gpu::normal_buffer`]): row-major, the normal of
    /// each pixel's receiver ([`Frame::receivers`]) as the scene pass writes it to its second
    /// render target (RGBA16F, each component rounded to fp16), zero where nothing was drawn.
    /// Only the methods run with `horizon = clip` read it, and only they count its memory and
    /// the scene pass's writes to it ([`crate::methods::horizon_clip`]); computed once per
    /// frame, on first use.
    pub fn receiver_normals(&self) -> &[DVec3] {
        self.receiver_normals.get_or_init(|| {
            self.receivers()
                .par_iter()
                .map(|r| {
                    r.map_or(DVec3::ZERO, |r| {
                        crate::gpu::normal_buffer::quantize(r.normal)
                    })
                })
                .collect()
        })
    }

    /// How many receivers of [`Frame::receivers`] were moved onto their triangle's plane
    /// because the depth buffer could not hold the surface.
    pub fn snapped_receivers(&self) -> usize {
        self.depth_receivers_and_snaps().1
    }

    fn depth_receivers_and_snaps(&self) -> &(Vec<Option<Receiver>>, usize) {
        self.depth_receivers.get_or_init(|| {
            let depth = self.depth_values();
            let (lo, hi) = self.scene.mesh_bounds();
            let tolerance = RECEIVER_PLANE_TOLERANCE * (hi - lo).length() as f64;
            let snapped = std::sync::atomic::AtomicUsize::new(0);
            let receivers = self.receivers_with(|i, x, y, prim| {
                let p = self
                    .proj
                    .unproject(x, y, self.gpu.depth.to_window(depth[i]));
                let (n, a) = self.plane_of(prim);
                if n.dot(p - a).abs() <= tolerance {
                    return p;
                }
                snapped.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                self.primary_hit(x, y, prim)
            });
            (receivers, snapped.into_inner())
        })
    }

    /// The unit normal and a vertex of primitive `prim`'s triangle, in f64: computed for every
    /// primitive at once on first use, where each pixel computed its primitive's, twice
    /// (`Frame::receivers` of `cube-of-spheres` 512², one thread: 9.1 → 6.7 ms).
    ///
    /// The initialization is sequential on purpose: it runs inside the callers' parallel
    /// loops, and a parallel initializer lets the initializing worker steal another pixel's
    /// job, which then waits on the same `OnceLock` the worker is still initializing — a
    /// deadlock (seen in `goldens_do_not_depend_on_thread_count` with 3 threads).
    fn plane_of(&self, prim: u32) -> (DVec3, DVec3) {
        let planes = self.prim_planes.get_or_init(|| {
            self.prim_owner
                .iter()
                .map(|&(mi, ti)| {
                    let m = &self.scene.meshes[mi as usize];
                    let [a, b, c] =
                        m.triangles[ti as usize].map(|i| m.positions[i as usize].as_dvec3());
                    ((b - a).cross(c - a).normalize_or_zero(), a)
                })
                .collect()
        });
        planes[prim as usize]
    }

    /// Like [`Frame::receivers`], but each point is the exact intersection of the ray through
    /// the pixel center with the plane of the visible triangle, in f64.
    pub fn primary_ray_receivers(&self) -> Vec<Option<Receiver>> {
        self.receivers_with(|_, x, y, prim| self.primary_hit(x, y, prim))
    }

    /// The receiver of [`Frame::primary_ray_receivers`] of the pixel of row-major index `i`.
    pub fn primary_ray_receiver(&self, i: usize) -> Option<Receiver> {
        self.receiver_with(i, |_, x, y, prim| self.primary_hit(x, y, prim))
    }

    fn receivers_with(
        &self,
        point: impl Fn(usize, u32, u32, u32) -> DVec3 + Sync,
    ) -> Vec<Option<Receiver>> {
        (0..self.pixel_count())
            .into_par_iter()
            .map(|i| self.receiver_with(i, &point))
            .collect()
    }

    fn receiver_with(
        &self,
        i: usize,
        point: impl Fn(usize, u32, u32, u32) -> DVec3,
    ) -> Option<Receiver> {
        let prim = self.prim_ids()[i];
        if prim == BACKGROUND {
            return None;
        }
        let w = self.scene.width;
        let (x, y) = (i as u32 % w, i as u32 / w);
        Some(Receiver {
            point: point(i, x, y, prim).as_vec3(),
            normal: self.normal_of(prim),
        })
    }

    fn primary_hit(&self, x: u32, y: u32, prim: u32) -> DVec3 {
        let eye = self.scene.camera.eye;
        let far = self.proj.unproject(x, y, 0.5);
        let dir = far - eye;
        let (mi, ti) = self.prim_owner[prim as usize];
        let m = &self.scene.meshes[mi as usize];
        let [a, b, c] = m.triangles[ti as usize].map(|i| m.positions[i as usize].as_dvec3());
        let n = (b - a).cross(c - a);
        let denom = n.dot(dir);
        if denom == 0.0 {
            return far;
        }
        eye + dir * (n.dot(a - eye) / denom)
    }
}

/// `docs/architecture.md` "Bad input": the camera must not sit inside geometry. If the eye or a
/// point of the near-plane rectangle is inside or on a closed mesh, the near plane cuts it open and
/// every shadow-volume count is wrong (z-fail only repairs near-plane points inside shadow
/// *volumes*, not inside occluders), so the scene is rejected naming the mesh, the point and the
/// near distance ([`crate::geometry::near_plane::near_plane_points`], the same ray-parity test as for lights,
/// [`crate::scene::validate::point_touches`]).
///
/// The message reports the most telling contact: the eye before the near plane, and a point
/// inside a mesh before a point on a surface (a near plane reaching into a mesh also has
/// points on its surface, which come first in grid order).
fn check_camera_outside_geometry(scene: &Scene, near: f64) -> Result<(), InputError> {
    let points = crate::geometry::near_plane::near_plane_points(scene, near);
    let contacts = points.iter().enumerate().flat_map(|(k, p)| {
        scene
            .meshes
            .iter()
            .enumerate()
            .filter_map(move |(i, mesh)| {
                crate::scene::validate::point_touches(mesh, p.as_vec3()).map(|why| (k, *p, i, why))
            })
    });
    // Rank: the eye (k = 0) first, then "inside" before "on the surface of".
    let worst = contacts.min_by_key(|&(k, _, _, why)| (k != 0, why != "inside", k));
    let Some((k, p, i, why)) = worst else {
        return Ok(());
    };
    let what = if k == 0 {
        "the eye".to_string()
    } else {
        format!("the near plane (near = {near})")
    };
    Err(InputError::at(
        &scene.source,
        "camera",
        format!(
            "camera inside geometry: {what} at ({}, {}, {}) is {why} meshes[{i}] ({})",
            p.x, p.y, p.z, scene.meshes[i].name
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    #[test]
    fn camera_inside_geometry_is_rejected() {
        let mut s = builtin::load("single-quad").unwrap();
        s.width = 16;
        s.height = 16;
        Frame::render(&s, GpuSettings::default()).unwrap();
        // The eye inside the floor slab (top face y = 0, thickness 0.1).
        s.camera.eye = DVec3::new(0.0, -0.05, 2.0);
        let e = Frame::render(&s, GpuSettings::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("single-quad: camera: camera inside geometry: the eye at (")
                && e.contains("is inside meshes[0] (floor)"),
            "{e}"
        );
        // The eye above the floor, but a near plane reaching into it.
        s.camera.eye.y = 0.02;
        s.camera.target = DVec3::new(0.0, -1.0, 1.5);
        s.camera.near = Some(0.1);
        let e = Frame::render(&s, GpuSettings::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("the near plane (near = 0.1)"), "{e}");
    }

    /// Early Z in the scene pass: at its end the tiles' bounds are exactly what
    /// `DepthTile::build_hiz` computes from the stored depths (zmin, zmax, both thresholds),
    /// with the unit on or off, with HiZ tiles finer than the raster tile (16 and 4, 8 and 2),
    /// in every depth format, with tiles cut by the image border (50 is not a multiple of 8);
    /// the depths and primitive ids are the same on and off and at every HiZ tile size; and
    /// with the floor drawn after the trees (the meshes reversed) it saves fragments.
    #[test]
    fn the_scene_pass_keeps_the_bounds_build_hiz_gives() {
        for (name, depth) in [
            ("forest-spheres", DepthFormat::D24),
            ("cube-of-spheres", DepthFormat::D16),
            ("pw-fractal", DepthFormat::D32F),
        ] {
            let mut s = builtin::load(name).unwrap();
            s.resize(Some(50), Some(50));
            for reversed in [false, true] {
                if reversed {
                    s.meshes.reverse();
                }
                // HiZ tiles of the raster tile's size, and finer ones.
                let [on, off, .., finest] =
                    [(true, 8, 8), (false, 8, 8), (true, 16, 4), (true, 8, 2)].map(
                        |(hiz, tile_size, hiz_tile_size)| {
                            let gpu = GpuSettings {
                                depth,
                                hiz,
                                tile_size,
                                hiz_tile_size,
                                ..GpuSettings::default()
                            };
                            let frame = Frame::render(&s, gpu).unwrap();
                            for (t, tile) in frame.tiles.iter().enumerate() {
                                let mut built = tile.depth.clone();
                                built.build_hiz(&frame.tiling, t);
                                assert_eq!(tile.depth, built, "{name}, hiz {hiz}, tile {t}");
                            }
                            frame
                        },
                    );
                assert_eq!(on.tiles, off.tiles, "{name}");
                assert_eq!(on.prim_ids(), finest.prim_ids(), "{name}");
                assert_eq!(on.depth_values(), finest.depth_values(), "{name}");
                let (c_on, c_off) = (on.pass.counters, off.pass.counters);
                assert_eq!(c_on.depth_passed, c_off.depth_passed, "{name}");
                assert!(c_on.fragments_rasterized <= c_off.fragments_rasterized);
                assert_eq!(
                    c_on.tiles_visited + c_on.tiles_culled_hiz,
                    c_off.tiles_visited,
                    "{name}"
                );
                if reversed && name == "forest-spheres" {
                    assert!(
                        c_on.fragments_rasterized < c_off.fragments_rasterized,
                        "{name}"
                    );
                }
            }
        }
    }

    /// A camera that sees no mesh is an error naming the camera, not a blank frame.
    #[test]
    fn an_empty_frame_is_refused() {
        let mut s = builtin::load("single-quad").unwrap();
        s.width = 16;
        s.height = 16;
        s.camera.target = s.camera.eye + (s.camera.eye - s.camera.target) * 3.0;
        let e = Frame::render(&s, GpuSettings::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("single-quad: camera: no geometry in view: every pixel would be"),
            "{e}"
        );
    }

    /// A near plane reaching into a tetrahedron, edge-on to one of its faces: its grid column
    /// on the face's plane comes before the columns inside, yet the report is "inside".
    #[test]
    fn camera_inside_is_reported_as_inside() {
        use crate::scene::Mesh;
        let mut s = builtin::load("single-quad").unwrap();
        s.width = 16;
        s.height = 16;
        // Faces x = 1, y = 1.2, z = 0 and x + y + z = 3.2.
        s.meshes.push(Mesh {
            name: "tet".into(),
            positions: vec![
                Vec3::new(1.0, 1.2, 0.0),
                Vec3::new(2.0, 1.2, 0.0),
                Vec3::new(1.0, 2.2, 0.0),
                Vec3::new(1.0, 1.2, 1.0),
            ],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            color: [0.5; 3],
            receiver_only: false,
            repairs: Default::default(),
        });
        crate::scene::validate::validate(&s).unwrap();
        // Outside the tetrahedron, looking along its face x = 1 toward −z; the near plane's
        // columns run from x < 1 (outside) over x = 1 (on the face) to x > 1 (inside).
        s.camera.eye = DVec3::new(1.0, 1.5, 1.5);
        s.camera.target = DVec3::new(1.0, 1.5, 0.0);
        s.camera.up = DVec3::Y;
        s.camera.near = Some(1.0);
        let e = Frame::render(&s, GpuSettings::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("the near plane (near = 1)") && e.contains("is inside meshes[2] (tet)"),
            "{e}"
        );
    }
}
