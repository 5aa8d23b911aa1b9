//! Wall time of the isolated Hrovat & Tobler take-off (the `bench/` scenario) in pure Rust:
//! `cargo run --release --example takeoff_timing`.
use std::time::Instant;

use tcsim_core::converter::dynamics::{HtDynamics, Inertias};
use tcsim_core::converter::hrovat_tobler::HtGeometry;
use tcsim_core::engine::isolated::{simulate, Drive, InitialState, TurbineLoad};
use tcsim_core::engine::options::SolverOptions;
use tcsim_core::engine::outputs::columns;
use tcsim_core::engine::signal::Signal;

fn main() {
    let model = HtDynamics::new(
        HtGeometry::appendix_d(),
        Inertias::new(0.109, 0.056, 0.01).unwrap(),
        0.2914,
        [-0.00569, 0.00134, 0.0009],
    )
    .unwrap();
    let drive = Drive::PumpTorqueLoad {
        pump_torque_nm: Signal::new("pump_torque_nm", vec![0.0, 0.1, 0.3, 10.0], vec![40.0, 40.0, 250.0, 250.0], 0.0)
            .unwrap(),
        load: TurbineLoad { torque_nm: Signal::constant(10.0), inertia_kg_m2: 1.2, drag_nm_s2: 0.002 },
        lockup: None,
    };
    let t: Vec<f64> = (0..=1000).map(|i| i as f64 * 0.01).collect();
    let mut times = Vec::new();
    let mut steps = 0;
    for _ in 0..200 {
        let start = Instant::now();
        let traj = simulate(&model, &drive, &t, &InitialState::default(), &SolverOptions::default()).unwrap();
        let cols = columns(&model, &traj).expect("the columns fit in memory");
        times.push(start.elapsed().as_secs_f64());
        steps = traj.steps;
        std::hint::black_box(cols);
    }
    times.sort_by(f64::total_cmp);
    println!("median {:.1} µs, min {:.1} µs, {steps} steps", times[100] * 1e6, times[0] * 1e6);
}
