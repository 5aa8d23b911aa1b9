//! Where the time of one isolated Hrovat & Tobler take-off goes (issue 16, item 2): the bundled
//! `li-sunden-2016` converter (geometry of Table D.1, its derived fluid length and shape effects),
//! drive c of `bench/` (pump torque 40 → 250 N·m over 0.1–0.3 s, load 1.2 kg·m², 10 N·m,
//! 0.002 N·m/(rad/s)²), 10 s, SAMPLES equally spaced samples, default solver options.
//!
//! `cargo run --release --example takeoff_profile -- [RUNS] [SAMPLES]` (default 200, 1001) prints
//! the steps per run and the median wall time of the two phases: `simulate` (integration with its
//! sampling) and `columns` (the 27 output columns). For counts and the split by function, run it
//! under `valgrind --tool=callgrind` with two run counts and take the difference (bench/README.md).
use std::time::Instant;

use tcsim_core::converter::dynamics::{HtDynamics, Inertias};
use tcsim_core::converter::hrovat_tobler::HtGeometry;
use tcsim_core::engine::isolated::{simulate, Drive, InitialState, TurbineLoad};
use tcsim_core::engine::options::SolverOptions;
use tcsim_core::engine::outputs::columns;
use tcsim_core::engine::signal::Signal;

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<usize> = std::env::args().skip(1).map(|a| a.parse().expect("RUNS SAMPLES: integers")).collect();
    let runs = args.first().copied().unwrap_or(200).max(1);
    let samples = args.get(1).copied().unwrap_or(1001).max(2);
    // python/tcsim/data/converters/li-sunden-2016.toml
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
