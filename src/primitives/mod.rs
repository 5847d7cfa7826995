//! The geometric primitives shared by every floor of the crate — one ray–triangle test
//! ([`ray_triangle`]) and one convex-polygon clip ([`polygon_clip`]) — at the bottom of the
//! dependency graph (`docs/architecture.md` "Layout"): they use nothing of the crate, so the
//! scene checks (`scene::validate`), the geometry the methods build (`geometry`), the light's
//! coverage (`light::coverage`) and the ray tracer (`methods::raycast`) all call the same
//! arithmetic, with the same rules at edges and degenerate cases.
//!
//! The emulated GPU's clipper (`gpu::clip`) is not one of them: it clips homogeneous
//! triangles the way the OpenGL specification does, with its own interpolation of varyings.

pub mod polygon_clip;
pub mod ray_triangle;
