//! `tcsim._core`: the thin PyO3 layer over `tcsim-core`.
//!
//! Every entry point converts NumPy arrays to slices, releases the GIL for the computation and
//! turns a core error into `tcsim._core.CoreError(message, field, value, expected)`. A Rust panic
//! is caught here and becomes a `RuntimeError`; it never unwinds into Python.

use std::panic::{catch_unwind, AssertUnwindSafe};

use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use tcsim_core::batch::{ht_ratio_gradients as core_ratio_gradients, ht_steady_states as core_steady_states};
use tcsim_core::capacity::CapacityConvention;
use tcsim_core::hrovat_tobler::{coupling_point, HtGeometry, HtParam, N_PARAMS};
use tcsim_core::table::Characteristic;
use tcsim_core::CoreError;

pyo3::create_exception!(_core, CoreInputError, PyValueError, "Bad input to the tcsim core: args are (message, field, value, expected).");

fn input_error(e: CoreError) -> PyErr {
    CoreInputError::new_err((e.to_string(), e.field, e.value, e.expected))
}

/// Run `f`, turning a panic into a `RuntimeError` instead of letting it unwind into Python.
fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let msg = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(PyRuntimeError::new_err(format!("internal error in the tcsim core: {msg}")))
        }
    }
}

fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<&'a [f64]> {
    a.as_slice().map_err(|_| PyValueError::new_err(format!("{name} must be a contiguous 1-D float64 array")))
}

fn convention(key: &str) -> PyResult<CapacityConvention> {
    CapacityConvention::from_key(key).map_err(input_error)
}

fn geometry_rows(geometry: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<HtGeometry<f64>>> {
    let a = geometry.as_array();
    if a.ncols() != N_PARAMS {
        return Err(PyValueError::new_err(format!("geometry must have {N_PARAMS} columns, got {}", a.ncols())));
    }
    a.rows()
        .into_iter()
        .map(|row| {
            let mut v = [0.0; N_PARAMS];
            v.iter_mut().zip(row.iter()).for_each(|(d, s)| *d = *s);
            HtGeometry::new(v).map_err(input_error)
        })
        .collect()
}

fn param(key: &str) -> PyResult<HtParam> {
    HtParam::ALL.into_iter().find(|p| p.key() == key).ok_or_else(|| PyValueError::new_err(format!("unknown Hrovat & Tobler parameter {key:?}")))
}

/// Names of the capacity conventions.
#[pyfunction]
fn capacity_conventions() -> Vec<&'static str> {
    CapacityConvention::ALL.iter().map(|c| c.key()).collect()
}

/// Convert values in `convention` to capacity factor in N·m/(rad/s)².
#[pyfunction]
fn capacity_to_cf<'py>(py: Python<'py>, convention_key: &str, values: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let c = convention(convention_key)?;
        Ok(slice(&values, "values")?.iter().map(|&v| c.to_capacity_factor(v)).collect::<Vec<_>>().into_pyarray(py))
    })
}

/// Convert capacity factors in N·m/(rad/s)² to `convention`.
#[pyfunction]
fn cf_to_capacity<'py>(py: Python<'py>, convention_key: &str, cf: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let c = convention(convention_key)?;
        Ok(slice(&cf, "cf")?.iter().map(|&v| c.from_capacity_factor(v)).collect::<Vec<_>>().into_pyarray(py))
    })
}

/// Names of the Hrovat & Tobler steady-state parameters, in the column order the geometry
/// arrays use (angles in radians).
#[pyfunction]
fn ht_parameter_names() -> Vec<&'static str> {
    HtParam::ALL.iter().map(|p| p.key()).collect()
}

/// Validate one parameter row; raises CoreInputError naming the parameter.
#[pyfunction]
fn ht_check_geometry(geometry: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
    guard(|| {
        let v = slice(&geometry, "geometry")?;
        let arr: [f64; N_PARAMS] = v.try_into().map_err(|_| PyValueError::new_err(format!("geometry must have {N_PARAMS} values")))?;
        HtGeometry::new(arr).map(|_| ()).map_err(input_error)
    })
}

/// Closed-form steady states at `pump[i], turbine[i]` (rad/s) with parameter row `geometry[i]`,
/// or row 0 for all points. Returns a dict of arrays. With `strict`, the first point without a
/// steady state raises CoreInputError (its `field` gets the point index).
#[pyfunction]
#[pyo3(signature = (geometry, pump_speed_rad_s, turbine_speed_rad_s, strict=true))]
fn ht_steady_states<'py>(
    py: Python<'py>,
    geometry: PyReadonlyArray2<'py, f64>,
    pump_speed_rad_s: PyReadonlyArray1<'py, f64>,
    turbine_speed_rad_s: PyReadonlyArray1<'py, f64>,
    strict: bool,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let g = geometry_rows(&geometry)?;
        let (wp, wt) = (slice(&pump_speed_rad_s, "pump_speed_rad_s")?, slice(&turbine_speed_rad_s, "turbine_speed_rad_s")?);
        if wp.len() != wt.len() || (g.len() != 1 && g.len() != wp.len()) {
            return Err(PyValueError::new_err("pump and turbine speeds need equal lengths, and geometry one row or one row per point"));
        }
        let cols = py
            .detach(|| core_steady_states(&g, wp, wt, strict))
            .map_err(|e| input_error(CoreError { field: format!("{} (point {})", e.error.field, e.index), ..e.error }))?;
        let d = PyDict::new(py);
        d.set_item("flow_m3_s", cols.flow_m3_s.into_pyarray(py))?;
        d.set_item("stator_speed_rad_s", cols.stator_speed_rad_s.into_pyarray(py))?;
        d.set_item("pump_torque_nm", cols.pump_torque_nm.into_pyarray(py))?;
        d.set_item("turbine_torque_nm", cols.turbine_torque_nm.into_pyarray(py))?;
        d.set_item("stator_torque_nm", cols.stator_torque_nm.into_pyarray(py))?;
        d.set_item("stator_mode", cols.stator_mode.into_pyarray(py))?;
        Ok(d)
    })
}

/// Coupling point (speed ratio where the locked stator's holding torque changes sign), or None.
#[pyfunction]
fn ht_coupling_point(geometry: PyReadonlyArray2<'_, f64>) -> PyResult<Option<f64>> {
    guard(|| {
        let g = geometry_rows(&geometry)?;
        Ok(g.first().and_then(coupling_point))
    })
}

/// TR and CF at `speed_ratio` (pump at `pump_speed_rad_s`) with exact derivatives with respect to
/// the parameters named in `free`: returns (tr, cf, d_tr, d_cf), derivatives shaped (n, len(free)).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn ht_ratio_gradients<'py>(
    py: Python<'py>,
    geometry: PyReadonlyArray2<'py, f64>,
    pump_speed_rad_s: f64,
    speed_ratio: PyReadonlyArray1<'py, f64>,
    free: Vec<String>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    guard(|| {
        let g = geometry_rows(&geometry)?;
        let g = *g.first().ok_or_else(|| PyValueError::new_err("geometry has no row"))?;
        let sr = slice(&speed_ratio, "speed_ratio")?;
        let free = free.iter().map(|k| param(k)).collect::<PyResult<Vec<_>>>()?;
        let (n, k) = (sr.len(), free.len());
        let (tr, cf, dtr, dcf) = py.detach(|| core_ratio_gradients(&g, pump_speed_rad_s, sr, &free));
        let shape = |v: Vec<f64>| numpy::ndarray::Array2::from_shape_vec((n, k), v).map(|a| a.into_pyarray(py));
        let err = |_| PyRuntimeError::new_err("gradient shape mismatch");
        Ok((tr.into_pyarray(py), cf.into_pyarray(py), shape(dtr).map_err(err)?, shape(dcf).map_err(err)?))
    })
}

fn characteristic(sr: &PyReadonlyArray1<'_, f64>, tr: &PyReadonlyArray1<'_, f64>, cf: &PyReadonlyArray1<'_, f64>) -> PyResult<Characteristic> {
    Characteristic::new(slice(sr, "speed_ratio")?.to_vec(), slice(tr, "torque_ratio")?.to_vec(), slice(cf, "capacity_factor_nm_s2")?.to_vec())
        .map_err(input_error)
}

/// Validate a characteristic table (finite, strictly increasing SR, equal lengths).
#[pyfunction]
fn table_check(speed_ratio: PyReadonlyArray1<'_, f64>, torque_ratio: PyReadonlyArray1<'_, f64>, capacity_factor_nm_s2: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
    guard(|| characteristic(&speed_ratio, &torque_ratio, &capacity_factor_nm_s2).map(|_| ()))
}

/// Steady states of the table model at `pump[i], turbine[i]` (rad/s). Returns a dict of arrays.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn table_steady_states<'py>(
    py: Python<'py>,
    speed_ratio: PyReadonlyArray1<'py, f64>,
    torque_ratio: PyReadonlyArray1<'py, f64>,
    capacity_factor_nm_s2: PyReadonlyArray1<'py, f64>,
    pump_speed_rad_s: PyReadonlyArray1<'py, f64>,
    turbine_speed_rad_s: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let t = characteristic(&speed_ratio, &torque_ratio, &capacity_factor_nm_s2)?;
        let (wp, wt) = (slice(&pump_speed_rad_s, "pump_speed_rad_s")?, slice(&turbine_speed_rad_s, "turbine_speed_rad_s")?);
        if wp.len() != wt.len() {
            return Err(PyValueError::new_err("pump and turbine speeds need equal lengths"));
        }
        let points = py
            .detach(|| wp.iter().zip(wt).enumerate().map(|(i, (&p, &t_))| t.operating_point(p, t_).map_err(|e| (i, e))).collect::<Result<Vec<_>, _>>())
            .map_err(|(i, e)| input_error(CoreError { field: format!("{} (point {i})", e.field), ..e }))?;
        let col = |f: fn(&tcsim_core::table::TableOperatingPoint) -> f64| points.iter().map(f).collect::<Vec<_>>().into_pyarray(py);
        let d = PyDict::new(py);
        d.set_item("speed_ratio", col(|p| p.speed_ratio))?;
        d.set_item("torque_ratio", col(|p| p.torque_ratio))?;
        d.set_item("capacity_factor_nm_s2", col(|p| p.capacity_factor_nm_s2))?;
        d.set_item("pump_torque_nm", col(|p| p.pump_torque_nm))?;
        d.set_item("turbine_torque_nm", col(|p| p.turbine_torque_nm))?;
        d.set_item("stator_torque_nm", col(|p| p.stator_torque_nm))?;
        d.set_item("extrapolated", points.iter().map(|p| p.extrapolated).collect::<Vec<_>>())?;
        Ok(d)
    })
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("CoreInputError", m.py().get_type::<CoreInputError>())?;
    m.add_function(wrap_pyfunction!(capacity_conventions, m)?)?;
    m.add_function(wrap_pyfunction!(capacity_to_cf, m)?)?;
    m.add_function(wrap_pyfunction!(cf_to_capacity, m)?)?;
    m.add_function(wrap_pyfunction!(ht_parameter_names, m)?)?;
    m.add_function(wrap_pyfunction!(ht_check_geometry, m)?)?;
    m.add_function(wrap_pyfunction!(ht_steady_states, m)?)?;
    m.add_function(wrap_pyfunction!(ht_coupling_point, m)?)?;
    m.add_function(wrap_pyfunction!(ht_ratio_gradients, m)?)?;
    m.add_function(wrap_pyfunction!(table_check, m)?)?;
    m.add_function(wrap_pyfunction!(table_steady_states, m)?)?;
    Ok(())
}
