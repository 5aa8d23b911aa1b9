//! Building a converter model from a specification (the binding's dicts, the FMU's model.json).

use super::dynamics::{ConverterDynamics, HtDynamics, Inertias, TableDynamics};
use super::hrovat_tobler::{HtGeometry, N_PARAMS};
use super::quasi_dynamic::QuasiDynamics;
use super::table::Characteristic;
use crate::error::{CoreError, CoreResult};

/// A model specification read field by field (the Python dicts of `tcsim.transient.DynamicModel`,
/// the FMU's `resources/model.json`). `numbers(key)` is None when the key is missing.
pub trait ModelSpec {
    fn kind(&self) -> CoreResult<String>;
    fn numbers(&self, key: &str) -> Option<Vec<f64>>;
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
    let kind = spec.kind()?;
    let i = numbers(spec, "inertia_kg_m2", Some(3))?;
    let inertia = Inertias::new(i[0], i[1], i[2])?;
    let table = || -> CoreResult<Characteristic> {
        Characteristic::new(
            numbers(spec, "speed_ratio", None)?,
            numbers(spec, "torque_ratio", None)?,
            numbers(spec, "capacity_factor_nm_s2", None)?,
        )
    };
    Ok(match kind.as_str() {
        "table" => Box::new(TableDynamics { characteristic: table()?, inertia }),
        "quasi-dynamic" => {
            let shape = numbers(spec, "shape_effect_m2", Some(2))?;
            let m = QuasiDynamics {
                characteristic: table()?,
                inertia,
                fluid_density_kg_m3: number(spec, "fluid_density_kg_m3")?,
                pump_radius_m: number(spec, "pump_exit_radius_m")?,
                pump_shape_effect_m2: shape[0],
                turbine_shape_effect_m2: shape[1],
                flow_time_constant_s: number(spec, "flow_time_constant_s")?,
            };
            m.validate()?;
            Box::new(m)
        }
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
