//! Light shapes and their sampling (`docs/architecture.md` "Layout": `light/`).
//!
//! The shapes themselves are defined with the scene ([`crate::scene::LightShape`]); this module
//! holds what the methods compute *on* a light:
//!
//! - [`sampling`]: stratified point samples with per-channel weights — the light positions of
//!   the papers' N-sample reference (Paper III §5.1) and of the ray-cast ground truth; sphere
//!   lights are sampled as the disk through their center facing the receiver (Paper IV §4.2.1).
//!
//! - [`coverage`]: exact coverage of a rectangular light by the projected semi-infinite hard
//!   shadow quad of one silhouette edge, by homogeneous clipping (Paper III §3.2.2).
//!
//! - [`coverage_texture`]: the 4D coverage texture of Paper III §3.3 (grey and RGB for textured
//!   lights), computed once per light shape and cached in the process and on disk
//!   ([`texture_cache`]).
//!
//! - [`horizon`]: the part of a light in front of a receiver's own tangent plane (issue 28:
//!   the *horizon receivers*, whose plane cuts the light).
//!
//! - [`radial_parts`]: the light split into four radial parts and the occluded area and
//!   bounding rectangle of one edge per part (Forest et al. 2006 §3.1, §4.2, §4.3).
//!
//! - [`lookup_tables`]: the lookup tables of Paper IV's optimized shaders (atan2 cube map, area
//!   tables, split table) at the paper's sizes and bit depths (§4.2.1, §4.2.2, §4.3, §6).

pub mod coverage;
pub mod coverage_texture;
pub mod horizon;
pub mod lookup_tables;
pub mod radial_parts;
pub mod sampling;
pub mod texture_cache;
