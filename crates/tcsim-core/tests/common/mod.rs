//! Shared scenarios for the transient tests: the bundled li-sunden-2016 converter and the
//! isolated take-off of `bench/scipy_reference.py`.
// Each test binary includes this module and uses a different part of it.
#![allow(dead_code)]

use tcsim_core::converter::dynamics::{HtDynamics, Inertias, TableDynamics};
use tcsim_core::converter::hrovat_tobler::HtGeometry;
use tcsim_core::converter::quasi_dynamic::QuasiDynamics;
use tcsim_core::converter::table::Characteristic;
use tcsim_core::engine::isolated::{Drive, TurbineLoad};
use tcsim_core::engine::signal::Signal;

pub fn c1() -> Characteristic {
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

pub fn inertia() -> Inertias {
    Inertias::new(0.109, 0.056, 0.01).unwrap()
}

/// The bundled converter's shape effects (torus estimate, eqs 2.16–2.18).
pub const SHAPE: [f64; 3] = [-0.00569, 0.00134, 0.00090];

pub fn ht(shape: [f64; 3]) -> HtDynamics {
    HtDynamics::new(HtGeometry::appendix_d(), inertia(), 0.2914, shape).unwrap()
}

pub fn table() -> TableDynamics {
    TableDynamics { characteristic: c1().into(), inertia: inertia(), lag: None }
}

pub fn qd(sp: f64, st: f64) -> QuasiDynamics {
    QuasiDynamics::new(c1().into(), inertia(), 840.0, 0.12, [sp, st], 0.03).unwrap()
}

pub fn signal(name: &str, points: &[(f64, f64)]) -> Signal {
    Signal::new(name, points.iter().map(|p| p.0).collect(), points.iter().map(|p| p.1).collect(), 0.0).unwrap()
}

/// Pump torque of the isolated take-off: 40 N·m, ramp to 250 N·m over 0.1–0.3 s; with a tip-out,
/// a ramp to −30 N·m over 5.0–5.1 s.
pub fn takeoff_torque(tip_out: bool) -> Signal {
    let mut p = vec![(0.0, 40.0), (0.1, 40.0), (0.3, 250.0)];
    if tip_out {
        p.extend([(5.0, 250.0), (5.1, -30.0)]);
    }
    p.push((10.0, *p.last().map(|x: &(f64, f64)| &x.1).unwrap()));
    signal("pump_torque_nm", &p)
}

/// Drive (c): the take-off pump torque with the turbine loaded by 1.2 kg·m², 10 N·m and a drag
/// of 0.002 N·m/(rad/s)².
pub fn takeoff(tip_out: bool) -> Drive {
    Drive::PumpTorqueLoad {
        pump_torque_nm: takeoff_torque(tip_out),
        load: TurbineLoad { torque_nm: Signal::constant(10.0), inertia_kg_m2: 1.2, drag_nm_s2: 0.002 },
        lockup: None,
    }
}

pub fn grid(t0: f64, t1: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| t0 + (t1 - t0) * i as f64 / (n - 1) as f64).collect()
}

/// The Appendix D geometry with the angles and losses fitted to Table C.1 by `tcsim fit`
/// (RMS TR 0.58 %, CF 0.57 % over SR 0–0.85; python/tcsim/data/converters/li-sunden-2016-fitted.toml).
pub fn ht_fitted(shape: [f64; 3]) -> HtDynamics {
    let d = std::f64::consts::PI / 180.0;
    let g = HtGeometry::new([
        0.01,
        840.0,
        0.12,
        0.065,
        0.06,
        -25.69502474000548 * d,
        -47.663399314312684 * d,
        51.88232627502204 * d,
        51.95679958169683 * d,
        -18.697626530192487 * d,
        -49.68888373188161 * d,
        0.5658235096868285,
        0.9473337805257149,
        0.22645682280069623,
        0.01,
    ])
    .unwrap();
    HtDynamics::new(g, inertia(), 0.2914, shape).unwrap()
}
