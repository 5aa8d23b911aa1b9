//! Hrovat & Tobler torque-converter model: the steady state in closed form.
//!
//! References: D. Hrovat and W. E. Tobler (1985), "Bond graph modelling and computer simulation
//! of automotive torque converters", J. Franklin Inst. 319(1/2):93–114; Li & Sundén (2016)
//! §2.2.2, eqs 2.12–2.25. Signs and units: docs/physics.md §2 and §4.
//!
//! With the left-hand sides of eqs 2.12–2.15 zero and Q > 0, the right-hand side of eq 2.15 is
//! a quadratic in `q = Q/A`: the Euler head gives a constant and a linear term, the shock
//! velocities (eqs 2.20–2.22) are affine in q, friction (eq 2.19 with
//! `|V_re,x|² = q²(1 + tan²α_x)`) adds to q². The positive root gives the flow; eqs 2.12–2.14 give
//! the torques.
//!
//! * **Locked stator** (ω_s = 0): the quadratic's leading coefficient is negative, so there is one
//!   positive root while the head at zero flow exceeds the shock losses.
//! * **Free-wheeling stator** (T_s = 0): eq 2.14 with Q > 0 gives ω_s affine in q,
//!   `ω_s = (ω_t R_t² + q (R_t tan α_t − R_s tan α_s)) / R_s²`, so eq 2.15 stays a quadratic in
//!   q. The branch that continues the locked solution at the coupling point is the larger root.
//!   T_p + T_t = 0 there, so TR = 1 exactly.
//! * **No flow.** Close to SR = 1 the free-wheeling quadratic loses its real roots: the shock
//!   terms of eq 2.19 do not vanish as Q → 0 (they carry sgn Q, not Q), so the model has no
//!   steady state with a small positive flow. tcsim then reports Q = 0 and zero torques (the
//!   Filippov solution of the sgn Q discontinuity), TR = 1 by continuity, and the stator speed,
//!   which the equations leave undetermined at Q = 0, equal to the turbine speed. At SR = 1
//!   this is docs/physics.md §4's ω_s = ω_p, Q = 0.
//! * **Reverse flow** (Q < 0, docs/models.md "Reverse flow"): the fluid leaves each element across
//!   its inlet edge; the same structure with the reverse geometry gives a quadratic in q for the
//!   locked and the free-wheeling stator (`solve_reverse`).
//! * **Every quadrant** ([`steady_state`]): the flow direction is the one in which the flow starts
//!   from rest with the stator at rest ([`start_direction`]); the clutch logic then follows.
//!   [`drive_steady_state`] keeps the drive-only forward solution for the fits.
//!
//! The solvers are generic over [`Scalar`] so that the same code yields exact derivatives.

use crate::error::{CoreError, CoreResult, InputSource};
use crate::scalar::{Dual, Scalar};

/// The fifteen parameters of Table 2.2 that fix the steady state, in SI units (angles in
/// radians). The order is the order of [`HtParam::ALL`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HtGeometry<T> {
    pub values: [T; N_PARAMS],
}

pub const N_PARAMS: usize = 15;

/// Names of the steady-state parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HtParam {
    FlowArea,
    FluidDensity,
    PumpExitRadius,
    TurbineExitRadius,
    StatorExitRadius,
    PumpExitAngle,
    TurbineExitAngle,
    StatorExitAngle,
    PumpInletAngle,
    TurbineInletAngle,
    StatorInletAngle,
    PumpShockLoss,
    TurbineShockLoss,
    StatorShockLoss,
    FrictionLoss,
}

impl HtParam {
    pub const ALL: [HtParam; N_PARAMS] = [
        Self::FlowArea,
        Self::FluidDensity,
        Self::PumpExitRadius,
        Self::TurbineExitRadius,
        Self::StatorExitRadius,
        Self::PumpExitAngle,
        Self::TurbineExitAngle,
        Self::StatorExitAngle,
        Self::PumpInletAngle,
        Self::TurbineInletAngle,
        Self::StatorInletAngle,
        Self::PumpShockLoss,
        Self::TurbineShockLoss,
        Self::StatorShockLoss,
        Self::FrictionLoss,
    ];

    /// Name with unit, as in the converter TOML `[geometry]` section, except that the core
    /// holds angles in radians (`_rad`) where files hold degrees (`_deg`).
    pub fn key(self) -> &'static str {
        match self {
            Self::FlowArea => "flow_area_m2",
            Self::FluidDensity => "fluid_density_kg_m3",
            Self::PumpExitRadius => "pump_exit_radius_m",
            Self::TurbineExitRadius => "turbine_exit_radius_m",
            Self::StatorExitRadius => "stator_exit_radius_m",
            Self::PumpExitAngle => "pump_exit_angle_rad",
            Self::TurbineExitAngle => "turbine_exit_angle_rad",
            Self::StatorExitAngle => "stator_exit_angle_rad",
            Self::PumpInletAngle => "pump_inlet_angle_rad",
            Self::TurbineInletAngle => "turbine_inlet_angle_rad",
            Self::StatorInletAngle => "stator_inlet_angle_rad",
            Self::PumpShockLoss => "pump_shock_loss",
            Self::TurbineShockLoss => "turbine_shock_loss",
            Self::StatorShockLoss => "stator_shock_loss",
            Self::FrictionLoss => "friction_loss",
        }
    }

    pub fn index(self) -> usize {
        self as usize
    }

    fn is_angle(self) -> bool {
        (Self::PumpExitAngle.index()..=Self::StatorInletAngle.index()).contains(&self.index())
    }
}

impl<T: Scalar> HtGeometry<T> {
    pub fn get(&self, p: HtParam) -> T {
        self.values[p.index()]
    }
}

impl HtGeometry<f64> {
    /// Check each parameter's admissible range and return the geometry.
    pub fn new(values: [f64; N_PARAMS]) -> CoreResult<Self> {
        for p in HtParam::ALL {
            let v = values[p.index()];
            let ok = if p.is_angle() {
                v.is_finite() && v.abs() < std::f64::consts::FRAC_PI_2
            } else if matches!(
                p,
                HtParam::PumpShockLoss | HtParam::TurbineShockLoss | HtParam::StatorShockLoss | HtParam::FrictionLoss
            ) {
                v.is_finite() && v >= 0.0
            } else {
                v.is_finite() && v > 0.0
            };
            if !ok {
                let expected = if p.is_angle() {
                    "an angle strictly between -90 and 90 degrees"
                } else if p.index() >= HtParam::PumpShockLoss.index() {
                    "a finite, non-negative loss coefficient"
                } else {
                    "a finite, positive value"
                };
                return Err(CoreError::new(p.key(), v, expected));
            }
        }
        let g = Self { values };
        let k = HtConstants::new(&g);
        g.check_finite(&k)?;
        let dissipation = k.dissipation_coefficient();
        if dissipation <= 0.0 {
            return Err(CoreError::new(
                "friction_loss",
                values[HtParam::FrictionLoss.index()],
                "a positive friction loss or shock losses with non-zero incidence: without losses the flow is unbounded",
            ));
        }
        if k.reverse_dissipation_coefficient() <= 0.0 {
            return Err(CoreError::new(
                "friction_loss",
                values[HtParam::FrictionLoss.index()],
                "a positive friction loss or shock losses with non-zero incidence in reverse flow too: without losses the reverse flow is unbounded",
            ));
        }
        Ok(g)
    }

    /// The steady states at the reference pump speed (stall and SR 0.5) must be finite: parameters
    /// that overflow them (a density of 1e300 kg/m³, radii of 1e100 m) are refused, naming the one
    /// farthest outside its plausible range ([`crate::plausibility`]). `k` are its constants.
    fn check_finite(&self, k: &HtConstants<f64>) -> CoreResult<()> {
        let wp = crate::units::REFERENCE_PUMP_SPEED_RAD_S;
        let finite = [0.0, 0.5].iter().all(|&sr| match steady_state_with(k, wp, sr * wp) {
            Ok(s) => s.is_finite(),
            Err(e) => e.source != InputSource::Drive, // no steady state is the dissipation check's
        });
        if finite && k.dissipation_coefficient().is_finite() {
            return Ok(());
        }
        let quantity = |p: HtParam| match p {
            HtParam::FlowArea => "flow_area_m2",
            HtParam::FluidDensity => "fluid_density_kg_m3",
            HtParam::PumpExitRadius | HtParam::TurbineExitRadius | HtParam::StatorExitRadius => "radius_m",
            p if p.is_angle() => "blade_angle_deg",
            _ => "loss_coefficient",
        };
        let shown = |p: HtParam| if p.is_angle() { self.get(p).to_degrees() } else { self.get(p) };
        let values: Vec<(f64, &str)> = HtParam::ALL.iter().map(|&p| (shown(p), quantity(p))).collect();
        let p = crate::plausibility::farthest_outside(&values).map_or(HtParam::FluidDensity, |i| HtParam::ALL[i]);
        Err(CoreError::new(
            p.key(),
            self.get(p),
            "a value at which the steady state is finite (these parameters overflow it at 2000 rpm; see the plausible ranges)",
        ))
    }

    /// Appendix D reference values (Li & Sundén 2016, Table D.1).
    pub fn appendix_d() -> Self {
        let d = |deg: f64| deg.to_radians();
        Self::new([
            0.01,
            840.0,
            0.12,
            0.065,
            0.06,
            d(-20.0),
            d(-50.0),
            d(60.0),
            d(-50.0),
            d(55.0),
            d(15.0),
            1.0,
            1.0,
            1.0,
            0.2,
        ])
        .unwrap()
    }

    /// Seed parameter `p` for a derivative.
    pub fn seeded(&self, p: HtParam) -> HtGeometry<Dual> {
        let mut values = self.values.map(Dual::cst);
        values[p.index()].d = 1.0;
        HtGeometry { values }
    }

    pub fn to_dual(&self) -> HtGeometry<Dual> {
        HtGeometry { values: self.values.map(Dual::cst) }
    }
}

/// A polynomial of degree ≤ 2 in q: `c[0] + c[1] q + c[2] q²`.
#[derive(Debug, Clone, Copy)]
struct Quad<T> {
    c: [T; 3],
}

impl<T: Scalar> Quad<T> {
    fn cst(v: T) -> Self {
        Self { c: [v, T::cst(0.0), T::cst(0.0)] }
    }
    fn affine(c0: T, c1: T) -> Self {
        Self { c: [c0, c1, T::cst(0.0)] }
    }
    fn eval(self, q: T) -> T {
        self.c[0] + q * (self.c[1] + q * self.c[2])
    }
}

/// Largest real root of `c0 + c1 q + c2 q²`, computed without cancellation; None if no real root.
#[inline]
fn largest_real_root<T: Scalar>(p: Quad<T>) -> Option<T> {
    let [c0, c1, c2] = p.c;
    if c2.re() == 0.0 {
        return if c1.re() == 0.0 { None } else { Some(-c0 / c1) };
    }
    let disc = c1 * c1 - T::cst(4.0) * c2 * c0;
    if disc.re() < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    // w = -(c1 + sign(c1) √disc)/2; roots w/c2 and c0/w
    let w = if c1.re() >= 0.0 { -(c1 + s).scale(0.5) } else { (s - c1).scale(0.5) };
    if w.re() == 0.0 {
        return Some(T::cst(0.0)); // c0 = c1 = 0: double root at zero
    }
    let (r1, r2) = (w / c2, c0 / w);
    Some(if r1.re() >= r2.re() { r1 } else { r2 })
}

/// Mode of the stator one-way clutch at a steady state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StatorMode {
    /// Clutch holding, ω_s = 0, T_s ≥ 0.
    Locked = 0,
    /// Clutch released, T_s = 0, TR = 1.
    FreeWheeling = 1,
    /// Free-wheeling with no flowing steady state (near SR = 1): Q = 0, zero torque.
    NoFlow = 2,
}

/// The mode code of a batch point without a steady state ([`crate::batch::ht_steady_states`]
/// with `strict = false`): its values are NaN.
pub const NO_STEADY_STATE: i8 = -1;

impl StatorMode {
    pub const ALL: [StatorMode; 3] = [StatorMode::Locked, StatorMode::FreeWheeling, StatorMode::NoFlow];

    /// The mode's code in batch outputs (`stator_mode` column).
    pub fn code(self) -> i8 {
        self as i8
    }

    /// The mode's name in outputs: `locked`, `free-wheeling`, `no-flow`.
    pub fn name(self) -> &'static str {
        match self {
            StatorMode::Locked => "locked",
            StatorMode::FreeWheeling => "free-wheeling",
            StatorMode::NoFlow => "no-flow",
        }
    }
}

/// Every code of the `stator_mode` column with its name: the [`StatorMode`]s and
/// [`NO_STEADY_STATE`] (`no-steady-state`).
pub fn steady_mode_names() -> Vec<(i8, &'static str)> {
    let mut names: Vec<(i8, &'static str)> = StatorMode::ALL.iter().map(|m| (m.code(), m.name())).collect();
    names.push((NO_STEADY_STATE, "no-steady-state"));
    names
}

/// The torque ratio of a steady state from its `stator_mode` code and torques (the rule of
/// [`HtSteadyState::torque_ratio`] on batch columns): 1 in `no-flow` (zero torques, TR = 1 by
/// continuity), else `T_t / T_p` (a zero pump torque divides by 1); NaN without a steady state.
pub fn steady_torque_ratio(stator_mode: i8, pump_torque_nm: f64, turbine_torque_nm: f64) -> f64 {
    if stator_mode == StatorMode::NoFlow.code() {
        1.0
    } else {
        turbine_torque_nm / if pump_torque_nm == 0.0 { 1.0 } else { pump_torque_nm }
    }
}

/// A steady state of the Hrovat & Tobler model. Torques follow docs/physics.md §2: the pump and
/// stator torques are the external torques on those elements, the turbine torque is the torque
/// delivered to the transmission (−T_t).
#[derive(Debug, Clone, Copy)]
pub struct HtSteadyState<T> {
    pub flow_m3_s: T,
    pub stator_speed_rad_s: T,
    pub pump_torque_nm: T,
    pub turbine_torque_nm: T,
    pub stator_torque_nm: T,
    pub mode: StatorMode,
}

impl<T: Scalar> HtSteadyState<T> {
    /// TR = delivered turbine torque / pump torque; 1 in the no-flow state by continuity.
    pub fn torque_ratio(&self) -> T {
        if self.mode == StatorMode::NoFlow {
            T::cst(1.0)
        } else {
            self.turbine_torque_nm / self.pump_torque_nm
        }
    }
}

/// Per-geometry constants of the steady state: the six blade-angle tangents and what the balances
/// and torques build from them and the radii, computed once per parameter set (issue 16: the
/// tangents were computed 2–4 times per point). [`crate::batch::ht_steady_states`] makes one per
/// parameter row; [`steady_state_with`] takes it.
#[derive(Debug, Clone, Copy)]
pub struct HtConstants<T> {
    /// Fluid density ρ, kg/m³, and flow area A, m².
    rho: T,
    area: T,
    /// Exit radii R_p, R_t, R_s, m, and their squares, m².
    r: [T; 3],
    r2: [T; 3],
    /// Shock loss coefficients C_sh,p, C_sh,t, C_sh,s.
    shock: [T; 3],
    /// `R tan α` at the edges the forward flow leaves (exit edges): R_p tan α_p, R_t tan α_t,
    /// R_s tan α_s, m.
    exit_swirl: [T; 3],
    /// `R tan α` at the edges the reverse flow leaves (inlet edges, at the radius of the element
    /// before): R_s tan α_pp, R_p tan α_tt, R_t tan α_ss, m.
    inlet_swirl: [T; 3],
    /// q-coefficients of the forward shock velocities (eqs 2.20–2.22): tan α_s − tan α_pp,
    /// tan α_p − tan α_tt, tan α_t − tan α_ss.
    shock_slope: [T; 3],
    /// q-coefficients of the reverse shock velocities (docs/models.md, "Reverse flow"):
    /// tan α_tt − tan α_p, tan α_ss − tan α_t, tan α_pp − tan α_s.
    reverse_shock_slope: [T; 3],
    /// `f Σ(1 + tan² α)` over the exit angles (forward friction, eqs 2.23–2.25) and over the inlet
    /// angles (reverse friction).
    friction: T,
    reverse_friction: T,
    /// The slope `k₁` of the free-wheeling stator's speed `ω_s = ω R²/R'² + k₁ x`: forwards
    /// (`ω = ω_t`, `x = q`) `k₁ = (R_t tan α_t − R_s tan α_s)/R_s²`; backwards (`ω = ω_p`, `x = −q`)
    /// `k₁ = (R_t tan α_ss − R_s tan α_pp)/R_t²`.
    free: T,
    reverse_free: T,
}

impl<T: Scalar> HtConstants<T> {
    /// The constants of parameter set `g` (six tangents, no check of the parameters).
    pub fn new(g: &HtGeometry<T>) -> Self {
        use HtParam::*;
        let r = [g.get(PumpExitRadius), g.get(TurbineExitRadius), g.get(StatorExitRadius)];
        let [rp, rt, rs] = r;
        let [tp, tt, ts, tpp, ttt, tss] =
            [PumpExitAngle, TurbineExitAngle, StatorExitAngle, PumpInletAngle, TurbineInletAngle, StatorInletAngle]
                .map(|p| g.get(p).tan());
        let one = T::cst(1.0);
        let f = g.get(FrictionLoss);
        let r2 = r.map(|x| x * x);
        Self {
            rho: g.get(FluidDensity),
            area: g.get(FlowArea),
            r,
            r2,
            shock: [g.get(PumpShockLoss), g.get(TurbineShockLoss), g.get(StatorShockLoss)],
            exit_swirl: [rp * tp, rt * tt, rs * ts],
            inlet_swirl: [rs * tpp, rp * ttt, rt * tss],
            shock_slope: [ts - tpp, tp - ttt, tt - tss],
            reverse_shock_slope: [ttt - tp, tss - tt, tpp - ts],
            friction: f * (one + tp * tp + one + tt * tt + one + ts * ts),
            reverse_friction: f * (one + tpp * tpp + one + ttt * ttt + one + tss * tss),
            free: (rt * tt - rs * ts) / r2[2],
            reverse_free: (rt * tss - rs * tpp) / r2[1],
        }
    }
}

impl HtConstants<f64> {
    /// The coefficient of q² in the reverse-flow locked-stator residual divided by ρ/2; positive
    /// when the losses bound a reverse flow.
    fn reverse_dissipation_coefficient(&self) -> f64 {
        (0..3).map(|x| self.shock[x] * self.reverse_shock_slope[x].powi(2)).sum::<f64>() + self.reverse_friction
    }

    /// The coefficient of −q² in the locked-stator residual divided by ρ/2; positive when the
    /// losses bound the flow.
    fn dissipation_coefficient(&self) -> f64 {
        (0..3).map(|x| self.shock[x] * self.shock_slope[x].powi(2)).sum::<f64>() + self.friction
    }
}

/// The right-hand side of eq 2.15 at steady state as a quadratic in q, for a stator speed that is
/// affine in q (zero when locked).
#[derive(Debug, Clone, Copy)]
struct Balance<T> {
    residual: Quad<T>,
    stator_speed: Quad<T>,
}

/// `Σ_x C_sh,x (u_x + v_x q)²` as the coefficients of `1, q, q²`: the shock term of the power loss,
/// eq 2.19, with the three shock velocities given as `u + v q` (forward or reverse flow).
fn shock_loss<T: Scalar>(k: &HtConstants<T>, shocks: [(T, T); 3]) -> [T; 3] {
    let squares = |x: usize| {
        let (u, v) = shocks[x];
        [u * u * k.shock[x], (u * v + v * u) * k.shock[x], v * v * k.shock[x]]
    };
    let (sp, st, ss) = (squares(0), squares(1), squares(2));
    std::array::from_fn(|i| sp[i] + st[i] + ss[i])
}

#[inline]
fn balance<T: Scalar>(k: &HtConstants<T>, wp: T, wt: T, stator_speed: Quad<T>) -> Balance<T> {
    let [rp, rt, rs] = k.r;
    let [rp2, rt2, rs2] = k.r2;
    let [mp, mt, ms] = k.exit_swirl;
    // ω_s = a + b q. The coefficients are the products of the affine factors written out, in the
    // order of the polynomial arithmetic they replace, so that they are the same to the last bit.
    let [a, b, _] = stator_speed.c;
    // Euler head, eq 2.15 first three lines: the ω_s-free terms, + R_s²ω_s² − (R_s²ω_p + R_t²ω_t) ω_s,
    // + q [ω_p(R_p tan α_p − R_s tan α_s) + ω_t(R_t tan α_t − R_p tan α_p) + ω_s(R_s tan α_s − R_t tan α_t)]
    let cross = rs2 * wp + rt2 * wt;
    let (e, f) = (wp * (mp - ms) + wt * (mt - mp), ms - mt);
    let head = [
        rp2 * wp * wp + rt2 * wt * wt - rp2 * wt * wp + a * a * rs2 - a * cross,
        (a * b + b * a) * rs2 - b * cross + (e + a * f),
        b * b * rs2 + b * f,
    ];
    // shock velocities, eqs 2.20–2.22, as u + v q: Σ C_sh (u + v q)²
    let [bp, bt, bs] = k.shock_slope;
    let shocks = [((a - wp) * rs, b * rs + bp), ((wp - wt) * rp, bt), ((wt - a) * rt, bs - b * rt)];
    let shock = shock_loss(k, shocks);
    // friction, eqs 2.19 and 2.23–2.25: Σ|V_re,x|² = q² Σ(1 + tan²α_x); the loss is halved
    let half = T::cst(0.5);
    let loss = [shock[0] * half, shock[1] * half, (shock[2] + k.friction) * half];
    let residual = Quad { c: std::array::from_fn(|i| (head[i] - loss[i]) * k.rho) };
    Balance { residual, stator_speed }
}

/// Torques of eqs 2.12–2.14 with zero left-hand sides, at flow `q = Q/A`.
#[inline]
fn torques<T: Scalar>(k: &HtConstants<T>, wp: T, wt: T, ws: T, q: T) -> (T, T, T) {
    let [rp, rt, rs] = k.r;
    let [mp, mt, ms] = k.exit_swirl;
    let flow = q * k.area;
    // angular momentum leaving each element per unit mass flow
    let hp = wp * rp * rp + mp * q;
    let ht = wt * rt * rt + mt * q;
    let hs = ws * rs * rs + ms * q;
    let pump = k.rho * (hp - hs) * flow;
    let turbine_external = k.rho * (ht - hp) * flow;
    let stator = k.rho * (hs - ht) * flow;
    (pump, -turbine_external, stator)
}

/// The stator speed of `mode` as a polynomial in the flow variable: zero when locked, the
/// free-wheeling one of [`HtConstants::free`] otherwise (`reverse`: of `reverse_free`, x = −q).
fn stator_speed<T: Scalar>(k: &HtConstants<T>, wp: T, wt: T, mode: StatorMode, reverse: bool) -> Quad<T> {
    match (mode, reverse) {
        (StatorMode::Locked, _) => Quad::cst(T::cst(0.0)),
        (_, false) => Quad::affine(wt * k.r[1] * k.r[1] / k.r2[2], k.free),
        // T_s = 0: the stator passes on the angular momentum it receives from the pump,
        // ω_s R_t² + R_t tan α_ss q = ω_p R_s² + R_s tan α_pp q, with q = −p
        (_, true) => Quad::affine(wp * k.r[2] * k.r[2] / k.r2[1], k.reverse_free),
    }
}

/// The forward steady state of `mode` from its balance `b`: the largest root q > 0.
#[inline]
fn forward_state<T: Scalar>(
    k: &HtConstants<T>,
    wp: T,
    wt: T,
    mode: StatorMode,
    b: Balance<T>,
) -> Option<HtSteadyState<T>> {
    let q = largest_real_root(b.residual)?;
    if q.re() <= 0.0 {
        return None;
    }
    let ws = b.stator_speed.eval(q);
    let (pump, turbine, stator) = torques(k, wp, wt, ws, q);
    Some(HtSteadyState {
        flow_m3_s: q * k.area,
        stator_speed_rad_s: ws,
        pump_torque_nm: pump,
        turbine_torque_nm: turbine,
        stator_torque_nm: if mode == StatorMode::Locked { stator } else { T::cst(0.0) },
        mode,
    })
}

fn solve_mode<T: Scalar>(k: &HtConstants<T>, wp: T, wt: T, mode: StatorMode) -> Option<HtSteadyState<T>> {
    forward_state(k, wp, wt, mode, balance(k, wp, wt, stator_speed(k, wp, wt, mode, false)))
}

/// Steady state with the stator held (ω_s = 0), whatever the sign of the holding torque.
pub fn locked_steady_state<T: Scalar>(
    g: &HtGeometry<T>,
    pump_speed_rad_s: T,
    turbine_speed_rad_s: T,
) -> Option<HtSteadyState<T>> {
    solve_mode(&HtConstants::new(g), pump_speed_rad_s, turbine_speed_rad_s, StatorMode::Locked)
}

/// Why an operating point has no steady state, before any message is formatted (the batch's loop
/// meets it per point). [`SteadyFailure::error`] gives the error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SteadyFailure {
    /// A pump speed that is not finite.
    PumpSpeed,
    /// A turbine speed that is not finite.
    TurbineSpeed,
    /// A steady state that overflows (pump speeds above about 1e150 rad/s, where ω² does).
    Overflow,
}

impl SteadyFailure {
    /// The error at speeds `wp`, `wt` (rad/s). The operating point's errors are about the speeds
    /// asked for ([`InputSource::Drive`]): any finite pair of speeds has a steady state. An
    /// overflow is never reported as a mode (it was `no-flow`).
    pub fn error(self, wp: f64, wt: f64) -> CoreError {
        match self {
            Self::PumpSpeed => CoreError::of(InputSource::Drive, "pump_speed_rad_s", wp, "a finite pump speed"),
            Self::TurbineSpeed => CoreError::of(InputSource::Drive, "turbine_speed_rad_s", wt, "a finite turbine speed"),
            Self::Overflow => CoreError::of(
                InputSource::Drive,
                "pump_speed_rad_s",
                wp.abs().max(wt.abs()),
                "a pump speed at which the steady state of these parameters is finite (it overflows: its torques grow as the speed squared)",
            ),
        }
    }
}

/// The reverse-flow residual `F_Q/ρ·ρ` (docs/models.md, "Reverse flow") as a polynomial in
/// `p = −q ≥ 0`, for a stator speed affine in p.
#[inline]
fn reverse_balance<T: Scalar>(k: &HtConstants<T>, wp: T, wt: T, stator_speed: Quad<T>) -> Balance<T> {
    let [rp, rt, rs] = k.r;
    let [rp2, rt2, rs2] = k.r2;
    let [ip, it, is] = k.inlet_swirl;
    // ω_s = a + b p
    let [a, b, _] = stator_speed.c;
    // angular momentum per unit mass leaving across the inlet edges, h_x = h0 + h1 p (q = −p)
    let (hp0, hp1) = (wp * rs2, -ip);
    let (ht0, ht1) = (wt * rp2, -it);
    let (hs0, hs1) = (a * rt2, b * rt2 - is);
    // head = ω_p (h_t − h_p) + ω_t (h_s − h_t) + ω_s (h_p − h_s)
    // (in the order of the polynomial arithmetic they replace, so that they are the same to the bit)
    let head = [
        wp * (ht0 - hp0) + wt * (hs0 - ht0) + a * (hp0 - hs0),
        wp * (ht1 - hp1) + wt * (hs1 - ht1) + (a * (hp1 - hs1) + b * (hp0 - hs0)),
        b * (hp1 - hs1),
    ];
    // shock at the entry of each element, from its source (pump ← turbine ← stator ← pump), u + v p
    let [bp, bt, bs] = k.reverse_shock_slope;
    let shocks = [((wt - wp) * rp, -bp), ((a - wt) * rt, b * rt - bt), ((wp - a) * rs, -b * rs - bs)];
    let shock = shock_loss(k, shocks);
    let half = T::cst(0.5);
    let loss = [shock[0] * half, shock[1] * half, (shock[2] + k.reverse_friction) * half];
    let residual = Quad { c: std::array::from_fn(|i| (head[i] + loss[i]) * k.rho) };
    Balance { residual, stator_speed }
}

/// The reverse steady state of `mode` from its balance `b`: the root in `p = −q > 0` of largest
/// magnitude (the locked residual has one), with the torques of the reverse form.
#[inline]
fn reverse_state<T: Scalar>(
    k: &HtConstants<T>,
    wp: T,
    wt: T,
    mode: StatorMode,
    b: Balance<T>,
) -> Option<HtSteadyState<T>> {
    let p = largest_real_root(b.residual)?;
    if p.re() <= 0.0 {
        return None;
    }
    let (ws, q) = (b.stator_speed.eval(p), -p);
    let flow = q * k.area;
    let [rp, rt, rs] = k.r;
    let [mp, mt, ms] = k.inlet_swirl;
    let hp = wp * rs * rs + mp * q;
    let ht = wt * rp * rp + mt * q;
    let hs = ws * rt * rt + ms * q;
    Some(HtSteadyState {
        flow_m3_s: flow,
        stator_speed_rad_s: ws,
        // external torque −F_x = −ρQ(h_x − h_src(x)); the turbine's delivered torque is F_t
        pump_torque_nm: -(k.rho * (hp - ht) * flow),
        turbine_torque_nm: k.rho * (ht - hs) * flow,
        stator_torque_nm: if mode == StatorMode::Locked { -(k.rho * (hs - hp) * flow) } else { T::cst(0.0) },
        mode,
    })
}

/// A reverse-flow steady state in `mode` (locked or free-wheeling): the root in `p = −q > 0` of
/// largest magnitude (the locked residual has one), with the torques of the reverse form.
#[cfg(test)]
pub(crate) fn solve_reverse<T: Scalar>(g: &HtGeometry<T>, wp: T, wt: T, mode: StatorMode) -> Option<HtSteadyState<T>> {
    let k = HtConstants::new(g);
    reverse_state(&k, wp, wt, mode, reverse_balance(&k, wp, wt, stator_speed(&k, wp, wt, mode, true)))
}

/// The direction in which the flow starts from rest with the stator at rest (σ of
/// [`crate::engine::converter_events::flow_sign_from_balance`] on `F_Q(0±)`): +1, −1 or 0 (held).
pub fn start_direction<T: Scalar>(g: &HtGeometry<T>, wp: T, wt: T) -> i8 {
    let (forward, reverse) = zero_flow_forces(g, wp, wt);
    direction_from_forces(forward, reverse)
}

/// [`start_direction`] from `(F_Q(0⁺), F_Q(0⁻))`.
fn direction_from_forces(forward: f64, reverse: f64) -> i8 {
    match (forward > 0.0, reverse < 0.0) {
        (true, true) => {
            if forward >= -reverse {
                1
            } else {
                -1
            }
        }
        (true, false) => 1,
        (false, true) => -1,
        (false, false) => 0,
    }
}

/// `(F_Q(0⁺), F_Q(0⁻))` with the stator at rest, Pa.
pub fn zero_flow_forces<T: Scalar>(g: &HtGeometry<T>, wp: T, wt: T) -> (f64, f64) {
    let k = HtConstants::new(g);
    let zero = Quad::cst(T::cst(0.0));
    (balance(&k, wp, wt, zero).residual.c[0].re(), reverse_balance(&k, wp, wt, zero).residual.c[0].re())
}

fn no_flow<T: Scalar>(stator_speed: T) -> HtSteadyState<T> {
    HtSteadyState {
        flow_m3_s: T::cst(0.0),
        stator_speed_rad_s: stator_speed,
        pump_torque_nm: T::cst(0.0),
        turbine_torque_nm: T::cst(0.0),
        stator_torque_nm: T::cst(0.0),
        mode: StatorMode::NoFlow,
    }
}

impl<T: Scalar> HtSteadyState<T> {
    /// Whether every value is finite (the steady state overflows at pump speeds above about
    /// 1e150 rad/s, where ω² does).
    fn is_finite(&self) -> bool {
        [self.flow_m3_s, self.stator_speed_rad_s, self.pump_torque_nm, self.turbine_torque_nm, self.stator_torque_nm]
            .iter()
            .all(|x| x.re().is_finite())
    }
}

/// Steady state with the one-way clutch at any finite speeds (docs/models.md, "Steady state in
/// every quadrant"). The flow direction is the one in which the flow starts from rest with the
/// stator at rest ([`start_direction`]); in that direction: locked while the clutch holds
/// (T_s ≥ 0), else free-wheeling if that has a steady state with ω_s ≥ 0, else no flow (Q = 0,
/// zero torques, ω_s = ω_t). Where the flow could start either way and that gives no flow, the
/// other direction's flowing steady state if it has one. A flow held at rest gives no flow with
/// ω_s = 0.
pub fn steady_state<T: Scalar>(
    g: &HtGeometry<T>,
    pump_speed_rad_s: T,
    turbine_speed_rad_s: T,
) -> CoreResult<HtSteadyState<T>> {
    steady_state_with(&HtConstants::new(g), pump_speed_rad_s, turbine_speed_rad_s)
}

/// [`steady_state`] with the geometry's constants computed beforehand (once for many points).
pub fn steady_state_with<T: Scalar>(
    k: &HtConstants<T>,
    pump_speed_rad_s: T,
    turbine_speed_rad_s: T,
) -> CoreResult<HtSteadyState<T>> {
    try_steady_state(k, pump_speed_rad_s, turbine_speed_rad_s)
        .map_err(|e| e.error(pump_speed_rad_s.re(), turbine_speed_rad_s.re()))
}

/// [`steady_state_with`] with the reason of a failure instead of its error.
pub fn try_steady_state<T: Scalar>(
    k: &HtConstants<T>,
    pump_speed_rad_s: T,
    turbine_speed_rad_s: T,
) -> Result<HtSteadyState<T>, SteadyFailure> {
    let (wp, wt) = (pump_speed_rad_s, turbine_speed_rad_s);
    if !wp.re().is_finite() {
        return Err(SteadyFailure::PumpSpeed);
    }
    if !wt.re().is_finite() {
        return Err(SteadyFailure::TurbineSpeed);
    }
    // the locked balances: their constant terms are F_Q(0±) with the stator at rest, which decide
    // the direction; the forward one is the drive state's own balance (the reverse one is built
    // again where it is needed, so that only its constant term is computed here once inlined)
    let zero = Quad::cst(T::cst(0.0));
    let fw_locked = balance(k, wp, wt, zero);
    let (forward, reverse) = (fw_locked.residual.c[0].re(), reverse_balance(k, wp, wt, zero).residual.c[0].re());
    if !(forward.is_finite() && reverse.is_finite()) {
        return Err(SteadyFailure::Overflow);
    }
    let direction = direction_from_forces(forward, reverse);
    if direction == 0 {
        return Ok(no_flow(T::cst(0.0)));
    }
    let solve = |sign: i8, mode: StatorMode| match (sign > 0, mode) {
        (true, StatorMode::Locked) => forward_state(k, wp, wt, mode, fw_locked),
        (true, _) => solve_mode(k, wp, wt, mode),
        (false, _) => reverse_state(k, wp, wt, mode, reverse_balance(k, wp, wt, stator_speed(k, wp, wt, mode, true))),
    };
    let locked = if direction > 0 {
        forward_state(k, wp, wt, StatorMode::Locked, fw_locked)
    } else {
        reverse_state(k, wp, wt, StatorMode::Locked, reverse_balance(k, wp, wt, zero))
    };
    let locked = locked.ok_or(SteadyFailure::Overflow)?;
    let first = with_clutch(locked, || solve(direction, StatorMode::FreeWheeling), wt)?;
    // where the direction the flow starts in has no flowing steady state, the other direction's is
    // taken if it has one: the free-wheeling stator spins up while the flow dies away and the flow
    // then settles in the other direction (coast just above SR 1: Appendix D at SR 1.0084–1.0303
    // starts forwards with the stator at rest and settles on reverse flow, as the transient does)
    if first.mode == StatorMode::NoFlow {
        let other = match solve(-direction, StatorMode::Locked) {
            Some(locked) => with_clutch(locked, || solve(-direction, StatorMode::FreeWheeling), wt)?,
            None => match solve(-direction, StatorMode::FreeWheeling) {
                Some(free) if free.is_finite() && free.stator_speed_rad_s.re() >= 0.0 => free,
                _ => first,
            },
        };
        if other.mode != StatorMode::NoFlow {
            return Ok(other);
        }
    }
    Ok(first)
}

/// The one-way clutch on a locked solution: kept while it holds (T_s ≥ 0), else the free-wheeling
/// one if it has ω_s ≥ 0, else no flow with ω_s = ω_t.
fn with_clutch<T: Scalar>(
    locked: HtSteadyState<T>,
    free: impl FnOnce() -> Option<HtSteadyState<T>>,
    wt: T,
) -> Result<HtSteadyState<T>, SteadyFailure> {
    if !locked.is_finite() {
        return Err(SteadyFailure::Overflow);
    }
    if locked.stator_torque_nm.re() >= 0.0 {
        return Ok(locked);
    }
    match free() {
        Some(free) if !free.is_finite() => Err(SteadyFailure::Overflow),
        Some(free) if free.stator_speed_rad_s.re() >= 0.0 => Ok(free),
        _ => Ok(no_flow(wt)),
    }
}

/// The drive steady state with the thesis's equations only (Q ≥ 0), 0 ≤ SR ≤ 1 and ω_p > 0, as
/// before issue 11: the locked stator's largest root, an error where it has no positive root.
/// [`steady_state`] gives the same numbers wherever the flow starts forwards; the fits
/// ([`crate::batch::ht_ratio_gradients`]) fit the drive characteristic with this one, so that a
/// trial geometry without a forward flow counts as a failure, as it did.
pub fn drive_steady_state<T: Scalar>(
    g: &HtGeometry<T>,
    pump_speed_rad_s: T,
    turbine_speed_rad_s: T,
) -> CoreResult<HtSteadyState<T>> {
    let (wp, wt) = (pump_speed_rad_s, turbine_speed_rad_s);
    let sr = wt.re() / wp.re();
    if !(wp.re().is_finite() && wp.re() > 0.0) {
        return Err(CoreError::of(InputSource::Drive, "pump_speed_rad_s", wp.re(), "a finite, positive pump speed"));
    }
    if !(0.0..=1.0).contains(&sr) {
        return Err(CoreError::of(InputSource::Drive, "speed_ratio", sr, "a speed ratio from 0 to 1 (drive)"));
    }
    let k = HtConstants::new(g);
    let locked = solve_mode(&k, wp, wt, StatorMode::Locked).ok_or_else(|| {
        CoreError::new(
            "speed_ratio",
            sr,
            "an operating point where the locked-stator head exceeds the shock losses (no steady state with positive flow for these parameters)",
        )
    })?;
    with_clutch(locked, || solve_mode(&k, wp, wt, StatorMode::FreeWheeling), wt).map_err(|e| e.error(wp.re(), wt.re()))
}

/// The coupling point: the speed ratio in (0, 1) where the locked-stator holding torque changes
/// sign. The steady state is homogeneous in speed (q ∝ ω_p), so it does not depend on the pump
/// speed. None if the holding torque keeps one sign on [0, 1].
///
/// Safeguarded Newton iteration on T_s(SR) with the exact derivative from [`Dual`].
pub fn coupling_point(g: &HtGeometry<f64>) -> Option<f64> {
    let k = HtConstants::new(&g.to_dual());
    let ts = |sr: f64| -> Option<(f64, f64)> {
        let s = solve_mode(&k, Dual::cst(1.0), Dual::var(sr), StatorMode::Locked)?;
        Some((s.stator_torque_nm.v, s.stator_torque_nm.d))
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    let (f_lo, _) = ts(lo)?;
    let (f_hi, _) = ts(hi)?;
    if f_lo <= 0.0 || f_hi >= 0.0 {
        return None;
    }
    let mut x = lo + (hi - lo) * f_lo / (f_lo - f_hi);
    for _ in 0..100 {
        let (f, df) = ts(x)?;
        if f > 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - f / df;
        let next = if df != 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if (next - x).abs() <= 1e-15 || hi - lo <= 1e-15 {
            return Some(next);
        }
        x = next;
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_overflowing_steady_state_is_an_error_not_no_flow() {
        let g = HtGeometry::appendix_d();
        for wp in [1e155, 1e200, 1e300] {
            for sr in [0.0, 0.5, 0.95, 1.0] {
                let e = steady_state(&g, wp, sr * wp).unwrap_err();
                assert_eq!((e.field.as_str(), e.source), ("pump_speed_rad_s", InputSource::Drive), "{wp} {sr}");
            }
        }
        // below the overflow the modes are those of ordinary speeds
        let s = steady_state(&g, 1e100, 0.0).unwrap();
        assert_eq!(s.mode, StatorMode::Locked);
        assert!(s.is_finite());
    }

    const WP: f64 = crate::units::REFERENCE_PUMP_SPEED_RAD_S;

    fn eq_2_15_rhs(g: &HtGeometry<f64>, wp: f64, wt: f64, ws: f64, flow: f64) -> f64 {
        // Direct transcription of the right-hand side of eq 2.15 with eqs 2.19–2.25, Q > 0.
        use HtParam::*;
        let v = |p: HtParam| g.get(p);
        let rho = v(FluidDensity);
        let q = flow / v(FlowArea);
        let (rp, rt, rs) = (v(PumpExitRadius), v(TurbineExitRadius), v(StatorExitRadius));
        let (tp, tt, ts) = (v(PumpExitAngle).tan(), v(TurbineExitAngle).tan(), v(StatorExitAngle).tan());
        let (tpp, ttt, tss) = (v(PumpInletAngle).tan(), v(TurbineInletAngle).tan(), v(StatorInletAngle).tan());
        let head = rho
            * (rp * rp * wp * wp + rt * rt * wt * wt + rs * rs * ws * ws
                - rs * rs * wp * ws
                - rp * rp * wt * wp
                - rt * rt * ws * wt)
            + wp * rho * (rp * tp - rs * ts) * q
            + wt * rho * (rt * tt - rp * tp) * q
            + ws * rho * (rs * ts - rt * tt) * q;
        let vsh = [rs * (ws - wp) + q * (ts - tpp), rp * (wp - wt) + q * (tp - ttt), rt * (wt - ws) + q * (tt - tss)];
        let c = [v(PumpShockLoss), v(TurbineShockLoss), v(StatorShockLoss)];
        let vre2: f64 = [tp, tt, ts].iter().map(|t| q * q * (1.0 + t * t)).sum();
        let ploss =
            rho / 2.0 * (0..3).map(|i| c[i] * vsh[i] * vsh[i]).sum::<f64>() + rho * v(FrictionLoss) / 2.0 * vre2;
        head - ploss
    }

    fn scale_of_head(wp: f64) -> f64 {
        840.0 * 0.12f64.powi(2) * wp * wp
    }

    #[test]
    fn closed_form_satisfies_eq_2_15_to_round_off() {
        let g = HtGeometry::appendix_d();
        for i in 0..=20 {
            let wt = WP * i as f64 / 20.0;
            let s = steady_state(&g, WP, wt).unwrap();
            let r = eq_2_15_rhs(&g, WP, wt, s.stator_speed_rad_s, s.flow_m3_s);
            if s.mode != StatorMode::NoFlow {
                assert!(r.abs() < 1e-12 * scale_of_head(WP), "SR {}: residual {r}", i as f64 / 20.0);
            }
        }
    }

    #[test]
    fn torques_sum_to_zero_at_a_locked_steady_state() {
        let g = HtGeometry::appendix_d();
        for sr in [0.0, 0.2, 0.5, 0.8] {
            let s = steady_state(&g, WP, sr * WP).unwrap();
            assert_eq!(s.mode, StatorMode::Locked);
            // external torques: T_p + T_t + T_s with T_t = −delivered
            let sum = s.pump_torque_nm - s.turbine_torque_nm + s.stator_torque_nm;
            assert!(sum.abs() < 1e-12 * s.pump_torque_nm, "SR {sr}: {sum}");
            assert!(s.stator_torque_nm > 0.0);
        }
    }

    #[test]
    fn appendix_d_reference_is_close_to_table_c1_at_stall() {
        // physics.md §1: CF(0) ≈ 2.94e-3 N·m/(rad/s)², TR(0) ≈ 2.12 (Table C.1: 3.272e-3, 2.14)
        let s = steady_state(&HtGeometry::appendix_d(), WP, 0.0).unwrap();
        let cf = s.pump_torque_nm / (WP * WP);
        assert!((cf - 2.944e-3).abs() < 1e-6, "{cf}");
        assert!((s.torque_ratio() - 2.123).abs() < 1e-3);
    }

    #[test]
    fn coupling_point_separates_locked_and_free_wheeling() {
        let g = HtGeometry::appendix_d();
        let sr_c = coupling_point(&g).unwrap();
        assert!((0.85..0.95).contains(&sr_c), "{sr_c}");
        let ts = |sr: f64| locked_steady_state(&g, WP, sr * WP).unwrap().stator_torque_nm;
        assert!(ts(sr_c).abs() < 1e-9, "{}", ts(sr_c));
        assert!(ts(sr_c - 1e-6) > 0.0 && ts(sr_c + 1e-6) < 0.0);
        // below: locked and multiplying torque; above: free-wheeling with TR = 1
        let below = steady_state(&g, WP, (sr_c - 1e-3) * WP).unwrap();
        assert_eq!(below.mode, StatorMode::Locked);
        assert!(below.torque_ratio() > 1.0);
        for sr in [sr_c + 1e-3, 0.93, 0.95, 0.98] {
            let s = steady_state(&g, WP, sr * WP).unwrap();
            assert_eq!(s.mode, StatorMode::FreeWheeling, "SR {sr}");
            assert!((s.torque_ratio() - 1.0).abs() < 1e-12, "SR {sr}: TR {}", s.torque_ratio());
            assert!(s.stator_speed_rad_s > 0.0 && s.flow_m3_s > 0.0);
        }
        // the free-wheeling branch starts from the locked solution: continuous flow and torque
        let (l, f) =
            (locked_steady_state(&g, WP, sr_c * WP).unwrap(), steady_state(&g, WP, (sr_c + 1e-9) * WP).unwrap());
        assert!((l.flow_m3_s - f.flow_m3_s).abs() < 1e-7 && f.stator_speed_rad_s.abs() < 1e-4);
    }

    #[test]
    fn speed_ratio_one_has_no_flow_and_stator_at_pump_speed() {
        let s = steady_state(&HtGeometry::appendix_d(), WP, WP).unwrap();
        assert_eq!(s.mode, StatorMode::NoFlow);
        assert_eq!(s.flow_m3_s, 0.0);
        assert_eq!(s.pump_torque_nm, 0.0);
        assert_eq!(s.stator_speed_rad_s, WP);
        assert_eq!(s.torque_ratio(), 1.0);
    }

    #[test]
    fn only_non_finite_speeds_are_errors() {
        let g = HtGeometry::appendix_d();
        assert_eq!(steady_state(&g, f64::NAN, 0.0).unwrap_err().field, "pump_speed_rad_s");
        assert_eq!(steady_state(&g, WP, f64::INFINITY).unwrap_err().field, "turbine_speed_rad_s");
        for (wp, wt) in [(WP, 1.1 * WP), (WP, -0.1 * WP), (-WP, 0.0), (0.0, WP), (0.0, 0.0), (-WP, -3.0 * WP)] {
            let s = steady_state(&g, wp, wt).unwrap();
            assert!(s.is_finite(), "{wp} {wt}");
        }
        // both speeds zero: nothing moves
        let s = steady_state(&g, 0.0, 0.0).unwrap();
        assert_eq!((s.mode, s.flow_m3_s, s.pump_torque_nm, s.stator_speed_rad_s), (StatorMode::NoFlow, 0.0, 0.0, 0.0));
    }

    fn with_shock(c: f64) -> HtGeometry<f64> {
        let mut v = HtGeometry::appendix_d().values;
        for p in [HtParam::PumpShockLoss, HtParam::TurbineShockLoss, HtParam::StatorShockLoss] {
            v[p.index()] = c;
        }
        HtGeometry::new(v).unwrap()
    }

    /// The rule at Q = 0 (docs/models.md, "At Q = 0"): with shock coefficients above 1 a band of held
    /// flow (F_Q(0⁺) ≤ 0 ≤ F_Q(0⁻)) gives no flow with the stator at rest; below 1 a band where both
    /// directions could start, decided by the larger force, and a flowing steady state is returned.
    #[test]
    fn the_flow_direction_at_rest_decides_between_steady_states() {
        // Appendix D, stator at rest: the centrifugal head vanishes at SR = √((R_p² − R_s²)/(R_p² − R_t²))
        let sr0 = ((0.0144f64 - 0.0036) / (0.0144 - 0.004225)).sqrt();
        let g = HtGeometry::appendix_d();
        let (fp, fm) = zero_flow_forces(&g, WP, sr0 * WP);
        assert!(fp.abs() < 1e-9 * scale_of_head(WP) && (fp - fm).abs() < 1e-9 * scale_of_head(WP));
        let held = with_shock(2.0);
        let (fp, fm) = zero_flow_forces(&held, WP, sr0 * WP);
        assert!(fp < 0.0 && fm > 0.0, "{fp} {fm}");
        assert_eq!(start_direction(&held, WP, sr0 * WP), 0);
        let s = steady_state(&held, WP, sr0 * WP).unwrap();
        assert_eq!((s.mode, s.flow_m3_s, s.stator_speed_rad_s), (StatorMode::NoFlow, 0.0, 0.0));
        let both = with_shock(0.5);
        for sr in [sr0 - 0.01, sr0, sr0 + 0.01] {
            let (fp, fm) = zero_flow_forces(&both, WP, sr * WP);
            assert!(fp > 0.0 && fm < 0.0, "SR {sr}: {fp} {fm}");
            let expected = if fp >= -fm { 1 } else { -1 };
            assert_eq!(start_direction(&both, WP, sr * WP), expected, "SR {sr}");
            let s = steady_state(&both, WP, sr * WP).unwrap();
            assert_ne!(s.mode, StatorMode::NoFlow, "SR {sr}: {s:?}");
        }
    }

    #[test]
    fn steady_state_scales_with_pump_speed() {
        // homogeneity: Q ∝ ω_p, torques ∝ ω_p²
        let g = HtGeometry::appendix_d();
        let (a, b) = (steady_state(&g, WP, 0.4 * WP).unwrap(), steady_state(&g, 2.0 * WP, 0.8 * WP).unwrap());
        assert!((b.flow_m3_s / a.flow_m3_s - 2.0).abs() < 1e-12);
        assert!((b.pump_torque_nm / a.pump_torque_nm - 4.0).abs() < 1e-12);
    }

    #[test]
    fn parameter_checks_name_the_field() {
        let mut v = HtGeometry::appendix_d().values;
        v[HtParam::FlowArea.index()] = -0.01;
        assert_eq!(HtGeometry::new(v).unwrap_err().field, "flow_area_m2");
        let mut v = HtGeometry::appendix_d().values;
        v[HtParam::StatorExitAngle.index()] = 95f64.to_radians();
        assert_eq!(HtGeometry::new(v).unwrap_err().field, "stator_exit_angle_rad");
        let mut v = HtGeometry::appendix_d().values;
        for p in [HtParam::PumpShockLoss, HtParam::TurbineShockLoss, HtParam::StatorShockLoss, HtParam::FrictionLoss] {
            v[p.index()] = 0.0;
        }
        assert_eq!(HtGeometry::new(v).unwrap_err().field, "friction_loss");
    }

    /// Every derivative the dual numbers produce (with respect to each parameter and both
    /// speeds, for each output and each stator mode) against central finite differences.
    #[test]
    fn analytic_derivatives_match_finite_differences() {
        let g = HtGeometry::appendix_d();
        let outputs = |s: &HtSteadyState<Dual>| {
            [s.flow_m3_s, s.pump_torque_nm, s.turbine_torque_nm, s.stator_torque_nm, s.stator_speed_rad_s]
        };
        let outputs_f = |s: &HtSteadyState<f64>| {
            [s.flow_m3_s, s.pump_torque_nm, s.turbine_torque_nm, s.stator_torque_nm, s.stator_speed_rad_s]
        };
        for sr in [0.0, 0.3, 0.75, 0.95, -0.5, 1.5, 3.0] {
            let wt = sr * WP;
            for p in HtParam::ALL {
                let ad = steady_state(&g.seeded(p), Dual::cst(WP), Dual::cst(wt)).unwrap();
                let x = g.values[p.index()];
                let h = 1e-6 * x.abs().max(1e-2);
                let eval = |dx: f64| {
                    let mut v = g.values;
                    v[p.index()] = x + dx;
                    steady_state(&HtGeometry { values: v }, WP, wt).unwrap()
                };
                let (a, b) = (eval(-h), eval(h));
                assert_eq!(a.mode, b.mode);
                for (k, (o, (fa, fb))) in
                    outputs(&ad).iter().zip(outputs_f(&a).iter().zip(outputs_f(&b).iter())).enumerate()
                {
                    let fd = (fb - fa) / (2.0 * h);
                    let tol = 1e-6 * (fd.abs() + o.v.abs() / x.abs().max(1e-2));
                    assert!((o.d - fd).abs() <= tol, "SR {sr}, {}, output {k}: {} vs {fd}", p.key(), o.d);
                }
            }
            for which in 0..2 {
                let (dp, dt) = if which == 0 { (Dual::var(WP), Dual::cst(wt)) } else { (Dual::cst(WP), Dual::var(wt)) };
                let ad = steady_state(&g.to_dual(), dp, dt).unwrap();
                let h = 1e-4;
                let eval = |d: f64| {
                    if which == 0 {
                        steady_state(&g, WP + d, wt).unwrap()
                    } else {
                        steady_state(&g, WP, wt + d).unwrap()
                    }
                };
                let (a, b) = (eval(-h), eval(h));
                for (o, (fa, fb)) in outputs(&ad).iter().zip(outputs_f(&a).iter().zip(outputs_f(&b).iter())) {
                    let fd = (fb - fa) / (2.0 * h);
                    assert!(
                        (o.d - fd).abs() <= 1e-6 * (fd.abs() + o.v.abs() / WP),
                        "SR {sr}, speed {which}: {} vs {fd}",
                        o.d
                    );
                }
            }
        }
    }

    #[test]
    fn largest_root_is_accurate_when_coefficients_cancel() {
        // (q − 1e8)(q − 1e-8) = q² − (1e8 + 1e-8) q + 1
        let p = Quad { c: [1.0, -(1e8 + 1e-8), 1.0] };
        assert!((largest_real_root(p).unwrap() - 1e8).abs() < 1e-6);
        let p = Quad { c: [-1.0, 0.0, 1.0] };
        assert_eq!(largest_real_root(p).unwrap(), 1.0);
        assert!(largest_real_root(Quad { c: [1.0, 0.0, 1.0] }).is_none());
    }

    /// A scalar that counts the tangents taken (issue 16: the steady state took the six blade-angle
    /// tangents 2–4 times per point, 54 % of its time).
    #[derive(Debug, Clone, Copy)]
    struct Counted(f64);

    thread_local! {
        static TANGENTS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
    }

    impl std::ops::Add for Counted {
        type Output = Self;
        fn add(self, o: Self) -> Self {
            Self(self.0 + o.0)
        }
    }
    impl std::ops::Sub for Counted {
        type Output = Self;
        fn sub(self, o: Self) -> Self {
            Self(self.0 - o.0)
        }
    }
    impl std::ops::Mul for Counted {
        type Output = Self;
        fn mul(self, o: Self) -> Self {
            Self(self.0 * o.0)
        }
    }
    impl std::ops::Div for Counted {
        type Output = Self;
        fn div(self, o: Self) -> Self {
            Self(self.0 / o.0)
        }
    }
    impl std::ops::Neg for Counted {
        type Output = Self;
        fn neg(self) -> Self {
            Self(-self.0)
        }
    }
    impl Scalar for Counted {
        fn cst(v: f64) -> Self {
            Self(v)
        }
        fn re(self) -> f64 {
            self.0
        }
        fn sqrt(self) -> Self {
            Self(self.0.sqrt())
        }
        fn tan(self) -> Self {
            TANGENTS.with(|c| c.set(c.get() + 1));
            Self(self.0.tan())
        }
    }

    /// One steady state takes the six tangents once, and a geometry's constants serve any number
    /// of points without another: the same numbers, bit for bit, as the plain `f64` path.
    #[test]
    fn a_steady_state_takes_the_six_tangents_once_per_geometry() {
        let g = HtGeometry::appendix_d();
        let counted = HtGeometry { values: g.values.map(Counted) };
        let taken = || TANGENTS.with(|c| c.get());
        let before = taken();
        steady_state(&counted, Counted(WP), Counted(0.5 * WP)).unwrap();
        assert_eq!(taken() - before, 6, "tangents of one steady state");
        let k = HtConstants::new(&counted);
        let before = taken();
        for wp in [-WP, 0.0, WP] {
            for sr in [-3.0, -0.5, 0.0, 0.5, 0.95, 0.995, 1.0, 1.02, 1.2, 3.0] {
                let s = steady_state_with(&k, Counted(wp), Counted(sr * WP)).unwrap();
                let f = steady_state(&g, wp, sr * WP).unwrap();
                let bits = |v: [f64; 5]| v.map(f64::to_bits);
                assert_eq!(
                    bits([
                        s.flow_m3_s.0,
                        s.stator_speed_rad_s.0,
                        s.pump_torque_nm.0,
                        s.turbine_torque_nm.0,
                        s.stator_torque_nm.0
                    ]),
                    bits([
                        f.flow_m3_s,
                        f.stator_speed_rad_s,
                        f.pump_torque_nm,
                        f.turbine_torque_nm,
                        f.stator_torque_nm
                    ]),
                    "{wp} {sr}"
                );
                assert_eq!(s.mode, f.mode);
            }
        }
        assert_eq!(taken(), before, "tangents of 30 steady states from the constants");
    }

    #[test]
    fn steady_mode_codes_names_and_the_no_flow_torque_ratio() {
        assert_eq!(
            steady_mode_names(),
            vec![(0, "locked"), (1, "free-wheeling"), (2, "no-flow"), (-1, "no-steady-state")]
        );
        assert_eq!(steady_torque_ratio(StatorMode::NoFlow.code(), 0.0, 0.0), 1.0);
        assert_eq!(steady_torque_ratio(StatorMode::Locked.code(), 100.0, 180.0), 1.8);
        assert_eq!(steady_torque_ratio(StatorMode::FreeWheeling.code(), 0.0, 3.0), 3.0);
        assert!(steady_torque_ratio(NO_STEADY_STATE, f64::NAN, f64::NAN).is_nan());
        // the rule on columns agrees with the steady state's own
        let g = HtGeometry::appendix_d();
        for sr in [0.0, 0.5, 0.9, 0.99, 1.0] {
            let s = steady_state(&g, 200.0, sr * 200.0).unwrap();
            let tr = steady_torque_ratio(s.mode.code(), s.pump_torque_nm, s.turbine_torque_nm);
            assert_eq!(tr, s.torque_ratio());
        }
    }
}
