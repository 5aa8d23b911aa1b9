//! A variable-order (1–5), variable-step NDF/BDF integrator for small systems `M ẋ = f(x, t)` with
//! a constant mass matrix, on fixed-size stack arrays (`n ≤ N_MAX` = 12, no heap allocation per step).
//!
//! **Method.** The numerical differentiation formulas (NDF) of Shampine & Reichelt, "The MATLAB ODE
//! Suite", SIAM J. Sci. Comput. 18 (1997) 1–22 (the method of `ode15s`, SciPy's `BDF` and diffsol),
//! in their backward-difference form: the history is the array `D` of modified divided differences
//! of the solution on an equally spaced grid of step `h`; a step-size change by a factor `r`
//! re-interpolates it (`D ← (R U)ᵀ D`, their eq. (2.6)); the predictor is `x⁰ = Σ_{j≤k} D_j`, and the
//! corrector solves `M (d + ψ) = (h/α_k) f(x⁰ + d, t + h)` with `ψ = Σ_{j=1..k} γ_j D_j / α_k`,
//! `γ_j = Σ_{i≤j} 1/i`, `α_k = (1 − κ_k) γ_k` and the NDF constants `κ = (−0.1850, −1/9, −0.0823,
//! −0.0415, 0)` (their Table 1; order 5 is the plain BDF).
//!
//! **Newton iteration** as in CVODE (Hindmarsh et al., "SUNDIALS", ACM TOMS 31 (2005) 363–396): the
//! iteration matrix `M − c J` (`c = h/α_k`, `J = ∂f/∂x` assembled from the segment's Jacobian-vector
//! products on unit vectors) is factorised (LU, partial pivoting) and reused across steps; it is
//! refactorised when `c` has changed by more than 30 % since, every 20 steps, and after a Newton
//! failure; `J` itself is re-evaluated every 50 steps and after a Newton failure with an old `J`.
//! A stale factorisation's correction is scaled by `2/(1 + c/c_LU)`. At most 3 iterations; the
//! iteration has converged when `‖δ‖·min(1, ρ) ≤ min(0.1/C_k, max(10 ε/rtol, min(0.03, √rtol)))`
//! (`ρ` the estimated convergence rate, kept across steps, `C_k` the error constant: CVODE's bound,
//! or SciPy's when tighter), and diverges when `‖δ‖ > 2 ‖δ_prev‖`. A failure with a fresh `J` cuts
//! the step by 4.
//!
//! **Error control.** The local error estimate is `C_k d` (`C_k = κ_k γ_k + 1/(k+1)`) in the weighted
//! RMS norm `‖e‖ = sqrt(mean((e_i/(atol_i + rtol |x_i|))²))`; a step is accepted when `‖C_k d‖ ≤ 1`,
//! otherwise the step shrinks by `max(0.2, 0.9 s ‖C_k d‖^(−1/(k+1)))` (`s` a Newton-effort safety
//! factor, as in SciPy). After `k + 1` steps at one order and step, orders `k − 1`, `k`, `k + 1` are
//! compared by their estimated optimal steps (from `C_{k−1} D_k`, `C_k d`, `C_{k+1} D_{k+2}`), and the
//! step grows by at most 10 (changed only when it grows ≥ 20 %, shrinks, or the order changes, to keep
//! the factorisation). 20 failed attempts in a row at one step, or a step below `16 ε |t|`, are a
//! [`TransientError::Solver`] with the time, the state and the reason.
//!
//! **Dense output** is the method's interpolating polynomial through the last `k + 1` solution
//! points, exact at the step's ends. The step never passes `t_end` (the last step is cut, or
//! stretched by at most 0.1 %, to end on it exactly). **Events**: see [`roots`].

// Dense small-matrix code indexes several arrays by the same row and column, as the formulas do.
#![allow(clippy::needless_range_loop)]

mod lu;
pub mod roots;

#[cfg(test)]
pub(crate) mod crosscheck;
#[cfg(test)]
mod tests;

use crate::engine::options::{named_state, SolverOptions, TransientError, TransientResult};
use crate::engine::segment::SmoothSegment;
use lu::Lu;

/// The most states of a segment (the vehicle's `N_COORDS`).
pub const N_MAX: usize = 12;
/// The highest order.
pub const MAX_ORDER: usize = 5;
/// Integrators of at most this many states are instantiated for their exact size (`n = N`, every
/// converter segment): their loops run to the constant `N`, unrolled and without bounds checks.
/// Larger ones (the vehicle's, `N = N_MAX`) run their loops to their `n`.
pub const EXACT_MAX: usize = 4;

/// The number of states the loops of an integrator of size `N` with `n` states run over: `N` for an
/// exact-size one ([`EXACT_MAX`]), else `n`.
#[inline(always)]
pub(crate) const fn dim<const N: usize>(n: usize) -> usize {
    if N <= EXACT_MAX {
        N
    } else {
        n
    }
}

pub(crate) type Vector<const N: usize> = [f64; N];
pub(crate) type Matrix<const N: usize> = [[f64; N]; N];

const KAPPA: [f64; MAX_ORDER + 2] = [0.0, -0.1850, -1.0 / 9.0, -0.0823, -0.0415, 0.0, 0.0];
const GAMMA: [f64; MAX_ORDER + 2] = gammas();
const ALPHA: [f64; MAX_ORDER + 2] = alphas();
const ERROR_CONST: [f64; MAX_ORDER + 2] = error_constants();
/// `1/j` (index 0 unused).
const RECIPROCALS: [f64; MAX_ORDER + 1] = [0.0, 1.0, 0.5, 1.0 / 3.0, 0.25, 0.2];

const NEWTON_MAX_ITERS: usize = 3;
/// Convergence test of the Newton iteration, relative to the error test's bound on `‖d‖`, at most.
const NEWTON_TOL: f64 = 0.1;
/// Step factors: least after an error-test failure, most growth, least growth worth a change,
/// after a Newton failure with a fresh Jacobian.
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;
const MIN_GROWTH: f64 = 1.2;
const NEWTON_FAIL_FACTOR: f64 = 0.25;
/// Refactorise `M − cJ` when `c` changed by more than this fraction, or after this many steps;
/// re-evaluate `J` after this many steps.
const LU_C_CHANGE: f64 = 0.3;
const LU_MAX_AGE: usize = 20;
const JAC_MAX_AGE: usize = 50;
/// A step this close to `t_end` (relative to the step) is stretched to end on it.
const END_STRETCH: f64 = 1e-3;
/// Failed attempts in a row (Newton or error test) at one step before giving up.
const MAX_FAILED_ATTEMPTS: usize = 20;

const fn gammas() -> [f64; MAX_ORDER + 2] {
    let mut g = [0.0; MAX_ORDER + 2];
    let mut k = 1;
    while k < MAX_ORDER + 2 {
        g[k] = g[k - 1] + 1.0 / k as f64;
        k += 1;
    }
    g
}

const fn alphas() -> [f64; MAX_ORDER + 2] {
    let g = gammas();
    let mut a = [0.0; MAX_ORDER + 2];
    let mut k = 0;
    while k < MAX_ORDER + 2 {
        a[k] = (1.0 - KAPPA[k]) * g[k];
        k += 1;
    }
    a
}

const fn error_constants() -> [f64; MAX_ORDER + 2] {
    let g = gammas();
    let mut c = [0.0; MAX_ORDER + 2];
    let mut k = 0;
    while k < MAX_ORDER + 2 {
        c[k] = KAPPA[k] * g[k] + 1.0 / (k as f64 + 1.0);
        k += 1;
    }
    c
}

/// Work counters of one integrator.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    pub steps: usize,
    pub rhs: usize,
    pub jacobians: usize,
    pub lu: usize,
    pub newton_failures: usize,
    pub error_failures: usize,
}

/// The integrator's state over one segment.
pub struct Bdf<'s, S: SmoothSegment, const N: usize> {
    seg: &'s S,
    n: usize,
    rtol: f64,
    atol: Vector<N>,
    mass: Matrix<N>,
    jac: Matrix<N>,
    jac_age: usize,
    jac_fresh: bool,
    lu: Lu<N>,
    lu_c: f64,
    lu_age: usize,
    rate: f64,
    d: [Vector<N>; MAX_ORDER + 3],
    t: f64,
    h: f64,
    order: usize,
    n_equal: usize,
    /// Order selection due before the next step (after the interpolant of the last one is used).
    select_due: bool,
    last_error: f64,
    last_safety: f64,
    weights: Vector<N>,
    pub stats: Stats,
}

/// `‖v‖`: the RMS of `v_i w_i` over the first `n`.
fn wrms<const N: usize>(n: usize, v: &Vector<N>, w: &Vector<N>) -> f64 {
    let s: f64 = (0..n).map(|i| (v[i] * w[i]) * (v[i] * w[i])).sum();
    (s / n as f64).sqrt()
}

impl<'s, S: SmoothSegment, const N: usize> Bdf<'s, S, N> {
    /// Start at `(x0, t0)` with the step `o.first_step_s` (at most `t_end − t0`), order 1.
    pub fn new(seg: &'s S, x0: &[f64], t0: f64, t_end: f64, o: &SolverOptions) -> TransientResult<Self> {
        let n = seg.n_states();
        // the state named only for an error (naming it was two allocations of every segment)
        let state = || if x0.len() == n { seg.coordinates(x0, t0) } else { named_state(None, x0) };
        let fail = |m: String| TransientError::Solver { time_s: t0, state: state(), message: m };
        if n == 0 || n > N || x0.len() != n {
            return Err(fail(format!("{n} states ({} given): the solver takes 1 to {N}", x0.len())));
        }
        if N <= EXACT_MAX && n != N {
            return Err(fail(format!("{n} states on an integrator of exactly {N}")));
        }
        let atol_v = seg.atol(o);
        let mut atol = [0.0; N];
        atol[..n].copy_from_slice(&atol_v[..n]);
        let mut mass = [[0.0; N]; N];
        let (mut e, mut col) = ([0.0; N], [0.0; N]);
        for j in 0..n {
            e[j] = 1.0;
            col.iter_mut().for_each(|c| *c = 0.0);
            seg.mass_times(&e[..n], 0.0, &mut col[..n]);
            (0..n).for_each(|i| mass[i][j] = col[i]);
            e[j] = 0.0;
        }
        let mut d = [[0.0; N]; MAX_ORDER + 3];
        d[0][..n].copy_from_slice(x0);
        let mut b = Self {
            seg,
            n,
            rtol: o.rtol,
            atol,
            mass,
            jac: [[0.0; N]; N],
            jac_age: usize::MAX,
            jac_fresh: false,
            lu: Lu::empty(n),
            lu_c: f64::NAN,
            lu_age: 0,
            rate: 1.0,
            d,
            t: t0,
            h: o.first_step_s.min(t_end - t0),
            order: 1,
            n_equal: 0,
            select_due: false,
            last_error: 0.0,
            last_safety: 1.0,
            weights: [0.0; N],
            stats: Stats::default(),
        };
        b.init_derivative().map_err(fail)?;
        Ok(b)
    }

    /// The number of states the loops run over ([`dim`]).
    #[inline(always)]
    fn n(&self) -> usize {
        dim::<N>(self.n)
    }

    /// `D_1 = h ẋ(t0)`, from `M ẋ = f`.
    fn init_derivative(&mut self) -> Result<(), String> {
        let n = self.n();
        let mut f = [0.0; N];
        self.seg.rhs(&self.d[0][..n], self.t, &mut f[..n]);
        self.stats.rhs += 1;
        if !f[..n].iter().all(|v| v.is_finite()) {
            return Err(format!("the right-hand side is not finite at the start: {:?}", &f[..n]));
        }
        let mut m = Lu::empty(n);
        if !m.factor(&self.mass) {
            return Err("the mass matrix is singular or not finite".into());
        }
        m.solve(&mut f);
        (0..n).for_each(|i| self.d[1][i] = self.h * f[i]);
        if !self.h.is_finite() || self.h <= 0.0 {
            return Err(format!("the first step {} s is not positive", self.h));
        }
        Ok(())
    }

    /// The time reached.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// The state reached (length `n`).
    pub fn x(&self) -> &[f64] {
        &self.d[0][..self.n()]
    }

    /// The current order.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The state at `t` from the last step's interpolating polynomial (for `t` in that step; exact
    /// at its end), into `out[..n]`.
    pub fn interpolate(&self, t: f64, out: &mut [f64]) {
        let n = self.n();
        let mut x = [[0.0; N]; 1];
        self.interpolate_many(&[t], &mut x);
        out[..n].copy_from_slice(&x[0][..n]);
    }

    /// [`Self::interpolate`] at each of `ts` into the rows of `out` (as many as `ts`), with the
    /// order a constant: the loop over the differences unrolled, without a branch and an integer
    /// conversion per difference.
    pub fn interpolate_many(&self, ts: &[f64], out: &mut [Vector<N>]) {
        match self.order {
            1 => self.interpolate_order::<1>(ts, out),
            2 => self.interpolate_order::<2>(ts, out),
            3 => self.interpolate_order::<3>(ts, out),
            4 => self.interpolate_order::<4>(ts, out),
            _ => self.interpolate_order::<MAX_ORDER>(ts, out),
        }
    }

    /// [`Self::interpolate_many`] at the order `K` (the current one).
    #[inline(always)]
    fn interpolate_order<const K: usize>(&self, ts: &[f64], out: &mut [Vector<N>]) {
        debug_assert!(self.order == K);
        let (n, h) = (self.n(), self.h);
        for (o, &t) in out.iter_mut().zip(ts) {
            o[..n].copy_from_slice(&self.d[0][..n]);
            let (s, mut p) = ((t - self.t) / h, 1.0);
            for j in 1..=K {
                // Π_{m<j} (t − (t_n − m h)) / ((m + 1) h) = Π_{m<j} (s + m)/(m + 1), without a chain of divisions
                p *= (s + (j - 1) as f64) * RECIPROCALS[j];
                for (o, v) in o[..n].iter_mut().zip(&self.d[j][..n]) {
                    *o += p * v;
                }
            }
        }
    }

    fn error(&self, message: String) -> TransientError {
        TransientError::Solver { time_s: self.t, state: self.seg.coordinates(self.x(), self.t), message }
    }

    /// Rescale the differences to a step `factor · h` (order `order`), and the step.
    fn rescale(&mut self, factor: f64) {
        // the order as a constant: the small matrix products unrolled (the same arithmetic)
        match self.order {
            1 => self.rescale_order::<1>(factor),
            2 => self.rescale_order::<2>(factor),
            3 => self.rescale_order::<3>(factor),
            4 => self.rescale_order::<4>(factor),
            _ => self.rescale_order::<MAX_ORDER>(factor),
        }
        self.h *= factor;
        self.n_equal = 0;
    }

    /// [`Self::rescale`]'s differences at the order `K` (the current one).
    fn rescale_order<const K: usize>(&mut self, factor: f64) {
        debug_assert!(self.order == K);
        let n = self.n();
        let ru = rescale_matrix(K, factor);
        let mut out = [[0.0; N]; MAX_ORDER + 1];
        for (j, o) in out.iter_mut().enumerate().take(K + 1) {
            for i in 0..=K {
                let c = ru[i][j];
                for (o, v) in o[..n].iter_mut().zip(&self.d[i][..n]) {
                    *o += c * v;
                }
            }
        }
        for (d, o) in self.d.iter_mut().zip(&out).take(K + 1) {
            d[..n].copy_from_slice(&o[..n]);
        }
    }

    /// One accepted step, ending at `t_end` at the latest.
    pub fn step(&mut self, t_end: f64) -> TransientResult<()> {
        if self.select_due {
            self.select_order_and_step();
        }
        let mut failures = 0;
        loop {
            if failures >= MAX_FAILED_ATTEMPTS {
                return Err(self.error(format!(
                    "{failures} failed attempts in a row (Newton iteration or error test), down to a step of {:e} s",
                    self.h
                )));
            }
            // the last step ends on t_end exactly (stretched by at most 0.1 % rather than leave a sliver)
            let last = t_end - (self.t + self.h) <= END_STRETCH * self.h;
            if last && self.t + self.h != t_end {
                self.rescale((t_end - self.t) / self.h);
            }
            let min_step = 16.0 * f64::EPSILON * self.t.abs().max(t_end.abs());
            if self.h.is_nan() || self.h <= min_step {
                return Err(self.error(format!("the step {:e} s fell below the smallest step {min_step:e} s", self.h)));
            }
            let t_new = if last { t_end } else { self.t + self.h };
            match self.attempt(t_new) {
                Attempt::Accepted => return Ok(()),
                Attempt::NewtonFailed => {
                    self.stats.newton_failures += 1;
                    failures += 1;
                    self.rescale(NEWTON_FAIL_FACTOR);
                }
                Attempt::Fatal(message) => return Err(self.error(message)),
                Attempt::ErrorTestFailed(factor) => {
                    self.stats.error_failures += 1;
                    failures += 1;
                    self.rescale(factor);
                }
            }
        }
    }

    /// Try the step to `t_new` with the current `h` and order.
    fn attempt(&mut self, t_new: f64) -> Attempt {
        let (n, k) = (self.n(), self.order);
        let (mut pred, mut psi) = ([0.0; N], [0.0; N]);
        for j in 0..=k {
            for (p, v) in pred[..n].iter_mut().zip(&self.d[j][..n]) {
                *p += v;
            }
        }
        for j in 1..=k {
            let g = GAMMA[j] / ALPHA[k];
            for (p, v) in psi[..n].iter_mut().zip(&self.d[j][..n]) {
                *p += g * v;
            }
        }
        let c = self.h / ALPHA[k];
        for i in 0..n {
            self.weights[i] = 1.0 / (self.atol[i] + self.rtol * pred[i].abs());
        }
        loop {
            // no factorisation yet (lu_c NaN), c changed by more than 30 %, or an old one
            let change = (c / self.lu_c - 1.0).abs();
            let needs_lu = change.is_nan() || change > LU_C_CHANGE || self.lu_age >= LU_MAX_AGE;
            if needs_lu {
                if let Err(a) = self.refactor(t_new, &pred, c, self.jac_age >= JAC_MAX_AGE) {
                    return a;
                }
            }
            match self.newton(t_new, c, &pred, &psi) {
                Some((x, d, iters)) => return self.error_test(t_new, x, d, iters),
                None if self.jac_fresh => return Attempt::NewtonFailed,
                None => {
                    if let Err(a) = self.refactor(t_new, &pred, c, true) {
                        return a;
                    }
                }
            }
        }
    }

    /// Factorise `M − cJ`, re-evaluating `J` at `(pred, t)` first when `new_jacobian`. A Newton
    /// failure when the matrix is singular (a smaller step may help), fatal when `J` is not finite.
    fn refactor(&mut self, t: f64, pred: &Vector<N>, c: f64, new_jacobian: bool) -> Result<(), Attempt> {
        let n = self.n();
        if new_jacobian {
            let (mut e, mut col) = ([0.0; N], [0.0; N]);
            for j in 0..n {
                e[j] = 1.0;
                self.seg.jacobian_times(&pred[..n], t, &e[..n], &mut col[..n]);
                (0..n).for_each(|i| self.jac[i][j] = col[i]);
                e[j] = 0.0;
            }
            self.stats.jacobians += 1;
            self.jac_age = 0;
            self.jac_fresh = true;
            if let Some((i, j)) =
                (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).find(|&(i, j)| !self.jac[i][j].is_finite())
            {
                self.lu_c = f64::NAN;
                let v = self.jac[i][j];
                return Err(Attempt::Fatal(format!("the Jacobian is not finite at t = {t} s (∂f{i}/∂x{j} = {v})")));
            }
        }
        let (mass, jac) = (&self.mass, &self.jac);
        self.stats.lu += 1;
        self.lu_age = 0;
        self.rate = 1.0;
        if self.lu.factor_from(|i, j| mass[i][j] - c * jac[i][j]) {
            self.lu_c = c;
            Ok(())
        } else {
            self.lu_c = f64::NAN;
            Err(Attempt::NewtonFailed)
        }
    }

    /// The corrector: `(x, d, iterations)`, or None when it does not converge.
    fn newton(&mut self, t: f64, c: f64, pred: &Vector<N>, psi: &Vector<N>) -> Option<(Vector<N>, Vector<N>, usize)> {
        let n = self.n();
        // CVODE's bound, or SciPy's `max(10 ε / rtol, min(0.03, √rtol))` when tighter: a state at rest
        // is then an equilibrium to about √rtol of the tolerance
        let tol = (NEWTON_TOL / ERROR_CONST[self.order])
            .min((10.0 * f64::EPSILON / self.rtol).max(self.rtol.sqrt().min(0.03)));
        let scale = 2.0 / (1.0 + c / self.lu_c);
        let (mut x, mut d) = (*pred, [0.0; N]);
        let mut previous = 0.0;
        for m in 0..NEWTON_MAX_ITERS {
            let mut f = [0.0; N];
            self.seg.rhs(&x[..n], t, &mut f[..n]);
            self.stats.rhs += 1;
            let mut r = [0.0; N];
            for i in 0..n {
                let md: f64 = (0..n).map(|j| self.mass[i][j] * (psi[j] + d[j])).sum();
                r[i] = c * f[i] - md;
            }
            self.lu.solve(&mut r);
            r[..n].iter_mut().for_each(|v| *v *= scale);
            let norm = wrms(n, &r, &self.weights);
            if !norm.is_finite() {
                return None;
            }
            if m > 0 {
                self.rate = (0.3 * self.rate).max(norm / previous);
            }
            for i in 0..n {
                x[i] += r[i];
                d[i] += r[i];
            }
            if norm * self.rate.min(1.0) <= tol {
                return Some((x, d, m + 1));
            }
            if m > 0 && norm > 2.0 * previous {
                return None;
            }
            previous = norm;
        }
        None
    }

    /// Accept the corrected step or give the factor to cut it by.
    fn error_test(&mut self, t_new: f64, x: Vector<N>, d: Vector<N>, iters: usize) -> Attempt {
        let (n, k) = (self.n(), self.order);
        for i in 0..n {
            self.weights[i] = 1.0 / (self.atol[i] + self.rtol * x[i].abs());
        }
        let error = ERROR_CONST[k] * wrms(n, &d, &self.weights);
        let max_iters = NEWTON_MAX_ITERS as f64;
        let safety = 0.9 * (2.0 * max_iters + 1.0) / (2.0 * max_iters + iters as f64);
        if error > 1.0 {
            return Attempt::ErrorTestFailed((safety * error.powf(-1.0 / (k as f64 + 1.0))).max(MIN_FACTOR));
        }
        // the new differences: D_{k+2} = d − D_{k+1}, D_{k+1} = d, D_i += D_{i+1} downwards
        for i in 0..n {
            self.d[k + 2][i] = d[i] - self.d[k + 1][i];
            self.d[k + 1][i] = d[i];
        }
        for j in (0..=k).rev() {
            let (lo, hi) = self.d.split_at_mut(j + 1);
            for (a, b) in lo[j][..n].iter_mut().zip(&hi[0][..n]) {
                *a += b;
            }
        }
        self.d[0][..n].copy_from_slice(&x[..n]);
        self.t = t_new;
        self.stats.steps += 1;
        self.n_equal += 1;
        self.lu_age += 1;
        self.jac_age = self.jac_age.saturating_add(1);
        self.jac_fresh = false;
        self.last_error = error;
        self.last_safety = safety;
        self.select_due = true;
        Attempt::Accepted
    }

    /// After `k + 1` steps at one order and step: the order among `k − 1, k, k + 1` that allows the
    /// longest next step, and that step.
    fn select_order_and_step(&mut self) {
        self.select_due = false;
        let (n, k) = (self.n(), self.order);
        if self.n_equal < k + 1 {
            return;
        }
        let norm_of = |j: usize, c: f64| c * wrms(n, &self.d[j], &self.weights);
        let down = if k > 1 { norm_of(k, ERROR_CONST[k - 1]) } else { f64::INFINITY };
        let up = if k < MAX_ORDER { norm_of(k + 2, ERROR_CONST[k + 1]) } else { f64::INFINITY };
        let factors = [
            step_factor(down, k as f64),
            step_factor(self.last_error, k as f64 + 1.0),
            step_factor(up, k as f64 + 2.0),
        ];
        let mut best = 1;
        for (i, f) in factors.iter().enumerate() {
            if *f > factors[best] {
                best = i;
            }
        }
        let factor = (self.last_safety * factors[best]).min(MAX_FACTOR);
        if best != 1 || !(1.0..MIN_GROWTH).contains(&factor) {
            self.order = k + best - 1;
            self.rescale(factor);
        }
    }
}

/// The step factor `norm^(−1/p)` an error estimate `norm` of order `p − 1` allows: exactly 0 for an
/// order that does not exist (`norm` infinite), without the call of `powf` that gives it.
#[inline(always)]
fn step_factor(norm: f64, p: f64) -> f64 {
    if norm == f64::INFINITY {
        0.0
    } else {
        norm.powf(-1.0 / p)
    }
}

enum Attempt {
    Accepted,
    NewtonFailed,
    /// The factor to cut the step by.
    ErrorTestFailed(f64),
    /// No smaller step can help.
    Fatal(String),
}

/// `R(k, r) U(k)` of Shampine & Reichelt (1997) eq. (2.6): the differences for a step `r h` are
/// `D ← (R U)ᵀ D` (`U = R(k, 1)`; `R(k, r)_{ij} = Π_{m=1..i} (m − 1 − r j)/m`).
#[inline(always)]
fn rescale_matrix(k: usize, factor: f64) -> [[f64; MAX_ORDER + 1]; MAX_ORDER + 1] {
    let r = r_matrix(k, factor);
    let mut ru = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
    for i in 0..=k {
        for j in 0..=k {
            // U is upper triangular (its factor m = j + 1 vanishes below the diagonal)
            ru[i][j] = (0..=j).map(|m| r[i][m] * U[m][j]).sum();
        }
    }
    ru
}

/// `R(k, f)` (zero beyond row and column `k`).
#[inline(always)]
const fn r_matrix(k: usize, f: f64) -> [[f64; MAX_ORDER + 1]; MAX_ORDER + 1] {
    let mut r = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
    let mut j = 0;
    while j <= k {
        r[0][j] = 1.0;
        j += 1;
    }
    let mut i = 1;
    while i <= k {
        let mut j = 0;
        while j <= k {
            r[i][j] = r[i - 1][j] * ((i - 1) as f64 - f * j as f64) / i as f64;
            j += 1;
        }
        i += 1;
    }
    r
}

/// `U = R(k, 1)`: its entries up to row and column `k` do not depend on `k`, so one table serves
/// every order.
const U: [[f64; MAX_ORDER + 1]; MAX_ORDER + 1] = r_matrix(MAX_ORDER, 1.0);
