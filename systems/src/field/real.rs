//! The number type of the field kernels: `f64`, or [`Dual3`] for exact gradients.
//!
//! Every field formula is written once, generic over [`Real`]. Evaluated on `f64` it gives the
//! field; evaluated on [`Dual3`] (forward-mode automatic differentiation: a value and its three
//! partial derivatives) it gives the field and its exact gradient through the same code, so
//! the gradient is as accurate as the field (no finite differences).

use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::DVec3;

/// Arithmetic needed by the field kernels. Comparisons and branches use [`Real::val`].
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// A constant.
    fn cst(v: f64) -> Self;
    /// The value (derivatives dropped).
    fn val(self) -> f64;
    /// Square root (derivative undefined at 0; callers avoid it there).
    fn sqrt(self) -> Self;
    /// `|self|` (derivative sign of the value).
    fn abs(self) -> Self {
        if self.val() < 0.0 { -self } else { self }
    }
    /// `1 / self`.
    fn recip(self) -> Self {
        Self::cst(1.0) / self
    }
    /// Whether an iteration that produced `self` and `other` has converged to relative `tol`
    /// in the value and (for dual numbers) in every derivative.
    fn converged(self, other: Self, tol: f64) -> bool;
}

impl Real for f64 {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn val(self) -> f64 {
        self
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn recip(self) -> Self {
        1.0 / self
    }
    #[inline(always)]
    fn converged(self, other: Self, tol: f64) -> bool {
        (self - other).abs() <= self.abs() * tol
    }
}

/// A value and its gradient with respect to three variables (forward-mode differentiation).
///
/// ```
/// use magsep_systems::field::{Dual3, Real};
/// let x = Dual3::var(2.0, 0);
/// let f = x * x * 3.0 + 1.0; // 3 x^2 + 1
/// assert_eq!((f.v, f.d.x), (13.0, 12.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual3 {
    /// Value.
    pub v: f64,
    /// Partial derivatives.
    pub d: DVec3,
}

impl Dual3 {
    /// The variable number `axis` (0, 1, 2) with value `v`.
    pub fn var(v: f64, axis: usize) -> Self {
        let mut d = DVec3::ZERO;
        d[axis] = 1.0;
        Self { v, d }
    }

    /// The three coordinates of `p` as independent variables.
    pub fn seed(p: DVec3) -> [Self; 3] {
        [Self::var(p.x, 0), Self::var(p.y, 1), Self::var(p.z, 2)]
    }
}

impl Add for Dual3 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            d: self.d + o.d,
        }
    }
}
impl Sub for Dual3 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            d: self.d - o.d,
        }
    }
}
impl Mul for Dual3 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            d: self.d * o.v + o.d * self.v,
        }
    }
}
impl Div for Dual3 {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let inv = 1.0 / o.v;
        let v = self.v * inv;
        Self {
            v,
            d: (self.d - o.d * v) * inv,
        }
    }
}
impl Neg for Dual3 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self {
            v: -self.v,
            d: -self.d,
        }
    }
}
impl Add<f64> for Dual3 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: f64) -> Self {
        Self {
            v: self.v + o,
            d: self.d,
        }
    }
}
impl Sub<f64> for Dual3 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: f64) -> Self {
        Self {
            v: self.v - o,
            d: self.d,
        }
    }
}
impl Mul<f64> for Dual3 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: f64) -> Self {
        Self {
            v: self.v * o,
            d: self.d * o,
        }
    }
}
impl Div<f64> for Dual3 {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: f64) -> Self {
        let inv = 1.0 / o;
        Self {
            v: self.v * inv,
            d: self.d * inv,
        }
    }
}

impl Real for Dual3 {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        Self { v, d: DVec3::ZERO }
    }
    #[inline(always)]
    fn val(self) -> f64 {
        self.v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        Self {
            v: s,
            d: self.d * (0.5 / s),
        }
    }
    #[inline(always)]
    fn converged(self, other: Self, tol: f64) -> bool {
        let scale = self.v.abs().max(self.d.abs().max_element());
        (self.v - other.v).abs() <= self.v.abs() * tol
            && (self.d - other.d).abs().max_element() <= scale * tol
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dual_rules_match_hand_derivatives() {
        let [x, y, z] = Dual3::seed(DVec3::new(1.5, -0.5, 2.0));
        // f = sqrt(x^2 + y^2) / z
        let f = (x * x + y * y).sqrt() / z;
        let r = (1.5f64 * 1.5 + 0.25).sqrt();
        assert!((f.v - r / 2.0).abs() < 1e-15);
        let want = DVec3::new(1.5 / r / 2.0, -0.5 / r / 2.0, -r / 4.0);
        assert!((f.d - want).abs().max_element() < 1e-15);
        assert_eq!((-x).abs().d, x.d);
    }
}
