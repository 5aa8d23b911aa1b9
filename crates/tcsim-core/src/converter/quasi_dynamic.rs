//! tcsim's quasi-dynamic converter model (tables plus fluid inertia) in mass-matrix form.

use super::dynamics::{
    table_steady, table_torques, ConverterDynamics, Inertias, Mat4, SteadyPoint, Vec4, FLOW, PUMP, TURBINE,
};
use super::table::{Characteristic, Region};
use super::torque_capacity::TorqueCharacteristic;
use crate::error::{CoreError, CoreResult};
use crate::interp;

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
///
/// Within a single table's rows `Q_ss` uses the C¹ monotone cubic (Fritsch–Carlson) interpolant of
/// CF through the rows ([`smooth_capacity`]), not the table's piecewise-linear CF: `Q̇` follows the
/// slope of CF, so a slope that jumps at a row (5× at the coupling point of Table C.1) steps the
/// fluid torques `ρS Q̇` and rings the driveline (docs/models.md, "Steady flow: a C¹ interpolation of CF").
/// The torques stay the table's; at steady state nothing changes.
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

    /// Steady flow Q_ss and its gradient with respect to (ω_p, ω_t): the table's flow, with CF
    /// from [`smooth_capacity`] where a single table is pump-referred within its rows.
    fn steady_flow(&self, wp: f64, wt: f64) -> (f64, [f64; 2]) {
        let t = self.characteristic.torques(wp, wt);
        let k = self.flow_scale();
        if t.region == Region::Pump {
            if let Some((cf, dcf)) = self.characteristic.single().and_then(|c| smooth_capacity(c, wt / wp)) {
                let (speed, dsr) = (wp.abs(), [-wt / (wp * wp), 1.0 / wp]);
                let d_flow = [dcf * dsr[0] * speed + cf * wp.signum(), dcf * dsr[1] * speed];
                return (k * cf * speed, [k * d_flow[0], k * d_flow[1]]);
            }
        }
        // (k·factor)·speed, the arithmetic of the drive-only model before issue 11, bit for bit
        (k * t.flow_factor * t.flow_speed, [k * t.d_flow[0], k * t.d_flow[1]])
    }
}

/// CF and dCF/dSR at `sr` from the monotone piecewise-cubic Hermite interpolant of the table's
/// rows (Fritsch & Carlson 1980, with the Fritsch–Butland weighted harmonic mean of the adjacent
/// secants as the slope at an interior row, zero where they differ in sign, and the end secant at
/// the first and last rows): C¹, equal to CF at every row, monotone where the rows are. None
/// outside the rows (the table's held or turbine-referred values apply there).
pub fn smooth_capacity(c: &Characteristic, sr: f64) -> Option<(f64, f64)> {
    let (x, y) = (c.speed_ratio(), c.capacity_factor_nm_s2());
    let n = x.len();
    if !(sr >= x[0] && sr <= x[n - 1]) {
        return None;
    }
    let secant = |j: usize| (y[j] - y[j - 1]) / (x[j] - x[j - 1]);
    let slope = |j: usize| {
        if j == 0 {
            return secant(1);
        }
        if j == n - 1 {
            return secant(n - 1);
        }
        let (d0, d1) = (secant(j), secant(j + 1));
        if d0 * d1 <= 0.0 {
            return 0.0;
        }
        let (h0, h1) = (x[j] - x[j - 1], x[j + 1] - x[j]);
        let (w0, w1) = (2.0 * h1 + h0, h1 + 2.0 * h0);
        (w0 + w1) / (w0 / d0 + w1 / d1)
    };
    let (i, t) = interp::segment(x, sr);
    let h = x[i] - x[i - 1];
    let (m0, m1) = (slope(i - 1) * h, slope(i) * h);
    let (t2, t3) = (t * t, t * t * t);
    let cf = (2.0 * t3 - 3.0 * t2 + 1.0) * y[i - 1]
        + (t3 - 2.0 * t2 + t) * m0
        + (3.0 * t2 - 2.0 * t3) * y[i]
        + (t3 - t2) * m1;
    let dcf =
        ((6.0 * t2 - 6.0 * t) * (y[i - 1] - y[i]) + (3.0 * t2 - 4.0 * t + 1.0) * m0 + (3.0 * t2 - 2.0 * t) * m1) / h;
    Some((cf, dcf))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::converter::dynamics::tests::c1;

    fn qd(characteristic: TorqueCharacteristic) -> QuasiDynamics {
        QuasiDynamics {
            characteristic,
            inertia: Inertias::new(0.109, 0.056, 0.01).unwrap(),
            fluid_density_kg_m3: 840.0,
            pump_radius_m: 0.12,
            pump_shape_effect_m2: 0.4,
            turbine_shape_effect_m2: 0.3,
            flow_time_constant_s: 0.0029,
        }
    }

    /// The smooth CF is the table's at every row, monotone between rows where the rows are, and
    /// its slope is continuous at every interior row.
    #[test]
    fn smooth_capacity_passes_the_rows_monotone_and_c1() {
        let c = c1();
        let (x, y) = (c.speed_ratio().to_vec(), c.capacity_factor_nm_s2().to_vec());
        for (xi, yi) in x.iter().zip(&y) {
            assert_eq!(smooth_capacity(&c, *xi).unwrap().0, *yi, "row SR {xi}");
        }
        for i in 1..x.len() {
            let (lo, hi) = (y[i - 1].min(y[i]), y[i - 1].max(y[i]));
            for k in 1..50 {
                let cf = smooth_capacity(&c, x[i - 1] + (x[i] - x[i - 1]) * k as f64 / 50.0).unwrap().0;
                assert!(cf >= lo - 1e-15 && cf <= hi + 1e-15, "CF {cf} outside [{lo}, {hi}] in segment {i}");
            }
        }
        for xi in &x[1..x.len() - 1] {
            let (left, right) = (smooth_capacity(&c, xi - 1e-9).unwrap().1, smooth_capacity(&c, xi + 1e-9).unwrap().1);
            assert!((left - right).abs() <= 1e-6 * left.abs().max(1e-6), "dCF/dSR jumps at SR {xi}: {left} {right}");
        }
        assert!(smooth_capacity(&c, -1e-9).is_none() && smooth_capacity(&c, 1.0 + 1e-9).is_none());
    }

    /// The gradient of the steady flow, which sets Q̇ and the fluid torques, is continuous across
    /// the coupling point of Table C.1 (SR 0.85), where the table's CF slope jumps from −2.2e-3 to
    /// −10.6e-3: it jumped by that factor with the linear CF (the ringing of issue 14).
    #[test]
    fn steady_flow_gradient_is_continuous_at_the_table_kink() {
        let m = qd(c1().into());
        let wp = 360.0;
        let (_, left) = m.steady_flow(wp, wp * (0.85 - 1e-9));
        let (_, right) = m.steady_flow(wp, wp * (0.85 + 1e-9));
        for j in 0..2 {
            assert!((left[j] - right[j]).abs() <= 1e-6 * left[j].abs(), "dQ_ss/dω[{j}]: {} vs {}", left[j], right[j]);
        }
        // and the flow is the table's at the rows (steady state unchanged)
        let t = c1().torques(wp, wp * 0.85);
        assert_eq!(m.steady_flow(wp, wp * 0.85).0, m.flow_scale() * t.flow_factor * t.flow_speed);
    }
}
