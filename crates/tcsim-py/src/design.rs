//! Issue 15: the geometry of converter designs (`tcsim_core::converter::design`), batched.

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use tcsim_core::converter::design::{
    design_geometries as core_design_geometries, geometry_columns, BladeAngles, Design, Profile, DEFAULT_POINTS,
    POINTS_RANGE, POLYLINE_TOLERANCE_M, PROFILE_KINDS,
};
use tcsim_core::CoreError;

use crate::{guard, input_error, item, opt_item};

fn angles(d: &Bound<'_, PyDict>, element: &str) -> PyResult<BladeAngles> {
    Ok(BladeAngles {
        inlet_deg: item(d, &format!("{element}_inlet_angle_deg"))?,
        exit_deg: item(d, &format!("{element}_exit_angle_deg"))?,
    })
}

fn design_from(d: &Bound<'_, PyDict>) -> PyResult<Design> {
    let kind: String = item(d, "profile")?;
    let paths: [Option<Vec<[f64; 2]>>; 3] =
        [opt_item(d, "pump_path_m")?, opt_item(d, "turbine_path_m")?, opt_item(d, "stator_path_m")?];
    let paths = match paths {
        [None, None, None] => None,
        [p, t, s] => Some([p.unwrap_or_default(), t.unwrap_or_default(), s.unwrap_or_default()]),
    };
    let profile = Profile::from_parts(&kind, opt_item(d, "squash_ratio")?, paths).map_err(input_error)?;
    Ok(Design {
        pump_exit_radius_m: item(d, "pump_exit_radius_m")?,
        turbine_exit_radius_m: item(d, "turbine_exit_radius_m")?,
        stator_exit_radius_m: item(d, "stator_exit_radius_m")?,
        profile,
        pump: angles(d, "pump")?,
        turbine: angles(d, "turbine")?,
        stator: angles(d, "stator")?,
        flow_area_m2: item(d, "flow_area_m2")?,
        fluid_density_kg_m3: item(d, "fluid_density_kg_m3")?,
    })
}

/// The geometry of each design (a dict with the fields of `tcsim.models.design.TorusDesign`,
/// `profile` one of `design_profiles()`), `points` integration nodes per element, on up to
/// `threads` threads. Returns a dict of float64 arrays named by `design_columns()`, one value per
/// design, and `error`: per design None or the message of its bad input. With `strict` the first
/// bad design raises CoreInputError instead (its `field` gets ` (design i)` when there are several).
#[pyfunction]
#[pyo3(signature = (designs, points=DEFAULT_POINTS, strict=true, threads=2))]
fn design_geometries<'py>(
    py: Python<'py>,
    designs: &Bound<'py, PyList>,
    points: usize,
    strict: bool,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let several = designs.len() > 1;
        let mut parsed = Vec::with_capacity(designs.len());
        for (i, d) in designs.iter().enumerate() {
            let d =
                d.cast_into::<PyDict>().map_err(|_| pyo3::exceptions::PyTypeError::new_err("a design is a dict"))?;
            match design_from(&d) {
                Ok(x) => parsed.push(x),
                Err(e) if several && e.is_instance_of::<crate::CoreInputError>(py) => {
                    return Err(with_index(py, e, i));
                }
                Err(e) => return Err(e),
            }
        }
        let results = py.detach(|| core_design_geometries(&parsed, points, threads));
        let names = geometry_columns();
        let mut cols = vec![Vec::with_capacity(results.len()); names.len()];
        let errors = PyList::empty(py);
        for (i, r) in results.into_iter().enumerate() {
            match r {
                Ok(g) => {
                    cols.iter_mut().zip(g.values()).for_each(|(c, v)| c.push(v));
                    errors.append(py.None())?;
                }
                Err(e) if strict => {
                    let field = if several { format!("{} (design {i})", e.field) } else { e.field.clone() };
                    return Err(input_error(CoreError { field, ..e }));
                }
                Err(e) => {
                    cols.iter_mut().for_each(|c| c.push(f64::NAN));
                    errors.append(e.to_string())?;
                }
            }
        }
        let out = PyDict::new(py);
        for (name, col) in names.iter().zip(cols) {
            out.set_item(name, col.into_pyarray(py))?;
        }
        out.set_item("error", errors)?;
        Ok(out)
    })
}

/// A CoreInputError of design `i` of several, its field suffixed ` (design i)`.
fn with_index(py: Python<'_>, e: PyErr, i: usize) -> PyErr {
    let args = e.value(py).getattr("args").and_then(|a| a.extract::<(String, String, String, String, String)>());
    match args {
        Ok((_, field, value, expected, source)) => {
            let field = format!("{field} (design {i})");
            crate::CoreInputError::new_err((
                format!("{field} = {value}: expected {expected}"),
                field,
                value,
                expected,
                source,
            ))
        }
        Err(_) => e,
    }
}

/// The result columns of `design_geometries`, in order.
#[pyfunction]
fn design_columns() -> Vec<String> {
    geometry_columns()
}

/// The profile names a design's `profile` takes.
#[pyfunction]
fn design_profiles() -> Vec<&'static str> {
    PROFILE_KINDS.to_vec()
}

/// `(default, least, most)` integration nodes per element, and the polyline tolerance in m.
#[pyfunction]
fn design_integration() -> (usize, usize, usize, f64) {
    (DEFAULT_POINTS, POINTS_RANGE.0, POINTS_RANGE.1, POLYLINE_TOLERANCE_M)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(design_geometries, m)?)?;
    m.add_function(wrap_pyfunction!(design_columns, m)?)?;
    m.add_function(wrap_pyfunction!(design_profiles, m)?)?;
    m.add_function(wrap_pyfunction!(design_integration, m)?)?;
    Ok(())
}
