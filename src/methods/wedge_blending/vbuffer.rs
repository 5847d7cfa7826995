//! How the silhouette and final vBuffers of penumbra-wedges blending store a pixel's four
//! [`PartState`]s (Forest, Barthe & Paulin 2006 §4.3, Fig. 11).
//!
//! * [`Packed8`] (`packing = 8bit`, the paper's): per radial part two 32-bit scalars made by
//!   `PK4UB` ([`crate::gpu::pack4ub`]): the rectangle as `(top, bottom, left, right)` — the
//!   paper's order, x in the lowest byte — and `(occlusion, max X, max Y, free)`, where the
//!   free byte holds the center-of-gravity index with `centroid = on` (§6) and 0 otherwise.
//!   The eight scalars live in the channels of two RGBA32F render targets: target 0 holds the
//!   four rectangles (parts 0…3 in x, y, z, w), target 1 the four occlusion scalars (the paper
//!   says "two RGBA full precision float buffers" without the channel assignment). Every write
//!   goes through the target's float storage ([`FloatTarget`]), so a target that flushes
//!   denormals or canonicalizes NaNs corrupts the patterns that are such floats (counted).
//!   Values are quantized to 1/255 at every write: a fragment reads the pixel, unpacks,
//!   updates, packs and writes it back, so rounding accumulates over the half-wedges of a
//!   silhouette, and the occlusion is clamped to [0, 1] at every write (PK4UB saturates).
//!   32 bytes per pixel and vBuffer: at 1024×768 the silhouette and final vBuffers take
//!   `1024·768·4 channels·4 bytes·4 buffers` = 48 MiB, the paper's "48MB".
//! * [`UnpackedF32`] (`packing = f32`): the same algorithm with every value an f32 and nothing
//!   clamped or rounded but by f32 arithmetic, so the cost of the packing is measurable apart
//!   from the cost of the rectangle approximation. Counted at its real size: per part the
//!   occlusion, four rectangle coordinates and (silhouette vBuffer only) max X and Y, plus the
//!   two centroid coordinates with `centroid = on`, 4 bytes each.
//!
//! The center of gravity is stored as one of 256 positions per part (§6: "a center of gravity
//! discretized into 256 positions per radial part"): the cell of a 16×16 grid over the part,
//! index `16·row + column`, restored at the cell's center (the paper's "two-components 1D
//! look-up texture").

use super::blend::PartState;
use crate::gpu::pack4ub::{pk4ub, up4ub, FloatTarget, StoreEvents};
use crate::gpu::probe::Raw;
use crate::light::radial_parts::{BoundingRect, PART_COUNT};

/// The four parts of one pixel.
pub type PixelParts = [PartState; PART_COUNT];

/// A vBuffer pixel format (module doc).
pub trait VBufferStorage: Sync {
    /// What one pixel holds.
    type Pixel: Copy + Send + Sync;
    /// A cleared pixel (every part [`PartState::CLEARED`]).
    fn cleared(&self) -> Self::Pixel;
    /// The pixel's parts as the fragment program sees them after unpacking.
    fn load(&self, px: &Self::Pixel) -> PixelParts;
    /// Pack and write `parts`; special float patterns are added to `events`. Returns the pixel
    /// and the number of values the packing clamped.
    fn store(&self, parts: &PixelParts, events: &mut StoreEvents) -> (Self::Pixel, u64);
    /// Bytes per pixel of the silhouette vBuffer.
    fn silhouette_bytes(&self) -> u64;
    /// Bytes per pixel of the final vBuffer.
    fn final_bytes(&self) -> u64;
    /// The format, for the plan.
    fn describe(&self) -> String;
    /// A pixel as stored, for probes ([`crate::gpu::probe`]).
    fn raw(&self, px: &Self::Pixel) -> Raw;
    /// The pixel a probe recorded as `raw` ([`VBufferStorage::raw`]'s inverse); `None` for a
    /// value of another format.
    fn pixel_of_raw(&self, raw: &Raw) -> Option<Self::Pixel>;
}

/// The paper's packed 8-bit storage (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Packed8 {
    /// How the RGBA32F targets store a written pattern.
    pub target: FloatTarget,
    /// Whether the free byte holds the center-of-gravity index.
    pub centroid: bool,
}

/// The unpacked f32 storage (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnpackedF32 {
    /// Whether the center of gravity is stored.
    pub centroid: bool,
}

/// The grid side of the center-of-gravity positions (16 × 16 = 256).
const CENTROID_GRID: f32 = 16.0;

/// The index of the grid cell holding `c` (module doc).
pub fn centroid_index(c: [f32; 2]) -> u8 {
    let cell = |v: f32| (v * CENTROID_GRID).floor().clamp(0.0, CENTROID_GRID - 1.0) as u8;
    cell(c[1]) * CENTROID_GRID as u8 + cell(c[0])
}

/// The position index `i` restores: the center of its cell.
pub fn centroid_position(i: u8) -> [f32; 2] {
    let g = CENTROID_GRID as u8;
    [
        ((i % g) as f32 + 0.5) / CENTROID_GRID,
        ((i / g) as f32 + 0.5) / CENTROID_GRID,
    ]
}

/// The byte `PK4UB` stores for an index (k/255 packs back to k exactly).
fn index_unorm(i: u8) -> f32 {
    i as f32 / 255.0
}

impl VBufferStorage for Packed8 {
    type Pixel = [u32; 2 * PART_COUNT];

    fn cleared(&self) -> Self::Pixel {
        let mut ignored = StoreEvents::default();
        self.store(&[PartState::CLEARED; PART_COUNT], &mut ignored)
            .0
    }

    fn load(&self, px: &Self::Pixel) -> PixelParts {
        std::array::from_fn(|k| {
            let [top, bottom, left, right] = up4ub(px[k]);
            let [occlusion, max_x, max_y, free] = up4ub(px[PART_COUNT + k]);
            PartState {
                occlusion,
                rect: BoundingRect {
                    left,
                    bottom,
                    right,
                    top,
                },
                max_edge: [max_x, max_y],
                centroid: if self.centroid {
                    centroid_position((free * 255.0).round() as u8)
                } else {
                    [0.0, 0.0]
                },
            }
        })
    }

    fn store(&self, parts: &PixelParts, events: &mut StoreEvents) -> (Self::Pixel, u64) {
        let mut px = [0u32; 2 * PART_COUNT];
        let mut clamped = 0;
        for (k, p) in parts.iter().enumerate() {
            let r = p.rect;
            px[k] = self
                .target
                .store(pk4ub([r.top, r.bottom, r.left, r.right]), events);
            let free = if self.centroid {
                index_unorm(centroid_index(p.centroid))
            } else {
                0.0
            };
            clamped += !(0.0..=1.0).contains(&p.occlusion) as u64;
            px[PART_COUNT + k] = self.target.store(
                pk4ub([p.occlusion, p.max_edge[0], p.max_edge[1], free]),
                events,
            );
        }
        (px, clamped)
    }

    fn silhouette_bytes(&self) -> u64 {
        (2 * PART_COUNT * 4) as u64
    }

    fn final_bytes(&self) -> u64 {
        self.silhouette_bytes()
    }

    fn describe(&self) -> String {
        format!(
            "2×RGBA32F, per part PK4UB(top, bottom, left, right) + PK4UB(occlusion, max X, max Y, {}), target {:?}",
            if self.centroid { "centroid index" } else { "0" },
            self.target
        )
    }

    /// The eight packed words: the four rectangles, then the four occlusion scalars.
    fn raw(&self, px: &Self::Pixel) -> Raw {
        Raw::Channels(px.iter().map(|w| Raw::Word(*w)).collect())
    }

    fn pixel_of_raw(&self, raw: &Raw) -> Option<Self::Pixel> {
        let Raw::Channels(words) = raw else {
            return None;
        };
        let mut px = [0u32; 2 * PART_COUNT];
        if words.len() != px.len() {
            return None;
        }
        for (p, w) in px.iter_mut().zip(words) {
            let Raw::Word(w) = w else { return None };
            *p = *w;
        }
        Some(px)
    }
}

impl UnpackedF32 {
    /// f32 values per part: occlusion, four rectangle coordinates, optional centroid.
    fn values_per_part(&self) -> u64 {
        5 + 2 * self.centroid as u64
    }
}

impl VBufferStorage for UnpackedF32 {
    type Pixel = PixelParts;

    fn cleared(&self) -> Self::Pixel {
        [PartState::CLEARED; PART_COUNT]
    }

    fn load(&self, px: &Self::Pixel) -> PixelParts {
        *px
    }

    fn store(&self, parts: &PixelParts, _: &mut StoreEvents) -> (Self::Pixel, u64) {
        (*parts, 0)
    }

    fn silhouette_bytes(&self) -> u64 {
        PART_COUNT as u64 * (self.values_per_part() + 2) * 4
    }

    fn final_bytes(&self) -> u64 {
        PART_COUNT as u64 * self.values_per_part() * 4
    }

    fn describe(&self) -> String {
        format!(
            "f32: per part occlusion, rectangle{}{} (silhouette {} B, final {} B per pixel)",
            ", max X, max Y (silhouette only)",
            if self.centroid { ", centroid" } else { "" },
            self.silhouette_bytes(),
            self.final_bytes()
        )
    }

    /// Per part the f32 bits of occlusion, left, bottom, right, top, max X, max Y and the
    /// centroid.
    fn raw(&self, px: &Self::Pixel) -> Raw {
        Raw::Channels(
            px.iter()
                .flat_map(|p| {
                    let r = p.rect;
                    [p.occlusion, r.left, r.bottom, r.right, r.top]
                        .into_iter()
                        .chain(p.max_edge)
                        .chain(p.centroid)
                })
                .map(Raw::f32)
                .collect(),
        )
    }

    fn pixel_of_raw(&self, raw: &Raw) -> Option<Self::Pixel> {
        let Raw::Channels(values) = raw else {
            return None;
        };
        let floats: Vec<f32> = values
            .iter()
            .map(|v| match v {
                Raw::F32(b) => Some(f32::from_bits(*b)),
                _ => None,
            })
            .collect::<Option<_>>()?;
        if floats.len() != 9 * PART_COUNT {
            return None;
        }
        Some(std::array::from_fn(|k| {
            let v = &floats[9 * k..9 * k + 9];
            PartState {
                occlusion: v[0],
                rect: BoundingRect {
                    left: v[1],
                    bottom: v[2],
                    right: v[3],
                    top: v[4],
                },
                max_edge: [v[5], v[6]],
                centroid: [v[7], v[8]],
            }
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn cleared_packed_pixel_is_an_empty_rectangle_in_normal_floats() {
        let s = Packed8 {
            target: FloatTarget::Raw,
            centroid: false,
        };
        let px = s.cleared();
        // (top 0, bottom 255, left 255, right 0): exponent field 1, a normal float.
        assert_eq!(px[0], 0x00FF_FF00);
        assert_eq!(
            crate::gpu::pack4ub::classify(px[0]),
            crate::gpu::pack4ub::FloatClass::Normal
        );
        for p in s.load(&px) {
            assert!(p.rect.is_empty());
            assert_eq!(p.occlusion, 0.0);
        }
    }

    #[test]
    fn rectangle_coordinates_quantize_to_the_nearest_255th() {
        let s = Packed8 {
            target: FloatTarget::Raw,
            centroid: false,
        };
        let mut part = PartState::hard(1);
        part.rect = BoundingRect {
            left: 0.1,
            bottom: 0.2,
            right: 0.7,
            top: 0.9,
        };
        let mut e = StoreEvents::default();
        let (px, _) = s.store(&[part; PART_COUNT], &mut e);
        let back = s.load(&px)[0].rect;
        for (got, want) in [
            (back.left, 0.1f32),
            (back.bottom, 0.2),
            (back.right, 0.7),
            (back.top, 0.9),
        ] {
            assert_eq!(got, (want * 255.0 + 0.5).floor() / 255.0);
            assert!((got - want).abs() <= 0.5 / 255.0 + 1e-7);
        }
    }

    #[test]
    fn umbra_occlusion_is_a_denormal_and_a_far_half_rectangle_a_nan() {
        let s = Packed8 {
            target: FloatTarget::CanonicalNans,
            centroid: false,
        };
        let mut part = PartState::hard(1);
        let mut e = StoreEvents::default();
        s.store(&[part; PART_COUNT], &mut e);
        // The rectangle (255, 0, 0, 255) is a normal float; the occlusion scalar
        // (255, 0, 0, 0) has a zero exponent field: a denormal, which a flushing target zeroes.
        assert_eq!((e.nan, e.denormal), (0, PART_COUNT as u64));
        let mut e = StoreEvents::default();
        // left ≥ 0.5 and right = 1: right byte 255, left byte ≥ 128: a NaN pattern.
        part.rect.left = 0.6;
        let (px, _) = s.store(&[part; PART_COUNT], &mut e);
        assert_eq!(e.nan, PART_COUNT as u64);
        assert_eq!(e.altered, PART_COUNT as u64);
        assert_ne!(s.load(&px)[0].rect, part.rect);
    }

    #[test]
    fn probe_raw_round_trips_in_both_storages() {
        let mut part = PartState::hard(1);
        part.max_edge = [0.25, 0.5];
        let parts = [part, PartState::CLEARED, PartState::hard(-1), part];
        let mut e = StoreEvents::default();
        let packed = Packed8 {
            target: FloatTarget::Raw,
            centroid: true,
        };
        let (px, _) = packed.store(&parts, &mut e);
        assert_eq!(packed.pixel_of_raw(&packed.raw(&px)), Some(px));
        let unpacked = UnpackedF32 { centroid: true };
        let (px, _) = unpacked.store(&parts, &mut e);
        assert_eq!(unpacked.pixel_of_raw(&unpacked.raw(&px)), Some(px));
        assert_eq!(unpacked.pixel_of_raw(&packed.raw(&packed.cleared())), None);
    }

    #[test]
    fn centroid_index_round_trip_is_the_cell_center() {
        for i in 0..=255u8 {
            assert_eq!(centroid_index(centroid_position(i)), i);
        }
        assert_eq!(
            centroid_position(centroid_index([0.0, 0.0])),
            [1.0 / 32.0; 2]
        );
        assert_eq!(centroid_index([1.0, 1.0]), 255);
    }

    proptest! {
        #[test]
        fn packed_occlusion_is_clamped_and_rounded(occ in -2.0f32..3.0) {
            let s = Packed8 { target: FloatTarget::Raw, centroid: true };
            let part = PartState { occlusion: occ, ..PartState::hard(1) };
            let mut e = StoreEvents::default();
            let (px, clamped) = s.store(&[part; PART_COUNT], &mut e);
            let back = s.load(&px)[0].occlusion;
            let c = occ.clamp(0.0, 1.0);
            prop_assert!((back - c).abs() <= 0.5 / 255.0 + 1e-7);
            prop_assert_eq!(clamped > 0, !(0.0..=1.0).contains(&occ));
        }
    }
}
