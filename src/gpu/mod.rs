//! The emulated GPU pipeline (`docs/architecture.md` "The emulated GPU: the
//! bit-exactness contract").
//!
//! Each rule of the contract is defined once, here:
//! [`transform`] (camera, infinite-far projection, viewport), [`clip`] (homogeneous clipping),
//! [`fixed`] (sub-pixel snapping), [`setup`] (edge functions, fill rule, facing, depth plane),
//! [`tiling`] and [`raster`] (tile traversal, parallel draw), [`depth`] and [`stencil`]
//! (fixed-function tests and ops), [`buffers`] (typed, counted per-tile storage and
//! zmin/zmax), [`hiz`] (the hierarchical-Z unit's tile rejection), [`vbuffer`] (the V-buffer formats of Paper III §4), [`pack4ub`] (8-bit values
//! packed into 32-bit float channels, Forest et al. 2006 §4.3), [`counters`], [`probe`] (what
//! the passes did to one pixel),
//! [`texture`] (texel addressing and filtering), [`normal_buffer`] (the scene pass's receiver normals), [`shader_float`] (the fragment programs'
//! scalar at the shader precision), [`color`] (colour-buffer formats) and
//! [`light_view`] (render targets seen from a light: shadow maps and the maps built on them).

pub mod buffers;
pub mod clip;
pub mod color;
pub mod counters;
pub mod depth;
pub mod fixed;
pub mod hiz;
pub mod li_buffer;
pub mod light_view;
pub mod normal_buffer;
pub mod pack4ub;
pub mod probe;
pub mod raster;
pub mod setup;
pub mod shader_float;
pub mod shader_ops;
pub mod shader_vec;
pub mod split_blend;
pub mod stencil;
pub mod texture;
pub mod tiling;
pub mod transform;
pub mod vbuffer;
