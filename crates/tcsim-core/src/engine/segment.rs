//! The segment loop shared by the transient engines: one smooth segment of a piecewise-smooth
//! system, from a state to the first root of its event functions (or the end time), on the
//! fixed-size NDF/BDF integrator of [`crate::engine::bdf`].

use crate::engine::bdf::roots::RootFinder;
use crate::engine::bdf::{Bdf, EXACT_MAX, N_MAX};
use crate::engine::options::{Hysteresis, NamedState, SolverOptions, TransientError, TransientResult};

/// The most samples taken together ([`SmoothSegment::sample_block`]).
pub const SAMPLE_BLOCK: usize = 16;

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
    /// The samples at the times `ts` from the states `xs` (the first `n` values of row `k` are
    /// the state at `ts[k]`; at most [`SAMPLE_BLOCK`] rows), pushed to `out`: each the same as
    /// [`Self::sample`]'s. The default takes them one at a time; a segment whose sample is a long
    /// chain of dependent operations takes them stage by stage, where the chains overlap.
    fn sample_block<const N: usize>(&self, xs: &[[f64; N]], n: usize, ts: &[f64], out: &mut Vec<Self::Sample>) {
        for (x, &t) in xs.iter().zip(ts) {
            out.push(self.sample(&x[..n], t));
        }
    }
    /// The physical coordinates at (x, t), named, for error messages.
    fn coordinates(&self, x: &[f64], t: f64) -> NamedState;
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
    run_segment_with_stops(seg, x0, t0, t_end, &[], times_s, o, samples, steps)
}

/// [`run_segment`] whose steps end exactly on each of `stops` (sorted) they would pass: the
/// breakpoints of the piecewise-linear inputs (a launch scenario's pedals), where the forcing has a
/// kink (CVODE's stop time). Without them, a step grown over a long steady phase (the braked idle
/// before a launch) could pass a whole pedal ramp with no evaluation inside it, and the engine did
/// not see the ramp. The integrator goes on through a stop (its error control sees the kink), so
/// a densely logged pedal costs at most one step per sample.
#[allow(clippy::too_many_arguments)]
pub fn run_segment_with_stops<S: SmoothSegment>(
    seg: &S,
    x0: Vec<f64>,
    t0: f64,
    t_end: f64,
    stops: &[f64],
    times_s: &[f64],
    o: &SolverOptions,
    samples: &mut Vec<S::Sample>,
    steps: &mut usize,
) -> TransientResult<SegmentEnd<S::Root>> {
    #[cfg(test)]
    if crate::engine::bdf::crosscheck::diffsol_selected() {
        return crate::engine::bdf::crosscheck::run_segment(seg, x0, t0, t_end, times_s, o, samples, steps);
    }
    let stops = &stops[stops.partition_point(|&s| s <= t0)..];
    // the converter's segments (1 to 4 states) on integrators of their exact size
    const _: () = assert!(EXACT_MAX == 4);
    match x0.len() {
        1 => run_segment_on::<S, 1>(seg, x0, t0, t_end, stops, times_s, o, samples, steps),
        2 => run_segment_on::<S, 2>(seg, x0, t0, t_end, stops, times_s, o, samples, steps),
        3 => run_segment_on::<S, 3>(seg, x0, t0, t_end, stops, times_s, o, samples, steps),
        4 => run_segment_on::<S, 4>(seg, x0, t0, t_end, stops, times_s, o, samples, steps),
        _ => run_segment_on::<S, N_MAX>(seg, x0, t0, t_end, stops, times_s, o, samples, steps),
    }
}

/// Whether the span from `a` to `b` (`a ≤ b`) is shorter than twice the integrator's smallest step
/// (16 ε of the larger time, [`Bdf::step`]): too short for a step of its own.
fn no_step(a: f64, b: f64) -> bool {
    b - a <= 32.0 * f64::EPSILON * a.abs().max(b.abs())
}

/// [`run_segment`] on an integrator of `N` states: exactly `N` up to [`EXACT_MAX`] (its loops
/// unrolled), at most `N` beyond.
#[allow(clippy::too_many_arguments)]
fn run_segment_on<S: SmoothSegment, const N: usize>(
    seg: &S,
    x0: Vec<f64>,
    t0: f64,
    t_end: f64,
    stops: &[f64],
    times_s: &[f64],
    o: &SolverOptions,
    samples: &mut Vec<S::Sample>,
    steps: &mut usize,
) -> TransientResult<SegmentEnd<S::Root>> {
    // a span shorter than the integrator's smallest step (an event a few ulp before the end) is no
    // step: the state at its end is the state at its start, to round-off
    let reached = no_step(t0, t_end); // also at or past the end
    let upto = if reached { t0.max(t_end) } else { t0 };
    while samples.len() < times_s.len() && times_s[samples.len()] <= upto {
        samples.push(seg.sample(&x0, times_s[samples.len()]));
    }
    if reached {
        return Ok(None);
    }
    let mut bdf = Bdf::<S, N>::new(seg, &x0, t0, t_end, o)?;
    let n = x0.len();
    let roots = seg.roots();
    let mut finder = RootFinder::new(roots.len(), |g0| seg.root_values(&x0, t0, &o.hysteresis, g0));
    let mut x = [0.0; N];
    let mut next_stop = 0;
    let mut pending = Pending::<N>::new();
    loop {
        if *steps >= o.max_steps {
            let (t, x) = (bdf.t(), bdf.x());
            let message = format!("more than {} steps", o.max_steps);
            return Err(TransientError::Solver { time_s: t, state: seg.coordinates(x, t), message });
        }
        *steps += 1;
        let t_lo = bdf.t();
        // a stop a few ulp after the step's start or before the end (the last output time 2.4 +
        // 4e-16 s after a drive's time stamp at 2.4 s) would leave a span no step can take: it is
        // passed over, the kink crossed by less than the smallest step
        while next_stop < stops.len()
            && (stops[next_stop] <= t_lo || no_step(t_lo, stops[next_stop]) || no_step(stops[next_stop], t_end))
        {
            next_stop += 1;
        }
        bdf.step(stops.get(next_stop).map_or(t_end, |&s| s.min(t_end)))?;
        let t_hi = bdf.t();
        let root = if roots.is_empty() {
            None
        } else {
            finder.check(t_lo, t_hi, |t, g| {
                if t == t_hi {
                    seg.root_values(bdf.x(), t, &o.hysteresis, g);
                } else {
                    bdf.interpolate(t, &mut x);
                    seg.root_values(&x[..n], t, &o.hysteresis, g);
                }
            })
        };
        let upto = root.map_or(t_hi, |(t, _)| t);
        pending.take(&bdf, seg, n, times_s, upto, samples);
        if let Some((t, i)) = root {
            pending.flush(seg, n, samples);
            bdf.interpolate(t, &mut x);
            return Ok(Some((t, roots[i], x[..n].to_vec())));
        }
        if t_hi >= t_end {
            pending.flush(seg, n, samples);
            return Ok(None);
        }
    }
}

/// The interpolated states of output times not yet sampled: the samples are taken in full blocks
/// of [`SAMPLE_BLOCK`] across the steps of a segment (a step holds about 4 output times of a
/// take-off sampled every 10 ms), so that their chains of dependent operations overlap
/// ([`SmoothSegment::sample_block`]). Each state is interpolated in its own step, and the segment's
/// samples depend on nothing else: the samples are those taken step by step, bit for bit.
struct Pending<const N: usize> {
    xs: [[f64; N]; SAMPLE_BLOCK],
    ts: [f64; SAMPLE_BLOCK],
    len: usize,
}

impl<const N: usize> Pending<N> {
    fn new() -> Self {
        Self { xs: [[0.0; N]; SAMPLE_BLOCK], ts: [0.0; SAMPLE_BLOCK], len: 0 }
    }

    /// Interpolate the output times after the last one taken up to `upto` (within the last step of
    /// `bdf`, of `n` states), sampling each full block.
    fn take<S: SmoothSegment>(
        &mut self,
        bdf: &Bdf<'_, S, N>,
        seg: &S,
        n: usize,
        times_s: &[f64],
        upto: f64,
        samples: &mut Vec<S::Sample>,
    ) {
        let mut first = samples.len() + self.len;
        let count = times_s[first..].iter().take_while(|&&t| t <= upto).count();
        let end = first + count;
        while first < end {
            let room = (SAMPLE_BLOCK - self.len).min(end - first);
            let (ts, xs) = (&mut self.ts[self.len..self.len + room], &mut self.xs[self.len..self.len + room]);
            ts.copy_from_slice(&times_s[first..first + room]);
            bdf.interpolate_many(ts, xs);
            (self.len, first) = (self.len + room, first + room);
            if self.len == SAMPLE_BLOCK {
                self.flush(seg, n, samples);
            }
        }
    }

    /// Sample the states held.
    fn flush<S: SmoothSegment>(&mut self, seg: &S, n: usize, samples: &mut Vec<S::Sample>) {
        if self.len > 0 {
            seg.sample_block(&self.xs[..self.len], n, &self.ts[..self.len], samples);
            self.len = 0;
        }
    }
}
