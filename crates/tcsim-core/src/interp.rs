//! Linear interpolation with the end values held: the one helper behind the characteristic
//! tables ([`crate::converter::table`]), the input signals ([`crate::engine::signal`]) and the
//! vehicle's curves and pedal schedules ([`crate::vehicle`]).

/// Tables of at most this many abscissae are scanned rather than bisected ([`segment`]).
const SCAN_MAX: usize = 8;

/// The segment `[x[i−1], x[i]]` of the sorted abscissae `x` (two or more) that holds `t`, clamped
/// to the first or last segment, and the weight `w = (t − x[i−1])/(x[i] − x[i−1])` of `x[i]`.
#[inline]
pub fn segment(x: &[f64], t: f64) -> (usize, f64) {
    let n = x.len();
    // first index with x[i] > t, clamped so that [i-1, i] is a segment (a short table is scanned:
    // the branch follows t, which inputs sweep in order, where a bisection's branches are random)
    let first_above =
        if n <= SCAN_MAX { x.iter().take_while(|&&v| v <= t).count() } else { x.partition_point(|&v| v <= t) };
    let i = first_above.clamp(1, n - 1);
    (i, (t - x[i - 1]) / (x[i] - x[i - 1]))
}

/// `(1 − w)·y[i−1] + w·y[i]`: returns the table values exactly at the nodes.
pub fn mix(y: &[f64], i: usize, w: f64) -> f64 {
    (1.0 - w) * y[i - 1] + w * y[i]
}

/// `y(t)` linear between the points `(x, y)` (x strictly increasing), end values held outside;
/// a single point is a constant. Inlined: the engines call it for every input at every
/// evaluation, most often on a constant or a short table.
#[inline(always)]
pub fn linear_held(x: &[f64], y: &[f64], t: f64) -> f64 {
    let n = x.len();
    if n == 1 || t <= x[0] {
        return y[0];
    }
    if t >= x[n - 1] {
        return y[n - 1];
    }
    let (i, w) = segment(x, t);
    mix(y, i, w)
}

/// Two-point form: `at_zero` at p = 0, `at_one` at p = 1, linear between, ends held (pedal
/// schedules).
pub fn blend_held(at_zero: f64, at_one: f64, p: f64) -> f64 {
    at_zero + p.clamp(0.0, 1.0) * (at_one - at_zero)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_holds_ends() {
        let (x, y) = ([0.0, 1.0, 3.0], [0.0, 2.0, 6.0]);
        assert_eq!([-1.0, 0.5, 2.0, 9.0].map(|t| linear_held(&x, &y, t)), [0.0, 1.0, 4.0, 6.0]);
        assert_eq!(linear_held(&[1.0], &[5.0], 9.0), 5.0);
        assert_eq!([-1.0, 0.25, 2.0].map(|p| blend_held(2.0, 6.0, p)), [2.0, 3.0, 6.0]);
        assert!(linear_held(&x, &y, f64::NAN).is_nan());
    }

    #[test]
    fn a_scanned_segment_is_the_bisected_one() {
        // short tables are scanned (`SCAN_MAX`), long ones bisected: the same segment and weight
        for n in 2..=2 * SCAN_MAX {
            let x: Vec<f64> = (0..n).map(|i| (i as f64).powf(1.3) - 2.0).collect();
            let ts =
                (0..=40 * n).map(|k| -3.0 + k as f64 * 0.05).chain(x.iter().copied()).chain([f64::NAN, 1e300, -1e300]);
            for t in ts {
                let i = x.partition_point(|&v| v <= t).clamp(1, n - 1);
                let w = (t - x[i - 1]) / (x[i] - x[i - 1]);
                let (j, v) = segment(&x, t);
                assert!(j == i && (v == w || (v.is_nan() && w.is_nan())), "n {n}, t {t}: {j} {v} vs {i} {w}");
            }
        }
    }
}
