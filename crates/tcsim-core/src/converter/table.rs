//! Steady-state look-up-table model, Li & Sundén (2016) §2.2.1, eqs 2.8–2.11.
//!
//! `T_p,transferred = CF(SR)·ω_p·|ω_p|` and `T_t,transferred = TR(SR)·T_p,transferred`,
//! with ω in rad/s and CF in N·m/(rad/s)² (physics notes §1, §3).
//!
//! **Interpolation** is piecewise linear in SR between the table's points.
//!
//! **Outside the table** TR and CF are held at the nearest end point (constant extrapolation),
//! and [`Lookup::extrapolated`] says so. This covers SR < 0 (turbine turning backwards against
//! a stalled pump) and SR beyond the last point. A table that includes overrun rows (SR > 1,
//! negative capacity, as the JAMBE/TRAMI 9AT table does) is interpolated there like anywhere
//! else, so the pump torque changes sign and the turbine drives the pump. A table that stops at
//! SR = 1 gives, above 1, the end-point capacity (for Table C.1 a small positive CF): the
//! steady-state sweeps therefore stay inside the table, and overrun needs a table that has it.

use crate::error::{CoreError, CoreResult, InputSource};
use crate::interp;

/// A torque-converter characteristic: TR and CF against SR.
#[derive(Debug, Clone, PartialEq)]
pub struct Characteristic {
    speed_ratio: Vec<f64>,
    torque_ratio: Vec<f64>,
    capacity_factor_nm_s2: Vec<f64>,
}

/// The characteristic evaluated at one speed ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lookup {
    pub torque_ratio: f64,
    pub capacity_factor_nm_s2: f64,
    /// d TR / d SR of the segment used (0 outside the table).
    pub d_torque_ratio: f64,
    /// d CF / d SR of the segment used (0 outside the table).
    pub d_capacity_factor: f64,
    /// True when SR lies outside the table and the end values were held.
    pub extrapolated: bool,
}

/// Steady-state torques of the table model at one operating point (physics notes §2 signs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableOperatingPoint {
    pub speed_ratio: f64,
    pub torque_ratio: f64,
    pub capacity_factor_nm_s2: f64,
    /// External torque on the pump (engine torque), positive in drive.
    pub pump_torque_nm: f64,
    /// Torque delivered to the transmission, `−T_t`, positive in drive.
    pub turbine_torque_nm: f64,
    /// External torque on the stator from the housing, `T_s = −(T_p + T_t)`.
    pub stator_torque_nm: f64,
    pub extrapolated: bool,
}

impl Characteristic {
    /// Build a characteristic, checking that it can be interpolated: at least two points, equal
    /// lengths, finite values and strictly increasing SR. Physical plausibility (positive TR and
    /// CF in drive) is checked by the caller, who knows the file and convention.
    pub fn new(speed_ratio: Vec<f64>, torque_ratio: Vec<f64>, capacity_factor_nm_s2: Vec<f64>) -> CoreResult<Self> {
        let n = speed_ratio.len();
        if n < 2 {
            return Err(CoreError::new("speed_ratio", format!("{n} points"), "at least 2 points"));
        }
        for (name, v) in [("torque_ratio", &torque_ratio), ("capacity_factor_nm_s2", &capacity_factor_nm_s2)] {
            if v.len() != n {
                return Err(CoreError::new(
                    name,
                    format!("{} points", v.len()),
                    format!("{n} points, as many as speed_ratio"),
                ));
            }
        }
        for (name, v) in [
            ("speed_ratio", &speed_ratio),
            ("torque_ratio", &torque_ratio),
            ("capacity_factor_nm_s2", &capacity_factor_nm_s2),
        ] {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(CoreError::new(format!("{name}[{i}]"), v[i], "a finite number"));
            }
        }
        if let Some(i) = (1..n).find(|&i| speed_ratio[i] <= speed_ratio[i - 1]) {
            return Err(CoreError::new(
                format!("speed_ratio[{i}]"),
                speed_ratio[i],
                format!("strictly increasing speed ratio (previous value {})", speed_ratio[i - 1]),
            ));
        }
        Ok(Self { speed_ratio, torque_ratio, capacity_factor_nm_s2 })
    }

    pub fn speed_ratio(&self) -> &[f64] {
        &self.speed_ratio
    }
    pub fn torque_ratio(&self) -> &[f64] {
        &self.torque_ratio
    }
    pub fn capacity_factor_nm_s2(&self) -> &[f64] {
        &self.capacity_factor_nm_s2
    }

    /// Linear interpolation of TR and CF at `sr`, end values held outside the table.
    pub fn lookup(&self, sr: f64) -> Lookup {
        let x = &self.speed_ratio;
        let n = x.len();
        let held = |i: usize| Lookup {
            torque_ratio: self.torque_ratio[i],
            capacity_factor_nm_s2: self.capacity_factor_nm_s2[i],
            d_torque_ratio: 0.0,
            d_capacity_factor: 0.0,
            extrapolated: true,
        };
        if sr.is_nan() {
            return Lookup {
                torque_ratio: f64::NAN,
                capacity_factor_nm_s2: f64::NAN,
                d_torque_ratio: f64::NAN,
                d_capacity_factor: f64::NAN,
                extrapolated: true,
            };
        }
        if sr < x[0] {
            return held(0);
        }
        if sr > x[n - 1] {
            return held(n - 1);
        }
        let (i, w) = interp::segment(x, sr);
        let h = x[i] - x[i - 1];
        let lerp = |y: &[f64]| (interp::mix(y, i, w), (y[i] - y[i - 1]) / h);
        let (tr, dtr) = lerp(&self.torque_ratio);
        let (cf, dcf) = lerp(&self.capacity_factor_nm_s2);
        Lookup {
            torque_ratio: tr,
            capacity_factor_nm_s2: cf,
            d_torque_ratio: dtr,
            d_capacity_factor: dcf,
            extrapolated: false,
        }
    }

    /// Steady state at pump and turbine speeds in rad/s (eqs 2.8–2.9, no inertia terms).
    /// SR is ω_t/ω_p; the pump speed must be non-zero.
    pub fn operating_point(&self, pump_speed_rad_s: f64, turbine_speed_rad_s: f64) -> CoreResult<TableOperatingPoint> {
        if !(pump_speed_rad_s.is_finite() && pump_speed_rad_s != 0.0) {
            return Err(CoreError::new("pump_speed_rad_s", pump_speed_rad_s, "a finite, non-zero pump speed"));
        }
        if !turbine_speed_rad_s.is_finite() {
            return Err(CoreError::new("turbine_speed_rad_s", turbine_speed_rad_s, "a finite turbine speed"));
        }
        let sr = turbine_speed_rad_s / pump_speed_rad_s;
        let l = self.lookup(sr);
        let tp = l.capacity_factor_nm_s2 * pump_speed_rad_s * pump_speed_rad_s.abs();
        let t_delivered = l.torque_ratio * tp;
        if !(tp.is_finite() && t_delivered.is_finite() && (t_delivered - tp).is_finite()) {
            return Err(CoreError::of(
                InputSource::Drive,
                "pump_speed_rad_s",
                pump_speed_rad_s,
                "a pump speed at which the steady torques are finite (they grow as the speed squared and overflow)",
            ));
        }
        Ok(TableOperatingPoint {
            speed_ratio: sr,
            torque_ratio: l.torque_ratio,
            capacity_factor_nm_s2: l.capacity_factor_nm_s2,
            pump_torque_nm: tp,
            turbine_torque_nm: t_delivered,
            stator_torque_nm: t_delivered - tp,
            extrapolated: l.extrapolated,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c1() -> Characteristic {
        // Li & Sundén (2016) Table C.1, CF in N·m/(rad/s)²
        Characteristic::new(
            vec![0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0],
            vec![2.14, 1.99, 1.84, 1.70, 1.56, 1.43, 1.30, 1.18, 1.06, 1.00, 1.00, 1.00, 1.00],
            [3.272, 3.257, 3.228, 3.181, 3.112, 3.017, 2.887, 2.713, 2.481, 2.370, 1.842, 1.237, 0.187]
                .map(|v| v * 1e-3)
                .to_vec(),
        )
        .unwrap()
    }

    #[test]
    fn reproduces_table_points_exactly() {
        let t = c1();
        for i in 0..t.speed_ratio().len() {
            let l = t.lookup(t.speed_ratio()[i]);
            assert_eq!(l.torque_ratio, t.torque_ratio()[i]);
            assert_eq!(l.capacity_factor_nm_s2, t.capacity_factor_nm_s2()[i]);
            assert!(!l.extrapolated);
        }
    }

    #[test]
    fn interpolates_linearly_between_points() {
        let l = c1().lookup(0.825);
        assert!((l.torque_ratio - 1.03).abs() < 1e-12);
        assert!((l.capacity_factor_nm_s2 - 0.5 * (2.481e-3 + 2.370e-3)).abs() < 1e-15);
    }

    #[test]
    fn holds_end_values_outside_the_table() {
        let t = c1();
        let below = t.lookup(-0.2);
        assert!(
            below.extrapolated
                && below.torque_ratio == 2.14
                && below.capacity_factor_nm_s2 == t.capacity_factor_nm_s2()[0]
        );
        let above = t.lookup(1.3);
        assert!(
            above.extrapolated
                && above.torque_ratio == 1.0
                && above.capacity_factor_nm_s2 == t.capacity_factor_nm_s2()[12]
        );
        assert_eq!(above.d_capacity_factor, 0.0);
    }

    #[test]
    fn overrun_rows_reverse_the_pump_torque() {
        // JAMBE/TRAMI 9AT excerpt: negative capacity above SR = 1 (turbine drives the pump).
        let c = |v: f64| v * crate::units::RPM_PER_RAD_S.powi(2);
        let t = Characteristic::new(vec![0.9, 1.0, 1.1, 1.2], vec![1.0; 4], vec![c(30e-6), 0.0, c(-5e-6), c(-10e-6)])
            .unwrap();
        let op = t.operating_point(200.0, 230.0).unwrap();
        assert!(!op.extrapolated);
        assert!(op.pump_torque_nm < 0.0 && op.turbine_torque_nm < 0.0, "{op:?}");
        assert!((op.capacity_factor_nm_s2 - c(-7.5e-6)).abs() < 1e-12);
    }

    #[test]
    fn torques_balance_and_follow_eq_2_8_and_2_9() {
        let t = c1();
        let wp = crate::units::REFERENCE_PUMP_SPEED_RAD_S;
        let op = t.operating_point(wp, 0.3 * wp).unwrap();
        assert!((op.pump_torque_nm - 3.181e-3 * wp * wp).abs() < 1e-9);
        assert!((op.turbine_torque_nm - 1.70 * op.pump_torque_nm).abs() < 1e-9);
        // external torques: T_p + T_t + T_s = 0 with T_t = −delivered
        assert!((op.pump_torque_nm - op.turbine_torque_nm + op.stator_torque_nm).abs() < 1e-12);
        // negative pump speed: torque follows ω|ω|
        let back = t.operating_point(-wp, -0.3 * wp).unwrap();
        assert!((back.pump_torque_nm + op.pump_torque_nm).abs() < 1e-9);
    }

    #[test]
    fn slopes_agree_with_finite_differences() {
        let t = c1();
        for sr in [0.05, 0.33, 0.81, 0.87, 0.97] {
            let h = 1e-6;
            let (a, b) = (t.lookup(sr - h), t.lookup(sr + h));
            let l = t.lookup(sr);
            assert!((l.d_torque_ratio - (b.torque_ratio - a.torque_ratio) / (2.0 * h)).abs() < 1e-6);
            assert!(
                (l.d_capacity_factor - (b.capacity_factor_nm_s2 - a.capacity_factor_nm_s2) / (2.0 * h)).abs() < 1e-9
            );
        }
    }

    #[test]
    fn rejects_malformed_tables() {
        let e = Characteristic::new(vec![0.0, 0.5, 0.4], vec![2.0; 3], vec![1e-3; 3]).unwrap_err();
        assert_eq!(e.field, "speed_ratio[2]");
        assert!(e.expected.contains("strictly increasing"));
        let e = Characteristic::new(vec![0.0, 0.5], vec![2.0, f64::NAN], vec![1e-3; 2]).unwrap_err();
        assert_eq!(e.field, "torque_ratio[1]");
        assert!(Characteristic::new(vec![0.0], vec![2.0], vec![1e-3]).is_err());
        assert!(Characteristic::new(vec![0.0, 1.0], vec![2.0], vec![1e-3; 2]).is_err());
        assert!(c1().operating_point(0.0, 1.0).is_err());
    }
}
