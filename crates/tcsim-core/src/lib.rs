//! tcsim-core: torque-converter models in pure Rust.
//!
//! The core holds the models and their solvers and knows nothing of Python, so that the same code
//! builds the Python extension and, later, the FMU. Units are SI throughout (rad/s, N·m, m, m²,
//! m³/s, kg, kg/m³, s; angles in radians); signs follow the tcsim physics notes §2.
//!
//! * [`capacity`]: the six capacity conventions of characteristic tables.
//! * [`table`]: the steady-state look-up-table model (Li & Sundén 2016, eqs 2.8–2.11).
//! * [`hrovat_tobler`]: the Hrovat & Tobler model's closed-form steady state and coupling point.
//! * [`batch`]: batched evaluation for characteristics, studies and fitting.
//! * [`dynamics`]: the three models in mass-matrix form (table, Hrovat & Tobler, quasi-dynamic).
//! * [`signal`]: sampled input signals with a smoothed derivative.
//! * [`transient`]: the transient engine on diffsol (BDF, root-finding events).

pub mod batch;
pub mod capacity;
pub mod dynamics;
pub mod error;
pub mod hrovat_tobler;
pub mod linalg;
pub mod outputs;
pub mod scalar;
pub mod segment;
pub mod signal;
pub mod stepper;
pub mod table;
pub mod transient;
pub mod vehicle;

pub use error::{CoreError, CoreResult};
