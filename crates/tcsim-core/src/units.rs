//! Unit conversions and the defaults stated in user units, one place each.

/// rpm per rad/s (`60 / 2π`).
pub const RPM_PER_RAD_S: f64 = 60.0 / (2.0 * std::f64::consts::PI);
/// rad/s per rpm (`π/30`), the factor the Python side multiplies by.
pub const RAD_S_PER_RPM: f64 = std::f64::consts::PI / 30.0;
/// m/s per km/h.
pub const M_S_PER_KM_H: f64 = 1.0 / 3.6;
/// N·m per lbf·ft.
pub const NM_PER_LBF_FT: f64 = 1.355_817_948_331_400_4;
/// Standard gravity, m/s².
pub const GRAVITY_M_S2: f64 = 9.81;

/// rad/s of a speed in rpm, `rpm · π/30` (the arithmetic of the Python side, bit for bit).
pub fn rad_s_from_rpm(rpm: f64) -> f64 {
    rpm * std::f64::consts::PI / 30.0
}

/// The reference pump speed, rpm: the speed at which the default quasi-dynamic flow time constant
/// is evaluated ([`crate::converter::spec::default_flow_time_constant_s`]) and the default pump
/// speed of a characterisation sweep.
pub const REFERENCE_PUMP_SPEED_RPM: f64 = 2000.0;

/// [`REFERENCE_PUMP_SPEED_RPM`] in rad/s (`2000 · π/30`).
pub const REFERENCE_PUMP_SPEED_RAD_S: f64 = REFERENCE_PUMP_SPEED_RPM * std::f64::consts::PI / 30.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_speed_is_2000_rpm_as_python_computes_it() {
        assert_eq!(REFERENCE_PUMP_SPEED_RAD_S, 2000.0 * std::f64::consts::PI / 30.0);
        assert_eq!(rad_s_from_rpm(REFERENCE_PUMP_SPEED_RPM), REFERENCE_PUMP_SPEED_RAD_S);
        assert!((REFERENCE_PUMP_SPEED_RAD_S * RPM_PER_RAD_S - 2000.0).abs() < 1e-9);
        assert!((RAD_S_PER_RPM * RPM_PER_RAD_S - 1.0).abs() < 1e-15);
        assert!((M_S_PER_KM_H * 3.6 - 1.0).abs() < 1e-15);
    }
}
