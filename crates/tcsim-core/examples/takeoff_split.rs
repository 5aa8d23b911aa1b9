//! Where the wall time of the isolated take-off goes (integration, sampling, columns):
//! `cargo run --release --example takeoff_split`.
use std::time::Instant;

use tcsim_core::converter::dynamics::{HtDynamics, Inertias};
use tcsim_core::converter::hrovat_tobler::HtGeometry;
use tcsim_core::engine::isolated::{simulate, Drive, InitialState, TurbineLoad};
use tcsim_core::engine::options::SolverOptions;
use tcsim_core::engine::outputs::columns;
use tcsim_core::engine::signal::Signal;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2] * 1e6
}

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
    let dense: Vec<f64> = (0..=1000).map(|i| i as f64 * 0.01).collect();
    let sparse = vec![0.0, 10.0];
    let o = SolverOptions::default();
    if let Ok(mode) = std::env::var("TAKEOFF_ONLY") {
        // one part alone, for a profiler: `integration`, `sampling` (with columns)
        let t = if mode == "integration" { &sparse } else { &dense };
        for _ in 0..200 {
            let traj = simulate(&model, &drive, t, &InitialState::default(), &o).unwrap();
            std::hint::black_box(columns(&model, &traj).expect("the columns fit in memory"));
        }
        return;
    }
    let (mut a, mut b, mut c) = (vec![], vec![], vec![]);
    let mut steps = 0;
    for _ in 0..2000 {
        let s = Instant::now();
        let traj = simulate(&model, &drive, &sparse, &InitialState::default(), &o).unwrap();
        a.push(s.elapsed().as_secs_f64());
        std::hint::black_box(traj);
        let s = Instant::now();
        let traj = simulate(&model, &drive, &dense, &InitialState::default(), &o).unwrap();
        b.push(s.elapsed().as_secs_f64());
        let s = Instant::now();
        let cols = columns(&model, &traj).expect("the columns fit in memory");
        c.push(s.elapsed().as_secs_f64());
        steps = traj.steps;
        std::hint::black_box(cols);
    }
    let (a, b, c) = (median(a), median(b), median(c));
    println!(
        "integration {a:.1} µs, sampling {:.1} µs, columns {c:.1} µs; total {:.1} µs; {steps} steps",
        b - a,
        b + c
    );
}
