//! Rendering one scene with a set of methods.
