//! Light shapes and their sampling (DESIGN.md "Layout": `light/`).
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
//! Analytic coverage and the coverage lookup tables (Papers III, IV) belong
//! here too as they are added.

pub mod coverage;
pub mod lookup_tables;
pub mod sampling;
