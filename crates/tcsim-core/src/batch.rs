//! Batched steady-state evaluation: many operating points, one or many parameter sets.
//!
//! These loops are what the Python API calls (with the GIL released) for characteristics, the
//! parameter study and the fit.

use std::mem::MaybeUninit;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::converter::hrovat_tobler::{
    drive_steady_state, steady_state, try_steady_state, HtConstants, HtGeometry, HtParam, StatorMode, NO_STEADY_STATE,
};
use crate::engine::isolated::{simulate, Event};
use crate::engine::options::{try_reserve, SolverOptions, TransientError, TransientResult};
use crate::engine::outputs::{write_columns, OutputRow, Overflow, Selection};
use crate::error::CoreError;
use crate::scalar::{Dual, Scalar};

/// Column-wise steady states of the Hrovat & Tobler model.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HtSteadyColumns {
    pub flow_m3_s: Vec<f64>,
    pub stator_speed_rad_s: Vec<f64>,
    pub pump_torque_nm: Vec<f64>,
    pub turbine_torque_nm: Vec<f64>,
    pub stator_torque_nm: Vec<f64>,
    /// [`StatorMode`] as an integer, or −1 where the point has no steady state (lenient mode).
    pub stator_mode: Vec<i8>,
}

impl HtSteadyColumns {
    fn zeros(n: usize) -> Self {
        let v = || vec![0.0; n];
        Self {
            flow_m3_s: v(),
            stator_speed_rad_s: v(),
            pump_torque_nm: v(),
            turbine_torque_nm: v(),
            stator_torque_nm: v(),
            stator_mode: vec![0; n],
        }
    }

    /// The columns cut into consecutive pieces of `len` rows (the last one shorter).
    fn pieces(&mut self, len: usize) -> Vec<SteadyRows<'_>> {
        let mut flow = self.flow_m3_s.chunks_mut(len);
        let mut ws = self.stator_speed_rad_s.chunks_mut(len);
        let mut tp = self.pump_torque_nm.chunks_mut(len);
        let mut tt = self.turbine_torque_nm.chunks_mut(len);
        let mut ts = self.stator_torque_nm.chunks_mut(len);
        let mut mode = self.stator_mode.chunks_mut(len);
        let mut out = Vec::new();
        while let (Some(flow), Some(ws), Some(tp), Some(tt), Some(ts), Some(mode)) =
            (flow.next(), ws.next(), tp.next(), tt.next(), ts.next(), mode.next())
        {
            out.push(SteadyRows { values: [flow, ws, tp, tt, ts], mode });
        }
        out
    }
}

/// Consecutive rows of [`HtSteadyColumns`] that one worker fills: flow, stator speed, pump,
/// turbine and stator torque, and the mode.
struct SteadyRows<'a> {
    values: [&'a mut [f64]; 5],
    mode: &'a mut [i8],
}

/// A failed point: its index in the batch and the reason.
#[derive(Debug, Clone, PartialEq)]
pub struct PointError {
    pub index: usize,
    pub error: CoreError,
}

/// Steady states at `pump[i], turbine[i]` with parameter set `geometry[i]` (or `geometry[0]`
/// for every point when one set is given), on one thread. `strict` stops at the first point
/// without a steady state; otherwise such points are NaN with mode −1.
pub fn ht_steady_states(
    geometry: &[HtGeometry<f64>],
    pump_speed_rad_s: &[f64],
    turbine_speed_rad_s: &[f64],
    strict: bool,
) -> Result<HtSteadyColumns, PointError> {
    let never = AtomicBool::new(false);
    ht_steady_states_cancellable(geometry, pump_speed_rad_s, turbine_speed_rad_s, strict, 1, &never)
        .map(|cols| cols.unwrap_or_default())
}

/// Points between two looks at the cancel flag of [`ht_steady_states_cancellable`].
pub const CANCEL_CHECK_POINTS: usize = 4096;

/// The fewest points a worker thread of [`ht_steady_states_cancellable`] is given: smaller batches
/// run on fewer threads (a thread costs tens of µs to start; 16 384 points take about 1 ms).
pub const STEADY_POINTS_PER_THREAD: usize = 16_384;

/// [`ht_steady_states`] on `threads` worker threads (0: one per core; never more than one per
/// [`STEADY_POINTS_PER_THREAD`] points), each on consecutive points, that stops early, returning
/// `Ok(None)`, once `cancel` is set (looked at every [`CANCEL_CHECK_POINTS`] points). The results do
/// not depend on the number of threads; with `strict` the error is the first failed point's.
pub fn ht_steady_states_cancellable(
    geometry: &[HtGeometry<f64>],
    pump_speed_rad_s: &[f64],
    turbine_speed_rad_s: &[f64],
    strict: bool,
    threads: usize,
    cancel: &AtomicBool,
) -> Result<Option<HtSteadyColumns>, PointError> {
    let n = pump_speed_rad_s.len();
    assert!(
        turbine_speed_rad_s.len() == n && (geometry.len() == 1 || geometry.len() == n),
        "batch shapes are checked by the caller"
    );
    let workers = worker_threads(threads, n / STEADY_POINTS_PER_THREAD);
    let mut out = HtSteadyColumns::zeros(n);
    let len = n.div_ceil(workers).max(1);
    let pieces = out.pieces(len);
    let run = |(j, rows): (usize, SteadyRows<'_>)| {
        let start = j * len;
        let end = start + rows.mode.len();
        let g = if geometry.len() == 1 { geometry } else { &geometry[start..end] };
        let speeds = (&pump_speed_rad_s[start..end], &turbine_speed_rad_s[start..end]);
        fill_steady_rows(g, speeds, strict, cancel, rows).map_err(|e| PointError { index: start + e.index, ..e })
    };
    let results: Vec<Result<bool, PointError>> = if workers == 1 {
        pieces.into_iter().enumerate().map(run).collect()
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = pieces.into_iter().enumerate().map(|piece| scope.spawn(move || run(piece))).collect();
            handles.into_iter().map(|h| h.join().expect("a steady-state worker does not panic")).collect()
        })
    };
    // in point order: the first failed point's error, else whether any worker was cancelled
    let mut complete = true;
    for r in results {
        complete &= r?;
    }
    Ok(complete.then_some(out))
}

/// Fill `rows` with the steady states of consecutive points (`geometry`: one row, or one per
/// point); false if `cancel` was set, the error of the first failed point with `strict`.
fn fill_steady_rows(
    geometry: &[HtGeometry<f64>],
    (pump, turbine): (&[f64], &[f64]),
    strict: bool,
    cancel: &AtomicBool,
    rows: SteadyRows<'_>,
) -> Result<bool, PointError> {
    let SteadyRows { values: [flow, ws, tp, tt, ts], mode } = rows;
    // a parameter row's constants once: for all points, or while consecutive points repeat the row
    let mut k = HtConstants::new(&geometry[0]);
    let mut row = &geometry[0];
    for i in 0..mode.len() {
        if i % CANCEL_CHECK_POINTS == 0 && cancel.load(Ordering::Relaxed) {
            return Ok(false);
        }
        if geometry.len() > 1 && geometry[i].values != row.values {
            (row, k) = (&geometry[i], HtConstants::new(&geometry[i]));
        }
        match try_steady_state(&k, pump[i], turbine[i]) {
            Ok(s) => {
                (flow[i], ws[i], tp[i]) = (s.flow_m3_s, s.stator_speed_rad_s, s.pump_torque_nm);
                (tt[i], ts[i], mode[i]) = (s.turbine_torque_nm, s.stator_torque_nm, s.mode.code());
            }
            Err(e) if strict => return Err(PointError { index: i, error: e.error(pump[i], turbine[i]) }),
            Err(_) => {
                (flow[i], ws[i], tp[i], tt[i], ts[i]) = (f64::NAN, f64::NAN, f64::NAN, f64::NAN, f64::NAN);
                mode[i] = NO_STEADY_STATE;
            }
        }
    }
    Ok(true)
}

/// Iterations of [`ht_pump_speed_at_pump_torque`] at most.
const PUMP_TORQUE_ITERATIONS: usize = 60;

/// The positive pump speed (rad/s) at which the Hrovat & Tobler steady state at speed ratio
/// `speed_ratio` takes the pump torque `pump_torque_nm` (`characterise --input-torque-nm`), or None
/// where there is none (a torque of the other sign than the model's at that speed ratio, or no
/// steady state). A fixed-point iteration `ω ← ω·√(T/T_p(ω))` from the reference pump speed: the
/// steady torques grow as ω² at a fixed speed ratio, so it converges in one or two steps; it stops
/// when ω changes by less than 1e-14 relative.
pub fn ht_pump_speed_at_pump_torque(geometry: &HtGeometry<f64>, pump_torque_nm: f64, speed_ratio: f64) -> Option<f64> {
    if !(pump_torque_nm.is_finite() && pump_torque_nm != 0.0 && speed_ratio.is_finite()) {
        return None;
    }
    let mut w = crate::units::REFERENCE_PUMP_SPEED_RAD_S;
    for _ in 0..PUMP_TORQUE_ITERATIONS {
        let tp = steady_state(geometry, w, speed_ratio * w).ok()?.pump_torque_nm;
        let ratio = pump_torque_nm / tp;
        if !(ratio > 0.0 && ratio.is_finite()) {
            return None;
        }
        let next = w * ratio.sqrt();
        if !next.is_finite() {
            return None;
        }
        if (next - w).abs() <= 1e-14 * next {
            return Some(next);
        }
        w = next;
    }
    None
}

/// Torque ratio and capacity factor at the given speed ratios (pump speed `pump_speed_rad_s`),
/// with their exact derivatives with respect to the parameters `free`.
///
/// Returns `(tr, cf, d_tr, d_cf)`; the derivative matrices are row-major, `n_points × free.len()`.
/// Points without a forward-flow drive steady state ([`drive_steady_state`]), or where the model's
/// own steady state ([`try_steady_state`], the flow starting from rest) does not flow forwards, are
/// NaN, which a least-squares fit must treat as a failure.
pub fn ht_ratio_gradients(
    geometry: &HtGeometry<f64>,
    pump_speed_rad_s: f64,
    speed_ratio: &[f64],
    free: &[HtParam],
) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let (n, k) = (speed_ratio.len(), free.len());
    let mut tr = vec![f64::NAN; n];
    let mut cf = vec![f64::NAN; n];
    let mut dtr = vec![f64::NAN; n * k];
    let mut dcf = vec![f64::NAN; n * k];
    let wp = Dual::cst(pump_speed_rad_s);
    let w2 = pump_speed_rad_s * pump_speed_rad_s;
    let constants = HtConstants::new(geometry);
    for (i, &sr) in speed_ratio.iter().enumerate() {
        // the model's own steady state (from rest, as `characterise` and every run compute it) must
        // flow forwards here: a geometry whose flow is held at rest though a forward-flow state
        // exists (two steady states) fitted 0.5 % while the converter it wrote transmitted nothing
        let own = try_steady_state(&constants, pump_speed_rad_s, sr * pump_speed_rad_s);
        if !own.is_ok_and(|s| s.mode != StatorMode::NoFlow && s.flow_m3_s > 0.0) {
            continue;
        }
        let wt = Dual::cst(sr * pump_speed_rad_s);
        // one forward pass per free parameter; without free parameters, one plain pass
        let seeds: Vec<HtGeometry<Dual>> =
            if k == 0 { vec![geometry.to_dual()] } else { free.iter().map(|&p| geometry.seeded(p)).collect() };
        for (j, g) in seeds.iter().enumerate() {
            let Ok(s) = drive_steady_state(g, wp, wt) else { break };
            let (t, c) = (s.torque_ratio(), s.pump_torque_nm);
            tr[i] = t.v;
            cf[i] = c.v / w2;
            if k > 0 {
                dtr[i * k + j] = if s.mode == StatorMode::NoFlow { 0.0 } else { t.d };
                dcf[i * k + j] = c.d / w2;
            }
        }
    }
    (tr, cf, dtr, dcf)
}

// ---------------------------------------------------------------------------------------------
// Transient runs

/// One transient run of a batch.
pub struct TransientJob {
    pub model: Box<dyn crate::converter::dynamics::ConverterDynamics + Send>,
    pub drive: crate::engine::isolated::Drive,
    pub times_s: Vec<f64>,
    pub init: crate::engine::isolated::InitialState,
    pub options: crate::engine::options::SolverOptions,
}

/// Columns of a run (see [`crate::engine::outputs::COLUMNS`]) and its events.
pub type RunOutput = (Vec<Vec<f64>>, Vec<crate::engine::isolated::Event>);

/// Run `f`, turning a panic into a solver error instead of unwinding.
pub fn catch_panic<T>(
    f: impl FnOnce() -> crate::engine::options::TransientResult<T>,
) -> crate::engine::options::TransientResult<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let msg = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(crate::engine::options::TransientError::Solver {
            time_s: f64::NAN,
            state: vec![],
            message: format!("internal error: {msg}"),
        })
    })
}

/// Run one job.
pub fn run_transient_job(job: &TransientJob) -> crate::engine::options::TransientResult<RunOutput> {
    catch_panic(|| {
        let traj =
            crate::engine::isolated::simulate(job.model.as_ref(), &job.drive, &job.times_s, &job.init, &job.options)?;
        Ok((crate::engine::outputs::columns(job.model.as_ref(), &traj)?, traj.events))
    })
}

/// The worker threads of a batch asked for `threads` (0: one per core) with work for at most `most`:
/// at least one. The number of cores is read once per process, at the first batch: the standard
/// library reads it from the cgroup files each time, which cost about 25 µs, more than a short run.
/// A later change of the process's CPU affinity or quota (or a forked child's) is not seen: give
/// `threads` then.
pub fn worker_threads(threads: usize, most: usize) -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    let cores = || *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |c| c.get()));
    if threads == 0 { cores() } else { threads }.min(most).max(1)
}

/// `f` over `jobs` on `threads` worker threads (0: one per core), results in job order.
pub fn parallel_map<J: Sync, R: Send>(jobs: &[J], threads: usize, f: impl Fn(&J) -> R + Sync) -> Vec<R> {
    let never = AtomicBool::new(false);
    parallel_map_cancellable(jobs, threads, &never, f).into_iter().map(|r| r.expect("every job ran")).collect()
}

/// [`parallel_map`] that can be cancelled: once `cancel` is set, no worker starts another job (a
/// job already started runs to its end). Results are in job order, `None` for the jobs not run.
pub fn parallel_map_cancellable<J: Sync, R: Send>(
    jobs: &[J],
    threads: usize,
    cancel: &AtomicBool,
    f: impl Fn(&J) -> R + Sync,
) -> Vec<Option<R>> {
    use std::sync::atomic::AtomicUsize;
    use std::sync::Mutex;
    let threads = worker_threads(threads, jobs.len());
    if threads == 1 {
        return jobs.iter().map(|j| if cancel.load(Ordering::Relaxed) { None } else { Some(f(j)) }).collect();
    }
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<R>>> = Mutex::new((0..jobs.len()).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| loop {
                if cancel.load(Ordering::Relaxed) {
                    break;
                }
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= jobs.len() {
                    break;
                }
                let r = f(&jobs[i]);
                if let Ok(mut guard) = results.lock() {
                    guard[i] = Some(r);
                }
            });
        }
    });
    results.into_inner().unwrap_or_default()
}

/// Run all jobs on `threads` worker threads (0: one per core). Results are in job order.
pub fn run_transient_jobs(
    jobs: &[TransientJob],
    threads: usize,
) -> Vec<crate::engine::options::TransientResult<RunOutput>> {
    parallel_map(jobs, threads, run_transient_job)
}

/// [`run_transient_jobs`] that can be cancelled (see [`parallel_map_cancellable`]).
pub fn run_transient_jobs_cancellable(
    jobs: &[TransientJob],
    threads: usize,
    cancel: &AtomicBool,
) -> Vec<Option<crate::engine::options::TransientResult<RunOutput>>> {
    parallel_map_cancellable(jobs, threads, cancel, run_transient_job)
}

// ---------------------------------------------------------------------------------------------
// Columnar transient batches

/// Status of a run of a columnar batch ([`BatchColumns::status`]): finished.
pub const RUN_OK: u8 = 0;
/// Status: the run's input was refused ([`RunFailure::Error`] with [`TransientError::Input`]).
pub const RUN_INPUT_ERROR: u8 = 1;
/// Status: the solver failed ([`RunFailure::Error`] with [`TransientError::Solver`]).
pub const RUN_SOLVER_ERROR: u8 = 2;
/// Status: the run finished but a column overflowed ([`RunFailure::Overflow`]); its rows hold the
/// values computed.
pub const RUN_OVERFLOW: u8 = 3;

/// Why a run of a columnar batch did not give a usable result.
#[derive(Debug, Clone)]
pub enum RunFailure {
    Error(TransientError),
    Overflow(Overflow),
}

/// The results of a columnar batch ([`run_transient_columns`]): one buffer per selected column for
/// all runs, run `i` at rows `offsets[i]..offsets[i + 1]` (NaN for a run that failed with an
/// error), its status, its events, and the failures of the runs that failed (only those).
#[derive(Debug, Clone)]
pub struct BatchColumns {
    pub selection: Selection,
    /// `runs + 1` row offsets.
    pub offsets: Vec<usize>,
    /// One per selected column, in the selection's order, `offsets[runs]` rows each.
    pub columns: Vec<Vec<f64>>,
    /// One per run: [`RUN_OK`], [`RUN_INPUT_ERROR`], [`RUN_SOLVER_ERROR`] or [`RUN_OVERFLOW`].
    pub status: Vec<u8>,
    /// Events of all runs in run order, each with its run's index.
    pub events: Vec<(usize, Event)>,
    /// The failed runs' indices and failures, in run order.
    pub failures: Vec<(usize, RunFailure)>,
}

/// Consecutive runs `first..first + status.len()` of a columnar batch and their rows of every
/// selected column, which one worker fills.
struct RunRows<'a> {
    first: usize,
    columns: Vec<&'a mut [MaybeUninit<f64>]>,
    status: &'a mut [u8],
}

/// What a worker reports of its [`RunRows`]: events and failures in run order, and whether every
/// run ran (false once the batch was cancelled).
struct RowsDone {
    events: Vec<(usize, Event)>,
    failures: Vec<(usize, RunFailure)>,
    complete: bool,
}

/// The most runs a worker of [`run_transient_columns`] takes at once.
const MAX_RUNS_PER_PIECE: usize = 32;

/// Run `jobs` on `threads` workers (0: one per core) and write the `selection`'s columns of each
/// straight into its rows of preallocated buffers (one per column for all runs; the first
/// `skips[i]` samples of job `i` are run, not stored; `skips` has one value per job or one for all).
/// The workers take pieces of at most `MAX_RUNS_PER_PIECE` consecutive runs in turn; nothing is
/// merged after but the events and the failures. The results do not depend on the number of
/// threads. `Ok(None)` once `cancel` is set (no worker starts another run); an error, before any
/// run, when the buffers cannot be had.
pub fn run_transient_columns(
    jobs: &[TransientJob],
    skips: &[usize],
    selection: &Selection,
    threads: usize,
    cancel: &AtomicBool,
) -> TransientResult<Option<BatchColumns>> {
    let n = jobs.len();
    assert!(skips.len() == 1 || skips.len() == n, "one skip, or one per job");
    let skip = |i: usize| skips[if skips.len() == 1 { 0 } else { i }];
    let mut offsets = Vec::with_capacity(n + 1);
    offsets.push(0);
    for (i, j) in jobs.iter().enumerate() {
        offsets.push(offsets[i] + j.times_s.len().saturating_sub(skip(i)));
    }
    let rows = offsets[n];
    // the buffers are not zeroed: each row is written once, by the worker of its run, so that
    // the workers share the first touch of the memory (zeroing it is a serial pass over all of it)
    let mut columns: Vec<Vec<f64>> = Vec::with_capacity(selection.len());
    for _ in 0..selection.len() {
        let mut c = Vec::new();
        try_reserve(&mut c, rows)?;
        columns.push(c);
    }
    let mut status = vec![RUN_OK; n];
    let workers = worker_threads(threads, n);
    let per_piece = (n / (16 * workers)).clamp(1, MAX_RUNS_PER_PIECE);
    let pieces = run_rows(&mut columns, &mut status, &offsets, per_piece);
    let piece_count = pieces.len();
    let work = |rows: RunRows<'_>| fill_run_rows(jobs, &skip, &offsets, selection, cancel, rows);
    let done: Vec<RowsDone> = if workers == 1 {
        pieces.into_iter().map(work).collect()
    } else {
        let queue: Vec<std::sync::Mutex<Option<RunRows<'_>>>> =
            pieces.into_iter().map(|p| std::sync::Mutex::new(Some(p))).collect();
        let next = std::sync::atomic::AtomicUsize::new(0);
        let mut out: Vec<(usize, RowsDone)> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..workers)
                .map(|_| {
                    scope.spawn(|| {
                        let mut mine = Vec::new();
                        loop {
                            let k = next.fetch_add(1, Ordering::Relaxed);
                            let Some(slot) = queue.get(k) else { break };
                            // each piece is taken once, by the worker that drew its index (a
                            // poisoned lock still holds it: nothing panics while it is held)
                            let piece = slot.lock().unwrap_or_else(std::sync::PoisonError::into_inner).take();
                            mine.push((k, work(piece.expect("each piece is drawn once"))));
                        }
                        mine
                    })
                })
                .collect();
            handles.into_iter().flat_map(|h| h.join().expect("a transient worker does not panic")).collect()
        });
        out.sort_by_key(|(k, _)| *k);
        out.into_iter().map(|(_, d)| d).collect()
    };
    let mut result =
        BatchColumns { selection: selection.clone(), offsets, columns, status, events: vec![], failures: vec![] };
    let result_pieces = done.len();
    for d in done {
        if !d.complete {
            return Ok(None);
        }
        result.events.extend(d.events);
        result.failures.extend(d.failures);
    }
    // every piece reported back (the rows of a piece that did not are not written)
    assert_eq!(result_pieces, piece_count, "every piece of the batch ran");
    for c in &mut result.columns {
        // SAFETY: every run ran (every piece reported back, none incomplete), and fill_run_rows wrote every row
        // of each run: write_columns writes all of its rows, a failed run's rows are filled with NaN
        unsafe { c.set_len(rows) };
    }
    Ok(Some(result))
}

/// The buffers cut into pieces of `per_piece` consecutive runs.
fn run_rows<'a>(
    columns: &'a mut [Vec<f64>],
    status: &'a mut [u8],
    offsets: &[usize],
    per_piece: usize,
) -> Vec<RunRows<'a>> {
    let n = status.len();
    let rows = offsets[n];
    let mut rest: Vec<&'a mut [MaybeUninit<f64>]> =
        columns.iter_mut().map(|c| &mut c.spare_capacity_mut()[..rows]).collect();
    let mut status_rest = status;
    let mut out = Vec::with_capacity(n.div_ceil(per_piece));
    let mut first = 0;
    while first < n {
        let end = (first + per_piece).min(n);
        let len = offsets[end] - offsets[first];
        let mut cols = Vec::with_capacity(rest.len());
        for c in rest.iter_mut() {
            let (head, tail) = std::mem::take(c).split_at_mut(len);
            cols.push(head);
            *c = tail;
        }
        let (st, st_tail) = std::mem::take(&mut status_rest).split_at_mut(end - first);
        status_rest = st_tail;
        out.push(RunRows { first, columns: cols, status: st });
        first = end;
    }
    out
}

/// Run the jobs of `rows` one after the other, writing each run's columns into its rows.
fn fill_run_rows(
    jobs: &[TransientJob],
    skip: &dyn Fn(usize) -> usize,
    offsets: &[usize],
    selection: &Selection,
    cancel: &AtomicBool,
    mut rows: RunRows<'_>,
) -> RowsDone {
    let mut done = RowsDone { events: vec![], failures: vec![], complete: true };
    let base = offsets[rows.first];
    let sampled = selection.sampled();
    for k in 0..rows.status.len() {
        if cancel.load(Ordering::Relaxed) {
            done.complete = false;
            break;
        }
        let i = rows.first + k;
        let (a, b) = (offsets[i] - base, offsets[i + 1] - base);
        let mut out: Vec<&mut [MaybeUninit<f64>]> = rows.columns.iter_mut().map(|c| &mut c[a..b]).collect();
        let job = &jobs[i];
        let run = catch_panic(|| {
            let options = SolverOptions { sampled, ..job.options };
            let traj = simulate(job.model.as_ref(), &job.drive, &job.times_s, &job.init, &options)?;
            let overflow = write_columns(job.model.as_ref(), &traj.samples, selection, skip(i), &mut out);
            Ok((traj.events, overflow))
        });
        match run {
            Ok((events, overflow)) => {
                done.events.extend(events.into_iter().map(|e| (i, e)));
                if let Some(o) = overflow {
                    rows.status[k] = RUN_OVERFLOW;
                    done.failures.push((i, RunFailure::Overflow(o)));
                }
            }
            Err(e) => {
                out.iter_mut().for_each(|c| c.iter_mut().for_each(|v| v.put(f64::NAN)));
                rows.status[k] = if matches!(e, TransientError::Input(_)) { RUN_INPUT_ERROR } else { RUN_SOLVER_ERROR };
                done.failures.push((i, RunFailure::Error(e)));
            }
        }
    }
    done
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ht_pump_speed_carries_the_given_pump_torque() {
        let g = HtGeometry::appendix_d();
        for sr in [0.0, 0.3, 0.6, 0.85, 0.95] {
            for t in [50.0, 150.0, 400.0] {
                let w = ht_pump_speed_at_pump_torque(&g, t, sr).unwrap();
                let tp = steady_state(&g, w, sr * w).unwrap().pump_torque_nm;
                assert!((tp - t).abs() <= 1e-9 * t, "SR {sr}, {t} N·m: ω_p {w}, T_p {tp}");
            }
        }
        // a drive torque in drive can't be negative at SR 0.5 with a positive pump speed
        assert_eq!(ht_pump_speed_at_pump_torque(&g, -100.0, 0.5), None);
        assert_eq!(ht_pump_speed_at_pump_torque(&g, f64::NAN, 0.5), None);
    }

    #[test]
    fn batch_matches_pointwise_and_reports_failures() {
        let g = HtGeometry::appendix_d();
        let wp = [200.0, 200.0, 200.0];
        let wt = [0.0, 100.0, f64::NAN];
        let lenient = ht_steady_states(&[g], &wp, &wt, false).unwrap();
        let one = steady_state(&g, 200.0, 100.0).unwrap();
        assert_eq!(lenient.pump_torque_nm[1], one.pump_torque_nm);
        assert_eq!(lenient.stator_mode[2], -1);
        assert!(lenient.flow_m3_s[2].is_nan());
        let strict = ht_steady_states(&[g], &wp, &wt, true).unwrap_err();
        assert_eq!(strict.index, 2);
        assert_eq!(strict.error.field, "turbine_speed_rad_s");
        // overrun has a steady state now (reverse flow)
        let coast = ht_steady_states(&[g], &[200.0], &[260.0], true).unwrap();
        assert!(coast.flow_m3_s[0] < 0.0 && coast.pump_torque_nm[0] < 0.0);
    }

    #[test]
    fn a_batch_has_at_least_one_worker_and_never_more_than_its_work_or_the_cores() {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        for most in [0, 1, 2, 7, usize::MAX] {
            assert_eq!(worker_threads(0, most), cores.min(most).max(1), "0 threads, {most} jobs");
            assert_eq!(worker_threads(0, most), worker_threads(0, most), "read once, the same after");
            for threads in [1, 3, 64] {
                assert_eq!(worker_threads(threads, most), threads.min(most).max(1), "{threads} threads, {most} jobs");
            }
        }
    }

    /// The bits of every column, NaN included.
    fn bits(c: &HtSteadyColumns) -> Vec<Vec<u64>> {
        let mut v: Vec<Vec<u64>> = [&c.flow_m3_s, &c.stator_speed_rad_s, &c.pump_torque_nm, &c.turbine_torque_nm]
            .iter()
            .map(|col| col.iter().map(|x| x.to_bits()).collect())
            .collect();
        v.push(c.stator_torque_nm.iter().map(|x| x.to_bits()).collect());
        v.push(c.stator_mode.iter().map(|&m| m as u64).collect());
        v
    }

    /// Issue 16: the batch computes a geometry's constants once (for one row, or while consecutive
    /// points repeat a row) and shares the points among threads; neither may change a result: each
    /// point is bit for bit `steady_state` of its own row, whatever the number of threads, and with
    /// `strict` the error is the first failed point's, not the first failing worker's.
    #[test]
    fn batch_results_do_not_depend_on_threads_or_shared_constants() {
        let n = 3 * STEADY_POINTS_PER_THREAD + 17;
        let mut fitted = HtGeometry::appendix_d().values;
        fitted[HtParam::FrictionLoss.index()] = 0.35;
        fitted[HtParam::StatorShockLoss.index()] = 1.6;
        let rows = [HtGeometry::appendix_d(), HtGeometry::new(fitted).unwrap()];
        // every quadrant: SR −3 to 5, both pump directions, the pump at rest; rows in runs of 7
        let wp: Vec<f64> = (0..n)
            .map(|i| {
                if i % 5 == 0 {
                    -200.0
                } else if i % 11 == 0 {
                    0.0
                } else {
                    210.0
                }
            })
            .collect();
        let mut wt: Vec<f64> = (0..n).map(|i| (-3.0 + 8.0 * (i as f64 * 0.618_034).fract()) * 200.0).collect();
        let geometry: Vec<HtGeometry<f64>> = (0..n).map(|i| rows[(i / 7) % 2]).collect();
        for (i, w) in [(n / 2, f64::NAN), (n - 3, f64::INFINITY)] {
            wt[i] = w;
        }
        let never = AtomicBool::new(false);
        let run = |g: &[HtGeometry<f64>], threads, strict| {
            ht_steady_states_cancellable(g, &wp, &wt, strict, threads, &never).map(Option::unwrap)
        };
        for g in [&geometry[..], &rows[..1]] {
            let one = run(g, 1, false).unwrap();
            for threads in [2, 3, 4] {
                assert_eq!(bits(&run(g, threads, false).unwrap()), bits(&one), "{threads} threads");
                let e = run(g, threads, true).unwrap_err();
                assert_eq!((e.index, e.error.field.as_str()), (n / 2, "turbine_speed_rad_s"), "{threads} threads");
            }
            for i in (0..n).step_by(97).chain([n / 2, n - 3]) {
                let row = if g.len() == 1 { &g[0] } else { &g[i] };
                match steady_state(row, wp[i], wt[i]) {
                    Ok(s) => {
                        let got = [one.flow_m3_s[i], one.stator_speed_rad_s[i], one.pump_torque_nm[i]];
                        let want = [s.flow_m3_s, s.stator_speed_rad_s, s.pump_torque_nm];
                        assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "point {i}");
                        assert_eq!(one.turbine_torque_nm[i].to_bits(), s.turbine_torque_nm.to_bits());
                        assert_eq!(one.stator_torque_nm[i].to_bits(), s.stator_torque_nm.to_bits());
                        assert_eq!(one.stator_mode[i], s.mode.code());
                    }
                    Err(_) => assert_eq!(one.stator_mode[i], NO_STEADY_STATE, "point {i}"),
                }
            }
        }
        // the modes met include every stator mode and both flow directions
        let one = run(&geometry, 1, false).unwrap();
        for m in [0, 1, 2, -1] {
            assert!(one.stator_mode.contains(&m), "mode {m}");
        }
        assert!(one.flow_m3_s.iter().any(|&q| q < 0.0) && one.flow_m3_s.iter().any(|&q| q > 0.0));
    }

    #[test]
    fn a_set_cancel_flag_stops_the_batches() {
        let cancel = AtomicBool::new(true);
        let jobs = [1, 2, 3, 4];
        assert!(parallel_map_cancellable(&jobs, 2, &cancel, |j| j * 2).iter().all(Option::is_none));
        assert!(parallel_map_cancellable(&jobs, 1, &cancel, |j| j * 2).iter().all(Option::is_none));
        let g = HtGeometry::appendix_d();
        assert!(ht_steady_states_cancellable(&[g], &[200.0], &[0.0], true, 1, &cancel).unwrap().is_none());
        let n = 3 * STEADY_POINTS_PER_THREAD;
        assert!(ht_steady_states_cancellable(&[g], &vec![200.0; n], &vec![0.0; n], true, 3, &cancel)
            .unwrap()
            .is_none());
        let go = AtomicBool::new(false);
        let all = parallel_map_cancellable(&jobs, 2, &go, |j| j * 2);
        assert_eq!(all, vec![Some(2), Some(4), Some(6), Some(8)]);
    }

    fn takeoff_job(times_s: Vec<f64>, pump_torque_nm: f64) -> TransientJob {
        use crate::converter::dynamics::{HtDynamics, Inertias};
        use crate::engine::isolated::{Drive, InitialState, TurbineLoad};
        use crate::engine::signal::Signal;
        let model =
            HtDynamics::new(HtGeometry::appendix_d(), Inertias::new(0.109, 0.056, 0.01).unwrap(), 0.2914, [1.3e-3; 3])
                .unwrap();
        let torque =
            Signal::new("pump_torque_nm", vec![0.0, 0.1, 0.3, 10.0], vec![40.0, 40.0, pump_torque_nm, 250.0], 0.0);
        let drive = Drive::PumpTorqueLoad {
            pump_torque_nm: torque.unwrap(),
            load: TurbineLoad { torque_nm: Signal::constant(10.0), inertia_kg_m2: 1.2, drag_nm_s2: 0.002 },
            lockup: None,
        };
        let options = crate::engine::options::SolverOptions::default();
        TransientJob { model: Box::new(model), drive, times_s, init: InitialState::default(), options }
    }

    /// Issue 16: a columnar batch writes each run into its rows; the rows are the run's own
    /// columns ([`run_transient_job`]) bit for bit, whatever the number of threads and the piece
    /// size, with ragged output times, skipped first samples, and a failing run among good ones
    /// (its rows NaN, its status and error reported; the others intact).
    #[test]
    fn a_columnar_batch_is_the_runs_bit_for_bit() {
        let grid = |n: usize, end: f64| (0..n).map(|i| end * i as f64 / (n - 1) as f64).collect::<Vec<f64>>();
        let mut jobs: Vec<TransientJob> =
            (0..70).map(|i| takeoff_job(grid(11 + i % 3, 2.0 + (i % 5) as f64), 150.0 + i as f64)).collect();
        jobs[33].times_s = vec![0.0]; // one output time: refused by the engine
        let skips: Vec<usize> = (0..70).map(|i| i % 2).collect();
        let sel = Selection::from_names(&["turbine_torque_nm", "time_s", "stator_mode"]).unwrap();
        let never = AtomicBool::new(false);
        let one = run_transient_columns(&jobs, &skips, &sel, 1, &never).unwrap().unwrap();
        assert_eq!(one.offsets.len(), 71);
        assert_eq!(one.status.iter().filter(|&&s| s != RUN_OK).count(), 1);
        assert_eq!(one.status[33], RUN_INPUT_ERROR);
        assert!(
            matches!(&one.failures[..], [(33, RunFailure::Error(TransientError::Input(e)))] if e.field == "time_s")
        );
        for (i, job) in jobs.iter().enumerate() {
            let rows = one.offsets[i]..one.offsets[i + 1];
            if i == 33 {
                assert!(rows.is_empty());
                continue;
            }
            assert_eq!(rows.len(), job.times_s.len() - skips[i], "run {i}");
            let (cols, events) = run_transient_job(job).unwrap();
            for (k, &c) in sel.indices().iter().enumerate() {
                let want: Vec<u64> = cols[c][skips[i]..].iter().map(|x| x.to_bits()).collect();
                let got: Vec<u64> = one.columns[k][rows.clone()].iter().map(|x| x.to_bits()).collect();
                assert_eq!(got, want, "run {i}, column {c}");
            }
            let mine: Vec<Event> = one.events.iter().filter(|(r, _)| *r == i).map(|(_, e)| *e).collect();
            assert_eq!(mine, events, "run {i}");
        }
        assert!(!one.events.is_empty());
        for threads in [2, 3, 8] {
            let other = run_transient_columns(&jobs, &skips, &sel, threads, &never).unwrap().unwrap();
            assert_eq!((&other.offsets, &other.status), (&one.offsets, &one.status), "{threads} threads");
            for (a, b) in other.columns.iter().zip(&one.columns) {
                assert_eq!(
                    a.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                    b.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
                );
            }
            assert_eq!(other.events, one.events, "{threads} threads");
            assert_eq!(other.failures.len(), 1);
        }
        // a solver error's rows are NaN: a run made to fail by a step limit of one
        jobs[5].options.max_steps = 1;
        let failed = run_transient_columns(&jobs, &[0], &sel, 2, &never).unwrap().unwrap();
        assert_eq!(failed.status[5], RUN_SOLVER_ERROR);
        let rows = failed.offsets[5]..failed.offsets[6];
        assert!(!rows.is_empty() && failed.columns.iter().all(|c| c[rows.clone()].iter().all(|x| x.is_nan())));
        assert_eq!(failed.columns[1][failed.offsets[6]..failed.offsets[7]], jobs[6].times_s[..]);
        let cancel = AtomicBool::new(true);
        assert!(run_transient_columns(&jobs, &[0], &sel, 2, &cancel).unwrap().is_none());
        let empty = run_transient_columns(&jobs[..3], &[0], &Selection::from_names::<&str>(&[]).unwrap(), 2, &never);
        let empty = empty.unwrap().unwrap();
        assert!(empty.columns.is_empty() && empty.status == [RUN_OK; 3] && !empty.events.is_empty());
    }

    /// A batch computes only what its columns read ([`Selection::sampled`]: the loss power, the
    /// stored energy, the transferred torques): each column chosen alone is that column of a run
    /// with all of them, bit for bit, for Hrovat & Tobler, the table model (no stator, whose stator
    /// torque is the transferred torques' balance) and the quasi-dynamic model, with and without
    /// the lock-up clutch.
    #[test]
    fn each_column_chosen_alone_is_the_column_of_all_bit_for_bit() {
        use crate::converter::dynamics::tests::{bundled_ht, c1};
        use crate::converter::dynamics::{ConverterDynamics, Inertias, TableDynamics};
        use crate::converter::quasi_dynamic::QuasiDynamics;
        use crate::engine::isolated::Drive;
        use crate::engine::lockup::LockupCommand;
        use crate::engine::options::Sampled;
        use crate::engine::outputs::COLUMNS;
        use crate::engine::signal::Signal;
        let inertia = Inertias::new(0.109, 0.056, 0.01).unwrap();
        let model = |kind: usize| -> Box<dyn ConverterDynamics + Send> {
            match kind {
                0 => Box::new(bundled_ht()),
                1 => Box::new(TableDynamics { characteristic: c1().into(), inertia, lag: None }),
                _ => Box::new(QuasiDynamics::new(c1().into(), inertia, 840.0, 0.12, [0.006, 0.002], 0.05).unwrap()),
            }
        };
        let times: Vec<f64> = (0..301).map(|i| i as f64 * 0.01).collect();
        let never = AtomicBool::new(false);
        assert_eq!(Selection::all().sampled(), Sampled::ALL);
        assert_eq!(Selection::from_names::<&str>(&[]).unwrap().sampled(), Sampled::NONE);
        for kind in 0..3 {
            for clutch in [false, true] {
                let mut job = takeoff_job(times.clone(), 250.0);
                job.model = model(kind);
                if clutch {
                    let capacity = Signal::new("c", vec![0.0, 1.0, 1.5, 3.0], vec![0.0, 0.0, 600.0, 600.0], 0.0);
                    if let Drive::PumpTorqueLoad { lockup, .. } = &mut job.drive {
                        *lockup = Some(LockupCommand::new(capacity.unwrap(), 1.2).unwrap());
                    }
                }
                let jobs = [job];
                let all = run_transient_columns(&jobs, &[0], &Selection::all(), 1, &never).unwrap().unwrap();
                assert!(all.failures.is_empty());
                for (c, name) in COLUMNS.iter().enumerate() {
                    let sel = Selection::from_names(&[*name]).unwrap();
                    let alone = run_transient_columns(&jobs, &[0], &sel, 1, &never).unwrap().unwrap();
                    let differs =
                        alone.columns[0].iter().zip(&all.columns[c]).position(|(a, b)| a.to_bits() != b.to_bits());
                    assert_eq!(differs, None, "model {kind}, {name}, clutch {clutch}: the first sample that differs");
                    assert_eq!(alone.events, all.events);
                }
            }
        }
    }

    #[test]
    fn ratio_gradients_match_finite_differences() {
        let g = HtGeometry::appendix_d();
        let sr = [0.0, 0.4, 0.8, 0.95];
        let free = [HtParam::PumpExitAngle, HtParam::FrictionLoss, HtParam::PumpExitRadius];
        let (tr, cf, dtr, dcf) = ht_ratio_gradients(&g, 209.4, &sr, &free);
        for (j, p) in free.iter().enumerate() {
            let h = 1e-7;
            let mut v = g.values;
            v[p.index()] += h;
            let (tr2, cf2, _, _) = ht_ratio_gradients(&HtGeometry { values: v }, 209.4, &sr, &[]);
            for i in 0..sr.len() {
                let (fd_tr, fd_cf) = ((tr2[i] - tr[i]) / h, (cf2[i] - cf[i]) / h);
                assert!(
                    (dtr[i * 3 + j] - fd_tr).abs() < 1e-5 * (1.0 + fd_tr.abs()),
                    "{} SR {}: {} vs {fd_tr}",
                    p.key(),
                    sr[i],
                    dtr[i * 3 + j]
                );
                assert!((dcf[i * 3 + j] - fd_cf).abs() < 1e-5 * (1e-3 + fd_cf.abs()), "{} SR {}", p.key(), sr[i]);
            }
        }
    }
}
