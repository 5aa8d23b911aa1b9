//! Cross-check of the NDF/BDF integrator against diffsol's BDF (a dev-dependency only): the old
//! diffsol segment loop is kept here, selected per thread by [`with_diffsol`], and whole runs
//! (isolated take-offs with the three models, a lock-up engagement, a vehicle launch, a piece of a
//! drive cycle) are compared sample by sample and event by event.
//!
//! Bound: both solvers keep the local error per step below `atol_i + rtol |x_i|`; their global
//! errors accumulate over hundreds of steps and events, and an event time moved by the tolerance
//! shifts the fast transient after it, so pointwise they differ by a multiple of the tolerance that
//! depends on the run. Each run is therefore also solved at `rtol = 1e-11` (the reference), and the
//! check is that the new solver is at least about as accurate as diffsol:
//! `max |x_new − x_ref| ≤ max(20, 2 · max |x_diffsol − x_ref|)`, in units of
//! `atol_i + rtol max|x_i|` (per coordinate over all samples; `max|x_i|` over the run, so that a
//! speed that passes through zero is compared at the run's scale), with the same events, their
//! times as close to the reference's: `max |t_new − t_ref| ≤ max(1e-4 s, 2 max |t_diffsol − t_ref|)`
//! (an event time is uncertain by the state error over the root function's rate, large where an
//! event function crosses slowly). The factor 2 is the scatter of these errors between two solvers
//! of the same tolerance. Over the 12 runs here the new solver's error is 0.01–1.3 times diffsol's
//! (16–110× smaller on the table and quasi-dynamic launches and drive cycles, 1.3× larger on the
//! Hrovat & Tobler take-off with lock-up), its event-time error 0.16–1.3 times diffsol's.. The numbers are printed (`cargo test -- --nocapture crosscheck`).

use std::cell::Cell;

use diffsol::{NalgebraLU, NalgebraMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason};

use crate::engine::options::{SolverOptions, TransientError, TransientResult};
use crate::engine::segment::{SegmentEnd, SmoothSegment};

type Matrix = NalgebraMat<f64>;
type Lu = NalgebraLU<f64>;

thread_local! {
    static DIFFSOL: Cell<bool> = const { Cell::new(false) };
}

/// Whether [`crate::engine::segment::run_segment`] runs diffsol on this thread.
pub(crate) fn diffsol_selected() -> bool {
    DIFFSOL.with(Cell::get)
}

/// Run `f` with diffsol as the segment solver on this thread.
pub(crate) fn with_diffsol<T>(f: impl FnOnce() -> T) -> T {
    DIFFSOL.with(|d| d.set(true));
    let out = f();
    DIFFSOL.with(|d| d.set(false));
    out
}

/// The diffsol segment loop of tcsim ≤ 0.x (main before the NDF integrator), unchanged.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_segment<S: SmoothSegment>(
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

#[cfg(test)]
mod runs {
    use super::with_diffsol;
    use crate::converter::dynamics::{ConverterDynamics, HtDynamics, Inertias, TableDynamics};
    use crate::converter::hrovat_tobler::HtGeometry;
    use crate::converter::quasi_dynamic::QuasiDynamics;
    use crate::converter::table::Characteristic;
    use crate::engine::isolated::{simulate, Drive, InitialState, TurbineLoad};
    use crate::engine::lockup::LockupCommand;
    use crate::engine::options::SolverOptions;
    use crate::engine::signal::Signal;
    use crate::vehicle::cycle::{simulate_drive, Driver, Trace, DRIVE_RTOL};
    use crate::vehicle::launch::{simulate_launch, LaunchTrajectory};
    use crate::vehicle::parameters::Scenario;
    use crate::vehicle::parameters::Vehicle;

    /// In units of `atol_i + rtol max|x_i|`: the error that always passes, and the factor on diffsol's.
    const FLOOR: f64 = 20.0;
    const FACTOR: f64 = 2.0;
    const EVENT_FLOOR_S: f64 = 1e-4;
    const VEHICLE_ATOL: [f64; 12] = [1e-5, 1e-5, 1e-5, 1e-8, 1e-5, 1e-5, 1e-5, 1e-6, 1e-7, 1e-7, 1e-4, 1e-4];

    fn c1() -> Characteristic {
        Characteristic::new(
            vec![0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0],
            vec![2.14, 1.99, 1.84, 1.70, 1.56, 1.43, 1.30, 1.18, 1.06, 1.00, 1.00, 1.00, 1.00],
            vec![
                3.272e-3, 3.257e-3, 3.228e-3, 3.181e-3, 3.112e-3, 3.017e-3, 2.887e-3, 2.713e-3, 2.481e-3, 2.370e-3,
                1.842e-3, 1.237e-3, 0.187e-3,
            ],
        )
        .unwrap()
    }

    fn models() -> Vec<(&'static str, Box<dyn ConverterDynamics>)> {
        let inertia = Inertias::new(0.109, 0.056, 0.01).unwrap();
        let shape = [-0.00569, 0.00134, 0.00090];
        vec![
            ("hrovat-tobler", Box::new(HtDynamics::new(HtGeometry::appendix_d(), inertia, 0.2914, shape).unwrap())),
            ("table", Box::new(TableDynamics { characteristic: c1().into(), inertia, lag: None })),
            (
                "quasi-dynamic",
                Box::new(QuasiDynamics::new(c1().into(), inertia, 840.0, 0.12, [0.00569, 0.00134], 0.03).unwrap()),
            ),
        ]
    }

    fn signal(name: &str, t: &[f64], v: &[f64]) -> Signal {
        Signal::new(name, t.to_vec(), v.to_vec(), 0.0).unwrap()
    }

    /// Drive (c) of the take-off (tests/common), with a tip-out, and optionally a lock-up
    /// clutch that engages from 6 s.
    fn takeoff(lockup: bool) -> Drive {
        let t = [0.0, 0.1, 0.3, 5.0, 5.1, 10.0];
        let torque = signal("pump_torque_nm", &t, &[40.0, 40.0, 250.0, 250.0, -30.0, -30.0]);
        let lockup = lockup.then(|| {
            LockupCommand::new(signal("lockup_capacity_nm", &[0.0, 6.0, 6.5, 10.0], &[0.0, 0.0, 400.0, 400.0]), 1.2)
                .unwrap()
        });
        let load = TurbineLoad { torque_nm: Signal::constant(10.0), inertia_kg_m2: 1.2, drag_nm_s2: 0.002 };
        Drive::PumpTorqueLoad { pump_torque_nm: torque, load, lockup }
    }

    /// The largest `|Δx_i| / (atol_i + rtol max|x_i|)` over samples and coordinates.
    fn worst(a: &[(f64, Vec<f64>)], b: &[(f64, Vec<f64>)], atol: &[f64], rtol: f64) -> f64 {
        assert_eq!(a.len(), b.len());
        let scale: Vec<f64> =
            (0..atol.len()).map(|i| atol[i] + rtol * a.iter().map(|s| s.1[i].abs()).fold(0.0, f64::max)).collect();
        let mut w: f64 = 0.0;
        for (sa, sb) in a.iter().zip(b) {
            assert_eq!(sa.0, sb.0);
            for (i, s) in scale.iter().enumerate() {
                w = w.max((sa.1[i] - sb.1[i]).abs() / s);
            }
        }
        w
    }

    /// The same events as diffsol and the reference; the largest event-time error of the new run and
    /// of diffsol's against the reference, s.
    fn events_agree(
        what: &str,
        new: &[(f64, String)],
        old: &[(f64, String)],
        reference: &[(f64, String)],
    ) -> (f64, f64) {
        let kinds = |e: &[(f64, String)]| e.iter().map(|x| x.1.clone()).collect::<Vec<_>>();
        assert_eq!(kinds(new), kinds(old), "{what}: event kinds");
        assert_eq!(kinds(new), kinds(reference), "{what}: event kinds");
        let error = |e: &[(f64, String)]| e.iter().zip(reference).map(|(x, y)| (x.0 - y.0).abs()).fold(0.0, f64::max);
        (error(new), error(old))
    }

    type Run = (Vec<(f64, Vec<f64>)>, Vec<(f64, String)>);

    /// Check the new run against diffsol's and a reference (see the module's doc).
    fn compare(what: &str, new: &Run, old: &Run, reference: &Run, atol: &[f64], rtol: f64) {
        let (de_new, de_old) = events_agree(what, &new.1, &old.1, &reference.1);
        let (e_new, e_old) = (worst(&new.0, &reference.0, atol, rtol), worst(&old.0, &reference.0, atol, rtol));
        let apart = worst(&new.0, &old.0, atol, rtol);
        println!(
            "{what}: error new {e_new:.1}, diffsol {e_old:.1}, apart {apart:.1}; {} events, time error new {de_new:.1e} s, diffsol {de_old:.1e} s",
            new.1.len()
        );
        assert!(e_new <= FLOOR.max(FACTOR * e_old), "{what}: error {e_new:.1} vs diffsol's {e_old:.1}");
        assert!(
            de_new <= EVENT_FLOOR_S.max(FACTOR * de_old),
            "{what}: event times {de_new:e} s from the reference, diffsol's {de_old:e} s"
        );
    }

    fn tight(o: &SolverOptions) -> SolverOptions {
        SolverOptions { rtol: 1e-11, speed_atol_rad_s: 1e-10, flow_atol_m3_s: 1e-13, ..*o }
    }

    #[test]
    fn isolated_runs_agree_with_diffsol() {
        let o = SolverOptions::default();
        let times: Vec<f64> = (0..=1000).map(|i| i as f64 * 0.01).collect();
        for (name, model) in models() {
            for lockup in [false, true] {
                let drive = takeoff(lockup);
                let run = |o: &SolverOptions| {
                    let t = simulate(model.as_ref(), &drive, &times, &InitialState::default(), o).unwrap();
                    let s = t.samples.iter().map(|s| (s.time_s, s.u.to_vec())).collect::<Vec<_>>();
                    let e = t.events.iter().map(|e| (e.time_s, format!("{:?}", e.kind))).collect::<Vec<_>>();
                    (s, e)
                };
                let (new, old, reference) = (run(&o), with_diffsol(|| run(&o)), run(&tight(&o)));
                let atol = [o.speed_atol_rad_s, o.speed_atol_rad_s, o.speed_atol_rad_s, o.flow_atol_m3_s];
                compare(&format!("{name} lockup={lockup}"), &new, &old, &reference, &atol, o.rtol);
            }
        }
    }

    fn sedan() -> Vehicle {
        let text = include_str!("../../../tests/data/sedan.toml");
        crate::vehicle::file::read_vehicle(text).unwrap_or_else(|e| panic!("{e}")).vehicle
    }

    fn pick(r: &LaunchTrajectory) -> Run {
        let s = r.samples.iter().map(|s| (s.time_s, s.u.to_vec())).collect();
        let e = r.events.iter().map(|e| (e.time_s, e.kind.to_string())).collect();
        (s, e)
    }

    #[test]
    fn a_vehicle_launch_and_a_drive_cycle_agree_with_diffsol() {
        let o = SolverOptions::default();
        let t = [0.0, 2.0, 2.05, 25.0];
        let sc = Scenario {
            accelerator_pedal: signal("accelerator_pedal", &t, &[0.0, 0.0, 0.8, 0.8]),
            brake_pedal: signal("brake_pedal", &t, &[1.0, 1.0, 0.0, 0.0]),
            end_time_s: 25.0,
            stop_speed_m_s: None,
            engine_torque_nm: None,
            shift_pedal: None,
        };
        let tt: Vec<f64> = (0..=20).map(f64::from).collect();
        let v: Vec<f64> = tt.iter().map(|&t| if t < 2.0 { 0.0 } else { (t - 2.0).min(12.0) }).collect();
        let trace = Trace::new(tt, v, None).unwrap();
        let od = SolverOptions { rtol: DRIVE_RTOL, ..o };
        for (name, model) in models() {
            let launch = |o: &SolverOptions| pick(&simulate_launch(model.as_ref(), &sedan(), &sc, 0.01, o).unwrap());
            let (new, old, reference) = (launch(&o), with_diffsol(|| launch(&o)), launch(&tight(&o)));
            compare(&format!("launch {name}"), &new, &old, &reference, &VEHICLE_ATOL, o.rtol);
            let drive = |o: &SolverOptions| {
                pick(&simulate_drive(model.as_ref(), &sedan(), &trace, &Driver::default(), o).unwrap().run)
            };
            let (new, old, reference) = (drive(&od), with_diffsol(|| drive(&od)), drive(&tight(&od)));
            compare(&format!("drive {name}"), &new, &old, &reference, &VEHICLE_ATOL, od.rtol);
        }
    }
}
