//! Event location on the dense output, as CVODE's rootfinding (Hindmarsh et al. 2005, §2.4 of the
//! CVODE guide): after every step the event functions `g` are evaluated at its end; an event function
//! that was positive at the step's start and is ≤ 0 at its end has a root in the step ("positive while
//! the mode holds": only that direction ends a mode). The first root is bracketed by the Illinois
//! variant of regula falsi on the interpolant, each trial point taken for the function that is crossed
//! furthest (largest `|g_hi| / |g_hi − g_lo|`), until the bracket is narrower than
//! `100 ε (|t_hi| + |t_hi − t_lo|)`. The upper end of the bracket is returned (its `g ≤ 0`), so the
//! event has always happened at the time given.

/// The most event functions a segment has (a vehicle's segment has at most 9: the converter's 3,
/// the brake's, 2 of the shift's, 2 of the lock-up's and the stop speed's).
pub const MAX_ROOTS: usize = 16;

/// Work arrays for the event functions of one segment (on the stack: they were four of the few
/// heap allocations left in a run's segments).
pub struct RootFinder {
    n: usize,
    lo: [f64; MAX_ROOTS],
    hi: [f64; MAX_ROOTS],
    mid: [f64; MAX_ROOTS],
}

/// The event function crossed furthest from `lo` (> 0) to `hi` (≤ 0), if any.
fn crossing(lo: &[f64], hi: &[f64]) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (i, (&a, &b)) in lo.iter().zip(hi).enumerate() {
        if a > 0.0 && b <= 0.0 {
            let frac = (b / (b - a)).abs();
            if best.is_none_or(|(_, f)| frac > f) {
                best = Some((i, frac));
            }
        }
    }
    best.map(|(i, _)| i)
}

impl RootFinder {
    /// Start from the `n` event functions (at most [`MAX_ROOTS`]) at the segment's start, which
    /// `g0` writes into the slice it is given (not called when there are none).
    pub fn new(n: usize, g0: impl FnOnce(&mut [f64])) -> Self {
        assert!(n <= MAX_ROOTS, "{n} event functions: a segment has at most {MAX_ROOTS}");
        let mut lo = [0.0; MAX_ROOTS];
        if n > 0 {
            g0(&mut lo[..n]);
        }
        Self { n, lo, hi: [0.0; MAX_ROOTS], mid: [0.0; MAX_ROOTS] }
    }

    /// After a step from `t_lo` to `t_hi`: `g_at(t, out)` gives the event functions on the step's
    /// interpolant. Returns the first root `(t, index)` in `(t_lo, t_hi]`, or None (and then the end
    /// of this step becomes the start of the next).
    pub fn check(&mut self, t_lo: f64, t_hi: f64, mut g_at: impl FnMut(f64, &mut [f64])) -> Option<(f64, usize)> {
        let n = self.n;
        g_at(t_hi, &mut self.hi[..n]);
        let Some(mut imax) = crossing(&self.lo[..n], &self.hi[..n]) else {
            self.lo[..n].swap_with_slice(&mut self.hi[..n]);
            return None;
        };
        let (mut t0, mut t1) = (t_lo, t_hi);
        let tol = 100.0 * f64::EPSILON * (t1.abs() + (t1 - t0).abs());
        let (mut alpha, mut last_two) = (1.0, [false, true]);
        let mut i = 0usize;
        // a copy of the lower end: the bracket moves, the next step starts from g(t_hi)
        let mut lo = self.lo;
        while (t1 - t0).abs() > tol {
            let (g1, g0) = (self.hi[imax], lo[imax]);
            let mut t = t1 - (t1 - t0) * g1 / (g1 - alpha * g0);
            let fraction = if (t1 - t0).abs() / tol > 5.0 { 0.1 } else { 0.5 * tol / (t1 - t0).abs() };
            if (t - t0).abs() < 0.5 * tol {
                t = t0 + fraction * (t1 - t0);
            }
            if (t1 - t).abs() < 0.5 * tol {
                t = t1 - fraction * (t1 - t0);
            }
            g_at(t, &mut self.mid[..n]);
            let lower = crossing(&lo[..n], &self.mid[..n]);
            if let Some(j) = lower {
                t1 = t;
                imax = j;
                self.hi[..n].swap_with_slice(&mut self.mid[..n]);
            } else {
                t0 = t;
                lo[..n].copy_from_slice(&self.mid[..n]);
            }
            last_two[i % 2] = lower.is_some();
            if i >= 2 {
                alpha = if last_two[0] != last_two[1] {
                    1.0
                } else if last_two[0] {
                    0.5 * alpha
                } else {
                    2.0 * alpha
                };
            }
            i += 1;
        }
        Some((t1, imax))
    }
}
