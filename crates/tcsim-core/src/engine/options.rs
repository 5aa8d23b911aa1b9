//! Solver options and the error type of the transient engines (isolated converter and vehicle).

use crate::converter::dynamics::ConverterDynamics;
use crate::error::{sig, CoreError, CoreResult, InputSource};

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
    /// The most memory a batch's outputs may take, bytes ([`DEFAULT_MAX_OUTPUT_BYTES`]): the
    /// estimate of [`OutputSize::check`] is compared with it before anything runs.
    pub max_output_bytes: f64,
    /// The optional quantities the samples compute (default all): a batch asks only for those its
    /// columns read ([`crate::engine::outputs::Selection::sampled`]).
    pub sampled: Sampled,
}

/// The quantities of a sample ([`crate::engine::converter_events::Sample`]) that only some output
/// columns read ([`crate::engine::outputs::Selection::sampled`]): each is computed only when
/// wanted, and is NaN in the sample otherwise. The default is all of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sampled {
    /// The fluid's loss power (`Sample::loss_power_w`).
    pub loss_power: bool,
    /// The stored energy (`Sample::stored_energy_j`).
    pub stored_energy: bool,
    /// The transferred torques (`Sample::transferred`; always computed for a model without a
    /// stator coordinate, whose stator torque is their balance).
    pub transferred: bool,
}

impl Sampled {
    /// Every quantity.
    pub const ALL: Self = Self { loss_power: true, stored_energy: true, transferred: true };
    /// None of them.
    pub const NONE: Self = Self { loss_power: false, stored_energy: false, transferred: false };

    /// The quantities wanted by either.
    pub fn or(self, other: Self) -> Self {
        Self {
            loss_power: self.loss_power || other.loss_power,
            stored_energy: self.stored_energy || other.stored_energy,
            transferred: self.transferred || other.transferred,
        }
    }
}

impl Default for Sampled {
    fn default() -> Self {
        Self::ALL
    }
}

/// Default of [`SolverOptions::max_output_bytes`]: 2 GB. A launch of 30 s sampled every 10 ms takes
/// 0.6 MB, a replay of a million samples with three models about 1 GB.
pub const DEFAULT_MAX_OUTPUT_BYTES: f64 = 2e9;

/// Bytes of one output value (f64).
pub const BYTES_PER_VALUE: usize = 8;

/// The size of a batch's output before it runs: `runs` runs of at most `samples` samples each, each
/// sample a trajectory state of `state_bytes` plus `columns` output values, and up to `max_events`
/// events of `event_bytes` per run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputSize {
    pub runs: usize,
    pub samples: f64,
    pub columns: usize,
    pub state_bytes: usize,
    pub max_events: usize,
    pub event_bytes: usize,
}

impl OutputSize {
    /// The estimate, bytes.
    pub fn bytes(&self) -> f64 {
        let per_sample = (self.columns * BYTES_PER_VALUE + self.state_bytes) as f64;
        self.runs as f64 * (self.samples * per_sample + ((self.max_events + 1) * self.event_bytes) as f64)
    }

    /// Refuse an output above `limit` bytes: an error about `source` (the input whose length or
    /// sampling makes the output: the drive's times, the scenario's end time, the output step) naming
    /// the sizes, the limit, and how to raise it or lower the sampling.
    pub fn check(&self, source: InputSource, limit: f64) -> CoreResult<()> {
        let bytes = self.bytes();
        if bytes <= limit {
            return Ok(());
        }
        let expected = format!(
            "an output of at most max_output_bytes = {} bytes, but {} run(s) × {} samples × ({} columns × {BYTES_PER_VALUE} + {} bytes of state) need {} bytes: lower the sampling (fewer output times, a larger output step, a shorter run) or raise the solver option max_output_bytes",
            sig(limit),
            self.runs,
            sig(self.samples),
            self.columns,
            self.state_bytes,
            sig(bytes)
        );
        Err(CoreError::of(source, "output_samples", format!("{:.0}", self.samples), expected))
    }
}

/// Reserve room for `n` more items, an error instead of an abort when the memory is not there.
pub fn try_reserve<T>(v: &mut Vec<T>, n: usize) -> TransientResult<()> {
    v.try_reserve_exact(n).map_err(|_| {
        let bytes = n as f64 * std::mem::size_of::<T>() as f64;
        let expected = "an output that fits in memory (allocating it failed): lower the sampling or max_output_bytes";
        TransientError::Input(CoreError::of(InputSource::Options, "output_bytes", sig(bytes), expected))
    })
}

/// See [`SolverOptions::hysteresis`].
#[derive(Debug, Clone, Copy)]
pub struct Hysteresis {
    pub flow_m3_s: f64,
    pub stator_speed_rad_s: f64,
    pub stator_torque_nm: f64,
    pub head_pa: f64,
}

impl SolverOptions {
    /// The tolerances and the first step are finite and positive, and the relative tolerance is
    /// below 1 (at 1 or more the error test passes whatever the step: a take-off at `rtol = 1e6`
    /// ended at 3.9·10⁷ rad/s, without an error). An error about [`InputSource::Options`] naming the
    /// first at fault.
    pub fn check_tolerances(&self) -> CoreResult<()> {
        for (k, v) in [
            ("rtol", self.rtol),
            ("speed_atol_rad_s", self.speed_atol_rad_s),
            ("flow_atol_m3_s", self.flow_atol_m3_s),
            ("first_step_s", self.first_step_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(CoreError::of(InputSource::Options, k, v, "a finite, positive tolerance"));
            }
        }
        if self.rtol >= 1.0 {
            return Err(CoreError::of(
                InputSource::Options,
                "rtol",
                self.rtol,
                "a relative tolerance below 1 (the default is 1e-6)",
            ));
        }
        Ok(())
    }
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
            max_output_bytes: DEFAULT_MAX_OUTPUT_BYTES,
            sampled: Sampled::ALL,
        }
    }
}

/// What went wrong in a transient run.
#[derive(Debug, Clone)]
pub enum TransientError {
    /// The user's input (exit code 2).
    Input(CoreError),
    /// The solver failed (exit code 1): time, state (each coordinate's name and value) and message.
    Solver { time_s: f64, state: NamedState, message: String },
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
                let shown: Vec<String> = state.iter().map(|(name, v)| format!("{name} = {}", sig(*v))).collect();
                write!(f, "solver failed at t = {} s ({}): {message}", sig(*time_s), shown.join(", "))
            }
        }
    }
}

pub type TransientResult<T> = Result<T, TransientError>;

/// A state as a solver error shows it: each coordinate's name and value.
pub type NamedState = Vec<(&'static str, f64)>;

/// The names of the converter's coordinates and then the vehicle's, in their order.
const COORDINATE_NAMES: [&str; 12] =
    ["ω_p", "ω_t", "ω_s", "Q", "ω_o", "ω_f", "ω_r", "v", "θ_f", "θ_r", "T_fast", "T_boost"];

/// `values` named by position (`COORDINATE_NAMES`, `x` beyond them): the converter's four
/// coordinates then the vehicle's. With `model`, the converter's coordinates the model lacks are left
/// out and a table model's lag state is named `T_lag` (a table model's error showed `ω_s = 0, Q = 0`,
/// and a lagged table's lag torque as `Q`).
pub fn named_state(model: Option<&dyn ConverterDynamics>, values: &[f64]) -> NamedState {
    let (present, lag) = model.map_or(([true; 4], false), |m| (m.coordinates(), m.lag_state()));
    values
        .iter()
        .enumerate()
        .filter(|&(i, _)| i >= 4 || present[i])
        .map(|(i, &v)| (if i == 3 && lag { "T_lag" } else { COORDINATE_NAMES.get(i).copied().unwrap_or("x") }, v))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerances_are_finite_positive_and_rtol_below_one() {
        assert!(SolverOptions::default().check_tolerances().is_ok());
        let ok = SolverOptions { rtol: 0.999, ..Default::default() };
        assert!(ok.check_tolerances().is_ok());
        for (rtol, expected) in
            [(1.0, "a relative tolerance below 1"), (1e6, "a relative"), (0.0, "a finite, positive")]
        {
            let e = SolverOptions { rtol, ..Default::default() }.check_tolerances().unwrap_err();
            assert_eq!((e.source, e.field.as_str()), (InputSource::Options, "rtol"));
            assert!(e.expected.starts_with(expected), "{}", e.expected);
        }
        let e = SolverOptions { first_step_s: f64::NAN, ..Default::default() }.check_tolerances().unwrap_err();
        assert_eq!(e.field, "first_step_s");
    }

    #[test]
    fn the_output_size_is_estimated_and_capped() {
        // two-row scenario of 1e5 s at 10 ms: 1e7 samples × 45 columns, 3.6 GB of columns alone
        let size =
            OutputSize { runs: 1, samples: 1e7 + 1.0, columns: 45, state_bytes: 0, max_events: 0, event_bytes: 0 };
        assert!((size.bytes() - (1e7 + 1.0) * 360.0).abs() < 1.0);
        let e = size.check(InputSource::Scenario, DEFAULT_MAX_OUTPUT_BYTES).unwrap_err();
        assert_eq!(
            (e.source, e.field.as_str(), e.value.as_str()),
            (InputSource::Scenario, "output_samples", "10000001")
        );
        assert!(
            e.expected.contains("max_output_bytes = 2e9 bytes") && e.expected.contains("need 3.6e9 bytes"),
            "{}",
            e.expected
        );
        assert!(size.check(InputSource::Scenario, 4e9).is_ok(), "raising the limit lets it run");
        let small = OutputSize {
            runs: 20,
            samples: 3001.0,
            columns: 45,
            state_bytes: 400,
            max_events: 10_000,
            event_bytes: 48,
        };
        assert!(small.check(InputSource::Options, DEFAULT_MAX_OUTPUT_BYTES).is_ok());
        let mut v: Vec<f64> = Vec::new();
        let e = try_reserve(&mut v, usize::MAX / 8).unwrap_err();
        assert!(matches!(e, TransientError::Input(ref c) if c.field == "output_bytes"), "{e}");
        assert!(try_reserve(&mut v, 10).is_ok());
    }

    #[test]
    fn solver_messages_print_six_digits() {
        let state = named_state(None, &[1e300, 50.0, 0.0, 0.0745]);
        let e = TransientError::Solver { time_s: 1e5 + 1e-9, state, message: "m".into() };
        assert_eq!(e.to_string(), "solver failed at t = 100000 s (ω_p = 1e300, ω_t = 50, ω_s = 0, Q = 0.0745): m");
    }
}
