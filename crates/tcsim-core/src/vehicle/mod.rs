//! Whole-vehicle take-off: engine, lock-up clutch, torque converter (any of the three models,
//! unchanged), automatic gearbox with timed shifts, compliant AWD driveline, tyres, body, brake.
//!
//! The plant is written over twelve coordinates, in the same mass-matrix form as the converter
//! models (`M u̇ = F(u, t)`):
//!
//! | index | coordinate | unit |
//! |---|---|---|
//! | 0–3 | ω_p (engine + pump), ω_t (turbine + gearbox input), ω_s, Q | rad/s, m³/s |
//! | 4 | ω_o, gearbox output (propshaft) | rad/s |
//! | 5, 6 | ω_f, ω_r, front and rear axle (wheels) | rad/s |
//! | 7 | v, vehicle speed | m/s |
//! | 8, 9 | θ_f, θ_r, front and rear shaft twist at the propshaft side | rad |
//! | 10, 11 | fast (aspirated) and boost parts of the engine torque | N·m |
//!
//! Modes link or hold coordinates: a gear in mesh links `ω_t = i_k ω_o`, a locked lock-up clutch
//! `ω_p = ω_t`, a held brake holds the axles at zero, and the converter's own modes hold the stator
//! or the flow. The states of a mode are generalised coordinates `x` with `u = P x`; the reduced
//! system `PᵀMP ẋ = PᵀF` goes to the BDF integrator. When a link closes (lock-up locks, a shift
//! synchronises) the new state is the momentum-conserving projection `(PᵀMP) x = PᵀM u`, and the
//! kinetic energy it removes is booked as a clutch loss, so the energy balance closes exactly.
//! Equations and parameters: docs/vehicle.md.
//!
//! * [`file`](mod@file): the vehicle file's schema (TOML), read once into the parameters, errors
//!   named as the file names its fields.
//! * [`parameters`]: the vehicle's parameters and scenario, with their one validation.
//! * [`components`]: the physics of engine, gearbox, lock-up, driveline, tyres, body and brake.
//! * [`modes`]: the discrete state (gear, shift, lock-up, brake hold) and the event kinds.
//! * [`plant`]: the plant in one mode (mass matrix, generalised coordinates, forces, roots).
//! * [`shift`]: the gearbox's inertia during a shift and the shift control of upshifts.
//! * [`shift_pedal`]: the TCU's filtered pedal the shift schedule reads.
//! * [`launch`]: the run loop of a launch, its initial state and its switches.
//! * [`outputs`]: the output columns of a launch.
//! * [`cycle`]: drive cycles, a driver following a speed trace with the same plant.

pub mod components;
pub mod cycle;
pub mod file;
pub mod launch;
pub mod modes;
pub mod outputs;
pub mod parameters;
pub mod plant;
pub mod range;
pub mod shift;
pub mod shift_pedal;

/// Number of coordinates of the vehicle plant.
pub const N_COORDS: usize = 12;
pub const GEARBOX_OUT: usize = 4;
pub const FRONT: usize = 5;
pub const REAR: usize = 6;
pub const SPEED: usize = 7;
pub const TWIST_F: usize = 8;
pub const TWIST_R: usize = 9;
pub const TORQUE_FAST: usize = 10;
pub const TORQUE_BOOST: usize = 11;
