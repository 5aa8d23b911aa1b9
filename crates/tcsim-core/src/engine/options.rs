//! Solver options and the error type of the transient engines (isolated converter and vehicle).

use crate::error::CoreError;

/// Tolerances and limits of the BDF solver.
#[derive(Debug, Clone, Copy)]
pub struct SolverOptions {
    pub rtol: f64,
    pub speed_atol_rad_s: f64,
    pub flow_atol_m3_s: f64,
    /// Initial step at the start and after every event, s.
    pub first_step_s: f64,
    /// More events than this in one run is reported as chattering.
    pub max_events: usize,
    pub max_steps: usize,
    /// Event hysteresis: a switch fires when its root function passes this far beyond zero
    /// (flow m³/s, stator speed rad/s, stator torque N·m, flow head Pa). It keeps round-off at a
    /// freshly switched zero (Q = 0, ω_s = 0) from firing the event back, and it is far below the
    /// tolerances of the results.
    pub hysteresis: Hysteresis,
}

/// See [`SolverOptions::hysteresis`].
#[derive(Debug, Clone, Copy)]
pub struct Hysteresis {
    pub flow_m3_s: f64,
    pub stator_speed_rad_s: f64,
    pub stator_torque_nm: f64,
    pub head_pa: f64,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            speed_atol_rad_s: 1e-5,
            flow_atol_m3_s: 1e-8,
            first_step_s: 1e-5,
            max_events: 10_000,
            max_steps: 2_000_000,
            hysteresis: Hysteresis { flow_m3_s: 1e-7, stator_speed_rad_s: 1e-4, stator_torque_nm: 1e-6, head_pa: 1e-3 },
        }
    }
}

/// What went wrong in a transient run.
#[derive(Debug, Clone)]
pub enum TransientError {
    /// The user's input (exit code 2).
    Input(CoreError),
    /// The solver failed (exit code 1): time, state and message.
    Solver { time_s: f64, state: Vec<f64>, message: String },
}

impl From<CoreError> for TransientError {
    fn from(e: CoreError) -> Self {
        TransientError::Input(e)
    }
}

impl std::fmt::Display for TransientError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TransientError::Input(e) => write!(f, "{e}"),
            TransientError::Solver { time_s, state, message } => {
                let names = ["ω_p", "ω_t", "ω_s", "Q", "ω_o", "ω_f", "ω_r", "v", "θ_f", "θ_r", "T_fast", "T_boost"];
                let shown: Vec<String> = state
                    .iter()
                    .enumerate()
                    .map(|(i, v)| format!("{} = {v:.6}", names.get(i).copied().unwrap_or("x")))
                    .collect();
                write!(f, "solver failed at t = {time_s:.6} s ({}): {message}", shown.join(", "))
            }
        }
    }
}

pub type TransientResult<T> = Result<T, TransientError>;
