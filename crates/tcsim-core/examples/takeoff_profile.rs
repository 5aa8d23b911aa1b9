//! Where the time of one isolated Hrovat & Tobler take-off goes (issue 16, item 2): the bundled
//! `li-sunden-2016` converter (geometry of Table D.1, its derived fluid length and shape effects),
//! drive c of `bench/` (pump torque 40 → 250 N·m over 0.1–0.3 s, load 1.2 kg·m², 10 N·m,
//! 0.002 N·m/(rad/s)²), 10 s, SAMPLES equally spaced samples, default solver options.
//!
//! `cargo run --release --example takeoff_profile -- [RUNS] [SAMPLES]` (default 200, 1001) prints
//! the steps per run and the median wall time of the two phases: `simulate` (integration with its
//! sampling) and `columns` (the 27 output columns). For counts and the split by function, run it
//! under `valgrind --tool=callgrind` with two run counts and take the difference (bench/README.md).
//!
//! `... --example takeoff_profile -- batch RUNS SAMPLES THREADS...` runs RUNS take-offs as one batch
//! ([`run_transient_jobs`], the core of `simulate_batch` without Python) with each thread count and
//! prints the wall time and the process's CPU time (user + system, from `/proc/self/stat`) per run,
//! and the speed-up over the first thread count. `... -- columns RUNS SAMPLES THREADS...` does the
//! same through [`run_transient_columns`] with all 33 columns (the columnar batch of
//! `simulate_columns`: one buffer per column for all runs, written by the workers). `... -- peer RUNS
//! SAMPLES` times one take-off per call with the 9 columns of the C + CVODE peer, the core of
//! Python's `simulate(..., columns=...)` without the binding.
use std::time::Instant;

use tcsim_core::batch::{run_transient_columns, run_transient_jobs, TransientJob};
use tcsim_core::converter::dynamics::{HtDynamics, Inertias};
use tcsim_core::converter::hrovat_tobler::HtGeometry;
use tcsim_core::engine::isolated::{simulate, Drive, InitialState, TurbineLoad};
use tcsim_core::engine::options::SolverOptions;
use tcsim_core::engine::outputs::{columns, Selection};
use tcsim_core::engine::signal::Signal;

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The bundled converter (python/tcsim/data/converters/li-sunden-2016.toml) and drive c of `bench/`.
fn takeoff() -> (HtDynamics, Drive) {
    let model = HtDynamics::new(
        HtGeometry::appendix_d(),
        Inertias::new(0.109, 0.056, 0.01).unwrap(),
        0.2914,
        [0.001310, 0.002324, 0.001723],
    )
    .unwrap();
    let drive = Drive::PumpTorqueLoad {
        pump_torque_nm: Signal::new("pump_torque_nm", vec![0.0, 0.1, 0.3, 10.0], vec![40.0, 40.0, 250.0, 250.0], 0.0)
            .unwrap(),
        load: TurbineLoad { torque_nm: Signal::constant(10.0), inertia_kg_m2: 1.2, drag_nm_s2: 0.002 },
        lockup: None,
    };
    (model, drive)
}

/// CPU time of this process so far (user + system), s; clock ticks of 1/100 s (Linux).
fn cpu_time_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("Linux /proc");
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap_or("").split_whitespace().collect();
    // after the command name: state is field 3, utime 14 and stime 15 (1-based, proc(5))
    let tick = |i: usize| fields[i - 3].parse::<f64>().unwrap_or(0.0) / 100.0;
    tick(14) + tick(15)
}

fn batch(runs: usize, samples: usize, threads: &[usize], columnar: bool) {
    let (model, drive) = takeoff();
    let t: Vec<f64> = (0..samples).map(|i| 10.0 * i as f64 / (samples - 1) as f64).collect();
    let jobs: Vec<TransientJob> = (0..runs)
        .map(|_| TransientJob {
            model: Box::new(model.clone()),
            drive: drive.clone(),
            times_s: t.clone(),
            init: InitialState::default(),
            options: SolverOptions::default(),
        })
        .collect();
    let mut first = None;
    for &n in threads {
        let (cpu0, start) = (cpu_time_s(), Instant::now());
        if columnar {
            let never = std::sync::atomic::AtomicBool::new(false);
            let out = run_transient_columns(&jobs, &[0], &Selection::all(), n, &never);
            assert!(out.is_ok_and(|o| o.is_some_and(|o| o.failures.is_empty())));
        } else {
            let out = run_transient_jobs(&jobs, n);
            assert!(out.iter().all(Result::is_ok));
        }
        let (wall, cpu) = (start.elapsed().as_secs_f64(), cpu_time_s() - cpu0);
        let base = *first.get_or_insert(wall);
        println!(
            "{runs} runs, {samples} samples, {n} threads: {:.1} µs/run wall, {:.1} µs/run CPU, speed-up {:.2}",
            wall / runs as f64 * 1e6,
            cpu / runs as f64 * 1e6,
            base / wall
        );
    }
}

/// The 9 columns the C + CVODE peer of `bench/` writes, by their tcsim names: time, the four
/// coordinates, the three torques and the power lost in the fluid. The same list as
/// `bench/cvode_peer.py` `TCSIM_COLUMNS`, which the Python benchmarks use (keep the two alike).
const PEER_COLUMNS: [&str; 9] = [
    "time_s",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
    "stator_speed_rad_s",
    "flow_m3_s",
    "pump_torque_nm",
    "turbine_torque_nm",
    "stator_torque_nm",
    "fluid_loss_power_w",
];

/// One take-off per call of [`run_transient_columns`] with the peer's columns, as Python's
/// `simulate(..., columns=...)` runs it without the binding: the median wall time per call.
fn peer(runs: usize, samples: usize) {
    let (model, drive) = takeoff();
    let t: Vec<f64> = (0..samples).map(|i| 10.0 * i as f64 / (samples - 1) as f64).collect();
    let selection = Selection::from_names(&PEER_COLUMNS).expect("known columns");
    let never = std::sync::atomic::AtomicBool::new(false);
    let mut wall = Vec::with_capacity(runs);
    for _ in 0..runs {
        let job = TransientJob {
            model: Box::new(model.clone()),
            drive: drive.clone(),
            times_s: t.clone(),
            init: InitialState::default(),
            options: SolverOptions::default(),
        };
        let start = Instant::now();
        let out = run_transient_columns(std::slice::from_ref(&job), &[0], &selection, 1, &never);
        wall.push(start.elapsed().as_secs_f64());
        assert!(out.is_ok_and(|o| o.is_some_and(|o| o.failures.is_empty())));
    }
    println!("{runs} runs, {samples} samples, the peer's 9 columns: median {:.1} µs per run", median(&mut wall) * 1e6);
}

fn main() {
    let words: Vec<String> = std::env::args().skip(1).collect();
    let columnar = words.first().is_some_and(|w| w == "columns");
    let is_peer = words.first().is_some_and(|w| w == "peer");
    let is_batch = columnar || is_peer || words.first().is_some_and(|w| w == "batch");
    let args: Vec<usize> = words
        .iter()
        .skip(usize::from(is_batch))
        .map(|a| a.parse().expect("RUNS SAMPLES [THREADS...]: integers"))
        .collect();
    let runs = args.first().copied().unwrap_or(200).max(1);
    let samples = args.get(1).copied().unwrap_or(1001).max(2);
    if is_peer {
        return peer(runs, samples);
    }
    if is_batch {
        let threads = if args.len() > 2 { args[2..].to_vec() } else { vec![1, 2] };
        return batch(runs, samples, &threads, columnar);
    }
    let (model, drive) = takeoff();
    let t: Vec<f64> = (0..samples).map(|i| 10.0 * i as f64 / (samples - 1) as f64).collect();
    let (mut sim, mut col) = (Vec::new(), Vec::new());
    let mut steps = 0;
    for _ in 0..runs {
        let start = Instant::now();
        let traj = simulate(&model, &drive, &t, &InitialState::default(), &SolverOptions::default()).unwrap();
        let mid = Instant::now();
        let cols = columns(&model, &traj).expect("the columns fit in memory");
        let end = Instant::now();
        sim.push((mid - start).as_secs_f64());
        col.push((end - mid).as_secs_f64());
        steps = traj.steps;
        std::hint::black_box(cols);
    }
    let (s, c) = (median(&mut sim), median(&mut col));
    println!(
        "{runs} runs, {samples} samples, {steps} steps per run; median simulate {:.1} µs, columns {:.1} µs",
        s * 1e6,
        c * 1e6
    );
}
