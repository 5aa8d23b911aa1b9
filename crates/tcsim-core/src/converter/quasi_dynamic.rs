//! tcsim's quasi-dynamic converter model (tables plus fluid inertia) in mass-matrix form.

use super::dynamics::{
    table_steady, table_torques, ConverterDynamics, Inertias, Mat4, SteadyPoint, Vec4, FLOW, PUMP, TURBINE,
};
use super::torque_capacity::TorqueCharacteristic;
use crate::error::{CoreError, CoreResult};

/// tcsim's quasi-dynamic model: the steady-state tables plus fluid inertia (physics notes §5;
/// derivation in docs/models.md). States ω_p, ω_t, Q:
///
/// ```text
///     I_p ω̇_p + ρ S_p Q̇ = T_p − CF(SR) ω_p|ω_p|
///     I_t ω̇_t + ρ S_t Q̇ = TR(SR) CF(SR) ω_p|ω_p| + T_t
///     Q̇ = (Q_ss − Q)/τ_Q,    Q_ss = CF(SR) |ω_p| / (ρ R_p²)
/// ```
///
/// in drive; in every other quadrant the torques are the table's ([`TorqueCharacteristic::torques`]) and
/// the steady flow follows the same regions: `Q_ss = −C(x)·m(x)·|ω_t| / (ρ R_p²)` where the
/// turbine-referred capacity C(x) applies (x = ω_p/ω_t), negative in overrun, continuous at the
/// region boundaries.
///
/// `Q_ss` is the Euler-equation flow that carries the table's pump torque with the fluid leaving
/// the pump at `R_p` and entering it with no swirl. At steady state Q̇ = 0, so the torques are the
/// table's whatever the shape effects; with S = 0 the flow does not act on the speeds at all.
#[derive(Debug, Clone)]
pub struct QuasiDynamics {
    /// One table, or several measured at different input torques (the pump torque solved).
    pub characteristic: TorqueCharacteristic,
    pub inertia: Inertias,
    pub fluid_density_kg_m3: f64,
    pub pump_radius_m: f64,
    pub pump_shape_effect_m2: f64,
    pub turbine_shape_effect_m2: f64,
    pub flow_time_constant_s: f64,
}

impl QuasiDynamics {
    pub fn validate(&self) -> CoreResult<()> {
        let checks = [
            ("fluid_density_kg_m3", self.fluid_density_kg_m3, "a finite, positive density in kg/m³"),
            ("pump_exit_radius_m", self.pump_radius_m, "a finite, positive radius in m"),
            ("quasi_dynamic.flow_time_constant_s", self.flow_time_constant_s, "a finite, positive time constant in s"),
        ];
        for (name, v, expected) in checks {
            if !(v.is_finite() && v > 0.0) {
                return Err(CoreError::new(name, v, expected));
            }
        }
        for (name, v) in [
            ("quasi_dynamic.pump_shape_effect_m2", self.pump_shape_effect_m2),
            ("quasi_dynamic.turbine_shape_effect_m2", self.turbine_shape_effect_m2),
        ] {
            if !v.is_finite() {
                return Err(CoreError::new(name, v, "a finite shape effect in m²"));
            }
        }
        Ok(())
    }

    fn flow_scale(&self) -> f64 {
        1.0 / (self.fluid_density_kg_m3 * self.pump_radius_m * self.pump_radius_m)
    }

    /// Steady flow Q_ss and its gradient with respect to (ω_p, ω_t).
    fn steady_flow(&self, wp: f64, wt: f64) -> (f64, [f64; 2]) {
        let t = self.characteristic.torques(wp, wt);
        let k = self.flow_scale();
        // (k·factor)·speed, the arithmetic of the drive-only model before issue 11, bit for bit
        (k * t.flow_factor * t.flow_speed, [k * t.d_flow[0], k * t.d_flow[1]])
    }
}

impl ConverterDynamics for QuasiDynamics {
    fn coordinates(&self) -> [bool; 4] {
        [true, true, false, true]
    }
    fn mass(&self) -> Mat4 {
        let rho = self.fluid_density_kg_m3;
        let mut m = [[0.0; 4]; 4];
        m[PUMP][PUMP] = self.inertia.pump_kg_m2;
        m[TURBINE][TURBINE] = self.inertia.turbine_kg_m2;
        m[PUMP][FLOW] = rho * self.pump_shape_effect_m2;
        m[TURBINE][FLOW] = rho * self.turbine_shape_effect_m2;
        m[FLOW][FLOW] = 1.0;
        m
    }
    fn forces(&self, u: &Vec4, _s: f64) -> Vec4 {
        let (tp, tt, _, _) = table_torques(&self.characteristic, u[PUMP], u[TURBINE]);
        let (qss, _) = self.steady_flow(u[PUMP], u[TURBINE]);
        [-tp, tt, 0.0, (qss - u[FLOW]) / self.flow_time_constant_s]
    }
    fn force_jacobian(&self, u: &Vec4, _s: f64) -> Mat4 {
        let (_, _, dtp, dtt) = table_torques(&self.characteristic, u[PUMP], u[TURBINE]);
        let (_, dq) = self.steady_flow(u[PUMP], u[TURBINE]);
        let tau = self.flow_time_constant_s;
        let mut j = [[0.0; 4]; 4];
        j[PUMP][PUMP] = -dtp[0];
        j[PUMP][TURBINE] = -dtp[1];
        j[TURBINE][PUMP] = dtt[0];
        j[TURBINE][TURBINE] = dtt[1];
        j[FLOW][PUMP] = dq[0] / tau;
        j[FLOW][TURBINE] = dq[1] / tau;
        j[FLOW][FLOW] = -1.0 / tau;
        j
    }
    /// The power the converter takes from the shafts and does not store: the table's loss
    /// `T_p,tr ω_p − T_t,tr ω_t` plus the power of the fluid terms `ρQ̇(S_p ω_p + S_t ω_t)`, which the
    /// model stores nowhere (its flow row is a lag, not a power balance; `Q̇ = f[FLOW]` since that
    /// row of `M` is the unit row). With [`Self::stored_energy_j`] this closes the energy identity;
    /// the fluid terms can make it negative for a moment (docs/models.md, "Quasi-dynamic model").
    fn loss_power_w(&self, u: &Vec4, f: &Vec4) -> f64 {
        let fluid = self.fluid_density_kg_m3
            * f[FLOW]
            * (self.pump_shape_effect_m2 * u[PUMP] + self.turbine_shape_effect_m2 * u[TURBINE]);
        -(u[PUMP] * f[PUMP] + u[TURBINE] * f[TURBINE]) + fluid
    }
    /// The kinetic energy of pump and turbine, J (the flow coordinate stores none).
    fn stored_energy_j(&self, u: &Vec4) -> f64 {
        0.5 * (self.inertia.pump_kg_m2 * u[PUMP] * u[PUMP] + self.inertia.turbine_kg_m2 * u[TURBINE] * u[TURBINE])
    }
    fn steady_point(&self, wp: f64, wt: f64) -> CoreResult<SteadyPoint> {
        let tp = table_steady(&self.characteristic, wp, wt)?;
        Ok(SteadyPoint { u: [wp, wt, 0.0, self.steady_flow(wp, wt).0], pump_torque_nm: tp })
    }
}
