//! Geometry preparation: possible silhouettes from a light point, silhouette
//! loops (Paper V), hard shadow volumes with caps, penumbra wedges, and the cones and sheets
//! of penumbra maps and the umbra and penumbra volumes of a disk light (CGI 2004); whether the
//! near plane lies in a shadow volume (the z-fail decision).

pub mod loops;
pub mod near_plane;
pub mod penumbra_cones;
pub mod penumbra_wedge;
pub mod shadow_volume;
pub mod silhouette;
pub mod ssv_wedge;
pub mod tight_wedge;
pub mod umbra_penumbra;
