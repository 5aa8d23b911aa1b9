//! The diffsol BDF loop shared by the transient engines: one smooth segment of a piecewise-smooth
//! system, from a state to the first root of its event functions (or the end time).

use diffsol::{NalgebraLU, NalgebraMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason};

use crate::engine::options::{Hysteresis, SolverOptions, TransientError, TransientResult};

type Matrix = NalgebraMat<f64>;
type Lu = NalgebraLU<f64>;

/// A smooth system `M ẋ = f(x, t)` with event functions, as one mode of a piecewise-smooth model.
pub trait SmoothSegment {
    type Root: Copy;
    type Sample;
    fn n_states(&self) -> usize;
    fn atol(&self, o: &SolverOptions) -> Vec<f64>;
    fn rhs(&self, x: &[f64], t: f64, out: &mut [f64]);
    /// `(∂f/∂x)·v`.
    fn jacobian_times(&self, x: &[f64], t: f64, v: &[f64], out: &mut [f64]);
    /// `y ← M v + β y`.
    fn mass_times(&self, v: &[f64], beta: f64, y: &mut [f64]);
    fn roots(&self) -> &[Self::Root];
    /// Event functions, positive while the mode holds.
    fn root_values(&self, x: &[f64], t: f64, h: &Hysteresis, out: &mut [f64]);
    fn sample(&self, x: &[f64], t: f64) -> Self::Sample;
    /// The physical coordinates at (x, t), for error messages.
    fn coordinates(&self, x: &[f64], t: f64) -> Vec<f64>;
}

/// How a segment ended: the root that fired, its time and the state there (None at the end time).
pub type SegmentEnd<R> = Option<(f64, R, Vec<f64>)>;

/// Integrate one segment from `x0` at `t0`, pushing a sample for every time of `times_s` it
/// covers. Returns the root that ended it, with its time and state, or None at `t_end`.
// Eight arguments: the segment, its start (state, time), end time, output times and options, and
// the two outputs (samples, step count) that live in differently typed trajectories of the callers.
#[allow(clippy::too_many_arguments)]
pub fn run_segment<S: SmoothSegment>(
    seg: &S,
    x0: Vec<f64>,
    t0: f64,
    t_end: f64,
    times_s: &[f64],
    o: &SolverOptions,
    samples: &mut Vec<S::Sample>,
    steps: &mut usize,
) -> TransientResult<SegmentEnd<S::Root>> {
    let n = seg.n_states();
    let fail = |t: f64, x: &[f64], e: &dyn std::fmt::Display| TransientError::Solver {
        time_s: t,
        state: if x.is_empty() { vec![] } else { seg.coordinates(x, t) },
        message: e.to_string(),
    };
    while samples.len() < times_s.len() && times_s[samples.len()] <= t0 {
        samples.push(seg.sample(&x0, times_s[samples.len()]));
    }
    if t0 >= t_end {
        return Ok(None);
    }
    let roots = seg.roots();
    let x_init = x0.clone();
    let problem = OdeBuilder::<Matrix>::new()
        .t0(t0)
        .h0(o.first_step_s.min(t_end - t0))
        .rtol(o.rtol)
        .atol(seg.atol(o))
        .rhs_implicit(
            |x: &[f64], _p: &[f64], t: f64, y: &mut [f64]| seg.rhs(x, t, y),
            |x: &[f64], _p: &[f64], t: f64, v: &[f64], y: &mut [f64]| seg.jacobian_times(x, t, v, y),
        )
        .mass(|v: &[f64], _p: &[f64], _t: f64, beta: f64, y: &mut [f64]| seg.mass_times(v, beta, y))
        .init(move |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&x_init), n)
        .root(
            |x: &[f64], _p: &[f64], t: f64, y: &mut [f64]| {
                if roots.is_empty() {
                    y[0] = 1.0;
                } else {
                    seg.root_values(x, t, &o.hysteresis, y)
                }
            },
            roots.len().max(1),
        )
        .build()
        .map_err(|e| fail(t0, &x0, &e))?;
    let mut solver = problem.bdf::<Lu>().map_err(|e| fail(t0, &x0, &e))?;
    solver.set_stop_time(t_end).map_err(|e| fail(t0, &x0, &e))?;
    let mut buffer = solver.state().y.clone();
    loop {
        if *steps >= o.max_steps {
            let s = solver.state();
            return Err(fail(s.t, s.y.batch_as_slice(0), &format!("more than {} steps", o.max_steps)));
        }
        *steps += 1;
        let reason = solver.step().map_err(|e| {
            let s = solver.state();
            fail(s.t, s.y.batch_as_slice(0), &e)
        })?;
        let t_now = solver.state().t;
        let (upto, root) = match reason {
            OdeSolverStopReason::RootFound(tr, idx) if !roots.is_empty() => (tr, Some(roots[idx.min(roots.len() - 1)])),
            _ => (t_now, None),
        };
        while samples.len() < times_s.len() && times_s[samples.len()] <= upto {
            let t = times_s[samples.len()];
            solver.interpolate_inplace(t, &mut buffer).map_err(|e| fail(t, &[], &e))?;
            samples.push(seg.sample(buffer.batch_as_slice(0), t));
        }
        if let Some(root) = root {
            let x = solver.interpolate(upto).map_err(|e| fail(upto, &[], &e))?;
            return Ok(Some((upto, root, x.batch_as_slice(0).to_vec())));
        }
        if matches!(reason, OdeSolverStopReason::TstopReached) || t_now >= t_end {
            return Ok(None);
        }
    }
}
