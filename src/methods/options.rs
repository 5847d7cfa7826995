//! Typed reading of a method's `[options.METHOD]` table (or `--opt METHOD.KEY=VALUE`): every
//! key must be known and every value valid, else a clear [`InputError`] naming
//! `options.METHOD.KEY`.

use crate::error::InputError;
use crate::gpu::depth::{DepthFormat, PolygonOffset};
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

    /// An option restricted to `allowed` values, written as a string or, where a value reads as
    /// a number or bool (`li = 12`, `--opt pw2002.li=8`), as that number or bool.
    pub fn choice(
        &mut self,
        key: &str,
        allowed: &[&'static str],
        default: &'static str,
    ) -> Result<&'static str, InputError> {
        let Some(v) = self.table.remove(key) else {
            return Ok(default);
        };
        let written = match &v {
            OptionValue::Str(s) => s.clone(),
            other => other.to_string(),
        };
        allowed
            .iter()
            .find(|a| **a == written)
            .copied()
            .ok_or_else(|| {
                self.err(
                    key,
                    format!("unknown value {v}; expected one of {}", allowed.join(", ")),
                )
            })
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

    /// A number option (an integer or a float) in `range`.
    pub fn float(
        &mut self,
        key: &str,
        default: f64,
        range: std::ops::RangeInclusive<f64>,
    ) -> Result<f64, InputError> {
        match self.table.remove(key) {
            None => Ok(default),
            Some(OptionValue::Float(x)) if range.contains(&x) => Ok(x),
            Some(OptionValue::Int(i)) if range.contains(&(i as f64)) => Ok(i as f64),
            Some(v) => Err(self.err(
                key,
                format!(
                    "expected a number in {}..={}, got {v}",
                    range.start(),
                    range.end()
                ),
            )),
        }
    }

    /// A depth format option: one of [`DepthFormat::OPTION_NAMES`].
    pub fn depth_format(
        &mut self,
        key: &str,
        default: DepthFormat,
    ) -> Result<DepthFormat, InputError> {
        let name = self.choice(key, &DepthFormat::OPTION_NAMES, default.option_name())?;
        Ok(DepthFormat::from_option(name).unwrap_or(default))
    }

    /// The edge of a map rendered from the light (`map_size`): 8…`max` texels, by default the
    /// image's larger side (at most `max`).
    pub fn map_size(&mut self, scene: &Scene, max: u32) -> Result<u32, InputError> {
        let default = scene.width.max(scene.height).min(max);
        Ok(self.uint("map_size", default as u64, 8..=max as u64)? as u32)
    }

    /// A shadow map's polygon offset: `bias` (units of the depth format's resolvable
    /// difference, default `units`) and `slope_bias` (the slope factor, default `factor`).
    pub fn polygon_offset(&mut self, units: f64, factor: f64) -> Result<PolygonOffset, InputError> {
        let units = self.float("bias", units, 0.0..=16_777_215.0)?;
        let factor = self.float("slope_bias", factor, 0.0..=1000.0)?;
        Ok(PolygonOffset { factor, units })
    }

    /// Error for the first key nobody asked for.
    pub fn finish(self) -> Result<(), InputError> {
        match self.table.keys().next() {
            None => Ok(()),
            Some(k) => Err(self.err(k, format!("unknown option for method {}", self.method))),
        }
    }
}
