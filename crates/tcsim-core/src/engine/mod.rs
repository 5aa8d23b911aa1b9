//! The transient engines: the BDF integrator, one segment loop, the converter's events, the isolated
//! converter under a drive, its Model Exchange view and its co-simulation stepper. Uses
//! [`crate::converter`]; never the vehicle.
//!
//! * [`options`]: solver tolerances, event hysteresis, the engines' error type.
//! * [`bdf`]: the variable-order NDF/BDF integrator (fixed-size arrays, events, dense output).
//! * [`segment`]: the generic loop over one smooth segment, up to the first root.
//! * [`converter_events`]: the converter's modes, roots, switches and samples (shared with the vehicle).
//! * [`lockup`]: the lock-up clutch (friction law, states, roots), shared with the vehicle.
//! * [`converter_segment`]: one smooth piece of an isolated run (roles, reduced mass, roots, switches).
//! * [`drive`]: the drives (a, b, c) of the isolated converter.
//! * [`isolated`]: a converter model under a [`isolated::Drive`]: initial state, runs, events.
//! * [`mode_view`]: one mode seen from outside (rates, event indicators, switches) for Model Exchange.
//! * [`stepper`]: a model stepped interval by interval by its host (co-simulation).
//! * [`signal`]: sampled input signals with a smoothed derivative.
//! * [`outputs`]: the named output columns of a run.

pub mod bdf;
pub mod converter_events;
pub mod converter_segment;
pub mod drive;
pub mod isolated;
pub mod lockup;
pub mod mode_view;
pub mod options;
pub mod outputs;
pub mod segment;
pub mod signal;
pub mod stepper;
