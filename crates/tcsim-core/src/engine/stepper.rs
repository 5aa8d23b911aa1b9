//! A converter model stepped through time by its caller, one communication interval at a time:
//! the engine of a co-simulation FMU (`fmi2DoStep`) and of any host that owns the clock.
//!
//! The inputs of each interval are interpolated linearly between their values at its start and at
//! its end (a first-order hold), so a speed input has a constant rate within the interval and the
//! inertia and shape-effect terms see it. The state and the discrete modes (stator clutch, flow
//! direction) carry over from one interval to the next, so a run stepped in many intervals follows
//! the same trajectory as one run over the same piecewise-linear inputs (tested).

use crate::converter::dynamics::{ConverterDynamics, Vec4};
use crate::engine::converter_events::{Mode, Sample};
use crate::engine::isolated::{initial_mode, initial_state, simulate_from, Drive, InitialState, TurbineLoad};
use crate::engine::lockup::{ClutchMode, LockupCommand, DEFAULT_STATIC_TO_KINETIC};
use crate::engine::mode_view::{ModeView, LOCKUP_INDICATOR};
use crate::engine::options::{SolverOptions, TransientResult};
use crate::engine::signal::Signal;

/// Which quantities the host gives and which come back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// The thesis/VSIM choice: pump torque and turbine speed in; pump speed and turbine torque out.
    PumpTorqueTurbineSpeed,
    /// Pump and turbine speeds in; the torques out.
    Speeds,
    /// Pump torque and the turbine's load torque in; both speeds out (drive (c): the converter with
    /// its inertias, and the load inertia, as one body; no input is differentiated).
    Torques,
}

/// The lock-up clutch and the load of a stepped drive: what the two inputs do not give.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepperDrive {
    /// Lock-up capacity at the start and at the end of the coming interval, N·m (linear in
    /// between); None: a converter without a clutch.
    pub lockup_capacity_nm: Option<[f64; 2]>,
    /// Static-to-kinetic friction ratio of the clutch (≥ 1).
    pub lockup_static_to_kinetic: f64,
    /// Load inertia on the turbine in [`Causality::Torques`], kg·m².
    pub load_inertia_kg_m2: f64,
    /// Load drag in [`Causality::Torques`]: `drag·ω_t|ω_t|` opposing rotation, N·m/(rad/s)².
    pub load_drag_nm_s2: f64,
}

impl Default for StepperDrive {
    fn default() -> Self {
        Self {
            lockup_capacity_nm: None,
            lockup_static_to_kinetic: DEFAULT_STATIC_TO_KINETIC,
            load_inertia_kg_m2: 0.0,
            load_drag_nm_s2: 0.0,
        }
    }
}

/// The state of a [`Stepper`] between two intervals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepperState {
    pub time_s: f64,
    pub inputs: [f64; 2],
    pub u: Vec4,
    pub mode: Mode,
}

/// A model, its state and modes, advanced interval by interval.
pub struct Stepper<M: ConverterDynamics> {
    pub model: M,
    pub causality: Causality,
    pub options: SolverOptions,
    /// The clutch and the load (set before [`Stepper::initialize`] and each [`Stepper::do_step`]).
    pub extra: StepperDrive,
    time_s: f64,
    inputs: [f64; 2],
    u: Vec4,
    mode: Mode,
    last: Option<Sample>,
}

impl<M: ConverterDynamics> Stepper<M> {
    pub fn new(model: M, causality: Causality, options: SolverOptions) -> Self {
        Self {
            model,
            causality,
            options,
            extra: StepperDrive::default(),
            time_s: 0.0,
            inputs: [0.0; 2],
            u: [0.0; 4],
            mode: Mode { stator_locked: false, flow_sign: 1.0, ..Mode::default() },
            last: None,
        }
    }

    fn drive(&self, t: [f64; 2], a: [f64; 2], b: [f64; 2]) -> TransientResult<Drive> {
        let sig = |name: &str, i: usize| Signal::interval(name, t, [a[i], b[i]]);
        let lockup = match self.extra.lockup_capacity_nm {
            Some(c) => Some(LockupCommand {
                capacity_nm: Signal::interval("lockup_capacity_nm", t, c)?,
                static_to_kinetic: self.extra.lockup_static_to_kinetic,
            }),
            None => None,
        };
        Ok(match self.causality {
            Causality::PumpTorqueTurbineSpeed => Drive::PumpTorqueTurbineSpeed {
                pump_torque_nm: sig("pump_torque_nm", 0)?,
                turbine_speed_rad_s: sig("turbine_speed_rad_s", 1)?,
                lockup,
            },
            Causality::Speeds => Drive::Speeds {
                pump_speed_rad_s: sig("pump_speed_rad_s", 0)?,
                turbine_speed_rad_s: sig("turbine_speed_rad_s", 1)?,
                lockup,
            },
            Causality::Torques => Drive::PumpTorqueLoad {
                pump_torque_nm: sig("pump_torque_nm", 0)?,
                load: TurbineLoad {
                    torque_nm: sig("load_torque_nm", 1)?,
                    inertia_kg_m2: self.extra.load_inertia_kg_m2,
                    drag_nm_s2: self.extra.load_drag_nm_s2,
                },
                lockup,
            },
        })
    }

    /// Start at `t0` with `inputs` (pump torque or speed, turbine speed or load torque): the steady state
    /// consistent with them unless `init` gives values.
    /// `rates` are the inputs' rates at `t0` (zero if unknown): they enter the outputs at the start
    /// (the inertia and shape-effect terms), not the steady state.
    pub fn initialize(
        &mut self,
        t0: f64,
        inputs: [f64; 2],
        rates: [f64; 2],
        init: &InitialState,
    ) -> TransientResult<Sample> {
        let drive = self.drive([t0, t0 + 1.0], inputs, [inputs[0] + rates[0], inputs[1] + rates[1]])?;
        let u = initial_state(&self.model, &drive, t0, init)?;
        let mode = initial_mode(&self.model, &drive, &u, t0);
        self.time_s = t0;
        self.inputs = inputs;
        self.u = u;
        self.mode = mode;
        // the outputs at the start: a zero-length run from the state
        let traj = simulate_from(&self.model, &drive, &[t0, t0 + 1e-9], u, mode, &self.options)?;
        self.last = traj.samples.first().copied();
        Ok(self.last.expect("a run samples its start"))
    }

    /// Advance by `h` to `time + h`, the inputs moving linearly from `inputs_start` to `inputs_end`
    /// (pass the previous end values for continuous inputs). Returns the sample at the end.
    pub fn do_step(&mut self, h: f64, inputs_start: [f64; 2], inputs_end: [f64; 2]) -> TransientResult<Sample> {
        if !(h.is_finite() && h > 0.0) {
            let e = crate::CoreError::of(
                crate::InputSource::Options,
                "communication step size",
                h,
                "a finite, positive step",
            );
            return Err(e.into());
        }
        let (t0, t1) = (self.time_s, self.time_s + h);
        let drive = self.drive([t0, t1], inputs_start, inputs_end)?;
        if self.mode.lockup.is_locked() && !drive.lockup().is_some_and(LockupCommand::engages) {
            // a command of zero over the whole interval has no events: the clutch opens at its start
            self.mode.lockup = ClutchMode::Unarmed { since_s: t0 };
        }
        // an input that jumps at the communication point (a capacity stepped below the torque of
        // the locked clutch) can leave the clutch's root negative at the start, where the solver
        // sees no crossing: its switch is made first
        for _ in 0..4 {
            let view = ModeView::new(&self.model, &drive, self.mode);
            if view.indicators(&self.u, t0, &self.options.hysteresis)[LOCKUP_INDICATOR] > 0.0 {
                break;
            }
            match view.event(&mut self.u, t0, &self.options.hysteresis) {
                Some((_, mode)) => self.mode = mode,
                None => break,
            }
        }
        let traj = simulate_from(&self.model, &drive, &[t0, t1], self.u, self.mode, &self.options)?;
        let end = *traj.samples.last().expect("a run samples its end");
        self.time_s = t1;
        self.inputs = inputs_end;
        self.u = traj.end_state;
        self.mode = traj.end_mode;
        self.last = Some(end);
        Ok(end)
    }

    /// What the continuation depends on: the time, the inputs, the coordinates and the modes (an
    /// FMU state, `fmi2GetFMUstate`).
    pub fn state(&self) -> StepperState {
        StepperState { time_s: self.time_s, inputs: self.inputs, u: self.u, mode: self.mode }
    }

    /// Continue from `state` (of [`Stepper::state`]); the next step continues bit for bit as the
    /// stepper it came from did.
    pub fn set_state(&mut self, state: &StepperState) {
        self.time_s = state.time_s;
        self.inputs = state.inputs;
        self.u = state.u;
        self.mode = state.mode;
        self.last = None;
    }

    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// The inputs at the current time (the end values of the last interval).
    pub fn inputs(&self) -> [f64; 2] {
        self.inputs
    }

    /// The latest sample (outputs of the current state).
    pub fn sample(&self) -> Option<&Sample> {
        self.last.as_ref()
    }
}
