//! A scalar that is either a plain `f64` or a forward-mode dual number.
//!
//! The steady-state solvers are written once, generic over [`Scalar`]. Evaluated with
//! [`Dual`] they return exact first derivatives with respect to whichever input was seeded
//! (a parameter, a speed), which the coupling-point Newton iteration and the fitting
//! Jacobian use. The tests compare every such derivative with finite differences.

use std::ops::{Add, Div, Mul, Neg, Sub};

pub trait Scalar:
    Copy
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A constant (zero derivative).
    fn cst(v: f64) -> Self;
    /// The real part.
    fn re(self) -> f64;
    fn sqrt(self) -> Self;
    fn tan(self) -> Self;
    fn scale(self, k: f64) -> Self {
        self * Self::cst(k)
    }
}

impl Scalar for f64 {
    fn cst(v: f64) -> Self {
        v
    }
    fn re(self) -> f64 {
        self
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn tan(self) -> Self {
        f64::tan(self)
    }
}

/// `v + d·ε` with ε² = 0: value and derivative along one seeded direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual {
    pub v: f64,
    pub d: f64,
}

impl Dual {
    /// The independent variable: derivative 1.
    pub fn var(v: f64) -> Self {
        Self { v, d: 1.0 }
    }
}

impl Add for Dual {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self { v: self.v + o.v, d: self.d + o.d }
    }
}
impl Sub for Dual {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self { v: self.v - o.v, d: self.d - o.d }
    }
}
impl Mul for Dual {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Self { v: self.v * o.v, d: self.d * o.v + self.v * o.d }
    }
}
impl Div for Dual {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        let v = self.v / o.v;
        Self { v, d: (self.d - v * o.d) / o.v }
    }
}
impl Neg for Dual {
    type Output = Self;
    fn neg(self) -> Self {
        Self { v: -self.v, d: -self.d }
    }
}

impl Scalar for Dual {
    fn cst(v: f64) -> Self {
        Self { v, d: 0.0 }
    }
    fn re(self) -> f64 {
        self.v
    }
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        Self { v: s, d: self.d / (2.0 * s) }
    }
    fn tan(self) -> Self {
        let t = self.v.tan();
        Self { v: t, d: self.d * (1.0 + t * t) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dual_derivatives_match_finite_differences() {
        let f = |x: Dual| (x * x + Dual::cst(3.0)).sqrt() / x.tan() - x;
        let g = |x: f64| (x * x + 3.0).sqrt() / x.tan() - x;
        for x in [0.3, 0.7, 1.1] {
            let h = 1e-6;
            let fd = (g(x + h) - g(x - h)) / (2.0 * h);
            let ad = f(Dual::var(x));
            assert!((ad.v - g(x)).abs() < 1e-15);
            assert!((ad.d - fd).abs() < 1e-7 * fd.abs().max(1.0), "{x}: {} vs {fd}", ad.d);
        }
    }
}
