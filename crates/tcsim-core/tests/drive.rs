//! Drive cycles (issue 14): the driver follows a trace, the energy balance closes, coasting brakes
//! the engine through the converter.

mod common;

use common::*;
use tcsim_core::converter::dynamics::ConverterDynamics;
use tcsim_core::engine::options::SolverOptions;
use tcsim_core::vehicle::cycle::*;
use tcsim_core::vehicle::parameters::Vehicle;
use tcsim_core::vehicle::SPEED;

fn sedan() -> Vehicle {
    tcsim_core::vehicle::file::read_vehicle(include_str!("data/sedan.toml")).unwrap_or_else(|e| panic!("{e}")).vehicle
}

/// Stand 2 s, 1 m/s² to 15 m/s, cruise, −1.5 m/s² to rest, stand.
fn trace() -> Trace {
    let t: Vec<f64> = (0..=45).map(f64::from).collect();
    let v = t
        .iter()
        .map(|&t| match t {
            t if t < 2.0 => 0.0,
            t if t < 17.0 => t - 2.0,
            t if t < 27.0 => 15.0,
            t => (15.0 - 1.5 * (t - 27.0)).max(0.0),
        })
        .collect();
    Trace::new(t, v, None).unwrap()
}

/// The solver options of a drive (the binding's default tolerance).
fn options() -> SolverOptions {
    SolverOptions { rtol: DRIVE_RTOL, ..SolverOptions::default() }
}

fn models() -> Vec<(&'static str, Box<dyn ConverterDynamics>)> {
    vec![
        ("table", Box::new(table())),
        ("quasi-dynamic", Box::new(qd(0.00569, 0.00134))),
        ("hrovat-tobler", Box::new(ht_fitted(SHAPE))),
    ]
}

#[test]
fn driver_follows_a_trace_and_the_energy_balances() {
    for (name, m) in models() {
        let traj = simulate_drive(m.as_ref(), &sedan(), &trace(), &Driver::default(), &options())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let s = &traj.run.samples;
        let err: Vec<f64> = traj.target_m_s.iter().zip(s).map(|(t, s)| t - s.u[SPEED]).collect();
        let rms = (err.iter().map(|e| e * e).sum::<f64>() / err.len() as f64).sqrt();
        assert!(rms < 1.0 / 3.6, "{name}: rms {rms} m/s");
        let e = traj.energies.last().unwrap();
        let stored = s.last().unwrap().stored_energy_j - s[0].stored_energy_j;
        let residual = e.engine_work_j - stored - e.loss_j - e.event_loss_j;
        assert!(residual.abs() < 1e-4 * e.engine_work_j, "{name}: residual {residual} J of {} J", e.engine_work_j);
        assert!(e.brake_j > 0.0 && e.converter_loss_j > 0.0, "{name}: {e:?}");
        // at rest at the end, held by the brake
        assert!(s.last().unwrap().u[SPEED].abs() < 1e-3, "{name}");
        println!("{name}: rms {rms:.4} m/s, residual {:.2e}, {e:?}", residual / e.engine_work_j);
    }
}

/// The solver's step budget (`max_steps`, sized for a launch of seconds) holds for each control
/// step: over a whole drive it made any trace longer than about an hour a solver failure.
#[test]
fn the_step_limit_holds_for_each_control_step_not_the_whole_drive() {
    let m = table();
    let full = simulate_drive(&m, &sedan(), &trace(), &Driver::default(), &options()).unwrap();
    let limited = SolverOptions { max_steps: full.run.steps / 4, ..options() };
    let again = simulate_drive(&m, &sedan(), &trace(), &Driver::default(), &limited).unwrap_or_else(|e| {
        panic!("{} steps in all, at most {} per control step: {e}", full.run.steps, limited.max_steps)
    });
    assert_eq!((again.run.steps, again.run.samples.len()), (full.run.steps, full.run.samples.len()));
    let starved = SolverOptions { max_steps: 1, ..options() };
    assert!(simulate_drive(&m, &sedan(), &trace(), &Driver::default(), &starved).is_err());
}
