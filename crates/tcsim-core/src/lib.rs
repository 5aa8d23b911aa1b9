//! tcsim-core: torque-converter models in pure Rust.
//!
//! The core holds the models and their solvers and knows nothing of Python, so that the same code
//! builds the Python extension (`tcsim-py`) and the FMU (`tcsim-fmu`). Units are SI throughout
//! (rad/s, N·m, m, m², m³/s, kg, kg/m³, s; angles in radians); signs follow the docs/physics.md
//! §2. Errors in the user's input are [`CoreError`]s (the Python layer raises them as
//! `CoreInputError`).
//!
//! Folders depend one way: `converter` ← `engine` ← `vehicle`; the shared utilities below them.
//!
//! * [`converter`]: the converter models (tables, Hrovat & Tobler, quasi-dynamic, specifications).
//! * [`engine`]: the transient engines (own BDF integrator, segments, converter events, isolated runs,
//!   Model Exchange view, co-simulation stepper, signals, output columns).
//! * [`vehicle`]: whole-vehicle take-off (parameters, components, plant, modes, launch, columns).
//! * [`batch`]: batched evaluation for characteristics, studies, fitting and parallel runs.
//! * [`interp`]: linear interpolation with the end values held.
//! * [`units`]: unit constants and the 2000 rpm reference pump speed.
//! * [`plausibility`]: the physical plausibility ranges of converters, fluids and measurements.
//! * [`linalg`], [`scalar`], [`error`]: small dense inverse, dual numbers, the error type.

pub mod batch;
pub mod converter;
pub mod engine;
pub mod error;
pub mod interp;
pub mod linalg;
pub mod plausibility;
pub mod scalar;
pub mod units;
pub mod vehicle;

pub use error::{CoreError, CoreResult, InputSource};
