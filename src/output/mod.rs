//! Writing a method's outputs to disk.
