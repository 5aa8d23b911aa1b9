//! The physics of the vehicle's components: engine torque and drag, the gearbox's shift
//! schedule and clutch handover, the lock-up schedule, shafts, tyres, body resistances and brake.
//! The plant ([`super::plant`]) assembles them.

use super::parameters::{Curve, Engine, Gearbox, Lockup, Scenario, Vehicle};
use super::{N_COORDS, TORQUE_BOOST, TORQUE_FAST};
use crate::converter::dynamics::PUMP;
use crate::interp::{blend_held, linear_held};

/// Speed below which the tyre slip is regularised, m/s.
pub const SLIP_SPEED_M_S: f64 = 0.5;
/// Slip scale of the regularised clutch friction (tanh), rad/s: the lock-up component's, shared by
/// the shift clutches.
pub use crate::engine::lockup::CLUTCH_SLIP_RAD_S;
/// Scale of the regularised brake sign, rad/s.
pub const BRAKE_SPEED_RAD_S: f64 = 0.002;
/// Scale of the regularised rolling-resistance sign, m/s.
pub const ROLL_SPEED_M_S: f64 = 0.01;

/// The engine's friction and pumping drag at speed `w` (rad/s), N·m, opposing rotation: a
/// constant part `drag_torque_nm` with its sign regularised over 1 rad/s (tanh) and a viscous part
/// `drag_nm_s_per_rad·w`. This is the drag of the vehicle plant ([`Engine::drag`]).
pub fn engine_drag_nm(w: f64, drag_torque_nm: f64, drag_nm_s_per_rad: f64) -> f64 {
    drag_torque_nm * (w / 1.0).tanh() + drag_nm_s_per_rad * w
}

/// The torque of a brake of capacity `capacity_nm` on an axle turning at `axle_speed_rad_s`,
/// opposing its rotation (smoothed over [`BRAKE_SPEED_RAD_S`]), N·m.
pub fn brake_torque_nm(capacity_nm: f64, axle_speed_rad_s: f64) -> f64 {
    capacity_nm * (axle_speed_rad_s / BRAKE_SPEED_RAD_S).tanh()
}

impl Curve {
    /// The value at `x`: linear between points, ends held.
    pub fn at(&self, x: f64) -> f64 {
        linear_held(self.x(), self.y(), x)
    }
}

impl Engine {
    /// Rev limiter: the full-load torque falls linearly to zero over the 5 % of speed above the
    /// full-load curve's last point.
    pub fn fuel_cut(&self, w: f64) -> f64 {
        let top = self.full_load.x().last().copied().unwrap_or(f64::INFINITY);
        ((1.05 * top - w) / (0.05 * top)).clamp(0.0, 1.0)
    }
    /// Friction and pumping drag, opposing rotation.
    pub fn drag(&self, w: f64) -> f64 {
        engine_drag_nm(w, self.drag_torque_nm, self.drag_nm_s_per_rad)
    }
    /// Targets of the aspirated and boost torque parts for pedal `p` at speed `w`.
    pub fn targets(&self, p: f64, w: f64) -> (f64, f64) {
        let full = self.full_load.at(w).max(0.0) * self.fuel_cut(w);
        let governor = self.idle_governor_gain_nm_s_per_rad * (self.idle_speed_rad_s - w).max(0.0);
        let boost = self.boost_fraction * p * full;
        ((p * full + governor).min(full) - boost, boost)
    }
}

impl Gearbox {
    /// Vehicle speed of the upshift from gear `k` (0-based) at pedal `p`.
    pub fn upshift_speed(&self, k: usize, p: f64) -> f64 {
        blend_held(self.upshift_speed_zero_pedal_m_s[k], self.upshift_speed_full_pedal_m_s[k], p)
    }
    /// Vehicle speed of the downshift from gear `k` ≥ 1 to `k − 1` at pedal `p`.
    pub fn downshift_speed(&self, k: usize, p: f64) -> f64 {
        blend_held(self.downshift_speed_zero_pedal_m_s[k - 1], self.downshift_speed_full_pedal_m_s[k - 1], p)
    }
}

impl Lockup {
    /// Vehicle speed above which the lock-up engages at pedal `p`.
    pub fn engage_speed(&self, p: f64) -> f64 {
        blend_held(self.engage_speed_zero_pedal_m_s, self.engage_speed_full_pedal_m_s, p)
    }
}

impl Vehicle {
    /// Sine and cosine of the road's grade angle.
    pub fn grade(&self) -> (f64, f64) {
        let a = (self.body.grade_percent / 100.0).atan();
        (a.sin(), a.cos())
    }
}

impl Scenario {
    /// The pedal the shift schedule reads at `t`: the TCU's filtered pedal if the scenario has it,
    /// else the accelerator pedal ([`super::shift_pedal`]).
    pub fn shift_pedal_at(&self, t: f64) -> f64 {
        self.shift_pedal.as_ref().unwrap_or(&self.accelerator_pedal).value(t)
    }

    /// Net crank torque, the engine's (indicated) power and its drag loss at `u`, `t`.
    pub fn engine(&self, e: &Engine, u: &[f64; N_COORDS], t: f64) -> (f64, f64, f64) {
        let w = u[PUMP];
        match &self.engine_torque_nm {
            Some(log) => {
                let torque = log.value(t);
                (torque, torque * w, 0.0)
            }
            None => {
                let drag = e.drag(w);
                let indicated = u[TORQUE_FAST] + u[TORQUE_BOOST];
                (indicated - drag, indicated * w, drag * w)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn engine() -> Engine {
        Engine {
            inertia_kg_m2: 0.2,
            idle_speed_rad_s: 78.5,
            full_load: Curve::new("x", "y", vec![60.0, 230.0, 500.0, 700.0], vec![150.0, 400.0, 400.0, 280.0]).unwrap(),
            drag_torque_nm: 15.0,
            drag_nm_s_per_rad: 0.05,
            fast_time_constant_s: 0.06,
            boost_time_constant_s: 0.8,
            boost_fraction: 0.4,
            idle_governor_gain_nm_s_per_rad: 10.0,
        }
    }

    #[test]
    fn curve_interpolates_holds_ends_and_refuses_bad_tables() {
        let c = Curve::new("c", "d", vec![0.0, 1.0, 3.0], vec![0.0, 2.0, 6.0]).unwrap();
        assert_eq!((c.at(-1.0), c.at(0.5), c.at(2.0), c.at(9.0)), (0.0, 1.0, 4.0, 6.0));
        assert_eq!(Curve::new("c", "d", vec![0.0, 1.0, 1.0], vec![0.0; 3]).unwrap_err().field, "c[2]");
    }

    #[test]
    fn engine_splits_pedal_torque_and_governs_idle() {
        let e = engine();
        // full pedal at 230 rad/s: 400 N·m, 40 % of it through the boost path
        let (fast, boost) = e.targets(1.0, 230.0);
        assert!((fast - 240.0).abs() < 1e-12 && (boost - 160.0).abs() < 1e-12);
        // no pedal above idle: nothing; below idle the governor pushes, limited by full load
        assert_eq!(e.targets(0.0, 100.0), (0.0, 0.0));
        let (fast, boost) = e.targets(0.0, 70.0);
        assert!((fast - 85.0).abs() < 1e-12 && boost == 0.0);
        assert!((e.targets(0.0, 0.0).0 - 150.0).abs() < 1e-12);
        // drag opposes rotation and vanishes at rest
        assert!(e.drag(100.0) > 15.0 && e.drag(0.0) == 0.0 && e.drag(-100.0) < 0.0);
        let mut bad = engine();
        bad.boost_fraction = 1.5;
        assert_eq!(bad.validate().unwrap_err().field, "[engine].boost_fraction");
    }

    #[test]
    fn gearbox_schedule_interpolates_in_pedal_and_is_validated() {
        let g = Gearbox {
            ratios: vec![4.0, 2.0, 1.0],
            efficiencies: vec![0.95, 0.96, 0.97],
            input_inertia_kg_m2: vec![0.05, 0.04, 0.03],
            output_inertia_kg_m2: 0.05,
            shift_clutch_capacity_nm: 500.0,
            shift_handover_s: 0.25,
            upshift_speed_zero_pedal_m_s: vec![4.0, 8.0],
            upshift_speed_full_pedal_m_s: vec![12.0, 24.0],
            downshift_speed_zero_pedal_m_s: vec![2.0, 5.0],
            downshift_speed_full_pedal_m_s: vec![8.0, 16.0],
            shift_control: Default::default(),
            shift_pedal: Default::default(),
        };
        g.validate().unwrap();
        assert_eq!((g.upshift_speed(0, 0.5), g.upshift_speed(1, 1.0), g.downshift_speed(2, 0.0)), (8.0, 24.0, 5.0));
        let mut bad = g.clone();
        bad.downshift_speed_full_pedal_m_s[1] = 30.0;
        assert_eq!(bad.validate().unwrap_err().field, "[gearbox].downshift_speed_full_pedal_m_s[1]");
        let mut bad = g.clone();
        bad.efficiencies.pop();
        assert_eq!(bad.validate().unwrap_err().field, "[gearbox].efficiencies");
        let mut bad = g;
        bad.ratios[1] = -2.0;
        assert_eq!(bad.validate().unwrap_err().field, "[gearbox].ratios[1]");
    }

    #[test]
    fn lockup_engage_speed_and_validation() {
        let l = Lockup {
            capacity_nm: 600.0,
            static_to_kinetic: 1.2,
            engage_time_s: 0.5,
            min_gear: 3,
            engage_speed_zero_pedal_m_s: 12.0,
            engage_speed_full_pedal_m_s: 25.0,
        };
        assert_eq!(l.engage_speed(0.0), 12.0);
        assert_eq!(l.engage_speed(2.0), 25.0);
        let bad = Lockup { static_to_kinetic: 0.9, ..l };
        assert_eq!(bad.validate(8).unwrap_err().field, "[lockup].static_to_kinetic");
    }

    #[test]
    fn engine_drag_is_the_plant_drag() {
        let e = engine();
        for w in [-50.0, 0.0, 0.3, 80.0, 600.0] {
            assert_eq!(engine_drag_nm(w, e.drag_torque_nm, e.drag_nm_s_per_rad), e.drag(w));
        }
    }
}
