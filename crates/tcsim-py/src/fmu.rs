//! The FMU's variable table (`tcsim_fmu::variables`) for `tcsim export-fmu`, which writes
//! `modelDescription.xml` from it and from nothing else.

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyTuple};

use tcsim_core::CoreError;
use tcsim_fmu::variables::{self, Model, SpecValue, Variable};

use crate::input_error;

fn model_of(kind: &str) -> PyResult<Model> {
    Model::from_kind(kind)
        .ok_or_else(|| input_error(CoreError::new("kind", kind, "table, quasi-dynamic or hrovat-tobler")))
}

/// A number of the specification as `tcsim.fmu` counts it: an int or a float, not a bool.
fn number(value: &Bound<'_, PyAny>) -> Option<f64> {
    let numeric =
        (value.is_instance_of::<PyFloat>() || value.is_instance_of::<PyInt>()) && !value.is_instance_of::<PyBool>();
    if numeric {
        value.extract::<f64>().ok()
    } else {
        None
    }
}

/// The numeric entries of a model specification (a dict, in its key order).
fn spec_entries(spec: &Bound<'_, PyDict>) -> PyResult<Vec<(String, SpecValue)>> {
    let mut out = Vec::new();
    for (key, value) in spec.iter() {
        let key: String = key.extract()?;
        if let Some(v) = number(&value) {
            out.push((key, SpecValue::Scalar(v)));
        } else if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
            let items: Vec<Bound<'_, PyAny>> = value.extract()?;
            let numbers: Option<Vec<f64>> = items.iter().map(number).collect();
            match numbers {
                Some(a) if !a.is_empty() => out.push((key, SpecValue::Array(a))),
                _ => {}
            }
        }
    }
    Ok(out)
}

fn variable_dict<'py>(py: Python<'py>, v: &Variable) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("vr", v.vr)?;
    d.set_item("name", &v.name)?;
    d.set_item("causality", v.causality)?;
    d.set_item("variability", v.variability)?;
    d.set_item("initial", v.initial)?;
    d.set_item("unit", &v.unit)?;
    d.set_item("display_unit", v.display_unit)?;
    d.set_item("description", &v.description)?;
    d.set_item("start", v.start)?;
    d.set_item("start_text", &v.start_text)?;
    d.set_item("derivative_of", v.derivative_of)?;
    d.set_item("dependencies", &v.dependencies)?;
    d.set_item("key", v.parameter.as_ref().map(|p| &p.0))?;
    d.set_item("index", v.parameter.as_ref().map(|p| p.1))?;
    Ok(d)
}

/// The variables of the FMU of the model specification `spec` (`tcsim.transient.DynamicModel.spec`,
/// whose `kind` is the model) under `causality` (`pump-torque`, `speeds` or `torques`), in the order of
/// `<ModelVariables>`: dicts with `vr`, `name`, `causality`, `variability`, `initial`, `unit`,
/// `display_unit`, `description`, `start`, `start_text` (as the XML writes it), `derivative_of`
/// (the state's value reference, for `der(x)`), `dependencies` (an output's direct inputs) and,
/// for a tunable parameter, the spec entry `key` and `index`.
#[pyfunction]
pub fn fmu_variables<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyDict>,
    causality: &str,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let kind: String = match spec.get_item("kind")? {
        Some(k) => k.extract()?,
        None => return Err(input_error(CoreError::new("kind", "missing", "a model kind"))),
    };
    let model = model_of(&kind)?;
    let causality = variables::causality_of(causality)
        .ok_or_else(|| input_error(CoreError::new("causality", causality, "pump-torque, speeds or torques")))?;
    let params = variables::parameters(&spec_entries(spec)?).map_err(pyo3::exceptions::PyValueError::new_err)?;
    variables::variables(model, causality, &params).iter().map(|v| variable_dict(py, v)).collect()
}

/// The signals of the FMU (whatever the causality), by value reference: dicts with `vr`,
/// `name`, `unit`, `description`, `models` (the model kinds that have it) and `state` (whether it
/// is a continuous state when it is not an input).
#[pyfunction]
pub fn fmu_signals(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    variables::SIGNALS
        .iter()
        .map(|s| {
            let d = PyDict::new(py);
            d.set_item("vr", s.vr)?;
            d.set_item("name", s.name)?;
            d.set_item("unit", s.unit)?;
            d.set_item("description", s.description)?;
            d.set_item("models", s.models.iter().map(|m| m.kind()).collect::<Vec<_>>())?;
            d.set_item("state", s.state.is_some())?;
            Ok(d)
        })
        .collect()
}

/// The `--causality` choices and the names of their two inputs.
#[pyfunction]
pub fn fmu_causalities() -> Vec<(&'static str, [&'static str; 2])> {
    variables::CAUSALITIES
        .iter()
        .map(|(name, _, inputs)| (*name, inputs.map(|vr| variables::signal_name(vr).unwrap_or_default())))
        .collect()
}

/// The names of the inputs every causality has besides its two (the lock-up capacity).
#[pyfunction]
pub fn fmu_common_inputs() -> Vec<&'static str> {
    variables::COMMON_INPUTS.iter().map(|&vr| variables::signal_name(vr).unwrap_or_default()).collect()
}

/// `numberOfEventIndicators` of the FMU of a model kind.
#[pyfunction]
pub fn fmu_event_indicators(model: &str) -> PyResult<usize> {
    Ok(model_of(model)?.event_indicators())
}

/// `<UnitDefinitions>`: (name, SI base-unit exponents, display units with their factors as the
/// XML writes them).
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn fmu_units() -> Vec<(&'static str, Vec<(&'static str, i32)>, Vec<(&'static str, String)>)> {
    variables::UNITS
        .iter()
        .map(|u| (u.name, u.base.to_vec(), u.display.iter().map(|&(n, f)| (n, variables::xml_number(f))).collect()))
        .collect()
}

/// FMI 3.0: the event indicators of a model kind as variables (dicts as [`fmu_variables`]), in
/// the order of `<EventIndicator>`.
#[pyfunction]
pub fn fmu_event_indicator_variables<'py>(py: Python<'py>, model: &str) -> PyResult<Vec<Bound<'py, PyDict>>> {
    variables::event_indicator_variables(model_of(model)?).iter().map(|v| variable_dict(py, v)).collect()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("FMU_MODEL_IDENTIFIER", variables::MODEL_IDENTIFIER)?;
    m.add("FMU_LOG_CATEGORIES", tcsim_fmu::LOG_CATEGORIES.to_vec())?;
    m.add("FMU_FIRST_PARAMETER_VR", variables::FIRST_PARAMETER)?;
    m.add_function(wrap_pyfunction!(fmu_variables, m)?)?;
    m.add_function(wrap_pyfunction!(fmu_signals, m)?)?;
    m.add_function(wrap_pyfunction!(fmu_causalities, m)?)?;
    m.add_function(wrap_pyfunction!(fmu_common_inputs, m)?)?;
    m.add_function(wrap_pyfunction!(fmu_event_indicators, m)?)?;
    m.add_function(wrap_pyfunction!(fmu_units, m)?)?;
    m.add("FMU_TIME_VR", variables::TIME)?;
    m.add("FMU_INSTANTIATION_TOKEN_KEY", tcsim_fmu::fmi3::TOKEN_KEY)?;
    m.add_function(wrap_pyfunction!(fmu_event_indicator_variables, m)?)?;
    Ok(())
}
