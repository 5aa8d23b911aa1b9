//! Building a converter model from a specification (the binding's dicts, the FMU's model.json).

use super::dynamics::{ConverterDynamics, HtDynamics, Inertias, TableDynamics, TorqueLag};
use super::hrovat_tobler::{steady_state, HtGeometry, HtParam, N_PARAMS};
use super::quasi_dynamic::QuasiDynamics;
use super::table::Characteristic;
use super::torque_capacity::TorqueCharacteristic;
use crate::error::{CoreError, CoreResult};
use crate::units::REFERENCE_PUMP_SPEED_RAD_S;

/// A model specification read field by field (the Python dicts of `tcsim.transient.DynamicModel`,
/// the FMU's `resources/model.json`). `numbers(key)` is None when the key is missing.
pub trait ModelSpec {
    fn kind(&self) -> CoreResult<String>;
    fn numbers(&self, key: &str) -> Option<Vec<f64>>;
    /// A text entry (`overrun`, `interpolation` of a table); None when missing.
    fn text(&self, _key: &str) -> Option<String> {
        None
    }
}

fn numbers(spec: &dyn ModelSpec, key: &str, n: Option<usize>) -> CoreResult<Vec<f64>> {
    let v = spec.numbers(key).ok_or_else(|| CoreError::new(key, "missing", "a value in the model specification"))?;
    match n {
        Some(n) if v.len() != n => Err(CoreError::new(key, format!("{} values", v.len()), format!("{n} values"))),
        _ => Ok(v),
    }
}

fn number(spec: &dyn ModelSpec, key: &str) -> CoreResult<f64> {
    Ok(numbers(spec, key, Some(1))?[0])
}

/// The model a specification describes: `kind` is `table`, `quasi-dynamic` or `hrovat-tobler`;
/// the keys are those of `tcsim.transient.DynamicModel.spec`.
pub fn build_model(spec: &dyn ModelSpec) -> CoreResult<Box<dyn ConverterDynamics + Send>> {
    let model = build_unchecked(spec)?;
    check_finite_model(spec, model.as_ref())?;
    Ok(model)
}

/// The model at its steady stall point at the reference pump speed must have finite torques and
/// a finite stored energy: a density of 8.4e-292 kg/m³ makes the quasi-dynamic model's flow, and so
/// its energy, overflow. The error names the parameter of `spec` farthest outside its plausible
/// range.
fn check_finite_model(spec: &dyn ModelSpec, model: &dyn ConverterDynamics) -> CoreResult<()> {
    let wp = REFERENCE_PUMP_SPEED_RAD_S;
    let finite = match model.steady_point(wp, 0.0) {
        Ok(p) => {
            let (u, m) = (p.u, model.mass());
            let f = model.forces(&u, 1.0);
            let energy: f64 = (0..4).map(|i| (0..4).map(|j| 0.5 * u[i] * m[i][j] * u[j]).sum::<f64>()).sum();
            u.iter().chain(f.iter()).all(|x| x.is_finite()) && energy.is_finite()
        }
        Err(_) => true, // the model's own checks report a missing steady state
    };
    if finite {
        return Ok(());
    }
    // (spec key, the names of its values in errors, as the models' own checks name them, quantity)
    let keys: [(&str, &[&str], &str); 4] = [
        ("fluid_density_kg_m3", &["fluid_density_kg_m3"], "fluid_density_kg_m3"),
        ("pump_exit_radius_m", &["pump_exit_radius_m"], "radius_m"),
        ("fluid_length_m", &["geometry.fluid_length_m"], "fluid_length_m"),
        ("inertia_kg_m2", &["inertia.pump_kg_m2", "inertia.turbine_kg_m2", "inertia.stator_kg_m2"], "inertia_kg_m2"),
    ];
    let mut values: Vec<(String, f64, &str)> = Vec::new();
    for (key, names, quantity) in keys {
        for (name, v) in names.iter().zip(spec.numbers(key).unwrap_or_default()) {
            values.push((name.to_string(), v, quantity));
        }
    }
    let pairs: Vec<(f64, &str)> = values.iter().map(|(_, v, q)| (*v, *q)).collect();
    let i = crate::plausibility::farthest_outside(&pairs).unwrap_or(0);
    let (field, value) =
        values.get(i).map_or(("fluid_density_kg_m3".to_string(), f64::NAN), |(k, v, _)| (k.clone(), *v));
    Err(CoreError::new(
        field,
        value,
        "a value at which the model's torques and stored energy are finite (they overflow at stall and 2000 rpm; see the plausible ranges)",
    ))
}

/// The key of the table model's first-order lag time constant, s (docs/lag.md); absent: no lag.
pub const LAG_KEY: &str = "lag_time_constant_s";

/// The table model's lag ([`TorqueLag`]) from the optional key [`LAG_KEY`].
fn lag(spec: &dyn ModelSpec) -> CoreResult<Option<TorqueLag>> {
    match spec.numbers(LAG_KEY) {
        None => Ok(None),
        Some(_) => Ok(Some(TorqueLag::new(number(spec, LAG_KEY)?)?)),
    }
}

fn build_unchecked(spec: &dyn ModelSpec) -> CoreResult<Box<dyn ConverterDynamics + Send>> {
    let kind = spec.kind()?;
    let i = numbers(spec, "inertia_kg_m2", Some(3))?;
    let inertia = Inertias::new(i[0], i[1], i[2])?;
    let table = || characteristic(spec);
    if kind != "table" && spec.numbers(LAG_KEY).is_some() {
        return Err(CoreError::new(
            "characteristic.lag_time_constant_s",
            kind,
            "the table model: the quasi-dynamic model has its own flow lag and Hrovat & Tobler its fluid inertia (docs/lag.md)",
        ));
    }
    Ok(match kind.as_str() {
        "table" => Box::new(TableDynamics { characteristic: table()?, inertia, lag: lag(spec)? }),
        "quasi-dynamic" => Box::new(quasi_dynamic(spec, inertia)?),
        "hrovat-tobler" => {
            let g = numbers(spec, "geometry", Some(N_PARAMS))?;
            let mut values = [0.0; N_PARAMS];
            values.copy_from_slice(&g);
            let shape = numbers(spec, "shape_effect_m2", Some(3))?;
            Box::new(HtDynamics::new(
                HtGeometry::new(values)?,
                inertia,
                number(spec, "fluid_length_m")?,
                [shape[0], shape[1], shape[2]],
            )?)
        }
        other => return Err(CoreError::new("kind", other, "table, quasi-dynamic or hrovat-tobler")),
    })
}

/// The table(s) of a specification: `speed_ratio`, `torque_ratio`, `capacity_factor_nm_s2` and the
/// converter's `overrun` and `interpolation`; with `input_torque_nm` (one torque per table, N·m) the
/// columns hold the tables one after the other, `table_rows` rows each (torque-dependent capacity,
/// [`TorqueCharacteristic`]). Without `input_torque_nm`: one table, exactly as before.
pub fn characteristic(spec: &dyn ModelSpec) -> CoreResult<TorqueCharacteristic> {
    let columns = [
        numbers(spec, "speed_ratio", None)?,
        numbers(spec, "torque_ratio", None)?,
        numbers(spec, "capacity_factor_nm_s2", None)?,
    ];
    let (overrun, interpolation) = (spec.text("overrun"), spec.text("interpolation"));
    match spec.numbers("input_torque_nm") {
        None => {
            let [sr, tr, cf] = columns;
            Ok(Characteristic::new(sr, tr, cf)?.with_rules(overrun.as_deref(), interpolation.as_deref())?.into())
        }
        Some(torques) => {
            let rows = numbers(spec, "table_rows", Some(torques.len()))?;
            TorqueCharacteristic::from_columns(
                torques,
                &rows,
                [&columns[0], &columns[1], &columns[2]],
                overrun.as_deref(),
                interpolation.as_deref(),
            )
        }
    }
}

/// The quasi-dynamic model of a specification whose `kind` is `quasi-dynamic`, with `inertia`
/// (read by the caller from `inertia_kg_m2`).
pub fn quasi_dynamic(spec: &dyn ModelSpec, inertia: Inertias) -> CoreResult<QuasiDynamics> {
    let shape = numbers(spec, "shape_effect_m2", Some(2))?;
    QuasiDynamics::new(
        characteristic(spec)?,
        inertia,
        number(spec, "fluid_density_kg_m3")?,
        number(spec, "pump_exit_radius_m")?,
        [shape[0], shape[1]],
        number(spec, "flow_time_constant_s")?,
    )
}

/// The quasi-dynamic model of a full specification (its `inertia_kg_m2` read here).
pub fn quasi_dynamic_model(spec: &dyn ModelSpec) -> CoreResult<QuasiDynamics> {
    let i = numbers(spec, "inertia_kg_m2", Some(3))?;
    quasi_dynamic(spec, Inertias::new(i[0], i[1], i[2])?)
}

/// The default flow time constant τ_Q of the quasi-dynamic model, s: the fluid's inertance over the
/// slope of the net head with respect to the flow, `τ_Q = (ρL_f/A) / |∂F_Q/∂Q|`, for the Hrovat &
/// Tobler `geometry` with fluid length `fluid_length_m` (m) at stall (locked stator, ω_t = 0) and
/// the reference pump speed [`REFERENCE_PUMP_SPEED_RAD_S`] (2000 rpm), docs/physics.md §5. It scales
/// as 1/ω_p. The arithmetic is that of the Python copy it replaces (`tcsim.transient`), term for
/// term: `L_f / |∂(eq 2.15 right-hand side / ρ)/∂q|` with `q = Q/A`.
pub fn default_flow_time_constant_s(geometry: &HtGeometry<f64>, fluid_length_m: f64) -> CoreResult<f64> {
    use HtParam::*;
    let wp = REFERENCE_PUMP_SPEED_RAD_S;
    let flow = steady_state(geometry, wp, 0.0)?.flow_m3_s;
    let g = |p: HtParam| geometry.get(p);
    let (tp, tt, ts) = (g(PumpExitAngle).tan(), g(TurbineExitAngle).tan(), g(StatorExitAngle).tan());
    let (tpp, ttt, tss) = (g(PumpInletAngle).tan(), g(TurbineInletAngle).tan(), g(StatorInletAngle).tan());
    let (rp, rs) = (g(PumpExitRadius), g(StatorExitRadius));
    let q = flow / g(FlowArea);
    // ∂/∂q of eq 2.15's right-hand side divided by ρ, at ω_t = ω_s = 0 (head, shock and friction)
    let slope = wp * (rp * tp - rs * ts)
        - (g(PumpShockLoss) * (-rs * wp + q * (ts - tpp)) * (ts - tpp)
            + g(TurbineShockLoss) * (rp * wp + q * (tp - ttt)) * (tp - ttt)
            + g(StatorShockLoss) * q * ((tt - tss) * (tt - tss))
            + g(FrictionLoss) * (3.0 + tp * tp + tt * tt + ts * ts) * q);
    let tau = fluid_length_m / slope.abs();
    if tau.is_finite() && tau > 0.0 {
        Ok(tau)
    } else {
        Err(CoreError::new(
            "quasi_dynamic.flow_time_constant_s",
            tau,
            "a finite, positive default from [geometry] (give flow_time_constant_s explicitly)",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_flow_time_constant_matches_the_python_value() {
        // tcsim.transient.default_flow_time_constant_s of the bundled li-sunden-2016 (Appendix D)
        // and li-sunden-2016-fitted converters, L_f = 0.2914 m, printed by Python (repr)
        let tau = default_flow_time_constant_s(&HtGeometry::appendix_d(), 0.2914).unwrap();
        assert!((tau - 0.002931041445525305).abs() <= 1e-12 * tau, "{tau}");
        let fitted = HtGeometry::new([
            0.01,
            840.0,
            0.12,
            0.065,
            0.06,
            -0.44846278309449555,
            -0.831883250727564,
            0.9055174170930996,
            0.9068172214994222,
            -0.3263351452601018,
            -0.8672346227619814,
            0.5658235096868285,
            0.9473337805257149,
            0.22645682280069623,
            0.01,
        ])
        .unwrap();
        let tau_fitted = default_flow_time_constant_s(&fitted, 0.2914).unwrap();
        assert!((tau_fitted - 0.01135401823191251).abs() <= 1e-12 * tau_fitted, "{tau_fitted}");
        // it scales with the fluid length
        let double = default_flow_time_constant_s(&HtGeometry::appendix_d(), 2.0 * 0.2914).unwrap();
        assert!((double - 2.0 * tau).abs() <= 1e-15 * tau);
        assert!(default_flow_time_constant_s(&HtGeometry::appendix_d(), f64::NAN).is_err());
    }
}
