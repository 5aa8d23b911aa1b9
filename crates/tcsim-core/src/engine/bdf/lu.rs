//! Dense LU factorisation with partial pivoting on fixed-size stack arrays (`n ≤ N_MAX`).

use super::{dim, Matrix, Vector};

/// An LU factorisation `P A = L U` of the leading `n × n` block of a [`Matrix`], in place
/// (`L` below the diagonal with a unit diagonal, `U` on and above it).
#[derive(Clone, Copy)]
pub(super) struct Lu<const N: usize> {
    a: Matrix<N>,
    piv: [usize; N],
    n: usize,
}

impl<const N: usize> Lu<N> {
    pub(super) fn empty(n: usize) -> Self {
        Self { a: [[0.0; N]; N], piv: [0; N], n }
    }

    /// The size the loops run over ([`dim`]).
    #[inline(always)]
    fn n(&self) -> usize {
        dim::<N>(self.n)
    }

    /// Factorise `a` (its leading `n × n` block). False when a pivot is zero or not finite (a
    /// singular or NaN matrix); the factorisation is then unusable.
    pub(super) fn factor(&mut self, a: &Matrix<N>) -> bool {
        self.factor_from(|i, j| a[i][j])
    }

    /// Factorise the matrix with entries `a(i, j)` (its leading `n × n` block), as [`Lu::factor`].
    pub(super) fn factor_from(&mut self, a: impl Fn(usize, usize) -> f64) -> bool {
        let n = self.n();
        for (i, row) in self.a.iter_mut().enumerate().take(n) {
            for (j, v) in row.iter_mut().enumerate().take(n) {
                *v = a(i, j);
            }
        }
        let m = &mut self.a;
        for k in 0..n {
            let mut p = k;
            let mut max = m[k][k].abs();
            for (i, row) in m.iter().enumerate().take(n).skip(k + 1) {
                if row[k].abs() > max {
                    max = row[k].abs();
                    p = i;
                }
            }
            // `!(max > 0.0)` is also true for NaN
            if !(max > 0.0 && max.is_finite()) {
                return false;
            }
            self.piv[k] = p;
            m.swap(p, k);
            let pivot_row = m[k];
            let inv = 1.0 / pivot_row[k];
            for row in m.iter_mut().take(n).skip(k + 1) {
                let l = row[k] * inv;
                row[k] = l;
                if l != 0.0 {
                    for j in k + 1..n {
                        row[j] -= l * pivot_row[j];
                    }
                }
            }
        }
        // a NaN can hide below a finite pivot; it would only show in the solutions
        m.iter().take(n).all(|row| row[..n].iter().all(|v| v.is_finite()))
    }

    /// Solve `A x = b` in place (`b` becomes `x`).
    pub(super) fn solve(&self, b: &mut Vector<N>) {
        let (n, m) = (self.n(), &self.a);
        for k in 0..n {
            b.swap(k, self.piv[k]);
        }
        for i in 1..n {
            let s: f64 = (0..i).map(|j| m[i][j] * b[j]).sum();
            b[i] -= s;
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|j| m[i][j] * b[j]).sum();
            b[i] = (b[i] - s) / m[i][i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::bdf::N_MAX;

    #[test]
    fn solves_a_system_that_needs_pivoting_and_refuses_singular_and_nan_matrices() {
        let mut a = [[0.0; N_MAX]; N_MAX];
        // leading zero: without pivoting the first step divides by zero
        a[0][..3].copy_from_slice(&[0.0, 2.0, 1.0]);
        a[1][..3].copy_from_slice(&[1.0, 1.0, 0.0]);
        a[2][..3].copy_from_slice(&[3.0, 0.0, 1.0]);
        let x = [1.0, -2.0, 0.5];
        let mut b = [0.0; N_MAX];
        for i in 0..3 {
            b[i] = (0..3).map(|j| a[i][j] * x[j]).sum();
        }
        let mut lu = Lu::<N_MAX>::empty(3);
        assert!(lu.factor(&a));
        lu.solve(&mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14, "{i}: {} vs {}", b[i], x[i]);
        }
        let mut singular = a;
        singular[2] = singular[0];
        assert!(!lu.factor(&singular));
        let mut nan = a;
        nan[1][1] = f64::NAN;
        assert!(!lu.factor(&nan));
    }
}
