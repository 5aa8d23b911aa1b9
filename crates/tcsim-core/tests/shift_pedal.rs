//! The TCU's filtered pedal for the shift schedule (`vehicle::shift_pedal`) in a launch: a lift of
//! the pedal upshifts later through the filter, the energy still balances, and the full-pedal
//! launch is the one without the filter.

mod common;

use common::*;
use tcsim_core::engine::options::SolverOptions;
use tcsim_core::engine::signal::Signal;
use tcsim_core::vehicle::launch::*;
use tcsim_core::vehicle::parameters::*;
use tcsim_core::vehicle::shift_pedal::PedalFilter;

fn sedan(filter: PedalFilter) -> Vehicle {
    let mut v = tcsim_core::vehicle::file::read_vehicle(include_str!("data/sedan.toml"))
        .unwrap_or_else(|e| panic!("{e}"))
        .vehicle;
    v.gearbox.shift_pedal = filter;
    v
}

/// Brake to 5 s, pedal `pedal` from 5.05 s, lifted to 0.1 at `lift_s` (within 0.05 s).
fn lift(pedal: f64, lift_s: f64, end: f64) -> Scenario {
    let t = vec![0.0, 5.0, 5.05, lift_s, lift_s + 0.05, end];
    Scenario {
        accelerator_pedal: Signal::new("accelerator_pedal", t.clone(), vec![0.0, 0.0, pedal, pedal, 0.1, 0.1], 0.0)
            .unwrap(),
        brake_pedal: Signal::new("brake_pedal", t, vec![1.0, 1.0, 0.0, 0.0, 0.0, 0.0], 0.0).unwrap(),
        end_time_s: end,
        stop_speed_m_s: None,
        engine_torque_nm: None,
        shift_pedal: None,
    }
}

fn upshifts(r: &LaunchTrajectory) -> Vec<f64> {
    r.events.iter().filter(|e| e.kind == "upshift-start").map(|e| e.time_s).collect()
}

/// Engine work minus losses, stored-energy change and event losses, over the engine work.
fn residual(r: &LaunchTrajectory) -> f64 {
    let s = &r.samples;
    let mut work = 0.0;
    let mut loss = 0.0;
    for w in s.windows(2) {
        let h = 0.5 * (w[1].time_s - w[0].time_s);
        work += h * (w[0].engine_power_w + w[1].engine_power_w);
        loss += h * (w[0].loss_power_w + w[1].loss_power_w);
    }
    let events: f64 = r.event_loss_j.iter().map(|e| e.1).sum();
    (work - loss - events - (s[s.len() - 1].stored_energy_j - s[0].stored_energy_j)) / work
}

#[test]
fn a_lift_upshifts_later_through_the_filter_and_the_energy_balances() {
    let options = SolverOptions { rtol: 1e-8, ..SolverOptions::default() };
    let sc = lift(0.8, 9.0, 15.0);
    let raw = simulate_launch(&table(), &sedan(PedalFilter::default()), &sc, 0.001, &options).unwrap();
    let held = PedalFilter { rise_s: 0.0, fall_s: 3.0 };
    let filtered = simulate_launch(&table(), &sedan(held), &sc, 0.001, &options).unwrap();
    // the same until the lift (a press passes at once without a rise time constant)
    let before = |r: &LaunchTrajectory| upshifts(r).into_iter().filter(|&t| t < 9.0).collect::<Vec<_>>();
    assert_eq!(before(&raw), before(&filtered));
    // raw, the lift upshifts at once; filtered, the gear is held for a while
    let after = |r: &LaunchTrajectory| upshifts(r).into_iter().find(|&t| t >= 9.0);
    let (a, b) = (after(&raw).expect("the raw lift upshifts"), after(&filtered).expect("and the filtered later"));
    assert!(a < 9.1, "{a} {:?}", raw.events);
    assert!(b > a + 0.5, "{a} {b} {:?}", raw.events);
    for r in [&raw, &filtered] {
        assert!(residual(r).abs() < 1e-4, "{}", residual(r));
    }
}

#[test]
fn the_full_pedal_launch_passes_the_filter() {
    let sc = lift(1.0, 15.0, 15.5);
    let options = SolverOptions::default();
    let raw = simulate_launch(&table(), &sedan(PedalFilter::default()), &sc, 0.01, &options).unwrap();
    let held = PedalFilter { rise_s: 0.5, fall_s: 3.0 };
    let filtered = simulate_launch(&table(), &sedan(held), &sc, 0.01, &options).unwrap();
    let full = |r: &LaunchTrajectory| upshifts(r).into_iter().filter(|&t| t < 15.0).collect::<Vec<_>>();
    assert!(full(&raw).len() >= 2, "{:?}", raw.events);
    assert_eq!(full(&raw), full(&filtered));
}
