//! `pw-restructured`: the restructured penumbra-wedge algorithm of Paper II (Assarsson &
//! Akenine-Möller) §3 (rasterizeUmbra / rasterizePenumbra), §4 (zmin/zmax tile occlusion
//! culling), §5 (eye inside shadow: z-fail with top and bottom caps), §6.1 (three-pass) and
//! §6.2 (single-pass). Wedges are those of `pw2002` ([`crate::geometry::penumbra_wedge`]).
//!
//! * **Umbra** (front planes, ±255): z-pass adds −255 for a front-facing front-plane fragment
//!   that passes LESS and +255 for a back-facing one; z-fail (top caps, bottom caps and front
//!   planes, rendered "in exactly the same way") adds +255 for front-facing and −255 for
//!   back-facing fragments that *fail* LESS.
//! * **Penumbra**: z-pass rasterizes the front-facing faces of every wedge, z-fail the
//!   back-facing ones; a fragment adds `li_amount(s(p))` when the depth-buffer point p is
//!   inside the wedge. Choices: the inside test is done in world space with the same
//!   [`Wedge::contains`](crate::geometry::penumbra_wedge::Wedge::contains) as `pw2002` (the paper
//!   does it in screen space to save a division; its screen-space plane equations are used here
//!   for tile culling), and p counts as inside only if it also lies behind (z-pass) or in front
//!   of (z-fail) the rasterized face by the depth test — implied in exact arithmetic, and it
//!   makes the umbra and penumbra contributions agree on the discrete depth buffer, so that
//!   with the eye outside all shadows this method and `pw2002` add the same integers.
//! * **Degenerate wedges** (Paper I Fig. 6: side planes crossing): the wedge's front face is
//!   then smaller than the quad `(b, a, P_a, P_b)` between its far front lines, which would
//!   leave a hole in the umbra surface (dark streaks to infinity). Choice: such a wedge's front
//!   face carries only penumbra and its umbra is drawn with that quad
//!   ([`Wedge::umbra_front_quad`](crate::geometry::penumbra_wedge::Wedge::umbra_front_quad)),
//!   submitted after all wedges.
//! * **Light spikes are the paper's approximation, not a bug** (measured on
//!   `cube-of-spheres-sphere`, 256², light radius 0.5 over spheres of radius 0.18): this method
//!   is lighter than `raycast` by more than 0.25 at 224 pixels. 173 lie on the spheres next to
//!   their silhouette seen from the light center, with the same LI in this method and in
//!   `pw2002` (both `side-planes` forms): 138 light-facing facets at LI 255 (`raycast` < 0.75)
//!   and 35 facets just past the silhouette at LI 64–251 (`raycast` 0–0.63). The wedges know
//!   only that one silhouette, not the sphere's own curvature (the single-silhouette
//!   approximation, Paper III §5.3).
//!   The other 51 are the thin spikes on the floor. At each, one sphere on its own adds light
//!   (LI > 255 from that sphere's wedges alone, impossible for one occluder): its loop's side
//!   planes cross (Paper I Fig. 6; zigzag silhouettes of tessellated spheres under a larger
//!   light), so its wedges no longer partition the region behind its front planes, and the
//!   eye ray reaches a point inside a wedge (e.g. pixel (85, 140): s = 185/255) without
//!   crossing that loop's umbra surface. The wedge's penumbra is then added without the
//!   umbra's −255. Paper II §1 names the case ("artifacts may appear when the light source is
//!   so large that there is no umbra region at all"). 33 of the 51 have exactly the LI of
//!   `pw2002` with `side-planes = cancel` (Paper I §5); the other 18 are 255 or 510 lighter
//!   than it because the outer-volume quad of a degenerate wedge is a bow-tie whose far half
//!   is wound the other way. The quad is kept: against `pw2002`/`cancel` it changes 529
//!   pixels, always by whole multiples of 255 (383 closer to `raycast`, 52 farther), and it
//!   cuts the pixels off by more than 0.25 from 4171 to 3858 and the largest error from 1.0
//!   to 0.84.
//! * **Three-pass** (§6.1): the front planes go to an 8-bit stencil cleared to 128 (the offset
//!   trick for an unsigned, saturating stencil): front-facing fragments DECR, then back-facing
//!   ones INCR (on depth pass for z-pass, depth fail for z-fail); a full-screen pass adds
//!   `±255·(stencil − 128)` to the LI buffer (255 for z-pass, −255 for z-fail); then the
//!   penumbra pass. **Single-pass** (§6.2): one pass over all wedge triangles; a front plane
//!   that carries both umbra and penumbra (front-facing for z-pass, back-facing for z-fail) is
//!   rasterized once: one depth read and at most one LI write per fragment.
//! * **Culling** (§4), per (tile, triangle), counted in `tiles_culled_hiz` once per culled
//!   contribution: umbra uses the hardware test of the triangle's depth range against the
//!   tile's zmax (z-pass) or zmin (z-fail); penumbra uses `zmax` — the wedge's zmin behind the
//!   tile's zmax — or `zmin+zmax` — that, the wedge's zmax in front of the tile's zmin, then the
//!   n/p-vertex test of the tile's screen-space box against the wedge's five screen-space
//!   planes. `off` culls nothing.
//! * z-pass or z-fail: `mode = auto` picks z-fail when [`crate::geometry::near_plane::eye_in_shadow`] finds the
//!   near plane in the shadow of a point of the light.
//!
//! * **Shader precision** (`[options.gpu] shader`, [`crate::gpu::shader_float`]): the penumbra
//!   fragment program — the inside test and equations 1–3 of Paper I §4.2 at the depth-buffer
//!   point and the scaling of s to an LI amount ([`crate::geometry::penumbra_wedge`], "Shader
//!   precision") — runs in the chosen precision; the umbra's ±255/n are integer constants, the
//!   LI buffer's and stencil's arithmetic is integer (exact). The tile culling of §4 is the
//!   rasterizer's hierarchical-Z test before any fragment program runs, and stays f64, as do the
//!   wedges and caps (CPU geometry submitted as vertices, Paper II §3). With `li = 16` the
//!   integer amounts hide most of fp32's rounding: on `cube-of-spheres-sphere` at 256² fp32
//!   gives the f64 image bit for bit, fp24 changes 55 pixels and fp16 1822.
//!
//! Buffer dump (`--dump-buffers`): `li`, as `pw2002`'s
//! ([`super::pw2002::li_dump`]).
//!
//! Options ([`PwRestructuredOptions`]): those of `pw2002` except `side-planes` (an error here: the restructured
//! algorithm never visits side planes, it is the `cancel` form by construction) plus `passes = single|three`, `culling = zmin-zmax|zmax|off`,
//! `mode = auto|zpass|zfail`.

use super::horizon_clip::{clip_to_horizon, HorizonKeys};
use super::output::MethodOutput;
use super::pw2002::{
    frame_wedges, li_buffer_plan, li_dump, li_row_major, resolve, wedge_primitive, MultiLight,
    WedgeKeys, WedgeSettings,
};
use crate::error::InputError;
use crate::frame::{setup_all, Frame};
use crate::geometry::near_plane::representative_light_points;
use crate::geometry::penumbra_wedge::{
    cap_triangles, li_amount, screen_wedge, shader_li_amount, shader_light_intensity,
    wedge_triangles, FaceKind, ScreenWedge, WedgeSet, WedgeTriangle,
};
use crate::gpu::buffers::{alloc_tiles, StencilTile};
use crate::gpu::counters::{count, Counters};
use crate::gpu::depth::DepthFunc;
use crate::gpu::li_buffer::{LiTile, LI_CLEAR};
use crate::gpu::probe::{PassProbe, PrimitiveKind, ProbeEvent, Raw};
use crate::gpu::raster::{bin, draw, Fragment};
use crate::gpu::setup::{CullMode, RasterTriangle};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::shader_vec::SVec3;
use crate::gpu::stencil::{StencilFace, StencilOp, StencilState};
use crate::methods::hard_sv::CountMode;
use crate::methods::output::BufferPlan;
use crate::methods::precision_spec::{NarrowFormat, PrecisionSpec};
use crate::methods::recorder::PassRecorder;
use crate::options::{option_names, option_table, OptionTable, OptionType};
use crate::scene::LightShape;

/// Counting direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum WedgeTest {
    /// Boundaries between the eye and the point.
    ZPass,
    /// Boundaries between the point and infinity (caps, back-facing penumbra faces).
    ZFail,
}

/// Pass structure (§6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Passes {
    /// Umbra and penumbra of the shared front planes in one pass (§6.2).
    Single,
    /// Stencil front-facing, stencil back-facing, penumbra (§6.1).
    Three,
}

/// Tile occlusion culling (§4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Culling {
    /// No culling.
    Off,
    /// Only the zmax quick rejection.
    Zmax,
    /// zmin and zmax quick rejection plus the n/p-vertex box test.
    ZminZmax,
}

/// Settings of one `pw-restructured` render.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RestructuredSettings {
    /// Wedges and LI buffer.
    pub wedge: WedgeSettings,
    /// z-pass or z-fail.
    pub test: WedgeTest,
    /// Single or three passes.
    pub passes: Passes,
    /// Tile culling.
    pub culling: Culling,
}

option_names!(Passes {
    Single = "single",
    Three = "three",
});

option_names!(Culling {
    ZminZmax = "zmin-zmax",
    Zmax = "zmax",
    Off = "off",
});

option_table! {
    /// `[options.pw-restructured]` (module doc).
    pub struct PwRestructuredOptions["pw-restructured"] {
        ..wedges: WedgeKeys,
        ..horizon: HorizonKeys,
        /// umbra and penumbra in one pass (Paper II §6.2), or stencil, stencil, penumbra (§6.1)
        passes: Passes = Passes::Single;
        /// tile occlusion culling (Paper II §4): zmin and zmax with the box test, zmax only, or none
        culling: Culling = Culling::ZminZmax;
        /// count z-pass or z-fail (Paper II §5); auto: z-fail when the near plane is in the light's shadow
        mode: CountMode = CountMode::Auto;
    }
}

/// Read the options of `pw-restructured`, and the `mode` as written.
pub fn read_settings(frame: &Frame) -> Result<(RestructuredSettings, CountMode), InputError> {
    let o = PwRestructuredOptions::read(frame.scene)?;
    let pts = representative_light_points(frame.scene);
    let test = if o.mode.zfail(frame.scene, frame.proj.near, &pts) {
        WedgeTest::ZFail
    } else {
        WedgeTest::ZPass
    };
    Ok((
        RestructuredSettings {
            wedge: o.wedges.settings(frame, o.horizon)?,
            test,
            passes: o.passes,
            // The hierarchical-Z unit off (`[options.gpu] hiz`), there is no zmin/zmax to read.
            culling: if frame.gpu.hiz {
                o.culling
            } else {
                Culling::Off
            },
        },
        o.mode,
    ))
}

/// What a rasterized triangle contributes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Roles {
    umbra: bool,
    penumbra: bool,
}

/// Per-frame data shared by the passes.
struct Ctx<'a> {
    frame: &'a Frame<'a>,
    set: &'a WedgeSet,
    screen: Vec<ScreenWedge>,
    tris: Vec<WedgeTriangle>,
    s: RestructuredSettings,
    /// Per wedge: whether its front face is the outer-volume quad (not degenerate).
    front_is_quad: Vec<bool>,
    /// Index of the first umbra-only quad of a degenerate wedge in `tris`.
    umbra_quads_from: usize,
}

impl Ctx<'_> {
    /// Count one tile zmin/zmax test of tile `t` in `c` (`hiz_read_bytes`): the values the
    /// culling mode reads, zmax, or zmin and zmax, in the depth format, of the tile's bounds
    /// (`DepthTile::tile_bounds`, the HiZ unit's coarse level).
    fn count_tile_test(&self, t: usize, c: &mut Counters) {
        let values = match self.s.culling {
            Culling::Off => 0,
            Culling::Zmax => 1,
            Culling::ZminZmax => 2,
        };
        count!(c.hiz_read_bytes += values * self.frame.tiles[t].depth.format.bytes());
    }

    /// Umbra sign of a front-plane or cap fragment (per §3/§5): the LI amount it adds when its
    /// depth condition holds.
    fn umbra_value(&self, front_facing: bool) -> i32 {
        let full = li_amount(1.0, self.s.wedge.lights);
        match (self.s.test, front_facing) {
            (WedgeTest::ZPass, true) | (WedgeTest::ZFail, false) => -full,
            (WedgeTest::ZPass, false) | (WedgeTest::ZFail, true) => full,
        }
    }

    fn roles(&self, tri: &RasterTriangle) -> Roles {
        if tri.prim as usize >= self.umbra_quads_from {
            return Roles {
                umbra: true,
                penumbra: false,
            };
        }
        let wt = &self.tris[tri.prim as usize];
        let degenerate = wt.wedge.is_some_and(|w| !self.front_is_quad[w as usize]);
        let penumbra_facing = match self.s.test {
            WedgeTest::ZPass => tri.front_facing,
            WedgeTest::ZFail => !tri.front_facing,
        };
        Roles {
            umbra: wt.kind.is_none_or(|k| k == FaceKind::Front && !degenerate),
            penumbra: wt.wedge.is_some() && penumbra_facing,
        }
    }

    /// Whether the umbra contribution of `tri` is culled in tile `t` (hardware hierarchical Z).
    fn umbra_culled(&self, t: usize, tri: &RasterTriangle) -> bool {
        if self.s.culling == Culling::Off {
            return false;
        }
        // z-pass adds nothing where LESS fails (every fragment at or behind every stored
        // depth), z-fail nothing where it passes (every fragment in front of every one).
        let idle = self.s.test == WedgeTest::ZFail;
        let tile = self.frame.tiles[t].depth.tile_bounds();
        tile.depth_outcome(DepthFunc::Less, tri) == Some(idle)
    }

    /// Whether the penumbra contribution of `tri` is culled in tile `t` (§4).
    fn penumbra_culled(&self, t: usize, tri: &RasterTriangle) -> bool {
        if self.s.culling == Culling::Off {
            return false;
        }
        let Some(wi) = self.tris[tri.prim as usize].wedge else {
            return true;
        };
        let sw = &self.screen[wi as usize];
        let d = &self.frame.tiles[t].depth;
        let fmt = d.format;
        let tile = d.tile_bounds();
        let (tz0, tz1) = (fmt.to_window(tile.zmin), fmt.to_window(tile.zmax));
        // Quick rejection: the wedge lies behind every stored point.
        if sw.z_range[0] > tz1 {
            return true;
        }
        if self.s.culling == Culling::Zmax {
            return false;
        }
        if sw.z_range[1] < tz0 {
            return true;
        }
        let r = self.frame.tiling.rect(t);
        sw.box_outside(
            [r.x0 as f64, r.x1 as f64],
            [r.y0 as f64, r.y1 as f64],
            [tz0, tz1],
            self.frame.scene.width as f64,
            self.frame.scene.height as f64,
        )
    }

    /// A probe's record of the primitive of fragment `tri` (wedge face, cap or umbra quad).
    fn primitive(&self, e: ProbeEvent, tri: &RasterTriangle) -> ProbeEvent {
        let prim = tri.prim as usize;
        let wt = &self.tris[prim];
        let facing = Some(tri.front_facing);
        match (wt.wedge, wt.kind) {
            (Some(wi), _) if prim >= self.umbra_quads_from => {
                let e = e.primitive(
                    PrimitiveKind::UmbraQuad,
                    wi,
                    format!("of degenerate wedge {wi}, triangle {prim}"),
                    facing,
                );
                match self.set.light_of_wedge(wi as usize) {
                    Some(l) if self.set.appended_at.len() > 1 => e.light(l),
                    _ => e,
                }
            }
            (Some(wi), Some(kind)) => wedge_primitive(e, self.set, wi, kind, tri),
            _ => {
                let e = e.primitive(PrimitiveKind::WedgeCap, tri.prim, "", facing);
                match self.set.light_of_cap(prim) {
                    Some(l) if self.set.appended_at.len() > 1 => e.light(l),
                    _ => e,
                }
            }
        }
    }

    /// Record (in the watched tile) that `tri`, which covers the probed pixel, was culled for
    /// its tile before rasterization (§4).
    fn record_culled(&self, probe: Option<&PassProbe>, t: usize, tri: &RasterTriangle, what: &str) {
        let Some(p) = probe.filter(|p| p.watches_tile(t)) else {
            return;
        };
        let [x, y] = p.probe().pixel();
        if tri.covers(x, y) {
            p.record(|tap| {
                self.primitive(tap.event(), tri)
                    .note(format!("{what} culled for the tile by zmin/zmax (§4)"))
            });
        }
    }

    /// The penumbra amount of fragment `f` of `tri` given the stored depth and the depth test,
    /// computed by the fragment program in the shader precision `T` (module doc, "Shader
    /// precision").
    fn penumbra_amount<T: ShaderFloat>(
        &self,
        tri: &RasterTriangle,
        f: &Fragment,
        stored: u32,
        pass: bool,
    ) -> i32 {
        let behind_face = match self.s.test {
            WedgeTest::ZPass => pass,
            WedgeTest::ZFail => !pass,
        };
        let fmt = self.frame.gpu.depth;
        if !behind_face || stored == fmt.far() {
            return 0;
        }
        let Some(wi) = self.tris[tri.prim as usize].wedge else {
            return 0;
        };
        let w = &self.set.wedges[wi as usize];
        let p = SVec3::<T>::from_f64(self.frame.proj.unproject(f.x, f.y, fmt.to_window(stored)));
        if w.shader_contains(p) {
            shader_li_amount(
                shader_light_intensity(w, p, self.s.wedge.smooth),
                self.s.wedge.lights,
            )
        } else {
            0
        }
    }
}

/// Per-tile storage: the LI buffer plus the cull decision of the triangle being drawn.
struct RTile {
    li: LiTile,
    /// (triangle address, umbra culled, penumbra culled).
    memo: (usize, bool, bool),
}

/// One draw over `rt` (filtered raster triangles) adding umbra and/or penumbra contributions
/// directly into the LI buffer, the fragment program in the shader precision `T`.
fn li_pass<T: ShaderFloat>(
    ctx: &Ctx,
    tiles: &mut [RTile],
    rt: &[RasterTriangle],
    umbra: bool,
    penumbra: bool,
    probe: Option<&PassProbe>,
) -> Counters {
    let tiling = &ctx.frame.tiling;
    let bins = bin(tiling, rt);
    let culls = |t: usize, tri: &RasterTriangle| {
        let roles = ctx.roles(tri);
        let u = !(umbra && roles.umbra) || ctx.umbra_culled(t, tri);
        let p = !(penumbra && roles.penumbra) || ctx.penumbra_culled(t, tri);
        (u, p)
    };
    draw(
        tiling,
        tiles,
        rt,
        &bins,
        probe,
        |t, _, tri, c| {
            let roles = ctx.roles(tri);
            let (u, p) = culls(t, tri);
            ctx.count_tile_test(t, c);
            count!(c.tiles_culled_hiz += (umbra && roles.umbra && u) as u64);
            count!(c.tiles_culled_hiz += (penumbra && roles.penumbra && p) as u64);
            if u && p {
                ctx.record_culled(probe, t, tri, "umbra and penumbra");
            }
            u && p
        },
        |t, tile, tri, f, c, tap| {
            let key = tri as *const RasterTriangle as usize;
            if tile.memo.0 != key {
                let (u, p) = culls(t, tri);
                tile.memo = (key, u, p);
            }
            let (_, u_culled, p_culled) = tile.memo;
            let depth = &ctx.frame.tiles[t].depth;
            let stored = depth.read(f.local, c);
            let z = depth.format.quantize(f.z);
            let pass = z < stored;
            count!(c.depth_passed += pass as u64);
            let mut delta = 0;
            let mut umbra_delta = None;
            if !u_culled {
                let counts = match ctx.s.test {
                    WedgeTest::ZPass => pass,
                    WedgeTest::ZFail => !pass,
                };
                if counts {
                    delta += ctx.umbra_value(tri.front_facing);
                }
                umbra_delta = Some(delta);
            }
            let mut penumbra_delta = None;
            if !p_culled {
                count!(c.fragments_shaded += 1);
                let amount = ctx.penumbra_amount::<T>(tri, &f, stored, pass);
                delta += amount;
                penumbra_delta = Some(amount);
            }
            let added = (delta != 0).then(|| tile.li.add(f.local, delta, c));
            if let Some(tap) = tap {
                let e = ctx.primitive(tap.event(), tri);
                let mut e = depth.record_test(e, DepthFunc::Less, f.local, z, pass);
                let mut notes = Vec::new();
                let roles = ctx.roles(tri);
                for (name, part, role) in [
                    ("umbra", umbra_delta, umbra && roles.umbra),
                    ("penumbra", penumbra_delta, penumbra && roles.penumbra),
                ] {
                    match part {
                        Some(v) => e = e.value(name, v as f64),
                        None if role => notes.push(format!("{name} culled for the tile (§4)")),
                        None => {}
                    }
                }
                let e = e.note(notes.join("; "));
                tap.push(match added {
                    Some(a) => tile.li.record_add(e, a),
                    None => e.read("li", Raw::Int(tile.li.values[f.local])),
                });
            }
        },
    )
}

/// Setup of every wedge (and, for z-fail, cap) triangle, kept only if it has a role.
fn raster_triangles(
    ctx: &Ctx,
    keep: impl Fn(Roles, &RasterTriangle) -> bool,
) -> (Vec<RasterTriangle>, Counters) {
    let prims: Vec<_> = ctx.tris.iter().map(|t| t.clip).collect();
    let (mut rt, c) = setup_all(&prims, CullMode::None, &ctx.frame.tiling);
    rt.retain(|t| keep(ctx.roles(t), t));
    (rt, c)
}

/// Render the LI buffer of `pw-restructured` (tile-major) on the recorder's frame; its passes
/// and buffers go to `rec` (the zmin/zmax reads of the culling tests in `hiz_read_bytes`). The
/// penumbra fragment program runs in the frame's shader precision.
pub fn render_li(rec: &mut PassRecorder, set: &WedgeSet, s: &RestructuredSettings) -> Vec<LiTile> {
    crate::with_shader_float!(rec.frame().gpu.shader, T => render_li_with::<T>(rec, set, s))
}

/// [`render_li`] with the penumbra fragment program in the precision `T` (module doc, "Shader
/// precision").
fn render_li_with<T: ShaderFloat>(
    rec: &mut PassRecorder,
    set: &WedgeSet,
    s: &RestructuredSettings,
) -> Vec<LiTile> {
    let frame = rec.frame();
    let mut tris = Vec::new();
    if s.test == WedgeTest::ZFail {
        tris.extend(cap_triangles(set, &frame.proj));
    }
    tris.extend(wedge_triangles(set, &frame.proj));
    // Degenerate wedges (Fig. 6): their front face only carries penumbra; the umbra uses the
    // outer-volume quad, submitted after all wedges, so the umbra surface stays closed.
    let front_is_quad: Vec<bool> = set.wedges.iter().map(|w| w.front_face_is_quad()).collect();
    let umbra_quads_from = tris.len();
    for (wi, w) in set.wedges.iter().enumerate() {
        if !front_is_quad[wi] {
            tris.extend(w.umbra_front_quad().map(|t| WedgeTriangle {
                clip: t.map(|p| frame.proj.clip_point(p.as_vec3())),
                wedge: Some(wi as u32),
                kind: Some(FaceKind::Front),
            }));
        }
    }
    let ctx = Ctx {
        front_is_quad,
        umbra_quads_from,
        frame,
        set,
        screen: set
            .wedges
            .iter()
            .map(|w| screen_wedge(w, &frame.proj))
            .collect(),
        tris,
        s: *s,
    };
    let tiling = &frame.tiling;
    let mut tiles = rec.allocate(li_buffer_plan(s.wedge.li), || {
        alloc_tiles(tiling, |_, len| RTile {
            li: LiTile::cleared(s.wedge.li, s.wedge.overflow, len).recording(frame.dump_buffers),
            memo: (0, false, false),
        })
    });
    if s.culling != Culling::Off {
        // The depth tiles' zmin and zmax (Paper II §4).
        rec.uses_hiz_depth();
    }
    frame.probe_record("clear", |tap, _| {
        tap.event().clear("li", Raw::Int(LI_CLEAR))
    });
    match s.passes {
        Passes::Single => rec.pass("wedges-single-pass", |pass| {
            let (rt, c) = raster_triangles(&ctx, |r, _| r.umbra || r.penumbra);
            pass.count(c);
            let probe = pass.probe();
            pass.count(li_pass::<T>(
                &ctx,
                &mut tiles,
                &rt,
                true,
                true,
                probe.as_ref(),
            ));
        }),
        Passes::Three => {
            let stencil_plan = BufferPlan {
                name: "stencil".into(),
                format: "S8 (offset 128)".into(),
                bytes_per_sample: 1,
            };
            let mut stencil = rec.allocate(stencil_plan, || {
                alloc_tiles(tiling, |_, len| StencilTile::cleared(128, len))
            });
            frame.probe_record("clear", |tap, _| tap.event().clear("stencil", Raw::U8(128)));
            for (name, front) in [("umbra-stencil-front", true), ("umbra-stencil-back", false)] {
                rec.pass(name, |pass| {
                    let (rt, c) = raster_triangles(&ctx, |r, t| r.umbra && t.front_facing == front);
                    pass.count(c);
                    let probe = pass.probe();
                    pass.count(stencil_pass(&ctx, &mut stencil, &rt, probe.as_ref()));
                });
            }
            rec.pass("umbra-to-li", |pass| {
                let mult = match s.test {
                    WedgeTest::ZPass => li_amount(1.0, s.wedge.lights),
                    WedgeTest::ZFail => -li_amount(1.0, s.wedge.lights),
                };
                let probe = pass.probe();
                let mut c = Counters::default();
                for (t, (tile, st)) in tiles.iter_mut().zip(&stencil).enumerate() {
                    let watched = probe.as_ref().filter(|p| p.watches_tile(t));
                    for (i, v) in st.values.iter().enumerate() {
                        count!(c.stencil_read_bytes += 1);
                        let d = mult * (*v as i32 - 128);
                        let added = (d != 0).then(|| tile.li.add(i, d, &mut c));
                        if let Some(tap) = watched.and_then(|p| p.tap(t, i)) {
                            let e = tap
                                .event()
                                .value("stencil", *v as f64)
                                .value("delta", d as f64);
                            let e = e.note(format!("±255·(stencil − 128), multiplier {mult}"));
                            tap.push(match added {
                                Some(a) => tile.li.record_add(e, a),
                                None => e.read("li", Raw::Int(tile.li.values[i])),
                            });
                        }
                    }
                }
                pass.count(c);
            });
            rec.pass("penumbra", |pass| {
                let (rt, c) = raster_triangles(&ctx, |r, _| r.penumbra);
                pass.count(c);
                let probe = pass.probe();
                pass.count(li_pass::<T>(
                    &ctx,
                    &mut tiles,
                    &rt,
                    false,
                    true,
                    probe.as_ref(),
                ));
            });
        }
    }
    tiles.into_iter().map(|t| t.li).collect()
}

/// One stencil pass of the three-pass umbra: DECR for front-facing, INCR for back-facing
/// fragments, on depth pass (z-pass) or depth fail (z-fail), saturating (offset 128).
fn stencil_pass(
    ctx: &Ctx,
    stencil: &mut [StencilTile],
    rt: &[RasterTriangle],
    probe: Option<&PassProbe>,
) -> Counters {
    let keep = StencilOp::Keep;
    let state = match ctx.s.test {
        WedgeTest::ZPass => StencilState {
            front: StencilFace::always(keep, StencilOp::Decr),
            back: StencilFace::always(keep, StencilOp::Incr),
        },
        WedgeTest::ZFail => StencilState {
            front: StencilFace::always(StencilOp::Decr, keep),
            back: StencilFace::always(StencilOp::Incr, keep),
        },
    };
    let tiling = &ctx.frame.tiling;
    let bins = bin(tiling, rt);
    draw(
        tiling,
        stencil,
        rt,
        &bins,
        probe,
        |t, _, tri, c| {
            let culled = ctx.umbra_culled(t, tri);
            ctx.count_tile_test(t, c);
            count!(c.tiles_culled_hiz += culled as u64);
            if culled {
                ctx.record_culled(probe, t, tri, "umbra");
            }
            culled
        },
        |t, st, tri, f, c, tap| {
            let depth = &ctx.frame.tiles[t].depth;
            let stored = depth.read(f.local, c);
            let z = depth.format.quantize(f.z);
            let pass = z < stored;
            count!(c.depth_passed += pass as u64);
            let update = st.apply(&state, tri.front_facing, &f, pass, c);
            if let Some(tap) = tap {
                let e = ctx.primitive(tap.event(), tri);
                let e = depth.record_test(e, DepthFunc::Less, f.local, z, pass);
                tap.push(update.record(e, "stencil"));
            }
        },
    )
}

/// `pw-restructured`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    crate::methods::Golden::new("cylinder"),
    crate::methods::Golden::new("two-lights"),
    crate::methods::Golden::new("cube-of-spheres-sphere"),
    crate::methods::Golden::new("pw-columns"),
    crate::methods::Golden::new("pw-fractal"),
    crate::methods::Golden::new("pw-2002"),
    crate::methods::Golden::new("scenes/real/scorpion.toml"),
    crate::methods::Golden::variant("pw-2002", "three", &[("passes", "three")]),
    crate::methods::Golden::variant("pw-columns", "zmax", &[("culling", "zmax")]),
    crate::methods::Golden::variant("pw-columns", "no-culling", &[("culling", "off")]),
    crate::methods::Golden::new("scenes/hard/eye-in-shadow-sphere.toml"),
];

/// `pw-restructured`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[
    &[("li", "16")],
    &[("li", "12")],
    &[("li", "8")],
    &[("li", "16"), ("horizon", "clip")],
];

/// What the precision experiment measures of it ([`crate::experiment::precision`]): Paper II's LI buffers.
const PRECISION: PrecisionSpec = PrecisionSpec {
    shader_arithmetic: true,
    storage: &[
        NarrowFormat::of("li", "12", "16"),
        NarrowFormat::of("li", "8", "16"),
    ],
    overflow: &[],
};

/// `pw-restructured` in the registry ([`crate::methods::ALL`]).
pub const METHOD: crate::methods::Method = crate::methods::Method {
    name: "pw-restructured",
    paper: "Paper II: restructured penumbra wedges",
    // Penumbra wedges are built for spherical lights only (Paper I §4).
    supports: |s| matches!(s, LightShape::Sphere { .. }),
    lights: crate::methods::SeveralLights::OnePass,
    options: crate::methods::OptionTableSpec::of::<PwRestructuredOptions>(),
    bytes_per_pixel: 96,
    bytes_per_triangle: 848,
    default_run: crate::methods::DefaultRun::EveryScene,
    sums_per_silhouette_edge: true,
    table_note: |_| None,
    check: |frame| read_settings(frame).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: PRECISION,
};

/// Run `pw-restructured` on a rendered frame.
pub fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    let (s, mode) = read_settings(frame)?;
    if s.wedge.multi_light == MultiLight::PerLight && frame.scene.is_multi_light() {
        return super::light_average::run("pw-restructured", frame, |_, f| run(f));
    }
    let mut rec = PassRecorder::new(frame, "pw-restructured");
    let set = frame_wedges(frame, &s.wedge)?;
    let tiles = render_li(&mut rec, &set, &s);
    let li = li_row_major(frame, &tiles);
    let (visibility, clamped) = resolve(frame, &li);
    rec.clamped(clamped.iter().filter(|&&c| c).count() as u64);
    for w in super::pw2002::fold_warnings(&set) {
        rec.warn(w);
    }
    rec.dump(|| li_dump(frame, &s.wedge, &tiles, &li, clamped, "Paper II §3, §6"));
    let (visibility, horizon) = clip_to_horizon(&mut rec, s.wedge.horizon, visibility);
    Ok(rec.finish(
        visibility,
        serde_json::json!({
            "mode": mode.written(),
            "horizon": horizon,
            "resolved": s,
            "wedges": set.wedges.len(),
            "open_wedges": set.open_wedges,
            "silhouette_folds": set.fold_count(),
            "gpu": frame.gpu,
        }),
    ))
}
