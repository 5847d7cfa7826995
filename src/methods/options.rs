//! Typed reading of a method's `[options.METHOD]` table (or `--opt METHOD.KEY=VALUE`): every
//! key must be known and every value valid, else a clear [`InputError`] naming
//! `options.METHOD.KEY`.

use crate::error::InputError;
use crate::scene::{OptionValue, Scene};
use std::collections::BTreeMap;

/// Reads the options of one method, consuming keys; [`OptionReader::finish`] rejects leftovers.
#[derive(Debug)]
pub struct OptionReader {
    source: String,
    method: String,
    table: BTreeMap<String, OptionValue>,
}

impl OptionReader {
    /// The reader for `method`'s table in `scene` (empty if the scene has none).
    pub fn new(scene: &Scene, method: &str) -> Self {
        Self {
            source: scene.source.clone(),
            method: method.to_string(),
            table: scene.options.get(method).cloned().unwrap_or_default(),
        }
    }

    /// Whether the table sets `key` (and it has not been read yet).
    pub fn has(&self, key: &str) -> bool {
        self.table.contains_key(key)
    }

    fn err(&self, key: &str, msg: String) -> InputError {
        InputError::at(&self.source, format!("options.{}.{key}", self.method), msg)
    }

    /// A string option restricted to `allowed`.
    pub fn choice(
        &mut self,
        key: &str,
        allowed: &[&'static str],
        default: &'static str,
    ) -> Result<&'static str, InputError> {
        match self.table.remove(key) {
            None => Ok(default),
            Some(OptionValue::Str(s)) => {
                allowed.iter().find(|a| **a == s).copied().ok_or_else(|| {
                    self.err(
                        key,
                        format!(
                            "unknown value {s:?}; expected one of {}",
                            allowed.join(", ")
                        ),
                    )
                })
            }
            Some(v) => Err(self.err(
                key,
                format!("expected one of {}, got {v}", allowed.join(", ")),
            )),
        }
    }

    /// An integer option in `range`.
    pub fn uint(
        &mut self,
        key: &str,
        default: u64,
        range: std::ops::RangeInclusive<u64>,
    ) -> Result<u64, InputError> {
        match self.table.remove(key) {
            None => Ok(default),
            Some(OptionValue::Int(i)) if i >= 0 && range.contains(&(i as u64)) => Ok(i as u64),
            Some(v) => Err(self.err(
                key,
                format!(
                    "expected an integer in {}..={}, got {v}",
                    range.start(),
                    range.end()
                ),
            )),
        }
    }

    /// Error for the first key nobody asked for.
    pub fn finish(self) -> Result<(), InputError> {
        match self.table.keys().next() {
            None => Ok(()),
            Some(k) => Err(self.err(k, format!("unknown option for method {}", self.method))),
        }
    }
}
