//! What the precision experiment (`penumbra experiment precision`,
//! [`crate::experiment::precision`]) measures of a method, declared in the method's module
//! ([`super::Method::precision`]) so that the experiment asks the registry instead of naming
//! methods: whether its fragment programs do arithmetic the shader precision rounds (part 1),
//! its narrow buffer formats and the wider ones they are measured against (part 2), and the
//! buffer formats whose overflow the overlap stack measures (part 3).

use super::OptionPairs;
use crate::scene::LightShape;
use glam::Vec3;

/// A method's entries in the precision experiment ([`super::Method::precision`]).
#[derive(Debug, Clone, Copy)]
pub struct PrecisionSpec {
    /// Whether its fragment programs do arithmetic the shader precision rounds (the soft
    /// methods); `false` for the reference and the stencil-only hard-shadow methods, which part
    /// 1 skips.
    pub shader_arithmetic: bool,
    /// Part 2: its narrow buffer formats, each against a wider one.
    pub storage: &'static [NarrowFormat],
    /// Part 3: its buffer formats whose overflow the overlap stack measures.
    pub overflow: &'static [OverflowKnobs],
}

impl PrecisionSpec {
    /// A method with no shader arithmetic and no buffer format of its own to measure.
    pub const NO_SHADER_ARITHMETIC: PrecisionSpec = PrecisionSpec {
        shader_arithmetic: false,
        storage: &[],
        overflow: &[],
    };
}

/// An option value giving a narrow buffer format and the value it is measured against (part
/// 2), e.g. `vbuffer = f16` against `vbuffer = f32`.
#[derive(Debug, Clone, Copy)]
pub struct NarrowFormat {
    /// The method's option key.
    pub key: &'static str,
    /// The measured value.
    pub narrow: &'static str,
    /// The value it is measured against.
    pub wide: &'static str,
}

impl NarrowFormat {
    /// `key = narrow` measured against `key = wide`.
    pub const fn of(key: &'static str, narrow: &'static str, wide: &'static str) -> Self {
        NarrowFormat { key, narrow, wide }
    }
}

/// Options whose buffer format the overlap stack drives to overflow (part 3), under the
/// stack's `light`.
#[derive(Debug, Clone, Copy)]
pub struct OverflowKnobs {
    /// The stack's light.
    pub light: StackLight,
    /// The method's options.
    pub knobs: OptionPairs,
}

impl OverflowKnobs {
    /// `knobs` on the stack under `light`.
    pub const fn of(light: StackLight, knobs: OptionPairs) -> Self {
        OverflowKnobs { light, knobs }
    }
}

/// The light of an overflow configuration's stack.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum StackLight {
    /// A point light (hard shadows: the stencil alone).
    Point,
    /// A sphere of radius 0.2 (Paper I's wedges and LI buffer).
    Sphere,
    /// A square of half extent 0.2 (the soft shadow volumes' V-buffers, wedge blending).
    Rect,
}

impl StackLight {
    /// The light's shape.
    pub fn shape(self) -> LightShape {
        match self {
            StackLight::Point => LightShape::Point,
            StackLight::Sphere => LightShape::Sphere { radius: 0.2 },
            StackLight::Rect => LightShape::Rect {
                u: Vec3::new(0.2, 0.0, 0.0),
                v: Vec3::new(0.0, 0.0, 0.2),
            },
        }
    }
}
