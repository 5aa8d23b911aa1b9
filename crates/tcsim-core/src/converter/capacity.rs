//! Capacity conventions of converter characteristic tables.
//!
//! tcsim works internally with the capacity factor `CF = T_pump / ω_pump²` in
//! N·m/(rad/s)² (`capacity_factor_nm_s2`). Tables arrive in six conventions
//! (docs `conventions.md`, docs/physics.md §1); each converts to and from CF exactly.

use crate::error::{CoreError, CoreResult};
use crate::units::{NM_PER_LBF_FT, RPM_PER_RAD_S};

/// Pump speed at which the VDI 2153 / VECTO MP1000 torque is quoted, rad/s.
pub const MP1000_SPEED_RAD_S: f64 = 1000.0 / RPM_PER_RAD_S;

/// A capacity convention, named by its column / TOML key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CapacityConvention {
    /// `capacity_factor_nm_s2`: CF = T/ω², N·m/(rad/s)². The internal convention.
    CapacityFactorNmS2,
    /// `k_factor_rpm_per_sqrt_nm`: K = n/√T (SAE J643 style).
    KFactorRpmPerSqrtNm,
    /// `k_factor_rad_s_per_sqrt_nm`: K = ω/√T.
    KFactorRadSPerSqrtNm,
    /// `k_factor_rpm_per_sqrt_lbf_ft`: K = n/√T with T in lbf·ft (US).
    KFactorRpmPerSqrtLbfFt,
    /// `capacity_nm_per_rpm2`: C = T/n².
    CapacityNmPerRpm2,
    /// `mp1000_nm`: input torque at 1000 rpm input speed (VDI 2153, VECTO).
    Mp1000Nm,
}

impl CapacityConvention {
    pub const ALL: [CapacityConvention; 6] = [
        Self::CapacityFactorNmS2,
        Self::KFactorRpmPerSqrtNm,
        Self::KFactorRadSPerSqrtNm,
        Self::KFactorRpmPerSqrtLbfFt,
        Self::CapacityNmPerRpm2,
        Self::Mp1000Nm,
    ];

    /// The column / key name of this convention.
    pub fn key(self) -> &'static str {
        match self {
            Self::CapacityFactorNmS2 => "capacity_factor_nm_s2",
            Self::KFactorRpmPerSqrtNm => "k_factor_rpm_per_sqrt_nm",
            Self::KFactorRadSPerSqrtNm => "k_factor_rad_s_per_sqrt_nm",
            Self::KFactorRpmPerSqrtLbfFt => "k_factor_rpm_per_sqrt_lbf_ft",
            Self::CapacityNmPerRpm2 => "capacity_nm_per_rpm2",
            Self::Mp1000Nm => "mp1000_nm",
        }
    }

    pub fn from_key(key: &str) -> CoreResult<Self> {
        Self::ALL
            .into_iter()
            .find(|c| c.key() == key)
            .ok_or_else(|| CoreError::new("capacity convention", key, format!("one of {}", Self::keys())))
    }

    pub fn keys() -> String {
        Self::ALL.map(|c| c.key()).join(", ")
    }

    /// Convert a value in this convention to CF in N·m/(rad/s)².
    ///
    /// K-factors must be positive (a K-factor cannot express zero or negative capacity);
    /// `f64::INFINITY` maps to CF = 0. The other conventions are linear and keep the sign,
    /// so overrun rows (negative capacity) survive conversion.
    pub fn to_capacity_factor(self, value: f64) -> f64 {
        match self {
            Self::CapacityFactorNmS2 => value,
            Self::KFactorRpmPerSqrtNm => RPM_PER_RAD_S * RPM_PER_RAD_S / (value * value),
            Self::KFactorRadSPerSqrtNm => 1.0 / (value * value),
            Self::KFactorRpmPerSqrtLbfFt => {
                let k_rpm_per_sqrt_nm = value / NM_PER_LBF_FT.sqrt();
                RPM_PER_RAD_S * RPM_PER_RAD_S / (k_rpm_per_sqrt_nm * k_rpm_per_sqrt_nm)
            }
            Self::CapacityNmPerRpm2 => value * RPM_PER_RAD_S * RPM_PER_RAD_S,
            Self::Mp1000Nm => value / (MP1000_SPEED_RAD_S * MP1000_SPEED_RAD_S),
        }
    }

    /// Convert CF in N·m/(rad/s)² to this convention. K-factors of CF ≤ 0 are `+∞` (CF = 0)
    /// or NaN (CF < 0): a K-factor cannot express them.
    pub fn from_capacity_factor(self, cf: f64) -> f64 {
        let k_rad = |cf: f64| if cf < 0.0 { f64::NAN } else { 1.0 / cf.sqrt() };
        match self {
            Self::CapacityFactorNmS2 => cf,
            Self::KFactorRpmPerSqrtNm => RPM_PER_RAD_S * k_rad(cf),
            Self::KFactorRadSPerSqrtNm => k_rad(cf),
            Self::KFactorRpmPerSqrtLbfFt => RPM_PER_RAD_S * k_rad(cf) * NM_PER_LBF_FT.sqrt(),
            Self::CapacityNmPerRpm2 => cf / (RPM_PER_RAD_S * RPM_PER_RAD_S),
            Self::Mp1000Nm => cf * MP1000_SPEED_RAD_S * MP1000_SPEED_RAD_S,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_convention_round_trips() {
        for conv in CapacityConvention::ALL {
            for cf in [1e-5, 3.272e-3, 0.11, 2.5] {
                let back = conv.to_capacity_factor(conv.from_capacity_factor(cf));
                assert!((back - cf).abs() <= 1e-14 * cf, "{conv:?}: {cf} -> {back}");
            }
            assert_eq!(CapacityConvention::from_key(conv.key()).unwrap(), conv);
        }
    }

    #[test]
    fn published_equivalences_hold() {
        // physics.md §1: 38e-6 N·m/rpm² is 3.47e-3 N·m/(rad/s)².
        let cf = CapacityConvention::CapacityNmPerRpm2.to_capacity_factor(38e-6);
        assert!((cf - 3.465e-3).abs() < 1e-5, "{cf}");
        // SI K-factor: CF = 1/K².
        assert!((CapacityConvention::KFactorRadSPerSqrtNm.to_capacity_factor(15.0) - 1.0 / 225.0).abs() < 1e-16);
        // MP1000 is the stall torque at 1000 rpm: CF·(104.72 rad/s)².
        let mp = CapacityConvention::Mp1000Nm.from_capacity_factor(3.272e-3);
        assert!((mp - 3.272e-3 * (1000.0 * 2.0 * std::f64::consts::PI / 60.0).powi(2)).abs() < 1e-12);
        // 1 lbf·ft = 1.35582 N·m, so K_US = K_SAE·√1.35582.
        let k_sae = CapacityConvention::KFactorRpmPerSqrtNm.from_capacity_factor(3e-3);
        let k_us = CapacityConvention::KFactorRpmPerSqrtLbfFt.from_capacity_factor(3e-3);
        assert!((k_us / k_sae - 1.35582f64.sqrt()).abs() < 1e-5);
    }

    #[test]
    fn k_factor_of_zero_and_negative_capacity() {
        let k = CapacityConvention::KFactorRadSPerSqrtNm;
        assert_eq!(k.from_capacity_factor(0.0), f64::INFINITY);
        assert!(k.from_capacity_factor(-1e-3).is_nan());
        assert_eq!(k.to_capacity_factor(f64::INFINITY), 0.0);
        // linear conventions keep the sign of overrun rows
        assert!(CapacityConvention::CapacityNmPerRpm2.to_capacity_factor(-5e-6) < 0.0);
    }

    #[test]
    fn unknown_key_is_an_error() {
        let err = CapacityConvention::from_key("k_factor").unwrap_err();
        assert!(err.to_string().contains("capacity_factor_nm_s2"), "{err}");
    }
}
