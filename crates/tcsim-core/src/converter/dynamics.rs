//! The three converter models in mass-matrix form, for the transient engine.
//!
//! Every model is written over the same four coordinates `u = [ω_p, ω_t, ω_s, Q]` (rad/s, rad/s,
//! rad/s, m³/s) as
//!
//! ```text
//!     M · u̇ = F(u) + T_ext
//! ```
//!
//! with a constant mass matrix `M`, the internal forces `F` (torques on pump, turbine and stator,
//! and the net head of eq 2.15) and the external torques `T_ext` (engine, load, stator clutch).
//! A model that lacks a coordinate (the table model has no flow, only Hrovat & Tobler has a stator
//! speed) leaves it out of [`ConverterDynamics::coordinates`]. Which of the remaining coordinates
//! are states and which are prescribed (a measured speed, a locked stator, a stalled flow) is the
//! engine's business ([`crate::engine`]), not the model's.
//!
//! * [`TableDynamics`]: the steady-state table with pump and turbine inertias, eqs 2.8–2.11.
//! * [`HtDynamics`]: Hrovat & Tobler, eqs 2.12–2.25.
//! * [`QuasiDynamics`](super::quasi_dynamic::QuasiDynamics): tcsim's quasi-dynamic model (tables plus fluid inertia), docs/physics.md §5.
//!
//! Sign conventions follow docs/physics.md §2: `T_ext` holds the external torques on pump, turbine
//! and stator; the torque delivered to the transmission is `−T_ext[TURBINE]`.

use super::hrovat_tobler::{steady_state_with, HtConstants, HtGeometry, HtParam};
use super::torque_capacity::TorqueCharacteristic;
use crate::error::{CoreError, CoreResult};

pub const PUMP: usize = 0;
pub const TURBINE: usize = 1;
pub const STATOR: usize = 2;
pub const FLOW: usize = 3;

pub type Vec4 = [f64; 4];
pub type Mat4 = [[f64; 4]; 4];

/// A steady state used to start a transient run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyPoint {
    /// Coordinates; the absent ones are zero.
    pub u: Vec4,
    /// External pump torque at this point.
    pub pump_torque_nm: f64,
}

/// A converter model in mass-matrix form.
pub trait ConverterDynamics: Sync {
    /// Which of `[ω_p, ω_t, ω_s, Q]` the model has.
    fn coordinates(&self) -> [bool; 4];
    /// The constant mass matrix (rows and columns of absent coordinates are ignored).
    fn mass(&self) -> Mat4;
    /// Internal forces `F(u)`. `flow_sign` is the sign of Q in the loss terms (eq 2.19), held as
    /// a discrete state by the engine: +1, −1, or 0 while the flow is held at zero.
    fn forces(&self, u: &Vec4, flow_sign: f64) -> Vec4;
    /// [`Self::forces`] at each of `u` into `out` (as long): the same values. A model whose
    /// forces are a chain of dependent operations computes them in one loop, where the chains of
    /// successive points overlap (the engine's samples, [`crate::engine::segment::SAMPLE_BLOCK`]).
    fn forces_many(&self, u: &[Vec4], flow_sign: f64, out: &mut [Vec4]) {
        for (o, u) in out.iter_mut().zip(u) {
            *o = self.forces(u, flow_sign);
        }
    }
    /// `∂F/∂u`, analytic.
    fn force_jacobian(&self, u: &Vec4, flow_sign: f64) -> Mat4;
    /// Torques transferred by the fluid at the pump and at the turbine (figure 3.15): the pump
    /// torque absorbed, and the turbine torque produced, not counting inertia and fluid terms,
    /// given the forces `f = F(u)`.
    fn transferred(&self, f: &Vec4) -> (f64, f64) {
        (-f[PUMP], f[TURBINE])
    }
    /// Power dissipated in the fluid given the forces `f = F(u)`: `−u·F`, which is `Q·P_loss`
    /// (≥ 0) for Hrovat & Tobler (the flow terms cancel, docs/physics.md §4) and the power the
    /// table's torques absorb, `T_p,tr ω_p − T_t,tr ω_t`, for the table models.
    fn loss_power_w(&self, u: &Vec4, f: &Vec4) -> f64 {
        -(u[0] * f[0] + u[1] * f[1] + u[2] * f[2] + u[3] * f[3])
    }
    /// The energy the model stores at `u`, J: `½uᵀMu` (the kinetic energy of the elements and, for
    /// Hrovat & Tobler, of the fluid with its coupling to the elements). With [`Self::loss_power_w`]
    /// it closes the energy identity `∫T_ext·ω dt = ΔE + ∫loss dt`.
    fn stored_energy_j(&self, u: &Vec4) -> f64 {
        quadratic_energy_j(&self.energy_mass().unwrap_or_else(|| self.mass()), u)
    }
    /// The matrix `E` of a stored energy `½uᵀEu` ([`Self::stored_energy_j`]), when the model's is
    /// such a form: its mass matrix by default. None for a model with another formula (then the
    /// engine calls [`Self::stored_energy_j`] at every sample instead of using `E` kept once).
    fn energy_mass(&self) -> Option<Mat4> {
        Some(self.mass())
    }
    /// The steady state at the given pump and turbine speeds (0 ≤ SR ≤ 1, ω_p > 0).
    fn steady_point(&self, pump_speed_rad_s: f64, turbine_speed_rad_s: f64) -> CoreResult<SteadyPoint>;
    /// Whether the model has a stator one-way clutch (and so stator events).
    fn has_stator_clutch(&self) -> bool {
        false
    }
    /// Whether the loss terms carry sgn Q (and so flow-reversal events).
    fn has_flow_sign(&self) -> bool {
        false
    }
    /// The force on the flow coordinate at Q = 0 approached from either side, `(F_Q(0⁺), F_Q(0⁻))`
    /// (σ = +1 and σ = −1): the flow is held at zero while `F_Q(0⁺) ≤ 0 ≤ F_Q(0⁻)` (the "dry
    /// friction" of the flow; see [`crate::engine::converter_events`]).
    fn zero_flow_head(&self, _u: &Vec4) -> (f64, f64) {
        (0.0, 0.0)
    }
    /// Whether the fourth coordinate holds a lagged pump torque (N·m, the table model's
    /// [`TorqueLag`]) rather than a flow: it is then a state of the ODE like a flow, but no flow in
    /// outputs, initial values or events.
    fn lag_state(&self) -> bool {
        false
    }
}

/// `½uᵀEu`, J: the stored energy of a model whose [`ConverterDynamics::energy_mass`] is `E`.
pub fn quadratic_energy_j(e: &Mat4, u: &Vec4) -> f64 {
    0.5 * (0..4).map(|r| u[r] * (0..4).map(|c| e[r][c] * u[c]).sum::<f64>()).sum::<f64>()
}

/// Inertias of the rotating elements (each including the fluid it carries).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inertias {
    pub pump_kg_m2: f64,
    pub turbine_kg_m2: f64,
    pub stator_kg_m2: f64,
}

impl Inertias {
    pub fn new(pump_kg_m2: f64, turbine_kg_m2: f64, stator_kg_m2: f64) -> CoreResult<Self> {
        for (name, v) in [
            ("inertia.pump_kg_m2", pump_kg_m2),
            ("inertia.turbine_kg_m2", turbine_kg_m2),
            ("inertia.stator_kg_m2", stator_kg_m2),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(CoreError::new(name, v, "a finite, positive inertia in kg·m²"));
            }
        }
        Ok(Self { pump_kg_m2, turbine_kg_m2, stator_kg_m2 })
    }
}

pub use crate::error::sig;

// ---------------------------------------------------------------------------------------------
// Table model

/// The steady-state table model with inertias (Li & Sundén 2016, eqs 2.8–2.11):
/// `I_p ω̇_p = T_p − CF(SR) ω_p|ω_p|`, `I_t ω̇_t = TR(SR) CF(SR) ω_p|ω_p| + T_t` in drive, and
/// the table's law in every other quadrant as [`TorqueCharacteristic::torques`] defines it (passive,
/// continuous; the overrun rule beyond the table's rows). With a [`TorqueLag`] the pump torque
/// follows the table's with a first-order lag (docs/lag.md).
#[derive(Debug, Clone)]
pub struct TableDynamics {
    /// One table, or several measured at different input torques ([`TorqueCharacteristic`]).
    pub characteristic: TorqueCharacteristic,
    pub inertia: Inertias,
    /// The first-order lag of the transferred torques (`[characteristic] lag_time_constant_s`);
    /// None: the table's torques act at once, the model of eqs 2.8–2.11.
    pub lag: Option<TorqueLag>,
}

/// The first-order transmission lag of the table model (docs/lag.md), the form of Simscape
/// Driveline's Torque Converter ("Model transmission lag") and SimCreator's `TCTorque` state:
///
/// ```text
///     t_c·Ṫ_lag = T_p,ss(ω_p, ω_t) − T_lag
///     T_p,tr = T_lag,   T_t,tr = TR(ω_p, ω_t)·T_lag            (the candidate pair)
/// ```
///
/// with `T_p,ss` and `TR` the table's pump torque and (passivity-projected) torque ratio at the
/// current speeds ([`TorqueCharacteristic::torques`]). **Passivity rule**: where the candidate pair
/// would deliver power, `P = T_p,tr·ω_p − T_t,tr·ω_t < 0` (the lagged torque keeps its sign while
/// the steady one has turned: a reversing pump, an overrun reached faster than t_c), the pair is
/// projected orthogonally onto `P = 0` in the (T_p,tr, T_t,tr) plane:
///
/// ```text
///     (T_p,tr, T_t,tr) ← (T_p,tr, T_t,tr) − P/(ω_p² + ω_t²)·(ω_p, −ω_t)
/// ```
///
/// so the converter never delivers power, and the pair is continuous. The lag stores no energy:
/// the loss is the absorbed power `T_p,tr·ω_p − T_t,tr·ω_t ≥ 0`.
///
/// The lag state `T_lag` (N·m) lives in the model's unused fourth coordinate (the table model has
/// no flow), a mass-matrix row with mass `t_c`; [`ConverterDynamics::lag_state`] tells the engine
/// and the outputs that it is not a flow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorqueLag {
    /// `t_c`, s: finite and positive.
    pub time_constant_s: f64,
}

impl TorqueLag {
    /// A lag with time constant `t_c` (s), finite and positive.
    pub fn new(time_constant_s: f64) -> CoreResult<Self> {
        if !(time_constant_s.is_finite() && time_constant_s > 0.0) {
            return Err(CoreError::new(
                "characteristic.lag_time_constant_s",
                time_constant_s,
                "a finite, positive time constant in s",
            ));
        }
        Ok(Self { time_constant_s })
    }
}

/// Table torques `(T_p,tr, T_t,tr)` and their gradients with respect to (ω_p, ω_t), in every
/// quadrant ([`TorqueCharacteristic::torques`]).
pub(super) fn table_torques(c: &TorqueCharacteristic, wp: f64, wt: f64) -> (f64, f64, [f64; 2], [f64; 2]) {
    let t = c.torques(wp, wt);
    (t.pump_nm, t.delivered_nm, t.d_pump, t.d_delivered)
}

/// Pump speed of a table steady state, and the table's pump torque there.
pub(super) fn table_steady(c: &TorqueCharacteristic, wp: f64, wt: f64) -> CoreResult<f64> {
    let op = c.operating_point(wp, wt)?;
    Ok(op.pump_torque_nm)
}

/// The lagged torques `(T_p,tr, T_t,tr)` at speeds (`wp`, `wt`) and lagged pump torque `z`, with
/// their gradients with respect to (ω_p, ω_t, T_lag), after the passivity rule ([`TorqueLag`]).
pub(super) fn lagged_torques(c: &TorqueCharacteristic, wp: f64, wt: f64, z: f64) -> (f64, f64, [f64; 3], [f64; 3]) {
    let t = c.torques(wp, wt);
    let tr = t.torque_ratio;
    let (tp, td) = (z, tr * z);
    let dtp = [0.0, 0.0, 1.0];
    let dtd = [t.d_torque_ratio[0] * z, t.d_torque_ratio[1] * z, tr];
    let power = tp * wp - td * wt;
    let norm = wp * wp + wt * wt;
    if power >= 0.0 || norm == 0.0 {
        return (tp, td, dtp, dtd);
    }
    // orthogonal projection onto T_p ω_p − T_t ω_t = 0 (k = P/N)
    let k = power / norm;
    let dpower = [dtp[0] * wp + tp - dtd[0] * wt, dtp[1] * wp - dtd[1] * wt - td, wp - tr * wt];
    let dnorm = [2.0 * wp, 2.0 * wt, 0.0];
    let dk: [f64; 3] = std::array::from_fn(|i| (dpower[i] - k * dnorm[i]) / norm);
    let unit = |i: usize, j: usize| if i == j { 1.0 } else { 0.0 };
    (
        tp - k * wp,
        td + k * wt,
        std::array::from_fn(|i| dtp[i] - dk[i] * wp - k * unit(i, 0)),
        std::array::from_fn(|i| dtd[i] + dk[i] * wt + k * unit(i, 1)),
    )
}

impl ConverterDynamics for TableDynamics {
    fn coordinates(&self) -> [bool; 4] {
        [true, true, false, self.lag.is_some()]
    }
    fn mass(&self) -> Mat4 {
        let mut m = [[0.0; 4]; 4];
        m[PUMP][PUMP] = self.inertia.pump_kg_m2;
        m[TURBINE][TURBINE] = self.inertia.turbine_kg_m2;
        if let Some(lag) = self.lag {
            m[FLOW][FLOW] = lag.time_constant_s;
        }
        m
    }
    fn forces(&self, u: &Vec4, _s: f64) -> Vec4 {
        if self.lag.is_some() {
            let (tp, tt, _, _) = lagged_torques(&self.characteristic, u[PUMP], u[TURBINE], u[FLOW]);
            let steady = self.characteristic.torques(u[PUMP], u[TURBINE]).pump_nm;
            return [-tp, tt, 0.0, steady - u[FLOW]];
        }
        let (tp, tt, _, _) = table_torques(&self.characteristic, u[PUMP], u[TURBINE]);
        [-tp, tt, 0.0, 0.0]
    }
    fn force_jacobian(&self, u: &Vec4, _s: f64) -> Mat4 {
        let mut j = [[0.0; 4]; 4];
        if self.lag.is_some() {
            let (_, _, dtp, dtt) = lagged_torques(&self.characteristic, u[PUMP], u[TURBINE], u[FLOW]);
            let steady = self.characteristic.torques(u[PUMP], u[TURBINE]).d_pump;
            for (k, c) in [PUMP, TURBINE, FLOW].into_iter().enumerate() {
                j[PUMP][c] = -dtp[k];
                j[TURBINE][c] = dtt[k];
            }
            j[FLOW] = [steady[0], steady[1], 0.0, -1.0];
            return j;
        }
        let (_, _, dtp, dtt) = table_torques(&self.characteristic, u[PUMP], u[TURBINE]);
        j[PUMP][PUMP] = -dtp[0];
        j[PUMP][TURBINE] = -dtp[1];
        j[TURBINE][PUMP] = dtt[0];
        j[TURBINE][TURBINE] = dtt[1];
        j
    }
    /// The power the table's torques absorb, `T_p,tr ω_p − T_t,tr ω_t` (≥ 0, with the lag too: its
    /// row is a lag, not a power balance, so it is left out).
    fn loss_power_w(&self, u: &Vec4, f: &Vec4) -> f64 {
        let mut g = *f;
        if self.lag.is_some() {
            g[FLOW] = 0.0;
        }
        -(u[0] * g[0] + u[1] * g[1] + u[2] * g[2] + u[3] * g[3])
    }
    /// The kinetic energy of pump and turbine (the lag stores none): the mass matrix without its
    /// fourth diagonal entry.
    fn energy_mass(&self) -> Option<Mat4> {
        let mut m = self.mass();
        m[FLOW][FLOW] = 0.0;
        Some(m)
    }
    fn steady_point(&self, wp: f64, wt: f64) -> CoreResult<SteadyPoint> {
        let tp = table_steady(&self.characteristic, wp, wt)?;
        let lagged = if self.lag.is_some() { tp } else { 0.0 };
        Ok(SteadyPoint { u: [wp, wt, 0.0, lagged], pump_torque_nm: tp })
    }
    fn lag_state(&self) -> bool {
        self.lag.is_some()
    }
}

// ---------------------------------------------------------------------------------------------
// Hrovat & Tobler

/// The Hrovat & Tobler model, eqs 2.12–2.25, in mass-matrix form:
///
/// ```text
///     M = [[I_p, 0, 0, ρS_p], [0, I_t, 0, ρS_t], [0, 0, I_s, ρS_s], [ρS_p, ρS_t, ρS_s, ρL_f/A]]
/// ```
///
/// Shape effects are signed as in eqs 2.16–2.18 (S = ∫R tan α dl). The fluid terms act on the
/// effective torques as `ρS_p Q̇` (pump) and `−ρS_t Q̇` (turbine): a positive S, as in thesis
/// chapter 4, lowers the effective TR while the flow builds up (docs/models.md).
///
/// Its parameters are private: the constants derived from them at [`HtDynamics::new`] (and the
/// checks made there) would not follow a change.
#[derive(Debug, Clone)]
pub struct HtDynamics {
    geometry: HtGeometry<f64>,
    inertia: Inertias,
    fluid_length_m: f64,
    /// Shape effects of pump, turbine and stator, m² (eqs 2.16–2.18).
    shape_effect_m2: [f64; 3],
    k: HtConst,
    /// The geometry's constants of the steady state (its six tangents computed once, not at every
    /// initial state).
    steady: HtConstants<f64>,
}

const SHAPE_KEYS: [&str; 3] =
    ["geometry.pump_shape_effect_m2", "geometry.turbine_shape_effect_m2", "geometry.stator_shape_effect_m2"];

/// Constants of eqs 2.12–2.25 for fast evaluation.
#[derive(Debug, Clone)]
struct HtConst {
    rho: f64,
    area: f64,
    r2: [f64; 3],
    /// R_x tan α_x at each exit.
    radius_tan: [f64; 3],
    /// Coefficients of q in the shock velocities (eqs 2.20–2.22).
    b: [f64; 3],
    c: [f64; 3],
    friction: f64,
    r: [f64; 3],
    /// The same quantities for reverse flow (Q < 0, [`ReverseConst`]).
    rev: ReverseConst,
}

/// Constants of the reverse-flow form (docs/models.md, "Reverse flow"): with Q < 0 the fluid
/// enters each element across its exit edge and leaves across its inlet edge, so the element x
/// receives from `src[x]` (pump ← turbine ← stator ← pump), leaves at the inlet radius (pump at
/// R_s, turbine at R_p, stator at R_t) with the inlet angle, and its entry shock compares the
/// inlet angle of `src[x]` with its own exit angle at its exit radius.
#[derive(Debug, Clone)]
struct ReverseConst {
    /// Square of the radius each element leaves across: `[R_s², R_p², R_t²]`.
    r2: [f64; 3],
    /// `R tan α` at the edge each element leaves across: `[R_s tan α_pp, R_p tan α_tt, R_t tan α_ss]`.
    radius_tan: [f64; 3],
    /// The element each one receives from: turbine, stator, pump.
    src: [usize; 3],
    /// The element each one delivers to (the inverse of `src`): stator, pump, turbine.
    dst: [usize; 3],
    /// Radius of each element's entry (its exit edge): `[R_p, R_t, R_s]`.
    r_entry: [f64; 3],
    /// Coefficients of q in the reverse shock velocities.
    b: [f64; 3],
    /// Friction coefficient `f (3 + Σ tan²α_in)` (the edges the fluid leaves across).
    friction: f64,
}

impl HtDynamics {
    /// Check the parameters and the positive definiteness of the mass matrix (docs/physics.md §4).
    /// An inadmissible shape effect is refused with the largest admissible magnitude.
    pub fn new(
        geometry: HtGeometry<f64>,
        inertia: Inertias,
        fluid_length_m: f64,
        shape_effect_m2: [f64; 3],
    ) -> CoreResult<Self> {
        if !(fluid_length_m.is_finite() && fluid_length_m > 0.0) {
            return Err(CoreError::new(
                "geometry.fluid_length_m",
                fluid_length_m,
                "a finite, positive fluid length in m",
            ));
        }
        for (k, s) in SHAPE_KEYS.iter().zip(shape_effect_m2) {
            if !s.is_finite() {
                return Err(CoreError::new(*k, s, "a finite shape effect in m²"));
            }
        }
        let (k, steady) = (Self::constants(&geometry), HtConstants::new(&geometry));
        let d = Self { k, steady, geometry, inertia, fluid_length_m, shape_effect_m2 };
        d.check_mass_matrix()?;
        Ok(d)
    }

    fn inertia_array(&self) -> [f64; 3] {
        [self.inertia.pump_kg_m2, self.inertia.turbine_kg_m2, self.inertia.stator_kg_m2]
    }

    /// `ρ L_f / A`, the fluid's own inertance.
    pub fn fluid_inertance(&self) -> f64 {
        inertance_kg_m4(&self.geometry, self.fluid_length_m)
    }

    /// The admissibility of the mass matrix with these parameters.
    pub fn mass_matrix_bound(&self) -> MassMatrixBound {
        MassMatrixBound::new(&self.geometry, &self.inertia, self.fluid_length_m, self.shape_effect_m2)
    }

    /// Largest admissible magnitude of each shape effect with the others as given (see
    /// [`MassMatrixBound::shape_effect_bounds`]).
    pub fn shape_effect_bounds(&self) -> [f64; 3] {
        self.mass_matrix_bound().shape_effect_bounds()
    }

    fn check_mass_matrix(&self) -> CoreResult<()> {
        let b = self.mass_matrix_bound();
        if b.margin_kg_m4() > 0.0 {
            return Ok(());
        }
        // blame the largest contribution
        let terms = b.shape_terms_kg_m4;
        let i = (0..3).max_by(|&a, &b| terms[a].total_cmp(&terms[b])).unwrap_or(0);
        let bound = b.shape_effect_bounds()[i];
        if !(bound.is_finite() && b.inertance_kg_m4.is_finite() && terms.iter().all(|t| t.is_finite())) {
            return Err(self.overflowing_parameter());
        }
        let (inertance, shape_terms) = (sig(b.inertance_kg_m4), sig(terms.iter().sum::<f64>()));
        let implausible_length =
            crate::plausibility::range("fluid_length_m").is_some_and(|r| !r.contains(self.fluid_length_m));
        if bound == 0.0 && implausible_length {
            // the other shape effects alone use up the ρL_f/A of an implausibly short fluid path (a
            // length in km typed as m): no value of this shape effect helps, a longer path does
            let shortest = terms.iter().sum::<f64>() * self.geometry.get(HtParam::FlowArea) / b.density_kg_m3;
            return Err(CoreError::new(
                "geometry.fluid_length_m",
                self.fluid_length_m,
                format!(
                    "a fluid length over {} m with these shape effects and inertias, so that the mass matrix is positive definite: ρL_f/A must exceed Σρ²S²/I, but ρL_f/A = {inertance} and Σρ²S²/I = {shape_terms} (docs/physics.md §4)",
                    sig(shortest)
                ),
            ));
        }
        if bound == 0.0 {
            // "|S| < 0 m²" would ask for a value none meets: the others alone use up ρL_f/A
            let equal = sig(b.equal_shape_effect_bound_m2());
            return Err(CoreError::new(
                SHAPE_KEYS[i],
                self.shape_effect_m2[i],
                format!(
                    "shape effects within the mass matrix's bound: the other shape effects alone already use up ρL_f/A = {inertance} (Σρ²S²/I = {shape_terms}), so no value of this one is admissible; with equal pump and turbine shape effects |S| < {equal} m² (docs/physics.md §4)"
                ),
            ));
        }
        let s = self.shape_effect_m2[i].abs();
        // at the bound six digits show the same number twice: say which side the value is on
        let shown =
            if sig(bound) == sig(s) { format!("{bound:e} (|S| = {s:e} is at or above it)") } else { sig(bound) };
        Err(CoreError::new(
            SHAPE_KEYS[i],
            self.shape_effect_m2[i],
            format!(
                "|S| < {shown} m² with the other parameters as given, so that the mass matrix is positive definite: ρL_f/A must exceed Σρ²S²/I, but ρL_f/A = {inertance} and Σρ²S²/I = {shape_terms} (docs/physics.md §4)"
            ),
        ))
    }

    /// The error of parameters whose mass-matrix bound is not finite (a NaN bound, "|S| < NaN",
    /// means the inputs were bad): it names the one farthest outside its plausible range.
    fn overflowing_parameter(&self) -> CoreError {
        let i = self.inertia_array();
        let candidates = [
            ("geometry.fluid_density_kg_m3", self.geometry.get(HtParam::FluidDensity), "fluid_density_kg_m3"),
            ("geometry.flow_area_m2", self.geometry.get(HtParam::FlowArea), "flow_area_m2"),
            ("geometry.fluid_length_m", self.fluid_length_m, "fluid_length_m"),
            ("inertia.pump_kg_m2", i[0], "inertia_kg_m2"),
            ("inertia.turbine_kg_m2", i[1], "inertia_kg_m2"),
            ("inertia.stator_kg_m2", i[2], "inertia_kg_m2"),
        ];
        let pairs: Vec<(f64, &str)> = candidates.iter().map(|&(_, v, q)| (v, q)).collect();
        let (field, value, _) = candidates[crate::plausibility::farthest_outside(&pairs).unwrap_or(0)];
        CoreError::new(
            field,
            value,
            "a value at which the mass matrix's bound on the shape effects is finite (these parameters overflow ρL_f/A or ρ²S²/I; see the plausible ranges)",
        )
    }

    fn constants(g: &HtGeometry<f64>) -> HtConst {
        use HtParam::*;
        let r = [g.get(PumpExitRadius), g.get(TurbineExitRadius), g.get(StatorExitRadius)];
        let t = [g.get(PumpExitAngle).tan(), g.get(TurbineExitAngle).tan(), g.get(StatorExitAngle).tan()];
        let ti = [g.get(PumpInletAngle).tan(), g.get(TurbineInletAngle).tan(), g.get(StatorInletAngle).tan()];
        HtConst {
            rho: g.get(FluidDensity),
            area: g.get(FlowArea),
            r2: r.map(|x| x * x),
            radius_tan: [r[0] * t[0], r[1] * t[1], r[2] * t[2]],
            // pump inlet from stator exit, turbine inlet from pump exit, stator inlet from turbine exit
            b: [t[2] - ti[0], t[0] - ti[1], t[1] - ti[2]],
            c: [g.get(PumpShockLoss), g.get(TurbineShockLoss), g.get(StatorShockLoss)],
            friction: g.get(FrictionLoss) * (3.0 + t[0] * t[0] + t[1] * t[1] + t[2] * t[2]),
            r,
            rev: ReverseConst {
                r2: [r[2] * r[2], r[0] * r[0], r[1] * r[1]],
                radius_tan: [r[2] * ti[0], r[0] * ti[1], r[1] * ti[2]],
                src: [1, 2, 0],
                dst: [2, 0, 1],
                r_entry: r,
                // pump entered from the turbine inlet, turbine from the stator inlet, stator from the pump inlet
                b: [ti[1] - t[0], ti[2] - t[1], ti[0] - t[2]],
                friction: g.get(FrictionLoss) * (3.0 + ti[0] * ti[0] + ti[1] * ti[1] + ti[2] * ti[2]),
            },
        }
    }

    /// `F(u)` of [`ConverterDynamics::forces`]: σ = +1 and σ = 0 (held) use the thesis's
    /// equations (the latter without the loss, which a held flow does not see); σ = −1 the
    /// reverse-flow form (`ReverseConst`). Inlined into both `forces` and `forces_many`.
    #[inline(always)]
    fn ht_forces(&self, u: &Vec4, sigma: f64) -> Vec4 {
        let k = &self.k;
        if sigma < 0.0 {
            return k.rev.forces(k, u);
        }
        let w = [u[PUMP], u[TURBINE], u[STATOR]];
        let flow = u[FLOW];
        let q = flow / k.area;
        // angular momentum per unit mass flow leaving each element
        let h: [f64; 3] = std::array::from_fn(|i| w[i] * k.r2[i] + k.radius_tan[i] * q);
        let head = k.r2[0] * w[0] * w[0] + k.r2[1] * w[1] * w[1] + k.r2[2] * w[2] * w[2]
            - k.r2[2] * w[0] * w[2]
            - k.r2[0] * w[1] * w[0]
            - k.r2[1] * w[2] * w[1];
        let a =
            [k.radius_tan[0] - k.radius_tan[2], k.radius_tan[1] - k.radius_tan[0], k.radius_tan[2] - k.radius_tan[1]];
        let linear = q * (w[0] * a[0] + w[1] * a[1] + w[2] * a[2]);
        let v = shock_velocities(k, &w, q);
        let loss =
            sigma * 0.5 * (k.c[0] * v[0] * v[0] + k.c[1] * v[1] * v[1] + k.c[2] * v[2] * v[2] + k.friction * q * q);
        [
            -k.rho * (h[0] - h[2]) * flow,
            -k.rho * (h[1] - h[0]) * flow,
            -k.rho * (h[2] - h[1]) * flow,
            k.rho * (head + linear - loss),
        ]
    }
}

/// The admissibility bound of the Hrovat & Tobler mass matrix on the shape effects (physics notes
/// §4): `M` is positive definite iff `ρL_f/A > Σ ρ²S_x²/I_x` (the Schur complement of the diagonal
/// inertias). Computed for any parameters, admissible or not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassMatrixBound {
    /// Fluid density ρ, kg/m³.
    pub density_kg_m3: f64,
    /// Pump, turbine and stator inertias `I_x`, kg·m².
    pub inertia_kg_m2: [f64; 3],
    /// `ρ L_f / A`, the fluid's own inertance, kg/m⁴.
    pub inertance_kg_m4: f64,
    /// `ρ² S_x² / I_x` for pump, turbine and stator, kg/m⁴.
    pub shape_terms_kg_m4: [f64; 3],
}

impl MassMatrixBound {
    pub fn new(geometry: &HtGeometry<f64>, inertia: &Inertias, fluid_length_m: f64, shape_effect_m2: [f64; 3]) -> Self {
        let rho = geometry.get(HtParam::FluidDensity);
        let inertia = [inertia.pump_kg_m2, inertia.turbine_kg_m2, inertia.stator_kg_m2];
        MassMatrixBound {
            density_kg_m3: rho,
            inertia_kg_m2: inertia,
            inertance_kg_m4: inertance_kg_m4(geometry, fluid_length_m),
            shape_terms_kg_m4: std::array::from_fn(|i| rho * rho * shape_effect_m2[i].powi(2) / inertia[i]),
        }
    }

    /// `ρL_f/A − Σ ρ²S_x²/I_x`, kg/m⁴: the mass matrix is admissible iff this is positive.
    pub fn margin_kg_m4(&self) -> f64 {
        self.inertance_kg_m4 - self.shape_terms_kg_m4.iter().sum::<f64>()
    }

    /// `ρL_f/A − ρ²S_s²/I_s`, kg/m⁴: the inertance left for the pump and turbine shape effects with the
    /// stator's as given (what a fit or a sweep of `S_p`, `S_t` may use).
    pub fn pump_turbine_room_kg_m4(&self) -> f64 {
        self.inertance_kg_m4 - self.shape_terms_kg_m4[2]
    }

    /// Largest admissible `|S|` with `S_p = S_t = S` and the stator's as given, m²:
    /// `√(room / (ρ²/I_p + ρ²/I_t))` (0 when no room is left).
    pub fn equal_shape_effect_bound_m2(&self) -> f64 {
        let (rho, inertia) = (self.density_kg_m3, self.inertia_kg_m2);
        let unit_load = rho * rho * 1.0f64.powi(2) / inertia[0] + rho * rho * 1.0f64.powi(2) / inertia[1];
        (self.pump_turbine_room_kg_m4().max(0.0) / unit_load).sqrt()
    }

    /// Largest admissible magnitude of each shape effect with the others as given, m² (0 when the
    /// others already use up the inertance).
    pub fn shape_effect_bounds(&self) -> [f64; 3] {
        let (rho, inertia, terms) = (self.density_kg_m3, self.inertia_kg_m2, self.shape_terms_kg_m4);
        std::array::from_fn(|i| {
            let room = self.inertance_kg_m4 - (terms.iter().sum::<f64>() - terms[i]);
            if room <= 0.0 {
                0.0
            } else {
                (room * inertia[i]).sqrt() / rho
            }
        })
    }
}

/// Shock velocities of eqs 2.20–2.22 at speeds ω and q = Q/A.
/// `ρ L_f / A`, kg/m⁴: the fluid's own inertance (the mass matrix's flow diagonal, eq. 2.14).
fn inertance_kg_m4(geometry: &HtGeometry<f64>, fluid_length_m: f64) -> f64 {
    geometry.get(HtParam::FluidDensity) * fluid_length_m / geometry.get(HtParam::FlowArea)
}

fn shock_velocities(k: &HtConst, w: &[f64; 3], q: f64) -> [f64; 3] {
    [k.r[2] * (w[2] - w[0]) + q * k.b[0], k.r[0] * (w[0] - w[1]) + q * k.b[1], k.r[1] * (w[1] - w[2]) + q * k.b[2]]
}

impl ReverseConst {
    /// Reverse shock velocities at the entry of pump, turbine and stator (each at its exit radius):
    /// `V_p = R_p(ω_t − ω_p) + q(tan α_tt − tan α_p)`, `V_t = R_t(ω_s − ω_t) + q(tan α_ss − tan α_t)`,
    /// `V_s = R_s(ω_p − ω_s) + q(tan α_pp − tan α_s)`.
    fn shock_velocities(&self, w: &[f64; 3], q: f64) -> [f64; 3] {
        std::array::from_fn(|x| self.r_entry[x] * (w[self.src[x]] - w[x]) + q * self.b[x])
    }

    /// Angular momentum per unit mass leaving each element across its inlet edge.
    fn h(&self, w: &[f64; 3], q: f64) -> [f64; 3] {
        std::array::from_fn(|x| w[x] * self.r2[x] + self.radius_tan[x] * q)
    }

    /// Reverse-flow forces: `F_x = ρQ(h_x − h_src(x))` (external torque ρ|Q|(h out − h in)), and
    /// `F_Q = ρ(head − σ loss)` with σ = −1 and `head = Σ ω_x (h_src(x) − h_x)`, the work per unit
    /// volume the blades do on the fluid, so that `ω·F + Q F_Q = −ρ|Q| loss`.
    fn forces(&self, k: &HtConst, u: &Vec4) -> Vec4 {
        let w = [u[PUMP], u[TURBINE], u[STATOR]];
        let (flow, q) = (u[FLOW], u[FLOW] / k.area);
        let h = self.h(&w, q);
        let head: f64 = (0..3).map(|x| w[x] * (h[self.src[x]] - h[x])).sum();
        let v = self.shock_velocities(&w, q);
        let loss = 0.5 * (k.c[0] * v[0] * v[0] + k.c[1] * v[1] * v[1] + k.c[2] * v[2] * v[2] + self.friction * q * q);
        [
            k.rho * (h[0] - h[self.src[0]]) * flow,
            k.rho * (h[1] - h[self.src[1]]) * flow,
            k.rho * (h[2] - h[self.src[2]]) * flow,
            k.rho * (head + loss),
        ]
    }

    /// `∂F/∂u` of [`ReverseConst::forces`].
    fn force_jacobian(&self, k: &HtConst, u: &Vec4) -> Mat4 {
        let (rho, area) = (k.rho, k.area);
        let w = [u[PUMP], u[TURBINE], u[STATOR]];
        let (flow, q) = (u[FLOW], u[FLOW] / area);
        let h = self.h(&w, q);
        let v = self.shock_velocities(&w, q);
        let mut j = [[0.0; 4]; 4];
        for x in 0..3 {
            let (s, d) = (self.src[x], self.dst[x]);
            j[x][x] += rho * self.r2[x] * flow;
            j[x][s] -= rho * self.r2[s] * flow;
            j[x][FLOW] = rho * (h[x] - h[s]) + rho * flow * (self.radius_tan[x] - self.radius_tan[s]) / area;
            // head: ∂/∂ω_x of Σ ω_y (h_src(y) − h_y), where x is the source of d
            let dhead = h[s] - h[x] + self.r2[x] * (w[d] - w[x]);
            // loss: V_x holds −ω_x, V_d holds +ω_x
            let dloss = k.c[d] * v[d] * self.r_entry[d] - k.c[x] * v[x] * self.r_entry[x];
            j[FLOW][x] = rho * (dhead + dloss);
        }
        let dhead_dq: f64 = (0..3).map(|x| w[x] * (self.radius_tan[self.src[x]] - self.radius_tan[x])).sum();
        let dloss_dq =
            k.c[0] * v[0] * self.b[0] + k.c[1] * v[1] * self.b[1] + k.c[2] * v[2] * self.b[2] + self.friction * q;
        j[FLOW][FLOW] = rho * (dhead_dq + dloss_dq) / area;
        j
    }
}

impl ConverterDynamics for HtDynamics {
    fn coordinates(&self) -> [bool; 4] {
        [true; 4]
    }
    fn has_stator_clutch(&self) -> bool {
        true
    }
    fn has_flow_sign(&self) -> bool {
        true
    }
    fn mass(&self) -> Mat4 {
        let rho = self.geometry.get(HtParam::FluidDensity);
        let inertia = self.inertia_array();
        let mut m = [[0.0; 4]; 4];
        for i in 0..3 {
            m[i][i] = inertia[i];
            m[i][FLOW] = rho * self.shape_effect_m2[i];
            m[FLOW][i] = rho * self.shape_effect_m2[i];
        }
        m[FLOW][FLOW] = self.fluid_inertance();
        m
    }
    fn forces(&self, u: &Vec4, sigma: f64) -> Vec4 {
        self.ht_forces(u, sigma)
    }
    fn forces_many(&self, u: &[Vec4], sigma: f64, out: &mut [Vec4]) {
        for (o, u) in out.iter_mut().zip(u) {
            *o = self.ht_forces(u, sigma);
        }
    }
    fn force_jacobian(&self, u: &Vec4, sigma: f64) -> Mat4 {
        let k = &self.k;
        if sigma < 0.0 {
            return k.rev.force_jacobian(k, u);
        }
        let (rho, area) = (k.rho, k.area);
        let w = [u[PUMP], u[TURBINE], u[STATOR]];
        let flow = u[FLOW];
        let q = flow / area;
        let h: [f64; 3] = std::array::from_fn(|i| w[i] * k.r2[i] + k.radius_tan[i] * q);
        let a =
            [k.radius_tan[0] - k.radius_tan[2], k.radius_tan[1] - k.radius_tan[0], k.radius_tan[2] - k.radius_tan[1]];
        let v = shock_velocities(k, &w, q);
        let mut j = [[0.0; 4]; 4];
        // torques: F_i = −ρ (h_i − h_prev(i)) Q with prev = stator, pump, turbine
        let prev = [2usize, 0, 1];
        for i in 0..3 {
            let p = prev[i];
            j[i][i] = -rho * k.r2[i] * flow;
            j[i][p] = rho * k.r2[p] * flow;
            j[i][FLOW] = -rho * (h[i] - h[p]) - rho * flow * (k.radius_tan[i] - k.radius_tan[p]) / area;
        }
        // head of eq 2.15
        let dhead = [
            2.0 * k.r2[0] * w[0] - k.r2[2] * w[2] - k.r2[0] * w[1],
            2.0 * k.r2[1] * w[1] - k.r2[0] * w[0] - k.r2[1] * w[2],
            2.0 * k.r2[2] * w[2] - k.r2[2] * w[0] - k.r2[1] * w[1],
        ];
        // ∂V/∂ω: V_p = R_s(ω_s − ω_p) + …, V_t = R_p(ω_p − ω_t) + …, V_s = R_t(ω_t − ω_s) + …
        let dloss = [
            sigma * (-k.c[0] * v[0] * k.r[2] + k.c[1] * v[1] * k.r[0]),
            sigma * (-k.c[1] * v[1] * k.r[0] + k.c[2] * v[2] * k.r[1]),
            sigma * (k.c[0] * v[0] * k.r[2] - k.c[2] * v[2] * k.r[1]),
        ];
        for i in 0..3 {
            j[FLOW][i] = rho * (dhead[i] + q * a[i] - dloss[i]);
        }
        let dloss_dq =
            sigma * (k.c[0] * v[0] * k.b[0] + k.c[1] * v[1] * k.b[1] + k.c[2] * v[2] * k.b[2] + k.friction * q);
        j[FLOW][FLOW] = rho * ((w[0] * a[0] + w[1] * a[1] + w[2] * a[2]) - dloss_dq) / area;
        j
    }
    fn steady_point(&self, wp: f64, wt: f64) -> CoreResult<SteadyPoint> {
        let s = steady_state_with(&self.steady, wp, wt)?;
        Ok(SteadyPoint { u: [wp, wt, s.stator_speed_rad_s, s.flow_m3_s], pump_torque_nm: s.pump_torque_nm })
    }
    fn zero_flow_head(&self, u: &Vec4) -> (f64, f64) {
        let mut at_zero = *u;
        at_zero[FLOW] = 0.0;
        (self.forces(&at_zero, 1.0)[FLOW], self.forces(&at_zero, -1.0)[FLOW])
    }
}

impl<T: ConverterDynamics + ?Sized> ConverterDynamics for Box<T> {
    fn coordinates(&self) -> [bool; 4] {
        (**self).coordinates()
    }
    fn mass(&self) -> Mat4 {
        (**self).mass()
    }
    fn forces(&self, u: &Vec4, s: f64) -> Vec4 {
        (**self).forces(u, s)
    }
    fn forces_many(&self, u: &[Vec4], s: f64, out: &mut [Vec4]) {
        (**self).forces_many(u, s, out)
    }
    fn force_jacobian(&self, u: &Vec4, s: f64) -> Mat4 {
        (**self).force_jacobian(u, s)
    }
    fn transferred(&self, f: &Vec4) -> (f64, f64) {
        (**self).transferred(f)
    }
    fn loss_power_w(&self, u: &Vec4, f: &Vec4) -> f64 {
        (**self).loss_power_w(u, f)
    }
    fn stored_energy_j(&self, u: &Vec4) -> f64 {
        (**self).stored_energy_j(u)
    }
    fn energy_mass(&self) -> Option<Mat4> {
        (**self).energy_mass()
    }
    fn steady_point(&self, wp: f64, wt: f64) -> CoreResult<SteadyPoint> {
        (**self).steady_point(wp, wt)
    }
    fn has_stator_clutch(&self) -> bool {
        (**self).has_stator_clutch()
    }
    fn has_flow_sign(&self) -> bool {
        (**self).has_flow_sign()
    }
    fn zero_flow_head(&self, u: &Vec4) -> (f64, f64) {
        (**self).zero_flow_head(u)
    }
    fn lag_state(&self) -> bool {
        (**self).lag_state()
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::converter::hrovat_tobler::steady_state;
    use crate::converter::quasi_dynamic::QuasiDynamics;
    use crate::converter::table::Characteristic;

    /// A torque-dependent pair: C.1 at 100 N·m, C.1 with CF +20 % and TR nearer 1 at 300 N·m.
    fn torque_pair() -> TorqueCharacteristic {
        let heavier = Characteristic::new(
            c1().speed_ratio().to_vec(),
            c1().torque_ratio().iter().map(|t| 1.0 + 0.8 * (t - 1.0)).collect(),
            c1().capacity_factor_nm_s2().iter().map(|c| 1.2 * c).collect(),
        )
        .unwrap();
        TorqueCharacteristic::new(vec![100.0, 300.0], vec![c1(), heavier]).unwrap()
    }

    /// A table with coast rows (JAMBE-like, the `table` overrun rule).
    fn coast_table() -> Characteristic {
        Characteristic::new(
            vec![-0.1, 0.0, 0.5, 0.9, 1.0, 1.5, 2.1],
            vec![1.81, 1.81, 1.36, 1.0, 1.0, 1.0, 1.0],
            vec![3.5e-3, 3.5e-3, 3.9e-3, 2.7e-3, 0.0, -1.5e-3, -2.4e-3],
        )
        .unwrap()
    }

    /// Li & Sundén (2016) Table C.1, CF in N·m/(rad/s)² (the core's unit tests' table).
    pub(crate) fn c1() -> Characteristic {
        Characteristic::new(
            vec![0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0],
            vec![2.14, 1.99, 1.84, 1.70, 1.56, 1.43, 1.30, 1.18, 1.06, 1.00, 1.00, 1.00, 1.00],
            vec![
                3.272e-3, 3.257e-3, 3.228e-3, 3.181e-3, 3.112e-3, 3.017e-3, 2.887e-3, 2.713e-3, 2.481e-3, 2.370e-3,
                1.842e-3, 1.237e-3, 0.187e-3,
            ],
        )
        .unwrap()
    }

    fn inertia() -> Inertias {
        Inertias::new(0.109, 0.056, 0.01).unwrap()
    }

    fn ht(shape: [f64; 3]) -> HtDynamics {
        HtDynamics::new(HtGeometry::appendix_d(), inertia(), 0.2914, shape).unwrap()
    }

    /// The bundled `li-sunden-2016` converter's Hrovat & Tobler model (Table D.1, its derived
    /// fluid length and shape effects): the engine's tests' take-off model.
    pub(crate) fn bundled_ht() -> HtDynamics {
        ht([0.001310, 0.002324, 0.001723])
    }

    #[test]
    fn the_steady_point_is_the_steady_state_of_the_geometry_bit_for_bit() {
        // the model keeps its geometry's steady-state constants (computed once): its steady point
        // must be `steady_state` of its geometry, every sign of the speeds, failures alike
        let m = bundled_ht();
        for wp in [0.0, 1e-3, 50.0, 209.4, 400.0, -150.0, 1e5] {
            for sr in [0.0, 0.3, 0.87, 1.0, 1.4, -0.5] {
                let (point, state) = (m.steady_point(wp, sr * wp), steady_state(&m.geometry, wp, sr * wp));
                match (point, state) {
                    (Ok(p), Ok(s)) => {
                        let want = [wp, sr * wp, s.stator_speed_rad_s, s.flow_m3_s, s.pump_torque_nm];
                        let got = [p.u[0], p.u[1], p.u[2], p.u[3], p.pump_torque_nm];
                        assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{wp} rad/s, SR {sr}");
                    }
                    (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                    (a, b) => panic!("{wp} rad/s, SR {sr}: {a:?} against {b:?}"),
                }
            }
        }
    }

    fn qd() -> QuasiDynamics {
        qd_with(c1().into())
    }

    fn qd_with(characteristic: TorqueCharacteristic) -> QuasiDynamics {
        QuasiDynamics::new(characteristic, inertia(), 840.0, 0.12, [0.006, 0.002], 0.05).unwrap()
    }

    fn check_jacobian(m: &dyn ConverterDynamics, u: Vec4, sigma: f64) {
        let j = m.force_jacobian(&u, sigma);
        let present = m.coordinates();
        for c in (0..4).filter(|&c| present[c]) {
            let h = 1e-6 * u[c].abs().max(if c == FLOW { 1e-3 } else { 1.0 });
            let (mut up, mut dn) = (u, u);
            up[c] += h;
            dn[c] -= h;
            let (fp, fm) = (m.forces(&up, sigma), m.forces(&dn, sigma));
            for r in (0..4).filter(|&r| present[r]) {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                let scale = m.forces(&u, sigma).iter().map(|x| x.abs()).fold(1e-3, f64::max) / u[c].abs().max(1e-6);
                assert!(
                    (fd - j[r][c]).abs() <= 1e-6 * scale + 1e-6 * fd.abs(),
                    "row {r} col {c} sigma {sigma}: analytic {} fd {fd}",
                    j[r][c]
                );
            }
        }
    }

    #[test]
    fn forces_of_many_points_are_the_forces_of_each_bit_for_bit() {
        // the engine samples through `forces_many` (H&T's own loop, the others' default): every
        // quadrant, every flow sign, zero and huge values, a NaN that must stay in its own point
        let table = TableDynamics { characteristic: c1().into(), inertia: inertia(), lag: None };
        let (ht, qd, lagged, boxed) = (bundled_ht(), qd(), lagged(c1(), 0.05), Box::new(qd()));
        let models: [&dyn ConverterDynamics; 5] = [&ht, &qd, &table, &lagged, &boxed];
        let mut points: Vec<Vec4> =
            vec![[0.0; 4], [-0.0, 0.0, -0.0, 0.0], [1e12, -1e12, 1e6, -1.0], [f64::NAN, 1.0, 0.0, 0.01]];
        for (i, wp) in [-300.0, -20.0, 0.0, 150.0, 400.0].into_iter().enumerate() {
            for wt in [-200.0, 0.0, 90.0, 500.0] {
                points.push([wp, wt, 0.3 * wt - 0.1 * wp, 0.004 * (i as f64 - 2.0)]);
            }
        }
        for m in models {
            for sigma in [1.0, 0.0, -1.0] {
                let mut many = vec![[0.0; 4]; points.len()];
                m.forces_many(&points, sigma, &mut many);
                for (u, f) in points.iter().zip(&many) {
                    let one = m.forces(u, sigma);
                    assert!(
                        one.iter().zip(f).all(|(a, b)| a.to_bits() == b.to_bits()),
                        "{u:?} σ {sigma}: {one:?} vs {f:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_non_finite_shape_effect_bound_names_the_parameter() {
        let g = HtGeometry::appendix_d();
        let tiny = Inertias::new(1e-310, 0.05, 0.02).unwrap();
        let e = HtDynamics::new(g, tiny, 0.3, [0.01, 0.001, 0.001]).unwrap_err();
        assert_eq!(e.field, "inertia.pump_kg_m2", "{e}");
        assert!(!e.expected.contains("NaN"), "{e}");
    }

    #[test]
    fn shape_effects_beyond_the_bound_together_ask_for_a_value_that_exists() {
        // a trial: S_p = S_t = 0.5 m² was refused with "expected |S| < 0 m²", a bound no value meets
        let inertia = Inertias::new(0.109, 0.056, 0.01).unwrap();
        let e = HtDynamics::new(HtGeometry::appendix_d(), inertia, 0.2914, [0.5, 0.5, 0.001723]).unwrap_err();
        assert!(!e.expected.contains("|S| < 0 m²"), "{e}");
        assert!(e.expected.contains("no value of this one is admissible"), "{e}");
        let ok = HtDynamics::new(HtGeometry::appendix_d(), inertia, 0.2914, [0.001, 0.001, 0.001723]).unwrap();
        let equal = ok.mass_matrix_bound().equal_shape_effect_bound_m2();
        assert!(e.expected.contains(&format!("|S| < {} m²", sig(equal))), "{e}");
        // just inside the equal bound the model is accepted, just outside refused
        assert!(HtDynamics::new(HtGeometry::appendix_d(), inertia, 0.2914, [0.999 * equal, 0.999 * equal, 0.001723])
            .is_ok());
        assert!(HtDynamics::new(HtGeometry::appendix_d(), inertia, 0.2914, [1.001 * equal, 1.001 * equal, 0.001723])
            .is_err());
    }

    #[test]
    fn analytic_jacobians_match_finite_differences() {
        let h = ht([-0.00569, 0.00134, 0.0009]);
        for u in [
            [200.0, 0.0, 0.0, 0.12],
            [210.0, 150.0, 20.0, 0.05],
            [150.0, 170.0, 60.0, -0.03],
            [100.0, 40.0, 0.0, 0.0],
            [200.0, 400.0, 0.0, -0.1],
            [-120.0, 30.0, 5.0, -0.02],
            [-80.0, -200.0, 15.0, -0.2],
            [60.0, -90.0, 0.0, 0.07],
        ] {
            for sigma in [1.0, -1.0, 0.0] {
                check_jacobian(&h, u, sigma);
            }
        }
        // points inside table segments (the table is piecewise linear)
        for u in [[200.0, 33.0, 0.0, 0.1], [210.0, 170.0, 0.0, 0.05], [150.0, 160.0, 0.0, 0.02]] {
            check_jacobian(&TableDynamics { characteristic: c1().into(), inertia: inertia(), lag: None }, u, 1.0);
            check_jacobian(&qd(), u, 1.0);
        }
    }

    #[test]
    fn table_jacobians_match_finite_differences_in_every_quadrant() {
        // a coast-row table (JAMBE-like: the `table` overrun rule) and Table C.1 (the mirror),
        // in CF and in K interpolation
        let coast = coast_table();
        // and a torque-dependent pair (C.1 at 100 N·m, C.1 with CF +20 % and TR nearer 1 at 300 N·m):
        // the solved input torque's gradient enters the Jacobian
        let pair = torque_pair();
        let tables: [TorqueCharacteristic; 4] =
            [c1().into(), c1().with_rules(None, Some("k_factor")).unwrap().into(), coast.into(), pair];
        let points = [
            [200.0, 90.0],   // drive
            [200.0, -60.0],  // roll-back, SR in [−1, 0]
            [100.0, -310.0], // roll-back beyond SR −1
            [-90.0, 270.0],  // reversed pump, turbine forward
            [-200.0, -70.0], // both reversed
            [150.0, 410.0],  // overrun, mirror on the table's rows / the table rule
            [288.0, 300.0],  // overrun on the mirror's last segment (x = 0.96)
            [200.0, 290.0],  // coast rows (SR 1.45)
            [100.0, 340.0],  // beyond the coast rows
            [-130.0, -370.0],
        ];
        for t in tables {
            let table = TableDynamics { characteristic: t.clone(), inertia: inertia(), lag: None };
            let q = qd_with(t.clone());
            for [wp, wt] in points {
                check_jacobian(&table, [wp, wt, 0.0, 0.0], 1.0);
                check_jacobian(&q, [wp, wt, 0.0, 0.01], 1.0);
            }
        }
    }

    fn lagged(t: Characteristic, tc: f64) -> TableDynamics {
        TableDynamics { characteristic: t.into(), inertia: inertia(), lag: Some(TorqueLag::new(tc).unwrap()) }
    }

    /// The lag's Jacobian, with the passivity rule inactive (drive) and active (a lagged torque of
    /// the wrong sign for the speeds), in every quadrant.
    #[test]
    fn lagged_table_jacobian_matches_finite_differences() {
        let m = lagged(c1(), 0.05);
        for [wp, wt] in [[200.0, 90.0], [200.0, -60.0], [-90.0, 270.0], [-200.0, -70.0], [150.0, 410.0], [0.5, 330.0]] {
            let tss = c1().torques(wp, wt).pump_nm;
            for z in [tss, 0.5 * tss, -tss - 30.0, 40.0, -40.0] {
                check_jacobian(&m, [wp, wt, 0.0, z], 1.0);
            }
        }
    }

    /// The lag on a torque-dependent characteristic (two tables, the input torque solved): the
    /// mixed tables' torque-ratio gradient carries into the lag's Jacobian, and where the lag state
    /// is the steady pump torque the lagged torques are the mixed table's.
    #[test]
    fn lagged_torque_dependent_table_jacobian_matches_finite_differences() {
        let pair = torque_pair();
        let m = TableDynamics { characteristic: pair.clone(), inertia: inertia(), lag: TorqueLag::new(0.05).ok() };
        let mut mixed = 0;
        let points = [[250.0, 90.0], [200.0, 150.0], [300.0, 57.0], [180.0, 100.0], [-200.0, -70.0], [150.0, 410.0]];
        for [wp, wt] in points {
            let t = pair.torques(wp, wt);
            let (a, b) = (pair.tables()[0].torques(wp, wt).torque_ratio, pair.tables()[1].torques(wp, wt).torque_ratio);
            mixed += usize::from((t.torque_ratio - a).abs() > 1e-9 && (t.torque_ratio - b).abs() > 1e-9);
            let f = m.forces(&[wp, wt, 0.0, t.pump_nm], 1.0);
            assert_eq!((-f[PUMP], f[TURBINE], f[FLOW]), (t.pump_nm, t.torque_ratio * t.pump_nm, 0.0));
            for z in [t.pump_nm, 0.5 * t.pump_nm, -t.pump_nm - 30.0] {
                check_jacobian(&m, [wp, wt, 0.0, z], 1.0);
            }
        }
        assert!(mixed >= 2, "only {mixed} points between the tables");
    }

    /// Passivity of the lag: for random speeds and lagged torques the absorbed power is ≥ 0, the
    /// loss power is that absorbed power, and where the candidate pair is passive it is unchanged
    /// (the Simscape form `T_t = TR·T_lag`).
    #[test]
    fn lagged_table_is_passive_at_any_state() {
        let coast = coast_table();
        let mut seed = 12345u64;
        let mut rnd = |lo: f64, hi: f64| {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
        };
        let (mut projected, mut unchanged) = (0, 0);
        for t in [c1(), coast] {
            let m = lagged(t.clone(), 0.1);
            for _ in 0..20000 {
                let (wp, wt, z) = (rnd(-400.0, 400.0), rnd(-400.0, 400.0), rnd(-300.0, 300.0));
                let u = [wp, wt, 0.0, z];
                let f = m.forces(&u, 1.0);
                let absorbed = -f[PUMP] * wp - f[TURBINE] * wt;
                let scale = (z.abs() + 1.0) * (wp.abs() + wt.abs() + 1.0);
                assert!(absorbed >= -1e-12 * scale, "{u:?}: absorbed {absorbed}");
                assert_eq!(m.loss_power_w(&u, &f), absorbed);
                let tq = t.torques(wp, wt);
                assert_eq!(f[FLOW], tq.pump_nm - z);
                if z * wp - tq.torque_ratio * z * wt >= 0.0 {
                    assert_eq!((-f[PUMP], f[TURBINE]), (z, tq.torque_ratio * z));
                    unchanged += 1;
                } else {
                    assert!(absorbed.abs() <= 1e-12 * scale, "{u:?}: projected onto P = 0, {absorbed}");
                    projected += 1;
                }
            }
        }
        assert!(projected > 1000 && unchanged > 1000, "{projected} projected, {unchanged} unchanged");
    }

    /// With the lag state at its steady value the lagged model is the table; the lag stores no
    /// energy; no lag is the old model exactly.
    #[test]
    fn lagged_table_steady_state_is_the_table() {
        let m = lagged(c1(), 0.2);
        let plain = TableDynamics { characteristic: c1().into(), inertia: inertia(), lag: None };
        for (wp, wt) in [(200.0, 100.0), (200.0, 400.0), (0.0, 300.0), (-150.0, 40.0), (100.0, -350.0)] {
            let p = m.steady_point(wp, wt).unwrap();
            assert_eq!(p.u[FLOW], p.pump_torque_nm);
            let (f, g) = (m.forces(&p.u, 1.0), plain.forces(&[wp, wt, 0.0, 0.0], 1.0));
            assert_eq!(f[FLOW], 0.0);
            assert_eq!((f[PUMP], f[TURBINE]), (g[PUMP], g[TURBINE]), "({wp}, {wt})");
            assert_eq!(m.stored_energy_j(&p.u), plain.stored_energy_j(&[wp, wt, 0.0, 0.0]));
            assert_eq!(plain.steady_point(wp, wt).unwrap().u[FLOW], 0.0);
        }
        assert_eq!(m.mass()[FLOW][FLOW], 0.2);
        assert!(m.lag_state() && !plain.lag_state() && plain.mass()[FLOW][FLOW] == 0.0);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(TorqueLag::new(bad).unwrap_err().field, "characteristic.lag_time_constant_s");
        }
    }

    #[test]
    fn quasi_dynamic_steady_state_is_the_table_in_every_quadrant() {
        let q = qd();
        for (wp, wt) in [(200.0, 100.0), (200.0, 400.0), (0.0, 300.0), (-150.0, 40.0), (100.0, -350.0), (-80.0, -90.0)]
        {
            let (tp, tt, _, _) = table_torques(&c1().into(), wp, wt); // qd()'s table
            let u = q.steady_point(wp, wt).unwrap().u;
            let f = q.forces(&u, 1.0);
            assert!(f[FLOW].abs() <= 1e-12 * u[FLOW].abs().max(1e-9), "Q̇ = {} at ({wp}, {wt})", f[FLOW]);
            assert_eq!((-f[PUMP], f[TURBINE]), (tp, tt));
            // the steady flow reverses in overrun (the turbine drives the fluid)
            if wt.abs() > wp.abs() {
                assert!(u[FLOW] < 0.0, "Q_ss = {} at ({wp}, {wt})", u[FLOW]);
            }
        }
    }

    /// The quasi-dynamic model's energy bookkeeping: with any external torques, the power they put
    /// in is the rate of change of the stored (kinetic) energy plus the loss power, the fluid terms
    /// `ρQ̇(S_p ω_p + S_t ω_t)` included (before issue 11 they were left out: 133 J over the isolated
    /// tip-out).
    #[test]
    fn qd_loss_and_stored_energy_close_the_power_balance() {
        let m = qd();
        let (ip, it) = (inertia().pump_kg_m2, inertia().turbine_kg_m2); // qd()'s inertias
        for u in [[200.0, 50.0, 0.0, 0.03], [150.0, 260.0, 0.0, -0.01], [-80.0, 120.0, 0.0, 0.02]] {
            let (f, mass) = (m.forces(&u, 1.0), m.mass());
            let t_ext = [35.0, -20.0];
            // M u̇ = F + T_ext: the flow row is the unit row, then the speed rows
            let q_dot = f[FLOW];
            let wp_dot = (f[PUMP] + t_ext[0] - mass[PUMP][FLOW] * q_dot) / ip;
            let wt_dot = (f[TURBINE] + t_ext[1] - mass[TURBINE][FLOW] * q_dot) / it;
            let stored_rate = ip * u[PUMP] * wp_dot + it * u[TURBINE] * wt_dot;
            let input = t_ext[0] * u[PUMP] + t_ext[1] * u[TURBINE];
            let loss = m.loss_power_w(&u, &f);
            assert!((input - stored_rate - loss).abs() < 1e-9 * (input.abs() + loss.abs()), "{u:?}");
            let kinetic = 0.5 * (ip * u[PUMP] * u[PUMP] + it * u[TURBINE] * u[TURBINE]);
            assert!((m.stored_energy_j(&u) - kinetic).abs() <= 1e-12 * kinetic);
        }
    }

    #[test]
    fn ht_flow_terms_cancel_in_the_power_balance() {
        // ω·F = −Q·P_loss with P_loss from eq 2.19 written out directly (Q > 0)
        let h = ht([0.0; 3]);
        let g = &h.geometry;
        use HtParam::*;
        let u = [210.0, 150.0, 20.0, 0.05];
        let q = u[3] / g.get(FlowArea);
        let t = |p| g.get(p).tan();
        let vp = g.get(StatorExitRadius) * (u[2] - u[0]) + q * (t(StatorExitAngle) - t(PumpInletAngle));
        let vt = g.get(PumpExitRadius) * (u[0] - u[1]) + q * (t(PumpExitAngle) - t(TurbineInletAngle));
        let vs = g.get(TurbineExitRadius) * (u[1] - u[2]) + q * (t(TurbineExitAngle) - t(StatorInletAngle));
        let rho = g.get(FluidDensity);
        let vre2: f64 =
            [PumpExitAngle, TurbineExitAngle, StatorExitAngle].iter().map(|&a| q * q * (1.0 + t(a).powi(2))).sum();
        let ploss = rho / 2.0 * (vp * vp + vt * vt + vs * vs) + rho * g.get(FrictionLoss) / 2.0 * vre2;
        let lp = h.loss_power_w(&u, &h.forces(&u, 1.0));
        assert!((lp - u[3] * ploss).abs() <= 1e-10 * lp.abs(), "{lp} vs {}", u[3] * ploss);
        assert!(lp > 0.0);
    }

    /// The reverse-flow form written out by hand (docs/models.md, "Reverse flow"): torques from the
    /// angular momentum leaving across the inlet edges, the reverse shock velocities, friction with
    /// the inlet angles; ω·F = −|Q|·P_loss in every quadrant of the speeds.
    #[test]
    fn ht_reverse_flow_terms_cancel_in_the_power_balance() {
        let h = ht([0.0; 3]);
        let g = &h.geometry;
        use HtParam::*;
        let t = |p| g.get(p).tan();
        let (rp, rt, rs) = (g.get(PumpExitRadius), g.get(TurbineExitRadius), g.get(StatorExitRadius));
        let rho = g.get(FluidDensity);
        for u in [
            [150.0, 170.0, 60.0, -0.03],
            [200.0, 400.0, 0.0, -0.1],
            [-120.0, 30.0, 0.0, -0.02],
            [-80.0, -200.0, 15.0, -0.2],
            [0.0, 300.0, 0.0, -0.05],
        ] {
            let q = u[3] / g.get(FlowArea);
            // leaving across the inlet edges: pump at R_s, turbine at R_p, stator at R_t
            let hp = u[0] * rs * rs + rs * t(PumpInletAngle) * q;
            let ht_ = u[1] * rp * rp + rp * t(TurbineInletAngle) * q;
            let hs = u[2] * rt * rt + rt * t(StatorInletAngle) * q;
            // external torque = ρ|Q|(h out − h in): pump ← turbine ← stator ← pump
            let mass_flow = rho * u[3].abs();
            let ext = [mass_flow * (hp - ht_), mass_flow * (ht_ - hs), mass_flow * (hs - hp)];
            let f = h.forces(&u, -1.0);
            for x in 0..3 {
                assert!((f[x] + ext[x]).abs() <= 1e-12 * ext[x].abs().max(1.0), "{x}: {} vs {}", f[x], -ext[x]);
            }
            let vp = rp * (u[1] - u[0]) + q * (t(TurbineInletAngle) - t(PumpExitAngle));
            let vt = rt * (u[2] - u[1]) + q * (t(StatorInletAngle) - t(TurbineExitAngle));
            let vs = rs * (u[0] - u[2]) + q * (t(PumpInletAngle) - t(StatorExitAngle));
            let vre2: f64 = [PumpInletAngle, TurbineInletAngle, StatorInletAngle]
                .iter()
                .map(|&a| q * q * (1.0 + t(a).powi(2)))
                .sum();
            let ploss = rho / 2.0 * (vp * vp + vt * vt + vs * vs) + rho * g.get(FrictionLoss) / 2.0 * vre2;
            let lp = h.loss_power_w(&u, &f);
            assert!((lp - u[3].abs() * ploss).abs() <= 1e-10 * lp.abs(), "{u:?}: {lp} vs {}", u[3].abs() * ploss);
            assert!(lp > 0.0);
        }
    }

    /// At Q = 0 with unit shock coefficients both forms give the centrifugal head
    /// `½ρ Σ ω_x² (R_exit,x² − R_inlet,x²)`: F_Q(0⁺) = F_Q(0⁻), so the flow passes through zero
    /// without sticking (docs/models.md, "At Q = 0").
    #[test]
    fn ht_zero_flow_force_is_the_same_from_both_sides_with_unit_shock_coefficients() {
        let h = ht([0.0; 3]);
        let (rp, rt, rs) = (0.12f64, 0.065f64, 0.06f64);
        for w in [[209.4, 209.4, 0.0], [100.0, 250.0, 0.0], [-50.0, 80.0, 30.0], [0.0, 0.0, 0.0]] {
            let (fp, fm) = h.zero_flow_head(&[w[0], w[1], w[2], 0.0]);
            let centrifugal = 0.5
                * 840.0
                * (w[0] * w[0] * (rp * rp - rs * rs)
                    + w[1] * w[1] * (rt * rt - rp * rp)
                    + w[2] * w[2] * (rs * rs - rt * rt));
            let scale = 840.0 * rp * rp * w.iter().map(|x| x * x).sum::<f64>() + 1e-300;
            assert!((fp - centrifugal).abs() <= 1e-12 * scale, "{w:?}: {fp} vs {centrifugal}");
            assert!((fm - centrifugal).abs() <= 1e-12 * scale, "{w:?}: {fm} vs {centrifugal}");
        }
        // the brief's hand check: stator locked, SR = 1: ½ρω²(R_t² − R_s²) > 0, the flow starts forwards
        let w = 209.4;
        let (fp, _) = h.zero_flow_head(&[w, w, 0.0, 0.0]);
        assert!((fp - 0.5 * 840.0 * w * w * (rt * rt - rs * rs)).abs() < 1e-9);
    }

    #[test]
    fn ht_steady_forces_balance_the_closed_form() {
        // at the closed-form steady state the flow equation has zero net head
        let h = ht([0.0; 3]);
        let p = h.steady_point(209.4, 100.0).unwrap();
        let f = h.forces(&p.u, 1.0);
        assert!(f[FLOW].abs() < 1e-9 * 840.0 * 0.0144 * 209.4f64.powi(2));
        assert!((-f[PUMP] - p.pump_torque_nm).abs() < 1e-10 * p.pump_torque_nm);
    }

    /// Passivity at every steady state of a grid over all signs of ω_p and ω_t (SR up to 5 and
    /// below −5): the absorbed power `T_p ω_p + T_t ω_t + T_s ω_s` (external torques, physics notes
    /// §2) equals `|Q|·P_loss ≥ 0`; the closed form balances the mass-matrix forces of its flow
    /// direction (F_Q = 0, torques equal) and respects the one-way clutch.
    #[test]
    fn ht_steady_states_in_every_quadrant_are_passive_and_balance_the_forces() {
        use crate::converter::hrovat_tobler::StatorMode;
        let h = ht([0.0; 3]);
        let speeds = [-400.0, -209.4, -60.0, -1.0, 0.0, 1e-3, 30.0, 150.0, 209.4, 300.0, 1000.0];
        let mut reverse = 0;
        for &wp in &speeds {
            for &wt in &speeds {
                let s = steady_state(&h.geometry, wp, wt).unwrap();
                let (ws, q) = (s.stator_speed_rad_s, s.flow_m3_s);
                let absorbed = s.pump_torque_nm * wp - s.turbine_torque_nm * wt + s.stator_torque_nm * ws;
                let scale = 840.0 * 0.0144 * 0.12 * (wp.abs() + wt.abs()).powi(3) + 1e-300;
                assert!(absorbed >= -1e-12 * scale, "{wp} {wt}: absorbed {absorbed}");
                match s.mode {
                    StatorMode::Locked => assert!(ws == 0.0 && s.stator_torque_nm >= 0.0, "{wp} {wt}: {s:?}"),
                    StatorMode::FreeWheeling => assert!(ws >= 0.0 && s.stator_torque_nm == 0.0, "{wp} {wt}: {s:?}"),
                    StatorMode::NoFlow => assert!(q == 0.0 && absorbed == 0.0, "{wp} {wt}: {s:?}"),
                }
                if q == 0.0 {
                    continue;
                }
                reverse += usize::from(q < 0.0);
                let sigma = q.signum();
                let u = [wp, wt, ws, q];
                let f = h.forces(&u, sigma);
                let torque_scale = 840.0 * 0.0144 * (wp.abs() + wt.abs()).powi(2) * 0.12;
                assert!(f[FLOW].abs() <= 1e-9 * 840.0 * 0.0144 * (wp.abs() + wt.abs()).powi(2), "{wp} {wt}: {f:?}");
                assert!((-f[PUMP] - s.pump_torque_nm).abs() <= 1e-10 * torque_scale, "{wp} {wt}");
                assert!((f[TURBINE] - s.turbine_torque_nm).abs() <= 1e-10 * torque_scale, "{wp} {wt}");
                assert!((absorbed - h.loss_power_w(&u, &f)).abs() <= 1e-9 * scale, "{wp} {wt}");
                assert!(h.loss_power_w(&u, &f) > 0.0);
            }
        }
        assert!(reverse > 10, "{reverse} reverse-flow points");
    }

    /// Sustained overrun of the bundled Appendix D converter (SR 1.2, 2, 3 at 2000 rpm): the flow
    /// reverses and the pump torque opposes the pump's rotation (engine braking), with the stator
    /// free-wheeling (the clutch lets go: the reversed flow drives it forwards) and with it locked.
    #[test]
    fn ht_coast_reverses_the_flow_and_brakes_the_pump() {
        use crate::converter::hrovat_tobler::{solve_reverse, StatorMode};
        let g = HtGeometry::appendix_d();
        let wp = 209.4;
        for sr in [1.2, 2.0, 3.0] {
            let s = steady_state(&g, wp, sr * wp).unwrap();
            assert_eq!(s.mode, StatorMode::FreeWheeling, "SR {sr}");
            assert!(s.flow_m3_s < 0.0 && s.pump_torque_nm < 0.0 && s.stator_speed_rad_s > 0.0, "SR {sr}: {s:?}");
            assert!((s.torque_ratio() - 1.0).abs() < 1e-12);
            let locked = solve_reverse(&g, wp, sr * wp, StatorMode::Locked).unwrap();
            assert!(locked.flow_m3_s < 0.0 && locked.pump_torque_nm < 0.0, "SR {sr}: {locked:?}");
            // the clutch cannot hold it: the reversed flow drives the stator forwards (T_s < 0)
            assert!(locked.stator_torque_nm < 0.0);
        }
    }

    #[test]
    fn mass_matrix_bound_is_the_models_check() {
        let shape = [0.004, -0.003, 0.001];
        let m = ht(shape);
        let b = MassMatrixBound::new(&m.geometry, &m.inertia, m.fluid_length_m, shape);
        assert_eq!(b.inertance_kg_m4, m.fluid_inertance());
        assert_eq!(b.shape_effect_bounds(), m.shape_effect_bounds());
        assert!(b.margin_kg_m4() > 0.0);
        let too_big = MassMatrixBound::new(&m.geometry, &m.inertia, m.fluid_length_m, [1.0, 0.0, 0.0]);
        assert!(too_big.margin_kg_m4() <= 0.0);
        assert!(HtDynamics::new(m.geometry, m.inertia, m.fluid_length_m, [1.0, 0.0, 0.0]).is_err());
    }

    #[test]
    fn inadmissible_shape_effect_is_refused_with_its_bound() {
        // S_p = 0.2 m² (thesis §4.1 range) breaks ρL_f/A > ρ²S_p²/I_p; the bound is √(I_p ρL_f/A)/ρ
        let err = HtDynamics::new(HtGeometry::appendix_d(), inertia(), 0.2914, [0.2, 0.0, 0.0]).unwrap_err();
        assert_eq!(err.field, "geometry.pump_shape_effect_m2");
        let expected_bound = (0.109f64 * 840.0 * 0.2914 / 0.01).sqrt() / 840.0;
        assert!(err.expected.starts_with(&format!("|S| < {} m²", sig(expected_bound))), "{}", err.expected);
        assert!(err.expected.starts_with("|S| < 0.0614"), "{}", err.expected);
        // with S_t alone past its bound there is no room left for S_p
        let err = HtDynamics::new(HtGeometry::appendix_d(), inertia(), 0.2914, [0.01, 0.2, 0.0]).unwrap_err();
        assert_eq!(err.field, "geometry.turbine_shape_effect_m2");
        // a fluid path too short for the shape effects: no shape effect's value helps, its length does
        let err =
            HtDynamics::new(HtGeometry::appendix_d(), inertia(), 1e-9, [0.00131, 0.002324, 0.001723]).unwrap_err();
        assert_eq!((err.field.as_str(), err.value.as_str()), ("geometry.fluid_length_m", "0.000000001"), "{err}");
        let i = inertia();
        let terms = 840.0
            * (0.00131f64.powi(2) / i.pump_kg_m2
                + 0.002324f64.powi(2) / i.turbine_kg_m2
                + 0.001723f64.powi(2) / i.stator_kg_m2);
        assert!(err.expected.starts_with(&format!("a fluid length over {} m", sig(terms * 0.01))), "{}", err.expected);
        assert!(
            HtDynamics::new(HtGeometry::appendix_d(), i, 1.001 * terms * 0.01, [0.00131, 0.002324, 0.001723]).is_ok()
        );
        // the bound is sharp: just below it is admitted, at it refused
        let b = ht([0.0; 3]).shape_effect_bounds()[1];
        assert!(HtDynamics::new(HtGeometry::appendix_d(), inertia(), 0.2914, [0.0, 0.999 * b, 0.0]).is_ok());
        assert!(HtDynamics::new(HtGeometry::appendix_d(), inertia(), 0.2914, [0.0, 1.001 * b, 0.0]).is_err());
    }
}
