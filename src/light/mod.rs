//! Light shapes and their sampling.
