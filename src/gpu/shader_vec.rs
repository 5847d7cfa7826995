//! The fragment programs' vectors: 2-, 3- and 4-component vectors of a [`ShaderFloat`], every
//! component operation rounded as the scalar's.
//!
//! Each operation evaluates in the order glam's f64 vectors do (`dot` as `(x·x′ + y·y′) + z·z′`,
//! `cross` as `y·z′ − y′·z, …`, `length` as `sqrt(dot)`), so a fragment program written with
//! these vectors at [`f64`] computes the bits the same code computed with `DVec2`/`DVec3`/
//! `DVec4`.

use super::shader_float::ShaderFloat;
use super::shader_ops::vector;
use glam::{DVec2, DVec3};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A 2-vector of shader scalars.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SVec2<T> {
    /// x.
    pub x: T,
    /// y.
    pub y: T,
}

/// A 3-vector of shader scalars.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SVec3<T> {
    /// x.
    pub x: T,
    /// y.
    pub y: T,
    /// z.
    pub z: T,
}

/// A 4-vector of shader scalars.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SVec4<T> {
    /// x.
    pub x: T,
    /// y.
    pub y: T,
    /// z.
    pub z: T,
    /// w.
    pub w: T,
}

impl<T: ShaderFloat> SVec2<T> {
    /// `(x, y)`.
    pub fn new(x: T, y: T) -> Self {
        SVec2 { x, y }
    }

    /// Each component rounded to `T`.
    pub fn from_f64(v: DVec2) -> Self {
        SVec2::new(T::from_f64(v.x), T::from_f64(v.y))
    }

    /// As f64 (exact).
    pub fn to_f64(self) -> DVec2 {
        DVec2::new(self.x.to_f64(), self.y.to_f64())
    }

    /// `x·o.x + y·o.y`, each operation rounded.
    pub fn dot(self, o: Self) -> T {
        let d = self.x * o.x + self.y * o.y;
        vector::<T>(3, 1); // DP3 with z = 0
        d
    }

    /// `x·y′ − y·x′`.
    pub fn perp_dot(self, o: Self) -> T {
        let d = self.x * o.y - self.y * o.x;
        vector::<T>(3, 2); // MUL, MAD
        d
    }

    /// Both components finite.
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

impl<T: ShaderFloat> SVec3<T> {
    /// `(x, y, z)`.
    pub fn new(x: T, y: T, z: T) -> Self {
        SVec3 { x, y, z }
    }

    /// Each component rounded to `T`.
    pub fn from_f64(v: DVec3) -> Self {
        SVec3::new(T::from_f64(v.x), T::from_f64(v.y), T::from_f64(v.z))
    }

    /// As f64 (exact).
    pub fn to_f64(self) -> DVec3 {
        DVec3::new(self.x.to_f64(), self.y.to_f64(), self.z.to_f64())
    }

    /// `(x·x′ + y·y′) + z·z′`.
    pub fn dot(self, o: Self) -> T {
        let d = self.x * o.x + self.y * o.y + self.z * o.z;
        vector::<T>(5, 1); // DP3
        d
    }

    /// The cross product, glam's order.
    pub fn cross(self, o: Self) -> Self {
        let c = SVec3::new(
            self.y * o.z - o.y * self.z,
            self.z * o.x - o.z * self.x,
            self.x * o.y - o.x * self.y,
        );
        vector::<T>(9, 2); // MUL, MAD with swizzles (XPD)
        c
    }

    /// `sqrt(dot(self, self))`.
    pub fn length(self) -> T {
        self.dot(self).sqrt()
    }

    /// `(x, y, z, w)`.
    pub fn extend(self, w: T) -> SVec4<T> {
        SVec4 {
            x: self.x,
            y: self.y,
            z: self.z,
            w,
        }
    }

    /// `(x, y)`.
    pub fn truncate(self) -> SVec2<T> {
        SVec2::new(self.x, self.y)
    }

    /// Every component finite.
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }

    /// A unit vector orthogonal to the unit vector `self` (glam's `any_orthonormal_vector`,
    /// Duff et al. 2017).
    pub fn any_orthonormal_vector(self) -> Self {
        let sign = self.z.signum();
        let a = -T::one() / (sign + self.z);
        let b = self.x * self.y * a;
        SVec3::new(b, sign + self.y * self.y * a, -self.y)
    }
}

impl<T: ShaderFloat> SVec4<T> {
    /// `(x, y, z, w)`.
    pub fn new(x: T, y: T, z: T, w: T) -> Self {
        SVec4 { x, y, z, w }
    }

    /// `((x·x′ + y·y′) + z·z′) + w·w′`.
    pub fn dot(self, o: Self) -> T {
        let d = self.x * o.x + self.y * o.y + self.z * o.z + self.w * o.w;
        vector::<T>(7, 1); // DP4
        d
    }
}

/// Component-wise `+ −`, scaling by a scalar `* /`, negation.
/// Each is one vector instruction ([`vector`]): `ADD`, `ADD`, `MUL`, and `RCP` + `MUL` for
/// the division (the scalar operations counted `n`, `n`, `n` and `2n` slots).
macro_rules! vector_ops {
    ($v:ident { $($c:ident),+ }, $n:expr) => {
        impl<T: ShaderFloat> Add for $v<T> {
            type Output = Self;
            fn add(self, o: Self) -> Self {
                let r = $v { $($c: self.$c + o.$c),+ };
                vector::<T>($n, 1);
                r
            }
        }
        impl<T: ShaderFloat> Sub for $v<T> {
            type Output = Self;
            fn sub(self, o: Self) -> Self {
                let r = $v { $($c: self.$c - o.$c),+ };
                vector::<T>($n, 1);
                r
            }
        }
        impl<T: ShaderFloat> Mul<T> for $v<T> {
            type Output = Self;
            fn mul(self, s: T) -> Self {
                let r = $v { $($c: self.$c * s),+ };
                vector::<T>($n, 1);
                r
            }
        }
        impl<T: ShaderFloat> Div<T> for $v<T> {
            type Output = Self;
            fn div(self, s: T) -> Self {
                let r = $v { $($c: self.$c / s),+ };
                vector::<T>(2 * $n, 2);
                r
            }
        }
        impl<T: ShaderFloat> Neg for $v<T> {
            type Output = Self;
            fn neg(self) -> Self {
                $v { $($c: -self.$c),+ }
            }
        }
    };
}

vector_ops!(SVec2 { x, y }, 2);
vector_ops!(SVec3 { x, y, z }, 3);
vector_ops!(SVec4 { x, y, z, w }, 4);

#[cfg(test)]
mod tests {
    use super::*;

    /// At f64 every operation gives glam's bits (the default output depends on it).
    #[test]
    fn f64_vectors_compute_glams_bits() {
        let a = DVec3::new(0.1, -2.7, 3.3e-5);
        let b = DVec3::new(1.0 / 3.0, 7.1, -0.2);
        let (sa, sb) = (SVec3::<f64>::from_f64(a), SVec3::<f64>::from_f64(b));
        assert_eq!(sa.dot(sb).to_bits(), a.dot(b).to_bits());
        assert_eq!(sa.cross(sb).to_f64(), a.cross(b));
        assert_eq!(sa.length().to_bits(), a.length().to_bits());
        let n = a.normalize();
        assert_eq!(
            SVec3::<f64>::from_f64(n).any_orthonormal_vector().to_f64(),
            n.any_orthonormal_vector()
        );
        let (p, q) = (a.truncate(), b.truncate());
        assert_eq!(
            sa.truncate().perp_dot(sb.truncate()).to_bits(),
            p.perp_dot(q).to_bits()
        );
        let (a4, b4) = (a.extend(0.5), b.extend(-1.5));
        assert_eq!(
            sa.extend(0.5).dot(sb.extend(-1.5)).to_bits(),
            a4.dot(b4).to_bits()
        );
    }
}
