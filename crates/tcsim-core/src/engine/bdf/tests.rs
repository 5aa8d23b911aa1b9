//! The integrator on problems with known solutions: accuracy against the tolerance, the mass
//! matrix, the end time, events, sizes, failures.
// Dense small-matrix code indexes several arrays by the same row and column, as the formulas do.
#![allow(clippy::needless_range_loop)]

use super::roots::RootFinder;
use super::{Bdf, Matrix, N_MAX};
use crate::engine::options::{named_state, Hysteresis, NamedState, SolverOptions, TransientError};
use crate::engine::segment::{run_segment, run_segment_with_stops, SmoothSegment};

type Fun = fn(&[f64], f64, &mut [f64]);

/// `M ẋ = A x + b(x, t)` with `A` dense and an optional nonlinear/failing part, event functions `g`.
struct Linear {
    n: usize,
    mass: Matrix<N_MAX>,
    a: Matrix<N_MAX>,
    extra: Option<Fun>,
    nan_jacobian: bool,
    roots: Vec<usize>,
    g: Option<Fun>,
}

impl Linear {
    fn new(n: usize, mass: Matrix<N_MAX>, a: Matrix<N_MAX>) -> Self {
        Self { n, mass, a, extra: None, nan_jacobian: false, roots: vec![], g: None }
    }
}

fn identity() -> Matrix<N_MAX> {
    let mut m = [[0.0; N_MAX]; N_MAX];
    (0..N_MAX).for_each(|i| m[i][i] = 1.0);
    m
}

impl SmoothSegment for Linear {
    type Root = usize;
    type Sample = (f64, Vec<f64>);
    fn n_states(&self) -> usize {
        self.n
    }
    fn atol(&self, o: &SolverOptions) -> Vec<f64> {
        vec![o.speed_atol_rad_s; self.n]
    }
    fn rhs(&self, x: &[f64], t: f64, out: &mut [f64]) {
        for i in 0..self.n {
            out[i] = (0..self.n).map(|j| self.a[i][j] * x[j]).sum();
        }
        if let Some(e) = self.extra {
            e(x, t, out);
        }
    }
    fn jacobian_times(&self, _x: &[f64], _t: f64, v: &[f64], out: &mut [f64]) {
        for i in 0..self.n {
            out[i] = (0..self.n).map(|j| self.a[i][j] * v[j]).sum();
            if self.nan_jacobian {
                out[i] = f64::NAN;
            }
        }
    }
    fn mass_times(&self, v: &[f64], beta: f64, y: &mut [f64]) {
        for i in 0..self.n {
            y[i] = (0..self.n).map(|j| self.mass[i][j] * v[j]).sum::<f64>() + beta * y[i];
        }
    }
    fn roots(&self) -> &[usize] {
        &self.roots
    }
    fn root_values(&self, x: &[f64], t: f64, _h: &Hysteresis, out: &mut [f64]) {
        (self.g.unwrap())(x, t, out)
    }
    fn sample(&self, x: &[f64], t: f64) -> (f64, Vec<f64>) {
        (t, x.to_vec())
    }
    fn coordinates(&self, x: &[f64], _t: f64) -> NamedState {
        named_state(None, x)
    }
}

fn options(rtol: f64) -> SolverOptions {
    SolverOptions { rtol, speed_atol_rad_s: rtol * 1e-3, ..SolverOptions::default() }
}

/// Integrate to `t_end` with samples at `times`: (samples, steps, the segment's end).
fn run(seg: &Linear, x0: &[f64], times: &[f64], o: &SolverOptions) -> (Vec<(f64, Vec<f64>)>, usize) {
    let (mut samples, mut steps) = (vec![], 0);
    let t_end = *times.last().unwrap();
    let end = run_segment(seg, x0.to_vec(), 0.0, t_end, times, o, &mut samples, &mut steps).unwrap();
    assert!(end.is_none());
    (samples, steps)
}

fn grid(t_end: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|i| t_end * i as f64 / n as f64).collect()
}

/// The largest error of the samples against `exact`, relative to max|x|.
fn max_error(samples: &[(f64, Vec<f64>)], exact: impl Fn(f64) -> Vec<f64>) -> f64 {
    samples
        .iter()
        .map(|(t, x)| exact(*t).iter().zip(x).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max)
}

#[test]
fn exponential_decay_error_follows_the_tolerance_and_the_order_rises() {
    // ẋ = −2x over 5 s, x(0) = 1; error sampled on 101 points (the interpolant between steps too)
    let mut a = [[0.0; N_MAX]; N_MAX];
    a[0][0] = -2.0;
    let seg = Linear::new(1, identity(), a);
    let mut errors = vec![];
    for rtol in [1e-4, 1e-6, 1e-8, 1e-10] {
        let (s, steps) = run(&seg, &[1.0], &grid(5.0, 100), &options(rtol));
        let e = max_error(&s, |t| vec![(-2.0 * t).exp()]);
        println!("rtol {rtol:e}: error {e:.2e}, {steps} steps");
        // global error within a small multiple of the tolerance (of x(0) = 1)
        assert!(e < 20.0 * rtol, "rtol {rtol:e}: error {e:e}");
        errors.push((e, steps));
    }
    for w in errors.windows(2) {
        // 100× tighter: at least 10× smaller error, for more steps
        assert!(w[1].0 < w[0].0 / 10.0 && w[1].1 > w[0].1, "{errors:?}");
    }
    // a high order is reached on a smooth problem at a tight tolerance
    let o = options(1e-10);
    let mut bdf = Bdf::<_, N_MAX>::new(&seg, &[1.0], 0.0, 5.0, &o).unwrap();
    let mut max_order = 1;
    while bdf.t() < 5.0 {
        bdf.step(5.0).unwrap();
        max_order = max_order.max(bdf.order());
    }
    assert!(max_order >= 4, "highest order {max_order}");
    assert!((bdf.x()[0] - (-10.0f64).exp()).abs() < 1e-8);
}

/// `M = [[2, 0.5], [0.5, 1]]`, `M ẋ = M R x` with `R` the rotation generator: `x = (cos t, sin t)`.
fn oscillator() -> Linear {
    let mut m = identity();
    m[0][0] = 2.0;
    m[0][1] = 0.5;
    m[1][0] = 0.5;
    let r = [[0.0, -1.0], [1.0, 0.0]];
    let mut a = [[0.0; N_MAX]; N_MAX];
    for i in 0..2 {
        for j in 0..2 {
            a[i][j] = (0..2).map(|k| m[i][k] * r[k][j]).sum();
        }
    }
    Linear::new(2, m, a)
}

#[test]
fn an_oscillator_with_a_full_mass_matrix_converges_as_the_tolerance_shrinks() {
    let seg = oscillator();
    let mut last = f64::INFINITY;
    for rtol in [1e-5, 1e-7, 1e-9] {
        let (s, steps) = run(&seg, &[1.0, 0.0], &grid(10.0, 200), &options(rtol));
        let e = max_error(&s, |t| vec![t.cos(), t.sin()]);
        println!("rtol {rtol:e}: error {e:.2e}, {steps} steps");
        // about 1.6 periods: the global error grows with time, bounded by 100 tolerances here
        assert!(e < 100.0 * rtol, "rtol {rtol:e}: error {e:e}");
        assert!(e < last / 10.0, "rtol {rtol:e}: {e:e} after {last:e}");
        last = e;
    }
}

#[test]
fn the_run_stops_exactly_at_the_end_time() {
    let seg = oscillator();
    let t_end = 1.234_567_890_123;
    let o = options(1e-6);
    let mut bdf = Bdf::<_, N_MAX>::new(&seg, &[1.0, 0.0], 0.0, t_end, &o).unwrap();
    while bdf.t() < t_end {
        bdf.step(t_end).unwrap();
        assert!(bdf.t() <= t_end, "passed the end: {}", bdf.t());
    }
    assert_eq!(bdf.t(), t_end);
    // through run_segment: the last sample is at t_end, its state the step's end
    let times = [0.0, 0.5, t_end];
    let (s, _) = run(&seg, &[1.0, 0.0], &times, &o);
    assert_eq!(s.len(), 3);
    assert_eq!(s[2].0, t_end);
    assert!((s[2].1[0] - t_end.cos()).abs() < 1e-4);
    // a right-hand side that is NaN past t_end is never evaluated there
    let mut nan_after = oscillator();
    nan_after.extra = Some(|_x, t, out| {
        if t > 1.234_567_890_123 {
            out[0] = f64::NAN;
        }
    });
    run(&nan_after, &[1.0, 0.0], &times, &o);
}

fn ends(seg: &Linear, x0: &[f64], t_end: f64, o: &SolverOptions) -> Option<(f64, usize, Vec<f64>)> {
    let (mut samples, mut steps) = (vec![], 0);
    let times = grid(t_end, 10);
    run_segment(seg, x0.to_vec(), 0.0, t_end, &times, o, &mut samples, &mut steps).unwrap()
}

#[test]
fn a_root_is_located_on_the_interpolant() {
    // x = e^{−t}: g = x − 0.5 crosses at ln 2 (to the solution's accuracy), g = 0.7 − t at 0.7 exactly
    let mut a = [[0.0; N_MAX]; N_MAX];
    a[0][0] = -1.0;
    let mut seg = Linear::new(1, identity(), a);
    seg.roots = vec![0];
    seg.g = Some(|x, _t, out| out[0] = x[0] - 0.5);
    let o = options(1e-10);
    let (t, root, x) = ends(&seg, &[1.0], 2.0, &o).expect("a root");
    assert_eq!(root, 0);
    assert!((t - 2f64.ln()).abs() < 1e-8, "root at {t}, ln 2 = {}", 2f64.ln());
    assert!((x[0] - 0.5).abs() < 1e-8 && x[0] <= 0.5 + 1e-12, "{x:?}");
    seg.g = Some(|_x, t, out| out[0] = 0.7 - t);
    let (t, _, x) = ends(&seg, &[1.0], 2.0, &options(1e-6)).expect("a root");
    assert!((t - 0.7).abs() < 1e-12, "root at {t}");
    assert!(t >= 0.7, "the event has happened at the time returned: {t}");
    assert!((x[0] - (-0.7f64).exp()).abs() < 1e-4);
    // a function negative from the start, rising through zero, is no event
    seg.g = Some(|_x, t, out| out[0] = t - 0.7);
    assert!(ends(&seg, &[1.0], 2.0, &options(1e-6)).is_none());
}

#[test]
fn the_first_of_two_roots_in_one_step_is_found() {
    // both cross within the step (0, 1]: the earlier one (index 1, at 0.3) wins, though the later
    // one (0.31² − t², at 0.31) is crossed further at the step's end (|g_hi|/|g_hi − g_lo| 0.90
    // against 0.70), so that the secant starts on it
    let g = |t: f64, out: &mut [f64]| {
        out[0] = 0.31 * 0.31 - t * t;
        out[1] = 0.3 - t;
    };
    let mut finder = RootFinder::new(2, |g0| g(0.0, g0));
    let (t, i) = finder.check(0.0, 1.0, g).expect("a root");
    assert_eq!(i, 1);
    assert!((t - 0.3).abs() < 1e-13, "{t}");
    // the same through run_segment, where steps grow large on ẋ = 0
    let mut seg = Linear::new(1, identity(), [[0.0; N_MAX]; N_MAX]);
    seg.roots = vec![0, 1];
    seg.g = Some(|_x, t, out| {
        out[0] = 0.31 - t;
        out[1] = 0.3 - t;
    });
    let (t, root, _) = ends(&seg, &[1.0], 5.0, &options(1e-6)).expect("a root");
    assert_eq!(root, 1);
    assert!((t - 0.3).abs() < 1e-12, "{t}");
    // no crossing: the step's end becomes the start of the next
    let mut finder = RootFinder::new(2, |g0| g(0.0, g0));
    assert!(finder.check(0.0, 0.2, g).is_none());
    assert!(finder.check(0.2, 0.305, g).is_some_and(|(t, i)| i == 1 && (t - 0.3).abs() < 1e-13));
}

#[test]
fn one_and_twelve_states() {
    // twelve decoupled decays at rates 0.5..6, coupled weakly through a lower-triangular term
    let mut a = [[0.0; N_MAX]; N_MAX];
    for i in 0..N_MAX {
        a[i][i] = -0.5 * (i + 1) as f64;
    }
    let seg = Linear::new(N_MAX, identity(), a);
    let x0 = [1.0; N_MAX];
    let (s, _) = run(&seg, &x0, &grid(2.0, 20), &options(1e-8));
    let e = max_error(&s, |t| (0..N_MAX).map(|i| (-0.5 * (i + 1) as f64 * t).exp()).collect());
    assert!(e < 1e-6, "12 states: {e:e}");
    let mut a1 = [[0.0; N_MAX]; N_MAX];
    a1[0][0] = 1.0;
    let (s, _) = run(&Linear::new(1, identity(), a1), &[1.0], &grid(1.0, 10), &options(1e-8));
    assert!(max_error(&s, |t| vec![t.exp()]) < 1e-6 * 3.0);
    // thirteen states are an error, not a panic
    let too_many = Linear { n: N_MAX + 1, ..Linear::new(1, identity(), a1) };
    let e = Bdf::<_, N_MAX>::new(&too_many, &[1.0; N_MAX + 1], 0.0, 1.0, &options(1e-6)).err().expect("an error");
    assert!(matches!(e, TransientError::Solver { ref message, .. } if message.contains("1 to 12")), "{e}");
}

fn solver_error(seg: &Linear, o: &SolverOptions) -> (f64, String) {
    let (mut samples, mut steps) = (vec![], 0);
    match run_segment(seg, vec![1.0; seg.n], 0.0, 2.0, &[0.0, 2.0], o, &mut samples, &mut steps) {
        Err(TransientError::Solver { time_s, message, .. }) => (time_s, message),
        other => panic!("expected a solver error, got {:?}", other.map(|e| e.map(|x| x.0))),
    }
}

#[test]
fn failures_are_solver_errors() {
    let mut a = [[0.0; N_MAX]; N_MAX];
    a[0][0] = -1.0;
    let o = options(1e-6);
    // a right-hand side that turns NaN at 0.5 s
    let mut nan = Linear::new(1, identity(), a);
    nan.extra = Some(|_x, t, out| {
        if t > 0.5 {
            out[0] = f64::NAN;
        }
    });
    let (t, m) = solver_error(&nan, &o);
    assert!((0.4..=0.5).contains(&t), "failed at {t}: {m}");
    // NaN at the start
    nan.extra = Some(|_x, _t, out| out[0] = f64::NAN);
    let (t, m) = solver_error(&nan, &o);
    assert!(t == 0.0 && m.contains("not finite"), "{t}: {m}");
    // a singular mass matrix
    let (_, m) = solver_error(&Linear::new(1, [[0.0; N_MAX]; N_MAX], a), &o);
    assert!(m.contains("mass matrix"), "{m}");
    // an iteration matrix that cannot be factorised (a NaN Jacobian)
    let mut bad_jacobian = Linear::new(1, identity(), a);
    bad_jacobian.nan_jacobian = true;
    let (_, m) = solver_error(&bad_jacobian, &o);
    assert!(m.starts_with("the Jacobian is not finite at t = "), "{m}");
    // the step limit
    let limited = SolverOptions { max_steps: 5, ..o };
    let (t, m) = solver_error(&Linear::new(1, identity(), a), &limited);
    assert!(m == "more than 5 steps" && t > 0.0 && t < 2.0, "{t}: {m}");
}

/// Step a segment of 3 states to `t_end` on an integrator of size `N`, recording every step's time,
/// state and order.
fn trace<const N: usize>(seg: &Linear, x0: &[f64], t_end: f64) -> Vec<(f64, Vec<f64>, usize)> {
    let o = options(1e-7);
    let mut bdf = Bdf::<_, N>::new(seg, x0, 0.0, t_end, &o).unwrap();
    let mut out = vec![];
    while bdf.t() < t_end {
        bdf.step(t_end).unwrap();
        let mut mid = [0.0; 3];
        bdf.interpolate(bdf.t() - 1e-3, &mut mid);
        out.push((bdf.t(), [bdf.x(), &mid[..]].concat(), bdf.order()));
    }
    out
}

#[test]
fn an_exact_size_integrator_steps_bit_for_bit_like_the_general_one() {
    // issue 16: segments of up to 4 states run on integrators of their exact size, whose loops run
    // to the constant N; the arithmetic must be the general integrator's, bit for bit
    let mut a = [[0.0; N_MAX]; N_MAX];
    a[0][..3].copy_from_slice(&[-1.0, 2.0, 0.0]);
    a[1][..3].copy_from_slice(&[-2.0, -1.0, 0.5]);
    a[2][..3].copy_from_slice(&[0.0, 0.0, -50.0]);
    let mut mass = identity();
    mass[0][2] = 0.3;
    mass[2][0] = 0.3;
    let seg = Linear { extra: Some(|x, t, out| out[2] += (3.0 * t).sin() * x[0] * x[1]), ..Linear::new(3, mass, a) };
    let exact = trace::<3>(&seg, &[1.0, 0.0, 2.0], 4.0);
    let general = trace::<N_MAX>(&seg, &[1.0, 0.0, 2.0], 4.0);
    assert!(exact.len() > 50 && exact.iter().any(|s| s.2 > 2), "a real run: {} steps", exact.len());
    assert_eq!(exact, general);
    // an exact-size integrator takes only its size
    let e = Bdf::<_, 4>::new(&seg, &[1.0, 0.0, 2.0], 0.0, 1.0, &options(1e-6)).err().expect("an error");
    assert!(e.to_string().contains("3 states on an integrator of exactly 4"), "{e}");
}

#[test]
fn the_rescaling_matrix_u_is_upper_triangular() {
    // `rescale_matrix` sums R U over the upper triangle of U only
    for i in 0..=super::MAX_ORDER {
        for j in 0..i {
            assert_eq!(super::U[i][j], 0.0, "U[{i}][{j}]");
        }
        assert_ne!(super::U[i][i], 0.0, "U[{i}][{i}]");
    }
}

#[test]
fn a_span_shorter_than_the_smallest_step_is_no_step() {
    // an event a few ulp before the end leaves a segment no step can take: its samples are the
    // state at its start (to round-off), not a solver error; a stop a few ulp after the start is
    // passed over
    let mut a = [[0.0; N_MAX]; N_MAX];
    a[0][0] = -2.0;
    let seg = Linear::new(1, identity(), a);
    let o = options(1e-8);
    let t0: f64 = 3.0;
    let t_end = f64::from_bits(t0.to_bits() + 3);
    let (mut samples, mut steps) = (vec![], 0);
    let end = run_segment(&seg, vec![0.5], t0, t_end, &[t0, t_end], &o, &mut samples, &mut steps).unwrap();
    assert!(end.is_none() && steps == 0);
    assert_eq!(samples, vec![(t0, vec![0.5]), (t_end, vec![0.5])]);
    let stop = f64::from_bits(t0.to_bits() + 2);
    let (mut samples, mut steps) = (vec![], 0);
    let times = [t0, 4.0];
    let end = run_segment_with_stops(&seg, vec![0.5], t0, 4.0, &[stop, 3.5], &times, &o, &mut samples, &mut steps);
    assert!(end.unwrap().is_none() && steps > 0);
    assert!((samples[1].1[0] - 0.5 * (-2.0f64).exp()).abs() < 1e-6, "{samples:?}");
}

/// The samples are taken in blocks across the steps of a segment (`segment::Pending`), and the
/// output times never change the steps: a sample is the same whatever the other output times.
/// Every third time of a dense grid gives the samples of a run at those times alone, bit for bit,
/// up to an event that ends the segment and up to the end time.
#[test]
fn a_sample_does_not_depend_on_the_other_output_times() {
    let mut a = [[0.0; N_MAX]; N_MAX];
    a[0][1] = 1.0;
    a[1][0] = -4.0; // x'' = −4x from x = 1: cos 2t, down to −0.5 at t = π/3
    let free = Linear::new(2, identity(), a);
    let mut ended = Linear::new(2, identity(), a);
    ended.roots = vec![0];
    ended.g = Some(|x, _t, out| out[0] = x[0] + 0.5);
    let dense: Vec<f64> = (0..=1000).map(|i| i as f64 * 0.004).collect();
    let sparse: Vec<f64> = dense.iter().step_by(3).copied().collect();
    let o = options(1e-8);
    for seg in [&free, &ended] {
        let sampled = |times: &[f64]| {
            let (mut samples, mut steps) = (vec![], 0);
            let end = run_segment(seg, vec![1.0, 0.0], 0.0, 4.0, times, &o, &mut samples, &mut steps).unwrap();
            (samples, end.map(|(t, _, _)| t))
        };
        let ((all, end_all), (some, end_some)) = (sampled(&dense), sampled(&sparse));
        assert_eq!(end_all, end_some);
        let every_third: Vec<_> = all.iter().step_by(3).cloned().collect();
        assert!(some.len() > 80, "{} samples", some.len()); // 88 up to the event, 334 to the end
        assert_eq!(every_third, some);
        if let Some(t) = end_all {
            assert!((t - std::f64::consts::FRAC_PI_3).abs() < 1e-6, "the event at {t}");
            assert_eq!(all.len(), dense.iter().take_while(|&&s| s <= t).count());
        }
    }
}

#[test]
fn a_root_finder_takes_max_roots_event_functions_and_refuses_more() {
    // its work arrays are fixed: all MAX_ROOTS functions are looked at (the last one crossing is
    // found), one more is refused rather than cut off
    use super::roots::MAX_ROOTS;
    let g = |t: f64, out: &mut [f64]| {
        let last = out.len() - 1;
        for (i, o) in out.iter_mut().enumerate() {
            *o = if i == last { 0.5 - t } else { 1.0 + i as f64 };
        }
    };
    let (t, i) = RootFinder::new(MAX_ROOTS, |g0| g(0.0, g0)).check(0.0, 1.0, g).expect("the last function's root");
    assert_eq!(i, MAX_ROOTS - 1);
    assert!((t - 0.5).abs() < 1e-13, "{t}");
    let more = std::panic::catch_unwind(|| RootFinder::new(MAX_ROOTS + 1, |g0| g0.fill(1.0)));
    assert!(more.is_err());
    // no event functions: none evaluated, and no root in any step
    let mut none = RootFinder::new(0, |_| panic!("nothing to evaluate"));
    assert!(none.check(0.0, 1.0, |_, g| assert!(g.is_empty())).is_none());
}
