//! Geometry preparation: mesh adjacency, possible silhouettes, loops, shadow volumes.

pub mod adjacency;
