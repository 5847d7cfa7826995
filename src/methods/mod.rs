//! One module per soft-shadow method; each cites its paper section.

pub mod output;
