//! The converter models: characteristic tables, the Hrovat & Tobler closed form, and the three
//! models in mass-matrix form for the transient engines. Depends on nothing above it.
//!
//! * [`backward`]: the backward (quasi-static) operating point: pump speed and torque from the
//!   turbine speed and torque.
//! * [`capacity`]: the six capacity conventions of characteristic tables.
//! * [`design`]: a design's torus and blades: shape effects over the axial projection, fluid length,
//!   fluid masses and inertias (issue 15).
//! * [`table`]: the steady-state look-up-table model (Li & Sundén 2016, eqs 2.8–2.11).
//! * [`hrovat_tobler`]: the Hrovat & Tobler model's closed-form steady state and coupling point.
//! * [`dynamics`]: the mass-matrix model trait and types, the table and Hrovat & Tobler models.
//! * [`quasi_dynamic`]: tcsim's quasi-dynamic model (tables plus fluid inertia).
//! * [`torque_capacity`]: several tables measured at different input torques (torque-dependent capacity).
//! * [`spec`]: building a model from a specification, and the default flow time constant.

pub mod backward;
pub mod capacity;
pub mod design;
pub mod dynamics;
pub mod hrovat_tobler;
pub mod quasi_dynamic;
pub mod spec;
pub mod table;
pub mod torque_capacity;
