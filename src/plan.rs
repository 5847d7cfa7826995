//! The frame plan.
