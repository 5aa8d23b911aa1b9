//! `tcsim._core`: the thin PyO3 layer over `tcsim-core`.
//!
//! Every entry point converts NumPy arrays to slices, releases the GIL for the computation and
//! turns a core error ([`CoreError`]) into `tcsim._core.CoreInputError(message, field, value,
//! expected, source)`, `source` naming the input at fault (`converter`, `drive`, `initial`,
//! `scenario`, `vehicle`, `options`). The batch runs return typed results (`TransientRun`,
//! `LaunchRun`). A Rust panic is caught here and becomes a `RuntimeError`; it never unwinds into
//! Python.

mod design;
mod fmu;

use std::collections::BTreeMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

use tcsim_core::batch::{
    ht_ratio_gradients as core_ratio_gradients, ht_steady_states_cancellable as core_steady_states,
    run_transient_columns, run_transient_jobs_cancellable, BatchColumns, RunFailure, TransientJob,
};
use tcsim_core::converter::backward::{backward_points, Backward, Load, Reason};
use tcsim_core::converter::capacity::CapacityConvention;
use tcsim_core::converter::dynamics::ConverterDynamics;
use tcsim_core::converter::dynamics::{Inertias, MassMatrixBound};
use tcsim_core::converter::hrovat_tobler::{
    coupling_point, steady_mode_names as steady_mode_names_core, steady_torque_ratio as steady_torque_ratio_core,
    HtGeometry, HtParam, N_PARAMS,
};
use tcsim_core::converter::table::{Characteristic, TableOperatingPoint};
use tcsim_core::converter::torque_capacity::TorqueCharacteristic;
use tcsim_core::engine::converter_events::EventKind;
use tcsim_core::engine::isolated::{Drive, IgnoredInitial, InitialState, TurbineLoad};
use tcsim_core::engine::lockup::LockupCommand;
use tcsim_core::engine::options::{SolverOptions, TransientError};
use tcsim_core::engine::outputs::{isolated_output_size, Selection, COLUMNS, INFINITE_ALLOWED, NAN_NOT_EXPECTED};
use tcsim_core::engine::signal::Signal;
use tcsim_core::vehicle::file::{read_vehicle as read_vehicle_core, VehicleDocument};
use tcsim_core::vehicle::launch::{check_launch_output, simulate_launch, DEFAULT_OUTPUT_STEP_S};
use tcsim_core::vehicle::outputs::launch_column_names;
use tcsim_core::vehicle::parameters::Scenario;
use tcsim_core::{CoreError, InputSource};

pyo3::create_exception!(
    _core,
    CoreInputError,
    PyValueError,
    "Bad input to the tcsim core: args are (message, field, value, expected, source), source the input at fault: converter, drive, initial, scenario, vehicle or options."
);

fn input_error(e: CoreError) -> PyErr {
    CoreInputError::new_err((e.to_string(), e.field, e.value, e.expected, e.source.key()))
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

/// How often a cancellable batch ([`cancellable`]) lets Python run its signal handlers.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Sets the `done` flag of [`cancellable`] when the work ends, also by a panic.
struct DoneOnDrop<'a>(&'a (Mutex<bool>, Condvar));

impl Drop for DoneOnDrop<'_> {
    fn drop(&mut self) {
        if let Ok(mut done) = self.0 .0.lock() {
            *done = true;
        }
        self.0 .1.notify_all();
    }
}

/// Run `work` with the GIL released on a helper thread, giving it a cancel flag, while this thread
/// re-attaches every [`SIGNAL_POLL`] to run Python's signal handlers (`check_signals`). When a
/// handler raises (Ctrl-C's `KeyboardInterrupt`, or the exception of a SIGTERM handler), the flag is
/// set, the work's end is awaited (the core's workers start no new job) and that exception returned.
/// `Ok(None)` from `work` (stopped by the flag) cannot reach the caller otherwise.
fn cancellable<R: Send>(py: Python<'_>, work: impl FnOnce(&AtomicBool) -> Option<R> + Send) -> PyResult<R> {
    let cancel = AtomicBool::new(false);
    let done = (Mutex::new(false), Condvar::new());
    let finished = || -> bool {
        let Ok(guard) = done.0.lock() else { return true };
        match done.1.wait_timeout_while(guard, SIGNAL_POLL, |d| !*d) {
            Ok((d, _)) => *d,
            Err(_) => true,
        }
    };
    std::thread::scope(|scope| {
        let handle = scope.spawn(|| {
            let _done = DoneOnDrop(&done);
            work(&cancel)
        });
        let mut pending = None;
        while !py.detach(finished) {
            if let Err(e) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                pending = Some(e);
                break;
            }
        }
        let result = handle.join();
        match (pending, result) {
            (Some(e), _) => Err(e),
            (None, Ok(Some(r))) => Ok(r),
            (None, Ok(None)) => Err(PyRuntimeError::new_err("internal error: a batch stopped without a cancel")),
            (None, Err(_)) => Err(PyRuntimeError::new_err("internal error in the tcsim core: a batch worker panicked")),
        }
    })
}

/// [`cancellable`] for a batch of `runs` runs ([`cancellable_unless_one_piece`]: a single run is
/// not cancelled part-way in either form, the flag stops a batch between runs).
fn cancellable_runs<R: Send>(
    py: Python<'_>,
    runs: usize,
    work: impl FnOnce(&AtomicBool) -> Option<R> + Send,
) -> PyResult<R> {
    cancellable_unless_one_piece(py, runs <= 1, work)
}

/// [`cancellable`], unless the work is `one_piece`, which the cancel flag could not stop part-way
/// (one run, or no more points than the core takes between two looks at the flag): that runs on
/// this thread with the GIL released, without the helper thread's start and hand-over (about 25 µs,
/// a third of a short take-off's time through Python and most of a steady state's of a few
/// points); a signal that arrived meanwhile raises right after it.
fn cancellable_unless_one_piece<R: Send>(
    py: Python<'_>,
    one_piece: bool,
    work: impl FnOnce(&AtomicBool) -> Option<R> + Send,
) -> PyResult<R> {
    if !one_piece {
        return cancellable(py, work);
    }
    let result = py.detach(|| work(&AtomicBool::new(false)));
    py.check_signals()?;
    result.ok_or_else(|| PyRuntimeError::new_err("internal error: a run stopped without a cancel"))
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
    HtParam::ALL
        .into_iter()
        .find(|p| p.key() == key)
        .ok_or_else(|| PyValueError::new_err(format!("unknown Hrovat & Tobler parameter {key:?}")))
}

/// The inputs a `CoreInputError` or a `RunError` may be about, as its `source` names them.
#[pyfunction]
fn input_sources() -> Vec<&'static str> {
    InputSource::ALL.iter().map(|s| s.key()).collect()
}

/// Names of the capacity conventions.
#[pyfunction]
fn capacity_conventions() -> Vec<&'static str> {
    CapacityConvention::ALL.iter().map(|c| c.key()).collect()
}

/// Convert values in `convention` to capacity factor in N·m/(rad/s)².
#[pyfunction]
fn capacity_to_cf<'py>(
    py: Python<'py>,
    convention_key: &str,
    values: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let c = convention(convention_key)?;
        Ok(slice(&values, "values")?.iter().map(|&v| c.to_capacity_factor(v)).collect::<Vec<_>>().into_pyarray(py))
    })
}

/// Convert capacity factors in N·m/(rad/s)² to `convention`.
#[pyfunction]
fn cf_to_capacity<'py>(
    py: Python<'py>,
    convention_key: &str,
    cf: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
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
        let arr: [f64; N_PARAMS] =
            v.try_into().map_err(|_| PyValueError::new_err(format!("geometry must have {N_PARAMS} values")))?;
        HtGeometry::new(arr).map(|_| ()).map_err(input_error)
    })
}

/// Closed-form steady states at `pump[i], turbine[i]` (rad/s) with parameter row `geometry[i]`,
/// or row 0 for all points. Returns a dict of arrays. With `strict`, the first point without a
/// steady state raises CoreInputError (its `field` gets the point index). `threads` workers (0: one
/// per core), at least 16 384 points each; the results do not depend on it.
#[pyfunction]
#[pyo3(signature = (geometry, pump_speed_rad_s, turbine_speed_rad_s, strict=true, threads=0))]
fn ht_steady_states<'py>(
    py: Python<'py>,
    geometry: PyReadonlyArray2<'py, f64>,
    pump_speed_rad_s: PyReadonlyArray1<'py, f64>,
    turbine_speed_rad_s: PyReadonlyArray1<'py, f64>,
    strict: bool,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let g = geometry_rows(&geometry)?;
        let (wp, wt) =
            (slice(&pump_speed_rad_s, "pump_speed_rad_s")?, slice(&turbine_speed_rad_s, "turbine_speed_rad_s")?);
        if wp.len() != wt.len() || (g.len() != 1 && g.len() != wp.len()) {
            return Err(PyValueError::new_err(
                "pump and turbine speeds need equal lengths, and geometry one row or one row per point",
            ));
        }
        let one_piece = wp.len() <= tcsim_core::batch::CANCEL_CHECK_POINTS;
        let cols = cancellable_unless_one_piece(py, one_piece, |cancel| {
            match core_steady_states(&g, wp, wt, strict, threads, cancel) {
                Ok(cols) => cols.map(Ok),
                Err(e) => Some(Err(e)),
            }
        })?
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

/// `(tr, cf, d_tr, d_cf)` of [`ht_ratio_gradients`].
type RatioGradients<'py> =
    (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// TR and CF at `speed_ratio` (pump at `pump_speed_rad_s`) with exact derivatives with respect to
/// the parameters named in `free`: returns (tr, cf, d_tr, d_cf), derivatives shaped (n, len(free)).
#[pyfunction]
fn ht_ratio_gradients<'py>(
    py: Python<'py>,
    geometry: PyReadonlyArray2<'py, f64>,
    pump_speed_rad_s: f64,
    speed_ratio: PyReadonlyArray1<'py, f64>,
    free: Vec<String>,
) -> PyResult<RatioGradients<'py>> {
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

/// The table(s) of the binding's table functions: one table, or with `input_torque_nm` several
/// concatenated, `table_rows` rows each (torque-dependent capacity).
#[allow(clippy::too_many_arguments)]
fn characteristic(
    sr: &PyReadonlyArray1<'_, f64>,
    tr: &PyReadonlyArray1<'_, f64>,
    cf: &PyReadonlyArray1<'_, f64>,
    overrun: Option<&str>,
    interpolation: Option<&str>,
    input_torque_nm: Option<Vec<f64>>,
    table_rows: Option<Vec<f64>>,
) -> PyResult<TorqueCharacteristic> {
    let (sr, tr, cf) = (slice(sr, "speed_ratio")?, slice(tr, "torque_ratio")?, slice(cf, "capacity_factor_nm_s2")?);
    match input_torque_nm {
        None => Characteristic::new(sr.to_vec(), tr.to_vec(), cf.to_vec())
            .and_then(|c| c.with_rules(overrun, interpolation))
            .map(TorqueCharacteristic::from),
        Some(torques) => TorqueCharacteristic::from_columns(
            torques,
            &table_rows.unwrap_or_default(),
            [sr, tr, cf],
            overrun,
            interpolation,
        ),
    }
    .map_err(input_error)
}

/// Validate a characteristic table (finite, strictly increasing SR, equal lengths, passive on its
/// rows) with its overrun rule and interpolation domain (None: the defaults).
#[pyfunction]
#[pyo3(signature = (speed_ratio, torque_ratio, capacity_factor_nm_s2, overrun=None, interpolation=None, input_torque_nm=None, table_rows=None))]
fn table_check(
    speed_ratio: PyReadonlyArray1<'_, f64>,
    torque_ratio: PyReadonlyArray1<'_, f64>,
    capacity_factor_nm_s2: PyReadonlyArray1<'_, f64>,
    overrun: Option<String>,
    interpolation: Option<String>,
    input_torque_nm: Option<Vec<f64>>,
    table_rows: Option<Vec<f64>>,
) -> PyResult<()> {
    guard(|| {
        characteristic(
            &speed_ratio,
            &torque_ratio,
            &capacity_factor_nm_s2,
            overrun.as_deref(),
            interpolation.as_deref(),
            input_torque_nm,
            table_rows,
        )
        .map(|_| ())
    })
}

/// Steady states of the table model at `pump[i], turbine[i]` (rad/s, any signs). Returns a dict
/// of arrays; `extension` says where the overrun rule extended the table beyond its rows. A point
/// without a steady state (torques that overflow) is an error naming the point, or with `lenient`
/// a row of NaN with `solved` false.
#[pyfunction]
#[pyo3(signature = (speed_ratio, torque_ratio, capacity_factor_nm_s2, pump_speed_rad_s, turbine_speed_rad_s, overrun=None, interpolation=None, lenient=false, input_torque_nm=None, table_rows=None))]
#[allow(clippy::too_many_arguments)]
fn table_steady_states<'py>(
    py: Python<'py>,
    speed_ratio: PyReadonlyArray1<'py, f64>,
    torque_ratio: PyReadonlyArray1<'py, f64>,
    capacity_factor_nm_s2: PyReadonlyArray1<'py, f64>,
    pump_speed_rad_s: PyReadonlyArray1<'py, f64>,
    turbine_speed_rad_s: PyReadonlyArray1<'py, f64>,
    overrun: Option<String>,
    interpolation: Option<String>,
    lenient: bool,
    input_torque_nm: Option<Vec<f64>>,
    table_rows: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let t = characteristic(
            &speed_ratio,
            &torque_ratio,
            &capacity_factor_nm_s2,
            overrun.as_deref(),
            interpolation.as_deref(),
            input_torque_nm,
            table_rows,
        )?;
        let (wp, wt) =
            (slice(&pump_speed_rad_s, "pump_speed_rad_s")?, slice(&turbine_speed_rad_s, "turbine_speed_rad_s")?);
        if wp.len() != wt.len() {
            return Err(PyValueError::new_err("pump and turbine speeds need equal lengths"));
        }
        let points: Vec<_> = py.detach(|| wp.iter().zip(wt).map(|(&p, &t_)| t.operating_point(p, t_)).collect());
        if !lenient {
            if let Some((i, e)) = points.iter().enumerate().find_map(|(i, p)| p.as_ref().err().map(|e| (i, e))) {
                return Err(input_error(CoreError { field: format!("{} (point {i})", e.field), ..e.clone() }));
            }
        }
        operating_point_dict(py, &points)
    })
}

/// The columns of table steady states `points` (NaN where a point has none, `solved` false).
fn operating_point_dict<'py>(
    py: Python<'py>,
    points: &[tcsim_core::CoreResult<TableOperatingPoint>],
) -> PyResult<Bound<'py, PyDict>> {
    let col = |f: fn(&TableOperatingPoint) -> f64| {
        points.iter().map(|p| p.as_ref().map_or(f64::NAN, f)).collect::<Vec<_>>().into_pyarray(py)
    };
    let flag = |f: fn(&TableOperatingPoint) -> bool| points.iter().map(|p| p.as_ref().is_ok_and(f)).collect::<Vec<_>>();
    let d = PyDict::new(py);
    d.set_item("speed_ratio", col(|p| p.speed_ratio))?;
    d.set_item("torque_ratio", col(|p| p.torque_ratio))?;
    d.set_item("capacity_factor_nm_s2", col(|p| p.capacity_factor_nm_s2))?;
    d.set_item("pump_torque_nm", col(|p| p.pump_torque_nm))?;
    d.set_item("turbine_torque_nm", col(|p| p.turbine_torque_nm))?;
    d.set_item("stator_torque_nm", col(|p| p.stator_torque_nm))?;
    d.set_item("extrapolated", flag(|p| p.extrapolated))?;
    d.set_item("extension", flag(|p| p.extension))?;
    d.set_item("solved", points.iter().map(Result::is_ok).collect::<Vec<_>>())?;
    Ok(d)
}

/// Steady states of the table model at input (pump) torque `pump_torque_nm` and the speed ratios
/// `at_speed_ratio`, the pump speed solved (positive; `characterise --input-torque-nm`). The dict of
/// [`table_steady_states`] with `pump_speed_rad_s` and `turbine_speed_rad_s`; a speed ratio where no
/// positive pump speed carries the torque is a row of NaN with `solved` false.
#[pyfunction]
#[pyo3(signature = (speed_ratio, torque_ratio, capacity_factor_nm_s2, pump_torque_nm, at_speed_ratio, overrun=None, interpolation=None, input_torque_nm=None, table_rows=None))]
#[allow(clippy::too_many_arguments)]
fn table_steady_states_at_pump_torque<'py>(
    py: Python<'py>,
    speed_ratio: PyReadonlyArray1<'py, f64>,
    torque_ratio: PyReadonlyArray1<'py, f64>,
    capacity_factor_nm_s2: PyReadonlyArray1<'py, f64>,
    pump_torque_nm: f64,
    at_speed_ratio: PyReadonlyArray1<'py, f64>,
    overrun: Option<String>,
    interpolation: Option<String>,
    input_torque_nm: Option<Vec<f64>>,
    table_rows: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let t = characteristic(
            &speed_ratio,
            &torque_ratio,
            &capacity_factor_nm_s2,
            overrun.as_deref(),
            interpolation.as_deref(),
            input_torque_nm,
            table_rows,
        )?;
        let sr = slice(&at_speed_ratio, "at_speed_ratio")?;
        let solved: Vec<_> = py.detach(|| sr.iter().map(|&s| t.at_pump_torque(pump_torque_nm, s)).collect());
        let wp: Vec<f64> = solved.iter().map(|p| p.as_ref().map_or(f64::NAN, |(w, _)| *w)).collect();
        let points: Vec<_> = solved.into_iter().map(|p| p.map(|(_, op)| op)).collect();
        let d = operating_point_dict(py, &points)?;
        let wt: Vec<f64> = wp.iter().zip(sr).map(|(w, s)| w * s).collect();
        d.set_item("pump_speed_rad_s", wp.into_pyarray(py))?;
        d.set_item("turbine_speed_rad_s", wt.into_pyarray(py))?;
        Ok(d)
    })
}

/// Pump speeds (rad/s, positive) at which the Hrovat & Tobler steady state at the speed ratios
/// `speed_ratio` takes the pump torque `pump_torque_nm`; NaN where there is none.
#[pyfunction]
fn ht_pump_speeds_at_pump_torque<'py>(
    py: Python<'py>,
    geometry: PyReadonlyArray2<'py, f64>,
    pump_torque_nm: f64,
    speed_ratio: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let g = one_geometry(&geometry)?;
        let sr = slice(&speed_ratio, "speed_ratio")?;
        let w: Vec<f64> = py.detach(|| {
            sr.iter()
                .map(|&s| tcsim_core::batch::ht_pump_speed_at_pump_torque(&g, pump_torque_nm, s).unwrap_or(f64::NAN))
                .collect()
        });
        Ok(w.into_pyarray(py))
    })
}

// ---------------------------------------------------------------------------------------------
// Backward operating points

/// The reason codes of the backward operating points: code → (name, valid).
#[pyfunction]
fn operating_point_reasons() -> BTreeMap<u8, (&'static str, bool)> {
    Reason::ALL.iter().map(|r| (r.code(), (r.key(), r.valid()))).collect()
}

/// The columns of a batch of backward operating points as a dict of arrays.
fn backward_dict<'py>(
    py: Python<'py>,
    b: &Backward,
    wt: &PyReadonlyArray1<'py, f64>,
    t: Option<PyReadonlyArray1<'py, f64>>,
    power: Option<PyReadonlyArray1<'py, f64>>,
    limit: Option<f64>,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let wt = slice(wt, "turbine_speed_rad_s")?;
    let (values, load) = match (&t, &power) {
        (Some(t), None) => (slice(t, "turbine_torque_nm")?, Load::TorqueNm),
        (None, Some(p)) => (slice(p, "turbine_power_w")?, Load::PowerW),
        _ => return Err(PyValueError::new_err("give either turbine_torque_nm or turbine_power_w")),
    };
    let limit = limit.unwrap_or(f64::INFINITY);
    let one_piece = wt.len() <= tcsim_core::converter::backward::POINTS_PER_CHUNK;
    let cols = cancellable_unless_one_piece(py, one_piece, |cancel| {
        match backward_points(b, wt, values, load, limit, threads, cancel) {
            Ok(cols) => cols.map(Ok),
            Err(e) => Some(Err(e)),
        }
    })?
    .map_err(input_error)?;
    let valid: Vec<bool> = cols.reason.iter().map(|&r| Reason::ALL[usize::from(r)].valid()).collect();
    let d = PyDict::new(py);
    d.set_item("turbine_torque_nm", cols.turbine_torque_nm.into_pyarray(py))?;
    d.set_item("pump_speed_rad_s", cols.pump_speed_rad_s.into_pyarray(py))?;
    d.set_item("pump_torque_nm", cols.pump_torque_nm.into_pyarray(py))?;
    d.set_item("speed_ratio", cols.speed_ratio.into_pyarray(py))?;
    d.set_item("torque_ratio", cols.torque_ratio.into_pyarray(py))?;
    d.set_item("efficiency", cols.efficiency.into_pyarray(py))?;
    d.set_item("valid", valid.into_pyarray(py))?;
    d.set_item("reason", cols.reason.into_pyarray(py))?;
    Ok(d)
}

/// Backward operating points of the table model (closed form per table segment): the pump speed and
/// torque at turbine speed `turbine_speed_rad_s[i]` (rad/s) delivering `turbine_torque_nm[i]` (N·m,
/// positive in drive; or `turbine_power_w[i]`, W, instead: T = P/ω_t), the pump speed at most
/// `pump_speed_limit_rad_s` (None: no limit). Returns a
/// dict of arrays with `valid` and the `reason` code of every point ([`operating_point_reasons`]).
#[pyfunction]
#[pyo3(signature = (speed_ratio, torque_ratio, capacity_factor_nm_s2, turbine_speed_rad_s, turbine_torque_nm=None, pump_speed_limit_rad_s=None, overrun=None, interpolation=None, threads=0, turbine_power_w=None))]
#[allow(clippy::too_many_arguments)]
fn table_operating_points<'py>(
    py: Python<'py>,
    speed_ratio: PyReadonlyArray1<'py, f64>,
    torque_ratio: PyReadonlyArray1<'py, f64>,
    capacity_factor_nm_s2: PyReadonlyArray1<'py, f64>,
    turbine_speed_rad_s: PyReadonlyArray1<'py, f64>,
    turbine_torque_nm: Option<PyReadonlyArray1<'py, f64>>,
    pump_speed_limit_rad_s: Option<f64>,
    overrun: Option<String>,
    interpolation: Option<String>,
    threads: usize,
    turbine_power_w: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let c = characteristic(
            &speed_ratio,
            &torque_ratio,
            &capacity_factor_nm_s2,
            overrun.as_deref(),
            interpolation.as_deref(),
            None,
            None,
        )?;
        let c = c.single().ok_or_else(|| PyValueError::new_err("one table"))?;
        let b = py.detach(|| Backward::table(c));
        backward_dict(py, &b, &turbine_speed_rad_s, turbine_torque_nm, turbine_power_w, pump_speed_limit_rad_s, threads)
    })
}

/// Backward operating points of the Hrovat & Tobler model at steady state (one geometry row), as
/// [`table_operating_points`].
#[pyfunction]
#[pyo3(signature = (geometry, turbine_speed_rad_s, turbine_torque_nm=None, pump_speed_limit_rad_s=None, threads=0, turbine_power_w=None))]
fn ht_operating_points<'py>(
    py: Python<'py>,
    geometry: PyReadonlyArray2<'py, f64>,
    turbine_speed_rad_s: PyReadonlyArray1<'py, f64>,
    turbine_torque_nm: Option<PyReadonlyArray1<'py, f64>>,
    pump_speed_limit_rad_s: Option<f64>,
    threads: usize,
    turbine_power_w: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let g = one_geometry(&geometry)?;
        let b = py.detach(|| Backward::hrovat_tobler(&g));
        backward_dict(py, &b, &turbine_speed_rad_s, turbine_torque_nm, turbine_power_w, pump_speed_limit_rad_s, threads)
    })
}

// ---------------------------------------------------------------------------------------------
// Typed results of the batch runs

/// Why a run of a batch failed: `kind` is `"input"` (the user's input; `source`, `field`,
/// `value` and `expected` as in `CoreInputError`) or `"solver"` (`message` only).
#[pyclass(frozen, get_all, module = "tcsim._core")]
struct RunError {
    kind: String,
    message: String,
    source: Option<String>,
    field: Option<String>,
    value: Option<String>,
    expected: Option<String>,
}

#[pymethods]
impl RunError {
    #[new]
    #[pyo3(signature = (kind, message, source=None, field=None, value=None, expected=None))]
    fn new(
        kind: String,
        message: String,
        source: Option<String>,
        field: Option<String>,
        value: Option<String>,
        expected: Option<String>,
    ) -> PyResult<Self> {
        if kind != "input" && kind != "solver" {
            return Err(PyValueError::new_err(format!("RunError kind {kind:?}: expected \"input\" or \"solver\"")));
        }
        Ok(RunError { kind, message, source, field, value, expected })
    }
    fn __repr__(&self) -> String {
        format!("RunError(kind={:?}, message={:?}, source={:?})", self.kind, self.message, self.source)
    }
}

impl RunError {
    fn from_core(e: TransientError) -> Self {
        match e {
            TransientError::Input(e) => RunError {
                kind: "input".into(),
                message: e.to_string(),
                source: Some(e.source.key().into()),
                field: Some(e.field),
                value: Some(e.value),
                expected: Some(e.expected),
            },
            e @ TransientError::Solver { .. } => RunError {
                kind: "solver".into(),
                message: e.to_string(),
                source: None,
                field: None,
                value: None,
                expected: None,
            },
        }
    }
}

/// An event of an isolated run: `kind` (stator-release, stator-lock, flow-zero, flow-start), the
/// stator clutch and the flow direction after it (+1, −1, 0 held at zero).
#[pyclass(frozen, get_all, module = "tcsim._core")]
struct TransientEvent {
    time_s: f64,
    kind: String,
    stator_locked: bool,
    flow_direction: f64,
}

#[pymethods]
impl TransientEvent {
    #[new]
    fn new(time_s: f64, kind: String, stator_locked: bool, flow_direction: f64) -> Self {
        TransientEvent { time_s, kind, stator_locked, flow_direction }
    }
    fn __repr__(&self) -> String {
        format!("TransientEvent(time_s={}, kind={:?})", self.time_s, self.kind)
    }
}

/// An event of a launch run: `kind` (gear shifts, lock-up, converter events) and the gear after it.
#[pyclass(frozen, get_all, module = "tcsim._core")]
struct LaunchEvent {
    time_s: f64,
    kind: String,
    gear: usize,
}

#[pymethods]
impl LaunchEvent {
    #[new]
    fn new(time_s: f64, kind: String, gear: usize) -> Self {
        LaunchEvent { time_s, kind, gear }
    }
    fn __repr__(&self) -> String {
        format!("LaunchEvent(time_s={}, kind={:?}, gear={})", self.time_s, self.kind, self.gear)
    }
}

/// One run of `transient_runs`: `columns` (name → array) and `events` if `ok`, else `error`.
#[pyclass(frozen, get_all, module = "tcsim._core")]
struct TransientRun {
    columns: Py<PyDict>,
    events: Vec<Py<TransientEvent>>,
    error: Option<Py<RunError>>,
}

#[pymethods]
impl TransientRun {
    #[new]
    #[pyo3(signature = (columns=None, events=Vec::new(), error=None))]
    fn new(
        py: Python<'_>,
        columns: Option<Py<PyDict>>,
        events: Vec<Py<TransientEvent>>,
        error: Option<Py<RunError>>,
    ) -> Self {
        TransientRun { columns: columns.unwrap_or_else(|| PyDict::new(py).unbind()), events, error }
    }
    /// True when the run finished (no `error`).
    #[getter]
    fn ok(&self) -> bool {
        self.error.is_none()
    }
}

/// One run of `launch_runs`: `columns` (name → array) and `events` if `ok`, else `error`.
#[pyclass(frozen, get_all, module = "tcsim._core")]
struct LaunchRun {
    columns: Py<PyDict>,
    events: Vec<Py<LaunchEvent>>,
    error: Option<Py<RunError>>,
}

#[pymethods]
impl LaunchRun {
    #[new]
    #[pyo3(signature = (columns=None, events=Vec::new(), error=None))]
    fn new(
        py: Python<'_>,
        columns: Option<Py<PyDict>>,
        events: Vec<Py<LaunchEvent>>,
        error: Option<Py<RunError>>,
    ) -> Self {
        LaunchRun { columns: columns.unwrap_or_else(|| PyDict::new(py).unbind()), events, error }
    }
    /// True when the run finished (no `error`).
    #[getter]
    fn ok(&self) -> bool {
        self.error.is_none()
    }
}

/// `{name: array}` of a run's output columns.
fn column_dict<'py>(py: Python<'py>, names: &[&str], cols: Vec<Vec<f64>>) -> PyResult<Py<PyDict>> {
    let d = PyDict::new(py);
    for (name, col) in names.iter().zip(cols) {
        d.set_item(*name, col.into_pyarray(py))?;
    }
    Ok(d.unbind())
}

fn transient_run(
    py: Python<'_>,
    r: tcsim_core::engine::options::TransientResult<tcsim_core::batch::RunOutput>,
) -> PyResult<TransientRun> {
    let names = tcsim_core::engine::outputs::COLUMNS;
    Ok(match r {
        Ok((cols, events)) => TransientRun {
            columns: column_dict(py, &names, cols)?,
            events: events
                .iter()
                .map(|e| {
                    let ev = TransientEvent::new(
                        e.time_s,
                        event_name(e.kind).into(),
                        e.mode.stator_locked,
                        e.mode.flow_sign,
                    );
                    Py::new(py, ev)
                })
                .collect::<PyResult<_>>()?,
            error: None,
        },
        Err(e) => TransientRun {
            columns: PyDict::new(py).unbind(),
            events: vec![],
            error: Some(Py::new(py, RunError::from_core(e))?),
        },
    })
}

// ---------------------------------------------------------------------------------------------
// Transient runs

/// The error of a dict value `key` that does not extract: `key: <the extraction's error>`.
fn field_error(key: &str, e: impl Into<PyErr>) -> PyErr {
    PyValueError::new_err(format!("{key}: {}", e.into()))
}

/// A [`std::hash::Hasher`] of a Rust string's address ([`key`]): one multiplication, where SipHash
/// over the text was most of a lookup.
#[derive(Default)]
struct AddressHasher(u64);

impl std::hash::Hasher for AddressHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        bytes.iter().for_each(|&b| self.write_u64(u64::from(b)));
    }
    fn write_u64(&mut self, n: u64) {
        let x = (self.0 ^ n).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        self.0 = x ^ (x >> 29);
    }
    fn write_usize(&mut self, n: usize) {
        self.write_u64(n as u64);
    }
}

/// The key strings of [`key`] by the address of the Rust string, with its text.
type KeyStrings =
    std::collections::HashMap<usize, (Box<str>, Py<PyString>), std::hash::BuildHasherDefault<AddressHasher>>;

thread_local! {
    /// The Python strings of the dict keys [`key`] was asked for on this thread, made once each.
    /// Only the binding's own names are asked for (the keys it reads, the columns' and the
    /// result's names), never a caller's text: a few dozen strings per thread at most, released
    /// when the thread ends (PyO3 defers the references it drops there, without the interpreter).
    static KEYS: std::cell::RefCell<KeyStrings> = Default::default();
}

/// The Python string of a dict key, made once per thread with its hash (making and hashing the
/// strings at every lookup was most of the cost of reading a model or a drive dict). The names are
/// string constants, found by their address; the text is compared too (a string at the address of
/// another that was dropped).
fn key<'py>(py: Python<'py>, key: &str) -> Bound<'py, PyString> {
    KEYS.with(|keys| {
        let mut keys = keys.borrow_mut();
        let entry =
            keys.entry(key.as_ptr() as usize).or_insert_with(|| (key.into(), PyString::intern(py, key).unbind()));
        if *entry.0 != *key {
            *entry = (key.into(), PyString::intern(py, key).unbind());
        }
        entry.1.clone_ref(py)
    })
    .into_bound(py)
}

/// `d[key]`, None when absent ([`key`]).
fn get<'py>(d: &Bound<'py, PyDict>, k: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
    d.get_item(key(d.py(), k))
}

fn present<'py>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Bound<'py, PyAny>> {
    get(d, key)?.ok_or_else(|| PyValueError::new_err(format!("missing key {key:?}")))
}

fn item<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<T> {
    present(d, key)?.extract::<T>().map_err(|e| field_error(key, e))
}

fn opt_item<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Option<T>> {
    match get(d, key)? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => v.extract::<T>().map(Some).map_err(|e| field_error(key, e)),
    }
}

/// The numbers of a drive's series (a signal's values, its time stamps, the output times): a 1-D
/// float64 NumPy array is copied in one go (strided too); anything else is extracted as a sequence
/// of floats, as before arrays were taken (a list, a tuple, an array of another dtype or order).
fn numbers(v: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if let Ok(a) = v.cast::<PyArray1<f64>>() {
        // copied at once under the GIL: no borrow of the array is held (its bookkeeping was a
        // third of reading a drive)
        return Ok(a.to_vec().unwrap_or_else(|_| a.to_owned_array().to_vec()));
    }
    v.extract::<Vec<f64>>()
}

/// [`item`] for a series ([`numbers`]), with its messages.
fn numbers_item(d: &Bound<'_, PyDict>, key: &str) -> PyResult<Vec<f64>> {
    let v = present(d, key)?;
    numbers(&v).map_err(|_| not_numbers(key, &v))
}

/// The input error of a drive's series `key` that is not numbers (a string, a 0-d array, a list of
/// text): it was a `ValueError` ("time_s: TypeError: 'float' object is not an instance of
/// 'Sequence'") that named neither the drive nor what was expected.
fn not_numbers(key: &str, v: &Bound<'_, PyAny>) -> PyErr {
    input_error(CoreError::of(InputSource::Drive, key, shown(v), "numbers: a list or a 1-D array of them"))
}

/// A value as an error shows it: its Python `repr` (`'a'`, `[1.0, 2.0]`).
fn shown(v: &Bound<'_, PyAny>) -> String {
    v.repr().map(|r| r.to_string_lossy().into_owned()).unwrap_or_default()
}

/// [`opt_item`] for a series ([`numbers`]), with its messages.
fn opt_numbers_item(d: &Bound<'_, PyDict>, key: &str) -> PyResult<Option<Vec<f64>>> {
    match get(d, key)? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => numbers(&v).map(Some).map_err(|_| not_numbers(key, &v)),
    }
}

/// A Python dict as a core model specification.
struct DictSpec<'a, 'py>(&'a Bound<'py, PyDict>);

impl tcsim_core::converter::spec::ModelSpec for DictSpec<'_, '_> {
    fn kind(&self) -> tcsim_core::CoreResult<String> {
        item::<String>(self.0, "kind").map_err(|e| CoreError::new("kind", e, "a model kind"))
    }
    fn numbers(&self, key: &str) -> Option<Vec<f64>> {
        let v = get(self.0, key).ok()??;
        if v.is_instance_of::<PyList>() {
            // a list is never a number: read it at once, without building the error of a failed
            // `f64` first (which was most of the cost of reading a model, once per run of a batch)
            return v.extract::<Vec<f64>>().ok();
        }
        v.extract::<f64>().map(|x| vec![x]).or_else(|_| v.extract::<Vec<f64>>()).ok()
    }
    fn text(&self, key: &str) -> Option<String> {
        get(self.0, key).ok()??.extract::<String>().ok()
    }
}

fn model_from(d: &Bound<'_, PyDict>) -> PyResult<Box<dyn ConverterDynamics + Send>> {
    tcsim_core::converter::spec::build_model(&DictSpec(d)).map_err(input_error)
}

/// A drive dict's time stamps (`time_s`), read once by the first of its signals ([`Self::signal`]).
struct DriveDict<'a, 'py> {
    d: &'a Bound<'py, PyDict>,
    window: f64,
    time_s: Option<Vec<f64>>,
}

impl DriveDict<'_, '_> {
    /// The time stamps, read (and checked to be numbers) at the first call.
    fn time_s(&mut self) -> PyResult<&Vec<f64>> {
        let t = match self.time_s.take() {
            Some(t) => t,
            None => numbers_item(self.d, "time_s")?,
        };
        Ok(self.time_s.insert(t))
    }

    /// The drive's signal `key`: a constant when a number (a float, a 0-d array), else one value
    /// per time stamp ([`numbers`]; a 1-D float64 array is a series even of one value). The time
    /// stamps are read first, whichever it is: a drive without them is refused for them.
    fn signal(&mut self, key: &str) -> PyResult<Signal> {
        self.time_s()?;
        let drive_error = |e: CoreError| input_error(e.about(InputSource::Drive));
        let v = present(self.d, key)?;
        if v.cast::<PyArray1<f64>>().is_err() {
            if let Ok(x) = v.extract::<f64>() {
                return Signal::constant_named(key, x).map_err(drive_error);
            }
        }
        let values = numbers(&v).map_err(|_| not_numbers(key, &v))?;
        Signal::new(key, self.time_s()?.clone(), values, self.window).map_err(drive_error)
    }
}

/// The lock-up clutch's command of a drive dict: `lockup_capacity_nm` (a constant or one value per
/// time, N·m, checked by [`LockupCommand::new`]) and `lockup_static_to_kinetic` (≥ 1, default
/// [`tcsim_core::engine::lockup::DEFAULT_STATIC_TO_KINETIC`]); None without a capacity.
fn lockup_from(dd: &mut DriveDict<'_, '_>) -> PyResult<Option<LockupCommand>> {
    if get(dd.d, "lockup_capacity_nm")?.is_none() {
        return Ok(None);
    }
    let capacity_nm = dd.signal("lockup_capacity_nm")?;
    let static_to_kinetic: f64 =
        opt_item(dd.d, "lockup_static_to_kinetic")?.unwrap_or(tcsim_core::engine::lockup::DEFAULT_STATIC_TO_KINETIC);
    LockupCommand::new(capacity_nm, static_to_kinetic).map(Some).map_err(input_error)
}

fn drive_from(d: &Bound<'_, PyDict>) -> PyResult<(Drive, Vec<f64>)> {
    let kind: String = item(d, "kind")?;
    let window: f64 =
        opt_item(d, "derivative_window_s")?.unwrap_or(tcsim_core::engine::signal::DEFAULT_DERIVATIVE_WINDOW_S);
    let mut dd = DriveDict { d, window, time_s: None };
    let out = match opt_numbers_item(d, "output_time_s")? {
        Some(t) => t,
        None => dd.time_s()?.clone(),
    };
    let drive = match kind.as_str() {
        "pump-torque-turbine-speed" => Drive::PumpTorqueTurbineSpeed {
            pump_torque_nm: dd.signal("pump_torque_nm")?,
            turbine_speed_rad_s: dd.signal("turbine_speed_rad_s")?,
            lockup: lockup_from(&mut dd)?,
        },
        "speeds" => Drive::Speeds {
            pump_speed_rad_s: dd.signal("pump_speed_rad_s")?,
            turbine_speed_rad_s: dd.signal("turbine_speed_rad_s")?,
            lockup: lockup_from(&mut dd)?,
        },
        "pump-torque-load" => {
            let load = TurbineLoad {
                torque_nm: dd.signal("load_torque_nm")?,
                inertia_kg_m2: item(d, "load_inertia_kg_m2")?,
                drag_nm_s2: opt_item(d, "load_drag_nm_s2")?.unwrap_or(0.0),
            };
            if !(load.inertia_kg_m2.is_finite() && load.inertia_kg_m2 >= 0.0) {
                return Err(input_error(CoreError::of(
                    InputSource::Drive,
                    "load_inertia_kg_m2",
                    load.inertia_kg_m2,
                    "a finite inertia of zero or more in kg·m²",
                )));
            }
            if !(load.drag_nm_s2.is_finite() && load.drag_nm_s2 >= 0.0) {
                return Err(input_error(CoreError::of(
                    InputSource::Drive,
                    "load_drag_nm_s2",
                    load.drag_nm_s2,
                    "a finite drag coefficient of zero or more",
                )));
            }
            Drive::PumpTorqueLoad { pump_torque_nm: dd.signal("pump_torque_nm")?, load, lockup: lockup_from(&mut dd)? }
        }
        other => return Err(PyValueError::new_err(format!("unknown drive kind {other:?}"))),
    };
    Ok((drive, out))
}

/// The keys of an initial state (`init_from`).
const INITIAL_KEYS: [&str; 4] = ["pump_speed_rad_s", "turbine_speed_rad_s", "stator_speed_rad_s", "flow_m3_s"];

/// The keys of the solver options (`options_from`).
const OPTION_KEYS: [&str; 6] =
    ["rtol", "speed_atol_rad_s", "flow_atol_m3_s", "first_step_s", "max_events", "max_output_bytes"];

/// An input error of `source` unless every key of `d` is one of `known` (a misspelt option, such as
/// `rtoll`, was ignored: the run went on with the default).
fn known_keys(d: &Bound<'_, PyDict>, source: InputSource, known: &[&str]) -> PyResult<()> {
    for (k, v) in d.iter() {
        let name = k.str()?.to_string_lossy().into_owned();
        if !known.contains(&name.as_str()) {
            let expected = format!("a known name, one of {}", known.join(", "));
            return Err(input_error(CoreError::of(source, name, shown(&v), expected)));
        }
    }
    Ok(())
}

/// The value of `key` in `d` (None when absent or None), else an input error of `source` naming
/// the key and the value (a string where a number goes).
fn opt_input<'py, T: FromPyObjectOwned<'py>>(
    d: &Bound<'py, PyDict>,
    source: InputSource,
    key: &str,
    expected: &str,
) -> PyResult<Option<T>> {
    match get(d, key)? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => v.extract::<T>().map(Some).map_err(|_| input_error(CoreError::of(source, key, shown(&v), expected))),
    }
}

fn init_from(d: Option<&Bound<'_, PyDict>>) -> PyResult<InitialState> {
    let Some(d) = d else { return Ok(InitialState::default()) };
    known_keys(d, InputSource::Initial, &INITIAL_KEYS)?;
    let value = |key: &str| opt_input(d, InputSource::Initial, key, "a number");
    Ok(InitialState {
        pump_speed_rad_s: value(INITIAL_KEYS[0])?,
        turbine_speed_rad_s: value(INITIAL_KEYS[1])?,
        stator_speed_rad_s: value(INITIAL_KEYS[2])?,
        flow_m3_s: value(INITIAL_KEYS[3])?,
    })
}

/// The solver options of `d`; its other keys must be among `extra` (the caller's own options).
fn options_from(d: Option<&Bound<'_, PyDict>>, extra: &[&str]) -> PyResult<SolverOptions> {
    let mut o = SolverOptions::default();
    if let Some(d) = d.filter(|d| !d.is_empty()) {
        known_keys(d, InputSource::Options, &[&OPTION_KEYS[..], extra].concat())?;
        let number = |key: &str| opt_input::<f64>(d, InputSource::Options, key, "a number");
        o.rtol = number("rtol")?.unwrap_or(o.rtol);
        o.speed_atol_rad_s = number("speed_atol_rad_s")?.unwrap_or(o.speed_atol_rad_s);
        o.flow_atol_m3_s = number("flow_atol_m3_s")?.unwrap_or(o.flow_atol_m3_s);
        o.first_step_s = number("first_step_s")?.unwrap_or(o.first_step_s);
        o.max_events = opt_input(d, InputSource::Options, "max_events", "a whole number")?.unwrap_or(o.max_events);
        o.max_output_bytes = number("max_output_bytes")?.unwrap_or(o.max_output_bytes);
    }
    if !(o.max_output_bytes.is_finite() && o.max_output_bytes > 0.0) {
        let expected = "a finite, positive number of bytes";
        return Err(input_error(CoreError::of(InputSource::Options, "max_output_bytes", o.max_output_bytes, expected)));
    }
    o.check_tolerances().map_err(input_error)?;
    Ok(o)
}

fn event_name(k: EventKind) -> &'static str {
    k.name()
}

/// The smoothed derivative the transient engine uses for given speeds (local least-squares slope
/// over ±window/2, tcsim_core::signal), at the sample times.
#[pyfunction]
fn smoothed_rate<'py>(
    py: Python<'py>,
    time_s: PyReadonlyArray1<'py, f64>,
    values: PyReadonlyArray1<'py, f64>,
    window_s: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let t = slice(&time_s, "time_s")?.to_vec();
        let v = slice(&values, "values")?.to_vec();
        let s = Signal::new_any_spacing("values", t.clone(), v, window_s).map_err(input_error)?;
        Ok(t.iter().map(|&ti| s.rate(ti)).collect::<Vec<_>>().into_pyarray(py))
    })
}

/// Output column names of a transient run.
#[pyfunction]
fn transient_columns() -> Vec<&'static str> {
    tcsim_core::engine::outputs::COLUMNS.to_vec()
}

/// Run transient jobs: `models[i]` under `drives[i]` (a list of length one is broadcast), with
/// the GIL released and `threads` workers (0: one per core). Each model and drive is a dict (see
/// tcsim.transient). Returns one [`TransientRun`] per job: its columns and [`TransientEvent`]s, or
/// its [`RunError`].
#[pyfunction]
#[pyo3(signature = (models, drives, init=None, options=None, threads=0))]
fn transient_runs<'py>(
    py: Python<'py>,
    models: Vec<Bound<'py, PyDict>>,
    drives: Vec<Bound<'py, PyDict>>,
    init: Option<Bound<'py, PyDict>>,
    options: Option<Bound<'py, PyDict>>,
    threads: usize,
) -> PyResult<Vec<TransientRun>> {
    guard(|| {
        let (jobs, _skips) = sized_transient_jobs(&models, &drives, init, options, COLUMNS.len())?;
        let results = cancellable_runs(py, jobs.len(), |cancel| {
            run_transient_jobs_cancellable(&jobs, threads, cancel).into_iter().collect::<Option<Vec<_>>>()
        })?;
        results.into_iter().map(|r| transient_run(py, r)).collect()
    })
}

/// Event kinds of a transient run in the order of their codes in `transient_batch`'s
/// `event_kind` (`transient_event_kinds()`).
const EVENT_KINDS: [EventKind; 7] = [
    EventKind::StatorRelease,
    EventKind::StatorLock,
    EventKind::FlowZero,
    EventKind::FlowStart,
    EventKind::LockupLock,
    EventKind::LockupSlip,
    EventKind::LockupArm,
];

/// Names of the event kinds of `transient_batch`: `event_kind` code `k` is the `k`-th.
#[pyfunction]
fn transient_event_kinds() -> Vec<&'static str> {
    EVENT_KINDS.iter().map(|k| k.name()).collect()
}

/// The rules of the overflow check of a run's columns: the columns that may be ±inf, and the unit
/// suffixes of the physical quantities that may not be NaN at some samples only
/// (`tcsim_core::engine::outputs::{INFINITE_ALLOWED, NAN_NOT_EXPECTED}`).
#[pyfunction]
fn output_value_rules() -> (Vec<&'static str>, Vec<&'static str>) {
    (INFINITE_ALLOWED.to_vec(), NAN_NOT_EXPECTED.to_vec())
}

/// `{name: value}` of a failed run of `transient_batch`.
fn failure_dict<'py>(py: Python<'py>, run: usize, f: RunFailure) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("run", run)?;
    match f {
        RunFailure::Overflow(o) => {
            d.set_item("kind", "overflow")?;
            d.set_item("column", COLUMNS[o.column])?;
            d.set_item("value", o.value)?;
            d.set_item("time_s", o.time_s)?;
        }
        RunFailure::Error(e) => {
            let e = RunError::from_core(e);
            for (k, v) in [("source", e.source), ("field", e.field), ("value", e.value), ("expected", e.expected)] {
                d.set_item(k, v)?;
            }
            d.set_item("kind", e.kind)?;
            d.set_item("message", e.message)?;
        }
    }
    Ok(d)
}

/// `d[name]` = a NumPy array of `values`, copied into NumPy's own memory (for the small arrays of a
/// batch's result, cheaper than handing over a `Vec`).
fn small_array<T: numpy::Element>(d: &Bound<'_, PyDict>, name: &str, values: &[T]) -> PyResult<()> {
    d.set_item(key(d.py(), name), PyArray1::from_slice(d.py(), values))
}

/// The dict `transient_batch` returns (see there), moving the buffers into NumPy without a copy.
fn batch_dict<'py>(py: Python<'py>, b: BatchColumns) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let names: Vec<Bound<'py, PyString>> = b.selection.names().into_iter().map(|name| key(py, name)).collect();
    let cols = PyDict::new(py);
    for (name, col) in names.iter().zip(b.columns) {
        cols.set_item(name, col.into_pyarray(py))?;
    }
    d.set_item(key(py, "names"), PyList::new(py, names)?)?;
    d.set_item(key(py, "columns"), cols)?;
    let offsets: Vec<i64> = b.offsets.iter().map(|&o| o as i64).collect();
    small_array(&d, "offsets", &offsets)?;
    small_array(&d, "status", &b.status)?;
    let ev = &b.events;
    let code = |k: EventKind| EVENT_KINDS.iter().position(|&c| c == k).unwrap_or(usize::MAX) as u8;
    small_array(&d, "event_run", &ev.iter().map(|(i, _)| *i as i64).collect::<Vec<_>>())?;
    small_array(&d, "event_time_s", &ev.iter().map(|(_, e)| e.time_s).collect::<Vec<_>>())?;
    small_array(&d, "event_kind", &ev.iter().map(|(_, e)| code(e.kind)).collect::<Vec<_>>())?;
    small_array(&d, "event_stator_locked", &ev.iter().map(|(_, e)| e.mode.stator_locked).collect::<Vec<_>>())?;
    small_array(&d, "event_flow_direction", &ev.iter().map(|(_, e)| e.mode.flow_sign).collect::<Vec<_>>())?;
    let failures = b.failures.into_iter().map(|(i, f)| failure_dict(py, i, f)).collect::<PyResult<Vec<_>>>()?;
    d.set_item(key(py, "failures"), PyList::new(py, failures)?)?;
    Ok(d)
}

/// The transient jobs of `models[i]` under `drives[i]` (a list of length one is broadcast) and each
/// drive's `output_skip` (leading output times run but not stored, default 0).
fn transient_jobs(
    models: &[Bound<'_, PyDict>],
    drives: &[Bound<'_, PyDict>],
    init: InitialState,
    options: SolverOptions,
) -> PyResult<(Vec<TransientJob>, Vec<usize>)> {
    let n = models.len().max(drives.len());
    if models.is_empty()
        || drives.is_empty()
        || (models.len() != n && models.len() != 1)
        || (drives.len() != n && drives.len() != 1)
    {
        return Err(PyValueError::new_err("models and drives must have equal lengths, or one of them length one"));
    }
    let mut parsed = Vec::with_capacity(drives.len());
    let mut skips = Vec::with_capacity(drives.len());
    for d in drives {
        let (drive, times) = drive_from(d)?;
        let skip: usize = opt_item(d, "output_skip")?.unwrap_or(0);
        if skip > 0 && skip >= times.len() {
            // an input error naming the field, as every other bad value of a drive dict (it was a
            // plain ValueError: the before/after comparison of issue 16)
            let expected = format!("fewer leading output times to drop than the {} output times", times.len());
            return Err(input_error(CoreError::of(InputSource::Drive, "output_skip", skip, expected)));
        }
        parsed.push((drive, times));
        skips.push(skip);
    }
    let job = |i: usize, (drive, times_s): (Drive, Vec<f64>)| -> PyResult<TransientJob> {
        let model = model_from(&models[if models.len() == 1 { 0 } else { i }])?;
        Ok(TransientJob { model, drive, times_s, init, options })
    };
    // each run's drive moved into its job; one drive for all runs copied into each
    let jobs = if parsed.len() == n {
        parsed.into_iter().enumerate().map(|(i, p)| job(i, p)).collect::<PyResult<Vec<_>>>()?
    } else {
        (0..n).map(|i| job(i, parsed[0].clone())).collect::<PyResult<Vec<_>>>()?
    };
    Ok((jobs, skips))
}

/// [`transient_jobs`] from the Python `init` and `options` dicts, refused (an input error) when the
/// outputs of all runs with `columns` columns would pass `max_output_bytes`.
fn sized_transient_jobs(
    models: &[Bound<'_, PyDict>],
    drives: &[Bound<'_, PyDict>],
    init: Option<Bound<'_, PyDict>>,
    options: Option<Bound<'_, PyDict>>,
    columns: usize,
) -> PyResult<(Vec<TransientJob>, Vec<usize>)> {
    let init = init_from(init.as_ref())?;
    let options = options_from(options.as_ref(), &[])?;
    let (jobs, skips) = transient_jobs(models, drives, init, options)?;
    let samples = jobs.iter().map(|j| j.times_s.len()).sum();
    isolated_output_size(1, samples, columns, &options)
        .check(InputSource::Drive, options.max_output_bytes)
        .map_err(input_error)?;
    Ok((jobs, skips))
}

/// Run transient jobs as [`transient_runs`] does, returning columnar results: a dict with `names`
/// (the selected columns, `columns` or all of `transient_columns()`), `columns` (name → one float64
/// array of all runs' rows, run `i` at rows `offsets[i]:offsets[i + 1]`, NaN for a run that failed
/// with an error), `offsets` (int64, runs + 1), `status` (uint8 per run: 0 ok, 1 input error, 2
/// solver error, 3 overflow), the events as flat arrays `event_run`, `event_time_s`, `event_kind`
/// (codes of `transient_event_kinds()`), `event_stator_locked`, `event_flow_direction`, and
/// `failures`, a dict per failed run (`run`, `kind` and, for `input`/`solver`, `message`, `source`,
/// `field`, `value`, `expected`; for `overflow`, `column`, `value`, `time_s`). The runs write their
/// rows straight into the buffers with the GIL released; the buffers become the arrays without a
/// copy. A drive dict's `output_skip` (int) leading output times are run but not stored.
#[pyfunction]
#[pyo3(signature = (models, drives, init=None, options=None, threads=0, columns=None))]
fn transient_batch<'py>(
    py: Python<'py>,
    models: Vec<Bound<'py, PyDict>>,
    drives: Vec<Bound<'py, PyDict>>,
    init: Option<Bound<'py, PyDict>>,
    options: Option<Bound<'py, PyDict>>,
    threads: usize,
    columns: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let selection = match &columns {
            Some(names) => Selection::from_names(names).map_err(input_error)?,
            None => Selection::all(),
        };
        let (jobs, skips) = sized_transient_jobs(&models, &drives, init, options, selection.len())?;
        let batch = cancellable_runs(py, jobs.len(), |cancel| {
            match run_transient_columns(&jobs, &skips, &selection, threads, cancel) {
                Ok(Some(b)) => Some(Ok(b)),
                Ok(None) => None,
                Err(e) => Some(Err(e)),
            }
        })?;
        match batch {
            Ok(b) => batch_dict(py, b),
            Err(TransientError::Input(e)) => Err(input_error(e)),
            Err(e) => Err(PyRuntimeError::new_err(e.to_string())),
        }
    })
}

// ---------------------------------------------------------------------------------------------
// Vehicle launch

/// A vehicle read from its file and validated once by the core (`read_vehicle`): what `launch_runs`
/// takes. Its getters give the file's top-level values; `to_dict()` the whole file, validated.
#[pyclass(frozen, name = "Vehicle", module = "tcsim._core")]
struct PyVehicle {
    file: String,
    doc: VehicleDocument,
}

#[pymethods]
impl PyVehicle {
    /// The file name used in messages.
    #[getter]
    fn file(&self) -> &str {
        &self.file
    }
    #[getter]
    fn name(&self) -> &str {
        &self.doc.file.name
    }
    #[getter]
    fn source(&self) -> &str {
        &self.doc.file.source
    }
    #[getter]
    fn description(&self) -> Option<&str> {
        self.doc.file.description.as_deref()
    }
    /// The `converter` reference as written (a bundled name or a path relative to the file).
    #[getter]
    fn converter(&self) -> &str {
        &self.doc.file.converter
    }
    /// `[sources]`: `{"section.key": text}` in file order.
    #[getter]
    fn sources<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.doc.file.sources {
            d.set_item(k, v)?;
        }
        Ok(d)
    }
    /// The validated file as a dict in file order: top-level values, one dict per section
    /// (keys as in the file, arrays as lists, `min_gear` an int), `sources` if any.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.doc.file.to_table() {
            d.set_item(k, py_value(py, v)?)?;
        }
        Ok(d)
    }
    fn __repr__(&self) -> String {
        format!("Vehicle(name={:?}, file={:?})", self.doc.file.name, self.file)
    }
}

fn py_value<'py>(py: Python<'py>, v: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        toml::Value::String(s) => s.into_pyobject(py)?.into_any(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        toml::Value::Float(f) => f.into_pyobject(py)?.into_any(),
        toml::Value::Boolean(b) => b.into_pyobject(py)?.to_owned().into_any(),
        toml::Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
        toml::Value::Array(a) => {
            PyList::new(py, a.iter().map(|x| py_value(py, x)).collect::<PyResult<Vec<_>>>()?)?.into_any()
        }
        toml::Value::Table(t) => {
            let d = PyDict::new(py);
            for (k, x) in t {
                d.set_item(k, py_value(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// The sections of a vehicle file that hold the vehicle's values, in file order.
#[pyfunction]
fn vehicle_sections() -> Vec<&'static str> {
    tcsim_core::vehicle::file::SECTIONS.to_vec()
}

/// The vehicle file's schema, one dict per key in file order (the core's `SCHEMA`, whose ranges are
/// the validator's): `section` (`""` top level), `key`, `unit`, `required`, `default` (text or
/// None), `range` (the allowed values in words) and `meaning`. The `[sources]` section is free-form.
#[pyfunction]
fn vehicle_schema(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    tcsim_core::vehicle::file::SCHEMA
        .iter()
        .map(|row| {
            let d = PyDict::new(py);
            d.set_item("section", row.section)?;
            d.set_item("key", row.key)?;
            d.set_item("unit", row.unit)?;
            d.set_item("required", row.default.is_none())?;
            d.set_item("default", row.default)?;
            d.set_item("range", row.range_text())?;
            d.set_item("meaning", row.meaning)?;
            Ok(d)
        })
        .collect()
}

/// Read a vehicle file's `text` (`file` names it in messages): the one parse and validation of a
/// vehicle. Raises CoreInputError whose field is named as the file writes it (`[body].grade_percent`,
/// `[gearbox].ratios[3]`, `(syntax)` with line and column).
#[pyfunction]
fn read_vehicle(text: &str, file: &str) -> PyResult<PyVehicle> {
    guard(|| {
        let doc = read_vehicle_core(text).map_err(|e| {
            let e = e.about(InputSource::Vehicle);
            CoreInputError::new_err((format!("{file}: {e}"), e.field, e.value, e.expected, e.source.key()))
        })?;
        Ok(PyVehicle { file: file.to_string(), doc })
    })
}

fn scenario_from(d: &Bound<'_, PyDict>) -> PyResult<Scenario> {
    let t: Vec<f64> = item(d, "time_s")?;
    let scenario_error = |e: CoreError| input_error(e.about(InputSource::Scenario));
    let signal =
        |key: &str| -> PyResult<Signal> { Signal::new(key, t.clone(), item(d, key)?, 0.0).map_err(scenario_error) };
    Ok(Scenario {
        accelerator_pedal: signal("accelerator_pedal")?,
        brake_pedal: signal("brake_pedal")?,
        end_time_s: item(d, "end_time_s")?,
        stop_speed_m_s: opt_item(d, "stop_speed_m_s")?,
        engine_torque_nm: match opt_item::<Vec<f64>>(d, "engine_torque_nm")? {
            Some(v) => Some(Signal::new("engine_torque_nm", t.clone(), v, 0.0).map_err(scenario_error)?),
            None => None,
        },
        shift_pedal: None,
    })
}

fn launch_run(
    py: Python<'_>,
    names: &[&'static str],
    r: tcsim_core::engine::options::TransientResult<(Vec<Vec<f64>>, Vec<tcsim_core::vehicle::modes::VehicleEvent>)>,
) -> PyResult<LaunchRun> {
    Ok(match r {
        Ok((cols, events)) => LaunchRun {
            columns: column_dict(py, names, cols)?,
            events: events
                .iter()
                .map(|e| Py::new(py, LaunchEvent::new(e.time_s, e.kind.into(), e.gear)))
                .collect::<PyResult<_>>()?,
            error: None,
        },
        Err(e) => LaunchRun {
            columns: PyDict::new(py).unbind(),
            events: vec![],
            error: Some(Py::new(py, RunError::from_core(e))?),
        },
    })
}

/// Output column names of a launch run.
#[pyfunction]
fn launch_columns() -> Vec<&'static str> {
    launch_column_names()
}

/// Launch runs: each model dict (as for transient_runs) in the same vehicle (a `Vehicle` from
/// `read_vehicle`, validated there) and scenario, from the
/// braked standstill, GIL released, `threads` workers. `options` takes the solver options of
/// transient_runs and `output_step_s` (default 0.01, at least the time resolution). The output's
/// size is estimated first and refused (CoreInputError) above `max_output_bytes`. Returns one [`LaunchRun`] per model: its
/// columns and [`LaunchEvent`]s, or its [`RunError`].
#[pyfunction]
#[pyo3(signature = (models, vehicle, scenario, options=None, threads=0))]
fn launch_runs<'py>(
    py: Python<'py>,
    models: Vec<Bound<'py, PyDict>>,
    vehicle: Bound<'py, PyVehicle>,
    scenario: Bound<'py, PyDict>,
    options: Option<Bound<'py, PyDict>>,
    threads: usize,
) -> PyResult<Vec<LaunchRun>> {
    guard(|| {
        let v = vehicle.get().doc.vehicle.clone();
        let sc = scenario_from(&scenario)?;
        let solver = options_from(options.as_ref(), &["output_step_s"])?;
        let step: f64 = match options.as_ref() {
            Some(o) => {
                opt_input(o, InputSource::Options, "output_step_s", "a number")?.unwrap_or(DEFAULT_OUTPUT_STEP_S)
            }
            None => DEFAULT_OUTPUT_STEP_S,
        };
        let parsed = models.iter().map(|m| model_from(m)).collect::<PyResult<Vec<_>>>()?;
        check_launch_output(&sc, step, parsed.len(), &solver).map_err(input_error)?;
        let results = cancellable_runs(py, parsed.len(), |cancel| {
            tcsim_core::batch::parallel_map_cancellable(&parsed, threads, cancel, |m| {
                tcsim_core::batch::catch_panic(|| {
                    let traj = simulate_launch(m.as_ref(), &v, &sc, step, &solver)?;
                    Ok((tcsim_core::vehicle::outputs::launch_columns(m.as_ref(), &sc, &traj)?, traj.events))
                })
            })
            .into_iter()
            .collect::<Option<Vec<_>>>()
        })?;
        let names = launch_column_names();
        results.into_iter().map(|r| launch_run(py, &names, r)).collect()
    })
}

// ---------------------------------------------------------------------------------------------
// Drive cycles

/// Output column names of a drive run: the launch's, then the driver's and the energies.
#[pyfunction]
fn drive_columns() -> Vec<&'static str> {
    tcsim_core::vehicle::cycle::drive_column_names()
}

/// The driver's options of `drive_runs` (`driver_from`).
const DRIVER_KEYS: [&str; 5] =
    ["driver_kp_per_s", "driver_ki_per_s2", "driver_control_step_s", "driver_hold_brake", "driver_preview_s"];

/// The driver's gains from `options` (`driver_kp_per_s`, `driver_ki_per_s2`,
/// `driver_control_step_s`, `driver_hold_brake`, `driver_preview_s`), defaults otherwise.
fn driver_from(d: Option<&Bound<'_, PyDict>>) -> PyResult<tcsim_core::vehicle::cycle::Driver> {
    let mut g = tcsim_core::vehicle::cycle::Driver::default();
    if let Some(d) = d {
        let number = |key: &str| opt_input::<f64>(d, InputSource::Options, key, "a number");
        g.kp_per_s = number(DRIVER_KEYS[0])?.unwrap_or(g.kp_per_s);
        g.ki_per_s2 = number(DRIVER_KEYS[1])?.unwrap_or(g.ki_per_s2);
        g.control_step_s = number(DRIVER_KEYS[2])?.unwrap_or(g.control_step_s);
        g.hold_brake = number(DRIVER_KEYS[3])?.unwrap_or(g.hold_brake);
        g.preview_s = number(DRIVER_KEYS[4])?.unwrap_or(g.preview_s);
    }
    g.validate().map_err(input_error)?;
    Ok(g)
}

/// Drive runs: each model dict (as for transient_runs) in the same vehicle follows the trace
/// `cycle` (`time_s`, `vehicle_speed_m_s`, optional `grade_percent`; errors about it name the
/// scenario), GIL released, `threads` workers. `options` takes the solver options (`rtol` by default
/// `DRIVE_RTOL`) and the driver's gains (`driver_*`); the output's size is estimated first and refused
/// (CoreInputError) above `max_output_bytes`. Returns one [`LaunchRun`] per model with the columns of `drive_columns`.
#[pyfunction]
#[pyo3(signature = (models, vehicle, cycle, options=None, threads=0))]
fn drive_runs<'py>(
    py: Python<'py>,
    models: Vec<Bound<'py, PyDict>>,
    vehicle: Bound<'py, PyVehicle>,
    cycle: Bound<'py, PyDict>,
    options: Option<Bound<'py, PyDict>>,
    threads: usize,
) -> PyResult<Vec<LaunchRun>> {
    use tcsim_core::vehicle::cycle::{
        check_drive_output, drive_column_names, drive_columns as columns, simulate_drive, Trace,
    };
    guard(|| {
        let v = vehicle.get().doc.vehicle.clone();
        let trace =
            Trace::new(item(&cycle, "time_s")?, item(&cycle, "vehicle_speed_m_s")?, opt_item(&cycle, "grade_percent")?)
                .map_err(input_error)?;
        let mut solver = options_from(options.as_ref(), &DRIVER_KEYS)?;
        if options.as_ref().map_or(Ok(None), |o| opt_item::<f64>(o, "rtol"))?.is_none() {
            solver.rtol = tcsim_core::vehicle::cycle::DRIVE_RTOL;
        }
        let driver = driver_from(options.as_ref())?;
        let parsed = models.iter().map(|m| model_from(m)).collect::<PyResult<Vec<_>>>()?;
        check_drive_output(&trace, &driver, parsed.len(), &solver).map_err(input_error)?;
        let results = cancellable_runs(py, parsed.len(), |cancel| {
            tcsim_core::batch::parallel_map_cancellable(&parsed, threads, cancel, |m| {
                tcsim_core::batch::catch_panic(|| {
                    let traj = simulate_drive(m.as_ref(), &v, &trace, &driver, &solver)?;
                    Ok((columns(m.as_ref(), &traj)?, traj.run.events))
                })
            })
            .into_iter()
            .collect::<Option<Vec<_>>>()
        })?;
        let names = drive_column_names();
        results.into_iter().map(|r| launch_run(py, &names, r)).collect()
    })
}

// ---------------------------------------------------------------------------------------------
// Physics owned by the core that the Python layer needs (one owner per fact)

fn one_geometry(geometry: &PyReadonlyArray2<'_, f64>) -> PyResult<HtGeometry<f64>> {
    geometry_rows(geometry)?.into_iter().next().ok_or_else(|| PyValueError::new_err("geometry needs one row"))
}

/// Default flow time constant τ_Q of the quasi-dynamic model, s: `(ρL_f/A) / |∂F_Q/∂Q|` for the
/// Hrovat & Tobler `geometry` (row 0 of an (n, 15) array, SI units, angles in rad) with fluid length
/// `fluid_length_m` (m), at stall (locked stator) and the reference pump speed
/// (`reference_pump_speed_rpm()`, 2000 rpm). Replaces `tcsim.transient.default_flow_time_constant_s`.
#[pyfunction]
fn default_flow_time_constant_s(geometry: PyReadonlyArray2<'_, f64>, fluid_length_m: f64) -> PyResult<f64> {
    guard(|| {
        let g = one_geometry(&geometry)?;
        tcsim_core::converter::spec::default_flow_time_constant_s(&g, fluid_length_m).map_err(input_error)
    })
}

/// The lock-up clutch's command limits (`tcsim_core::engine::lockup`): `max_capacity_nm` and the
/// wording `capacity_expected`, for the readers that name a file's row.
#[pyfunction]
fn lockup_limits() -> (f64, &'static str) {
    (tcsim_core::engine::lockup::MAX_CAPACITY_NM, tcsim_core::engine::lockup::CAPACITY_EXPECTED)
}

/// The unit conversions of the core (`tcsim_core::units`), by name: `rad_s_per_rpm`, `m_s_per_km_h`,
/// `nm_per_lbf_ft`, `gravity_m_s2`. Python's `tcsim.units` takes its constants from here.
#[pyfunction]
fn unit_constants() -> BTreeMap<&'static str, f64> {
    use tcsim_core::units::{GRAVITY_M_S2, M_S_PER_KM_H, NM_PER_LBF_FT, RAD_S_PER_RPM};
    BTreeMap::from([
        ("rad_s_per_rpm", RAD_S_PER_RPM),
        ("m_s_per_km_h", M_S_PER_KM_H),
        ("nm_per_lbf_ft", NM_PER_LBF_FT),
        ("gravity_m_s2", GRAVITY_M_S2),
    ])
}

/// The physical plausibility ranges (tcsim_core::plausibility, their one owner): a list of
/// `(quantity, unit, low, high, why)`.
#[pyfunction]
fn plausibility_ranges() -> Vec<(&'static str, &'static str, f64, f64, &'static str)> {
    tcsim_core::plausibility::RANGES.iter().map(|r| (r.quantity, r.unit, r.low, r.high, r.why)).collect()
}

/// The reference pump speed in rpm (2000): where the default τ_Q is evaluated and the default pump
/// speed of a characterisation. Convert with `reference_pump_speed_rad_s()`.
#[pyfunction]
fn reference_pump_speed_rpm() -> f64 {
    tcsim_core::units::REFERENCE_PUMP_SPEED_RPM
}

/// The reference pump speed in rad/s (`2000·π/30`).
#[pyfunction]
fn reference_pump_speed_rad_s() -> f64 {
    tcsim_core::units::REFERENCE_PUMP_SPEED_RAD_S
}

/// The Hrovat & Tobler mass-matrix admissibility bound on the shape effects (docs/physics.md §4): `M`
/// is positive definite iff `ρL_f/A > Σ ρ²S_x²/I_x`. Arguments: `geometry` (row 0 of an (n, 15)
/// array), `fluid_length_m` (m), `inertia_kg_m2` (pump, turbine, stator; kg·m²), `shape_effect_m2`
/// (pump, turbine, stator; m²). Returns a dict: `density_kg_m3`, `inertance_kg_m4` (ρL_f/A),
/// `shape_terms_kg_m4` (ρ²S_x²/I_x, three), `margin_kg_m4` (inertance less their sum; admissible iff
/// > 0) and `shape_effect_bounds_m2` (largest admissible |S_x| with the others as given, three).
/// Replaces the arithmetic of `tcsim.shape_fit.MassMatrixBound` (its `room` is `inertance_kg_m4 −
/// shape_terms_kg_m4[2]`).
#[pyfunction]
fn mass_matrix_bound<'py>(
    py: Python<'py>,
    geometry: PyReadonlyArray2<'py, f64>,
    fluid_length_m: f64,
    inertia_kg_m2: [f64; 3],
    shape_effect_m2: [f64; 3],
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let g = one_geometry(&geometry)?;
        let inertia = Inertias::new(inertia_kg_m2[0], inertia_kg_m2[1], inertia_kg_m2[2]).map_err(input_error)?;
        let b = MassMatrixBound::new(&g, &inertia, fluid_length_m, shape_effect_m2);
        let d = PyDict::new(py);
        d.set_item("density_kg_m3", b.density_kg_m3)?;
        d.set_item("inertance_kg_m4", b.inertance_kg_m4)?;
        d.set_item("shape_terms_kg_m4", b.shape_terms_kg_m4.to_vec())?;
        d.set_item("margin_kg_m4", b.margin_kg_m4())?;
        d.set_item("shape_effect_bounds_m2", b.shape_effect_bounds().to_vec())?;
        d.set_item("pump_turbine_room_kg_m4", b.pump_turbine_room_kg_m4())?;
        d.set_item("equal_shape_effect_bound_m2", b.equal_shape_effect_bound_m2())?;
        Ok(d)
    })
}

/// The quasi-dynamic model's turbine stability bound on τ_Q, s, for a model spec dict (kind
/// `quasi-dynamic`; `QuasiDynamics::coupling_time_constant_bound_s`): the smallest
/// `flow_time_constant_s` for which the turbine alone keeps a positive effective inertia through the
/// flow's lag near coupling (0: none needed; infinite: none suffices).
#[pyfunction]
fn qd_coupling_time_constant_bound_s(spec: &Bound<'_, PyDict>) -> PyResult<f64> {
    guard(|| {
        let m = tcsim_core::converter::spec::quasi_dynamic_model(&DictSpec(spec)).map_err(input_error)?;
        Ok(m.coupling_time_constant_bound_s())
    })
}

/// Check a model dict as a run would build it (`transient_batch`, `launch_runs`): None, or the
/// core's input error (a shape effect beyond the mass matrix's bound, …). A study checks the fixed
/// values of its grids with it before anything runs.
#[pyfunction]
fn check_model(spec: &Bound<'_, PyDict>) -> PyResult<()> {
    guard(|| model_from(spec).map(|_| ()))
}

/// Codes of the `stator_mode` column of `ht_steady_states` and their names: `{0: "locked",
/// 1: "free-wheeling", 2: "no-flow", -1: "no-steady-state"}`. Replaces the former Python `STATOR_MODES` table
/// and the bare `mode == 2` of `steady.py` and `study.py`.
#[pyfunction]
fn steady_mode_names() -> BTreeMap<i8, &'static str> {
    steady_mode_names_core().into_iter().collect()
}

/// The torque ratio of steady states from the `stator_mode`, `pump_torque_nm` and
/// `turbine_torque_nm` columns of `ht_steady_states`: 1 in no-flow (TR = 1 by continuity), else
/// `T_t/T_p` (a zero pump torque divides by 1), NaN without a steady state. Replaces
/// `np.where(mode == 2, 1.0, tt / np.where(tp == 0, 1.0, tp))` in `steady.py` and `study.py`.
#[pyfunction]
fn steady_torque_ratio<'py>(
    py: Python<'py>,
    stator_mode: PyReadonlyArray1<'py, i8>,
    pump_torque_nm: PyReadonlyArray1<'py, f64>,
    turbine_torque_nm: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let mode = stator_mode
            .as_slice()
            .map_err(|_| PyValueError::new_err("stator_mode must be a contiguous 1-D int8 array"))?;
        let (tp, tt) = (slice(&pump_torque_nm, "pump_torque_nm")?, slice(&turbine_torque_nm, "turbine_torque_nm")?);
        if mode.len() != tp.len() || tp.len() != tt.len() {
            return Err(PyValueError::new_err("stator_mode and the torques need equal lengths"));
        }
        let tr: Vec<f64> = (0..mode.len()).map(|i| steady_torque_ratio_core(mode[i], tp[i], tt[i])).collect();
        Ok(tr.into_pyarray(py))
    })
}

// ---------------------------------------------------------------------------------------------
// Issue 11: steady states at arbitrary speeds, time resolution

/// The time resolution of the engine at time `t` (s): 1 µs, or 1024 ulp of `t` when coarser
/// (`tcsim_core::engine::signal::time_resolution_s`).
#[pyfunction]
fn time_resolution_s(t: f64) -> f64 {
    tcsim_core::engine::signal::time_resolution_s(t)
}

/// The core's check of a run's time stamps or output times (`tcsim_core::engine::signal::
/// check_time_stamps`): finite, strictly increasing and at least the time resolution apart. A
/// `CoreInputError` about `name[i]`, the first time at fault (source `drive`).
#[pyfunction]
fn check_time_stamps(name: &str, time_s: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
    guard(|| {
        tcsim_core::engine::signal::check_time_stamps(name, slice(&time_s, name)?)
            .map_err(|e| input_error(e.about(InputSource::Drive)))
    })
}

/// The values of `initial` that a run of `model` under `drive` (the dicts of `transient_batch`)
/// does not use ([`InitialState::ignored`]): `(name, why)` pairs, `why` being `"drive"` (the drive
/// gives that speed) or `"model"` (the model has no such state).
#[pyfunction]
fn ignored_initial(
    model: &Bound<'_, PyDict>,
    drive: &Bound<'_, PyDict>,
    initial: &Bound<'_, PyDict>,
) -> PyResult<Vec<(&'static str, &'static str)>> {
    guard(|| {
        let m = model_from(model)?;
        let (d, _) = drive_from(drive)?;
        let why = |w| match w {
            IgnoredInitial::GivenByDrive => "drive",
            IgnoredInitial::NotAState => "model",
        };
        Ok(init_from(Some(initial))?.ignored(m.as_ref(), &d).into_iter().map(|(k, w)| (k, why(w))).collect())
    })
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("CoreInputError", m.py().get_type::<CoreInputError>())?;
    m.add_class::<RunError>()?;
    m.add_class::<TransientEvent>()?;
    m.add_class::<TransientRun>()?;
    m.add_class::<LaunchEvent>()?;
    m.add_class::<LaunchRun>()?;
    m.add_function(wrap_pyfunction!(input_sources, m)?)?;
    m.add_function(wrap_pyfunction!(capacity_conventions, m)?)?;
    m.add_function(wrap_pyfunction!(default_flow_time_constant_s, m)?)?;
    m.add_function(wrap_pyfunction!(qd_coupling_time_constant_bound_s, m)?)?;
    m.add_function(wrap_pyfunction!(check_model, m)?)?;
    m.add_function(wrap_pyfunction!(unit_constants, m)?)?;
    m.add_function(wrap_pyfunction!(lockup_limits, m)?)?;
    m.add_function(wrap_pyfunction!(plausibility_ranges, m)?)?;
    m.add_function(wrap_pyfunction!(reference_pump_speed_rpm, m)?)?;
    m.add_function(wrap_pyfunction!(reference_pump_speed_rad_s, m)?)?;
    m.add_function(wrap_pyfunction!(mass_matrix_bound, m)?)?;
    m.add_function(wrap_pyfunction!(steady_mode_names, m)?)?;
    m.add_function(wrap_pyfunction!(steady_torque_ratio, m)?)?;
    m.add_function(wrap_pyfunction!(capacity_to_cf, m)?)?;
    m.add_function(wrap_pyfunction!(cf_to_capacity, m)?)?;
    m.add_function(wrap_pyfunction!(ht_parameter_names, m)?)?;
    m.add_function(wrap_pyfunction!(ht_check_geometry, m)?)?;
    m.add_function(wrap_pyfunction!(ht_steady_states, m)?)?;
    m.add_function(wrap_pyfunction!(ht_coupling_point, m)?)?;
    m.add_function(wrap_pyfunction!(ht_ratio_gradients, m)?)?;
    m.add_function(wrap_pyfunction!(table_check, m)?)?;
    m.add_function(wrap_pyfunction!(table_steady_states, m)?)?;
    m.add_function(wrap_pyfunction!(table_steady_states_at_pump_torque, m)?)?;
    m.add_function(wrap_pyfunction!(ht_pump_speeds_at_pump_torque, m)?)?;
    m.add_function(wrap_pyfunction!(table_operating_points, m)?)?;
    m.add_function(wrap_pyfunction!(ht_operating_points, m)?)?;
    m.add_function(wrap_pyfunction!(operating_point_reasons, m)?)?;
    m.add_function(wrap_pyfunction!(transient_columns, m)?)?;
    m.add_function(wrap_pyfunction!(smoothed_rate, m)?)?;
    m.add_function(wrap_pyfunction!(launch_columns, m)?)?;
    m.add_function(wrap_pyfunction!(launch_runs, m)?)?;
    m.add_function(wrap_pyfunction!(drive_columns, m)?)?;
    m.add_function(wrap_pyfunction!(drive_runs, m)?)?;
    m.add_function(wrap_pyfunction!(read_vehicle, m)?)?;
    m.add_function(wrap_pyfunction!(vehicle_sections, m)?)?;
    m.add_function(wrap_pyfunction!(vehicle_schema, m)?)?;
    m.add_class::<PyVehicle>()?;
    m.add_function(wrap_pyfunction!(transient_runs, m)?)?;
    m.add_function(wrap_pyfunction!(transient_batch, m)?)?;
    m.add_function(wrap_pyfunction!(transient_event_kinds, m)?)?;
    m.add_function(wrap_pyfunction!(output_value_rules, m)?)?;
    m.add_function(wrap_pyfunction!(time_resolution_s, m)?)?;
    m.add_function(wrap_pyfunction!(check_time_stamps, m)?)?;
    m.add_function(wrap_pyfunction!(ignored_initial, m)?)?;
    fmu::register(m)?;
    design::register(m)?;
    Ok(())
}
