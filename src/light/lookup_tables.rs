//! The lookup tables of Paper IV's optimized pixel shaders (§4.2.1, §4.2.2, §4.3, §6), at the
//! paper's sizes and bit depths, and their exact-arithmetic counterparts:
//!
//! - [`Atan2CubeMap`]: a six-face 128×128 16-bit cube map that returns `atan2(y, x)` of the
//!   lookup direction (§4.2.1: "a cube-map that implements atan2(y, x)"); 192 KiB.
//! - [`AreaTable`]: 256×256 single channel, indexed by two angles (θ0, θ1), holding the area
//!   of the light between the rays at θ0 and θ1 along the minor arc, as a fraction of the light
//!   (§4.2.2 Fig. 6b, §4.2.1 Fig. 5b): 16-bit for the sphere (unit disk), 8-bit for the
//!   rectangle (the square [−1,1]², to which every rectangle maps affinely — area fractions
//!   are affine invariant).
//! - [`SplitTable`]: 1024 entries of four 8-bit channels converting a coverage value into the
//!   split V-buffer value of §4.3 ([`crate::gpu::split_blend`]).
//!
//! Total texture memory: 196,608 + 131,072 + 4,096 = 331,776 bytes = 324 KiB for the sphere
//! shader and 196,608 + 65,536 + 4,096 = 266,240 bytes = 260 KiB for the rectangle. §6 reports
//! "about 324KB" (KiB: exact) and "about 270KB" (4 % above the 260 KiB, 1.4 % above 266 kB in
//! powers of ten: the paper's KB is KiB in the first figure, so the second is rounded up). Every table is built once per process from the exact functions below and cached;
//! building is deterministic (f64, no parallel sums).
//!
//! Choices where the paper is silent (each tested below):
//! - Texel centers at +0.5 (`docs/architecture.md` "Textures"); texture coordinates wrap
//!   (GL_REPEAT) on the angle axes of the area table.
//! - The atan2 cube map is looked up with the direction (x, y, 0), i.e. on the four side
//!   faces, where the face coordinate is y/x or x/y — a uniform angular resolution of at most
//!   (π/2)/128 per texel, instead of the +Z face, whose resolution degrades near the center.
//!   It is sampled nearest (bilinear would blend −π and π across the seam on the −X face).
//!   Ties of the major axis go to X before Y before Z. Angles are stored as
//!   `round((θ + π) / 2π · 65535)`.
//! - Area values are stored relative to the largest minor-arc sector, one half of the light
//!   (the square and the disk are centrally symmetric, so a sector of angle π is exactly half):
//!   `round(fraction / 0.5 · (2^bits − 1))`. The area table is sampled nearest or bilinear
//!   ([`TableFilter`]). Because both shapes are centrally symmetric the tabulated function is
//!   continuous across |θ1 − θ0| = π, where the minor arc switches sides.
//! - The split table maps coverage c to entry `round(c · 1023)` (the shader scales c to the
//!   texel centers); entry i holds `round(i / 1023 · full)` split over R, G, B, A, so 0 and 1 are
//!   exact.

use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::split_blend::SplitFormat;
use crate::gpu::texture::{sample_2d, Wrap};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::OnceLock;

/// Edge of one atan2 cube-map face (Paper IV §6).
pub const ATAN2_FACE_SIZE: usize = 128;
/// Edge of the area table (Paper IV §6).
pub const AREA_TABLE_SIZE: usize = 256;
/// Entries of the split table (Paper IV §6).
pub const SPLIT_TABLE_SIZE: usize = 1024;

/// How a table is filtered (the GPU's texture filters, [`crate::gpu::texture::Filter`]).
pub type TableFilter = crate::gpu::texture::Filter;

/// A single-channel 2D texture of unsigned normalized texels (8 or 16 bits), wrapped
/// (GL_REPEAT) in both coordinates, texel centers at +0.5.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnormTexture2D {
    /// Width in texels.
    pub width: usize,
    /// Height in texels.
    pub height: usize,
    /// Bits per texel (8 or 16); a texel `q` stands for `q / (2^bits − 1)`.
    pub bits: u32,
    /// Row-major texels.
    pub texels: Vec<u16>,
}

impl UnormTexture2D {
    /// Storage size in bytes.
    pub fn bytes(&self) -> usize {
        self.texels.len() * (self.bits as usize / 8)
    }

    fn max(&self) -> f64 {
        ((1u32 << self.bits) - 1) as f64
    }

    fn texel(&self, i: u32, j: u32) -> f64 {
        self.texels[j as usize * self.width + i as usize] as f64 / self.max()
    }

    /// Sample at texture coordinates (s, t) (1.0 = one full width/height), wrapped
    /// ([`crate::gpu::texture::sample_2d`]).
    pub fn sample(&self, s: f64, t: f64, filter: TableFilter) -> f64 {
        let size = [self.width as u32, self.height as u32];
        let (x, y) = (s * self.width as f64, t * self.height as f64);
        crate::gpu::shader_ops::fetch();
        sample_2d(x, y, size, Wrap::Repeat, filter, |i, j| self.texel(i, j))
    }
}

/// Quantize `x ∈ [0, 1]` to an unsigned normalized integer of `bits` bits (round to nearest).
fn unorm(x: f64, bits: u32) -> u16 {
    let max = ((1u32 << bits) - 1) as f64;
    (x.clamp(0.0, 1.0) * max).round() as u16
}

/// The angle of a table texel coordinate `u ∈ [0,1)`: `−π + u·2π`.
fn angle_of(u: f64) -> f64 {
    -PI + u * TAU
}

/// The texture coordinate of angle θ: `(θ + π) / 2π`, in the shader precision `T`.
fn coord_of<T: ShaderFloat>(theta: T) -> T {
    (theta + T::from_f64(PI)) / T::from_f64(TAU)
}

/// The six faces of a cube map, in OpenGL order.
const FACES: usize = 6;

/// Paper IV §4.2.1/§4.2.2: the atan2 cube map, 6 faces of 128×128 16-bit angles.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Atan2CubeMap {
    /// One texture per face (+X, −X, +Y, −Y, +Z, −Z).
    pub faces: Vec<UnormTexture2D>,
}

/// The face and (s, t) ∈ [0, 1]² that OpenGL's cube-map addressing gives direction `d`
/// (major axis ties: X, then Y, then Z).
fn cube_face(d: [f64; 3]) -> (usize, f64, f64) {
    let [x, y, z] = d;
    let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
    let (face, sc, tc, ma) = if ax >= ay && ax >= az {
        if x >= 0.0 {
            (0, -z, -y, ax)
        } else {
            (1, z, -y, ax)
        }
    } else if ay >= az {
        if y >= 0.0 {
            (2, x, z, ay)
        } else {
            (3, x, -z, ay)
        }
    } else if z >= 0.0 {
        (4, x, -y, az)
    } else {
        (5, -x, -y, az)
    };
    (face, (sc / ma + 1.0) * 0.5, (tc / ma + 1.0) * 0.5)
}

/// The direction through (s, t) of `face` (the inverse of [`cube_face`]).
fn face_direction(face: usize, s: f64, t: f64) -> [f64; 3] {
    let (sc, tc) = (2.0 * s - 1.0, 2.0 * t - 1.0);
    match face {
        0 => [1.0, -tc, -sc],
        1 => [-1.0, -tc, sc],
        2 => [sc, 1.0, tc],
        3 => [sc, -1.0, -tc],
        4 => [sc, -tc, 1.0],
        _ => [-sc, -tc, -1.0],
    }
}

impl Atan2CubeMap {
    fn build() -> Self {
        let n = ATAN2_FACE_SIZE;
        let faces = (0..FACES)
            .map(|f| {
                let mut texels = Vec::with_capacity(n * n);
                for j in 0..n {
                    for i in 0..n {
                        let s = (i as f64 + 0.5) / n as f64;
                        let t = (j as f64 + 0.5) / n as f64;
                        let d = face_direction(f, s, t);
                        texels.push(unorm(coord_of(libm::atan2(d[1], d[0])), 16));
                    }
                }
                UnormTexture2D {
                    width: n,
                    height: n,
                    bits: 16,
                    texels,
                }
            })
            .collect();
        Self { faces }
    }

    /// The cached table.
    pub fn get() -> &'static Self {
        static TABLE: OnceLock<Atan2CubeMap> = OnceLock::new();
        TABLE.get_or_init(Self::build)
    }

    /// Storage size in bytes (196,608).
    pub fn bytes(&self) -> usize {
        self.faces.iter().map(|f| f.bytes()).sum()
    }

    /// `atan2(y, x)` by a nearest lookup of the direction (x, y, 0), in (−π, π].
    /// (0, 0) is looked up as (0, 0, 0), which addresses +X like OpenGL's tie rule here.
    pub fn atan2(&self, y: f64, x: f64) -> f64 {
        let (face, s, t) = if x == 0.0 && y == 0.0 {
            (0, 0.5, 0.5)
        } else {
            cube_face([x, y, 0.0])
        };
        // Cube-map faces are addressed CLAMP_TO_EDGE: s or t = 1.0 (|x| = |y|) is the last
        // texel, not the first.
        let edge = (ATAN2_FACE_SIZE as f64 - 0.5) / ATAN2_FACE_SIZE as f64;
        let (s, t) = (s.clamp(0.0, edge), t.clamp(0.0, edge));
        angle_of(self.faces[face].sample(s, t, TableFilter::Nearest))
    }
}

/// The light shape an area table tabulates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum AreaShape {
    /// The square [−1,1]² (rectangular lights after the affine map to it); 8-bit table.
    Square,
    /// The unit disk (spherical lights seen from the receiver); 16-bit table.
    Disk,
}

impl AreaShape {
    /// Cumulative area fraction of the shape between angle 0 and θ (counter-clockwise,
    /// continuous and increasing over all reals, +1 per turn), in the shader precision `T`.
    fn cumulative<T: ShaderFloat>(self, theta: T) -> T {
        let quarter = T::from_f64(FRAC_PI_2);
        match self {
            // Within the octants around axis k·π/2 the boundary is the side at distance 1:
            // the area from that axis to θ is tan(θ − kπ/2)/2; each quarter turn holds 1 of 4.
            AreaShape::Square => {
                let k = (theta / quarter).round();
                (k + (theta - k * quarter).tan() * T::from_f64(0.5)) / T::from_f64(4.0)
            }
            AreaShape::Disk => theta / T::from_f64(TAU),
        }
    }

    /// Exact area fraction of the shape inside the sector between the rays from the center at
    /// θ0 and θ1, along the minor arc (Paper IV Fig. 5b, Fig. 6b). At most 1/2.
    pub fn sector_fraction(self, theta0: f64, theta1: f64) -> f64 {
        self.shader_sector_fraction(theta0, theta1)
    }

    /// [`AreaShape::sector_fraction`] in the shader precision `T`
    /// ([`crate::gpu::shader_float`]): the spherical shader of Paper IV §4.2.1 with exact
    /// arithmetic instead of its area table.
    pub fn shader_sector_fraction<T: ShaderFloat>(self, theta0: T, theta1: T) -> T {
        let (pi, tau) = (T::from_f64(PI), T::from_f64(TAU));
        let d = (theta1 - theta0).rem_euclid(tau);
        let (a, b) = if d <= pi {
            (theta0, theta0 + d)
        } else {
            (theta1, theta1 + (tau - d))
        };
        (self.cumulative(b) - self.cumulative(a)).clamp(T::zero(), T::from_f64(0.5))
    }

    /// Bits per texel of this shape's table (§6: 8-bit for the rectangle, 16 for the sphere).
    pub fn table_bits(self) -> u32 {
        match self {
            AreaShape::Square => 8,
            AreaShape::Disk => 16,
        }
    }
}

/// Paper IV §4.2: the 256×256 area table of one light shape.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AreaTable {
    /// The shape tabulated.
    pub shape: AreaShape,
    /// Texels: sector fraction / 0.5 at the texel-center angles (θ0 along s, θ1 along t).
    pub texture: UnormTexture2D,
}

impl AreaTable {
    fn build(shape: AreaShape) -> Self {
        let n = AREA_TABLE_SIZE;
        let bits = shape.table_bits();
        let mut texels = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let t0 = angle_of((i as f64 + 0.5) / n as f64);
                let t1 = angle_of((j as f64 + 0.5) / n as f64);
                texels.push(unorm(shape.sector_fraction(t0, t1) / 0.5, bits));
            }
        }
        Self {
            shape,
            texture: UnormTexture2D {
                width: n,
                height: n,
                bits,
                texels,
            },
        }
    }

    /// The cached table of `shape`.
    pub fn get(shape: AreaShape) -> &'static Self {
        static SQUARE: OnceLock<AreaTable> = OnceLock::new();
        static DISK: OnceLock<AreaTable> = OnceLock::new();
        match shape {
            AreaShape::Square => SQUARE.get_or_init(|| Self::build(shape)),
            AreaShape::Disk => DISK.get_or_init(|| Self::build(shape)),
        }
    }

    /// The tabulated sector fraction between θ0 and θ1.
    pub fn sector_fraction(&self, theta0: f64, theta1: f64, filter: TableFilter) -> f64 {
        self.shader_sector_fraction(theta0, theta1, filter)
    }

    /// [`AreaTable::sector_fraction`] by a fragment program in the shader precision `T`
    /// ([`crate::gpu::shader_float`]): the texture coordinates and the scaling of the fetched
    /// value are computed in `T`; the texture unit's addressing and filtering are its own.
    pub fn shader_sector_fraction<T: ShaderFloat>(
        &self,
        theta0: T,
        theta1: T,
        filter: TableFilter,
    ) -> T {
        let (s, t) = (coord_of(theta0).to_f64(), coord_of(theta1).to_f64());
        T::from_f64(0.5) * T::from_f64(self.texture.sample(s, t, filter))
    }
}

/// Paper IV §4.3/§6: the 1024-entry texture of four 8-bit channels that converts a coverage
/// value into a split V-buffer value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SplitTable {
    /// The channel layout.
    pub format: SplitFormat,
    /// Entry i: `format.split(round(i / 1023 · full))`.
    pub entries: Vec<[u8; 4]>,
}

impl SplitTable {
    fn build(format: SplitFormat) -> Self {
        let last = (SPLIT_TABLE_SIZE - 1) as f64;
        let entries = (0..SPLIT_TABLE_SIZE)
            .map(|i| format.split((i as f64 / last * format.full() as f64).round() as u32))
            .collect();
        Self { format, entries }
    }

    /// The cached table of `format`.
    pub fn get(format: SplitFormat) -> &'static Self {
        static TABLES: [OnceLock<SplitTable>; 7] = [const { OnceLock::new() }; 7];
        TABLES[(format.reserved_bits - 1) as usize].get_or_init(|| Self::build(format))
    }

    /// The entry index of coverage `c` (clamped to [0, 1]; NaN maps to 0).
    pub fn index(c: f64) -> usize {
        Self::shader_index(c)
    }

    /// [`SplitTable::index`] by a fragment program in the shader precision `T`
    /// ([`crate::gpu::shader_float`]): the scaling of `c` to the texel centers is computed in
    /// `T`, the nearest texel is the texture unit's.
    pub fn shader_index<T: ShaderFloat>(c: T) -> usize {
        let c = if c.to_f64().is_nan() {
            T::zero()
        } else {
            c.clamp(T::zero(), T::one())
        };
        (c * T::from_f64((SPLIT_TABLE_SIZE - 1) as f64))
            .to_f64()
            .round() as usize
    }

    /// The split value of coverage `c`.
    pub fn lookup(&self, c: f64) -> [u8; 4] {
        self.shader_lookup(c)
    }

    /// [`SplitTable::lookup`] in the shader precision `T` ([`SplitTable::shader_index`]).
    pub fn shader_lookup<T: ShaderFloat>(&self, c: T) -> [u8; 4] {
        crate::gpu::shader_ops::fetch();
        self.entries[Self::shader_index(c)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_the_papers() {
        assert_eq!(Atan2CubeMap::get().bytes(), 196_608);
        assert_eq!(AreaTable::get(AreaShape::Disk).texture.bytes(), 131_072);
        assert_eq!(AreaTable::get(AreaShape::Square).texture.bytes(), 65_536);
        assert_eq!(
            SplitTable::get(SplitFormat::default()).entries.len() * 4,
            4096
        );
    }

    #[test]
    fn cube_face_inverts_face_direction() {
        for f in 0..FACES {
            let (g, s, t) = cube_face(face_direction(f, 0.3, 0.8));
            assert_eq!(g, f);
            assert!((s - 0.3).abs() < 1e-12 && (t - 0.8).abs() < 1e-12);
        }
    }

    #[test]
    fn atan2_map_is_within_half_a_texel_of_atan2() {
        let map = Atan2CubeMap::get();
        let mut worst = 0.0f64;
        for k in 0..3600 {
            let th = -PI + (k as f64 + 0.25) * TAU / 3600.0;
            let (y, x) = (libm::sin(th) * 0.7, libm::cos(th) * 0.7);
            let mut e = (map.atan2(y, x) - th).abs();
            e = e.min(TAU - e);
            worst = worst.max(e);
        }
        // One texel spans at most (π/2)/128·... of angle: atan's slope ≤ 1 on [−1,1] and a texel
        // is 2/128 wide, so half a texel is ≤ 1/128 rad.
        assert!(worst <= 1.0 / 128.0 + 1e-4, "{worst}");
    }

    #[test]
    fn atan2_map_on_the_face_diagonals() {
        let map = Atan2CubeMap::get();
        for (y, x) in [(-0.2, 0.2), (0.2, 0.2), (0.2, -0.2), (-0.2, -0.2)] {
            let e = (map.atan2(y, x) - libm::atan2(y, x)).abs();
            assert!(e <= 1.0 / 128.0, "({y}, {x}): {e}");
        }
    }

    #[test]
    fn square_sector_fraction_exact_values() {
        let s = AreaShape::Square;
        assert!((s.sector_fraction(0.0, FRAC_PI_2) - 0.25).abs() < 1e-15);
        assert!((s.sector_fraction(-FRAC_PI_2 / 2.0, FRAC_PI_2 / 2.0) - 0.25).abs() < 1e-15);
        assert!((s.sector_fraction(0.1, 0.1 + PI) - 0.5).abs() < 1e-12);
        // Minor arc: the same either way round and across ±π.
        assert_eq!(s.sector_fraction(3.0, -3.0), s.sector_fraction(-3.0, 3.0));
        // The triangle (0,0), (1,0), (1,1): area 1/2 of 4.
        assert!((s.sector_fraction(0.0, PI / 4.0) - 0.125).abs() < 1e-15);
        assert!((AreaShape::Disk.sector_fraction(0.0, 1.0) - 1.0 / TAU).abs() < 1e-15);
    }

    #[test]
    fn area_tables_match_the_exact_sector_at_texel_centers_and_between() {
        for shape in [AreaShape::Square, AreaShape::Disk] {
            let table = AreaTable::get(shape);
            let q = 0.5 / ((1u32 << shape.table_bits()) - 1) as f64;
            let n = AREA_TABLE_SIZE as f64;
            let c = |i: f64| angle_of((i + 0.5) / n);
            let (a, b) = (c(17.0), c(201.0));
            let e = (table.sector_fraction(a, b, TableFilter::Nearest)
                - shape.sector_fraction(a, b))
            .abs();
            assert!(e <= q / 2.0 + 1e-12, "{shape:?} {e}");
        }
    }

    #[test]
    fn split_table_ends_are_exact() {
        let t = SplitTable::get(SplitFormat::default());
        assert_eq!(t.lookup(0.0), [0; 4]);
        assert_eq!(t.lookup(1.0), [7; 4]);
        assert_eq!(t.lookup(f64::NAN), [0; 4]);
        assert_eq!(t.lookup(2.0), [7; 4]);
        assert_eq!(SplitTable::index(0.5), 512);
    }
}
