//! The backward (quasi-static) operating point: given the turbine speed ω_t and the torque
//! delivered to the transmission T (the torque the gearbox needs, positive in drive, negative in
//! coast), the pump speed ω_p and pump torque T_p of the steady state (docs/operating_point.md).
//!
//! **Normalisation.** Every model's steady torques are homogeneous of degree 2 in the speeds
//! (`T(λω_p, λω_t) = λ²·T(ω_p, ω_t)` for λ > 0), so with `s = sign(ω_t)`, `u = ω_p/|ω_t|` and
//! `τ = T/ω_t²` the problem is one equation in one unknown, `F_s(u) = τ`, where
//! `F_s(u) = T_del(u, s)` is the forward steady state at turbine speed ±1 rad/s. `F_s` does not
//! depend on the point, so it is analysed once per converter ([`Backward::table`],
//! [`Backward::hrovat_tobler`]) and split into **monotone pieces**: at the table's knots, at the
//! region boundaries of [`Characteristic::torques`] and at the extrema found between them.
//!
//! **Table model, closed form per segment (as VECTO does).** On a segment of the table where TR
//! and CF are linear in SR (`TR = α + β·SR`, `CF = γ + δ·SR`, capacity-factor interpolation) and
//! SR = 1/u lies in the pump-referred region, `T = TR·CF·ω_p|ω_p|` gives
//! `F(u) = sign(u)·(αu + β)(γu + δ)`, a quadratic in u solved in closed form. Everywhere else (the
//! K-factor interpolation, a quartic in u; the turbine-referred regions; where the passivity
//! projection bounds TR) the piece is solved by Brent's method on the forward model, which also
//! checks every closed-form root: each root is polished by a Newton step on the forward torques.
//!
//! **Hrovat & Tobler** at steady state: the same monotone pieces, found on a grid of speed ratios,
//! each solved by Brent's method on [`steady_state_with`]; a piece across which the steady state jumps
//! (a change of flow direction or stator mode) holds no root and is skipped.
//!
//! **Which root.** The pump is the engine's: it turns forwards (`ω_p ≥ 0`) whichever way the
//! turbine turns (a vehicle rolling back in drive has ω_t < 0 and ω_p > 0). Where several pump
//! speeds give the torque, the forward one with the smallest ω_p (VECTO: the lowest pump speed). If
//! only a pump turned backwards gives it (coast torques beyond what the converter takes with the
//! pump at rest, a negative torque at standstill or while rolling back), the backward root with the
//! smallest |ω_p| is returned, flagged [`Reason::PumpBackwards`].

use std::sync::atomic::AtomicBool;

use super::hrovat_tobler::{steady_state_with, steady_torque_ratio, HtConstants, HtGeometry};
use super::table::{Characteristic, Interpolation};
use crate::batch::parallel_map_cancellable;
use crate::error::{CoreError, CoreResult, InputSource};

/// Why a backward operating point is what it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reason {
    /// A steady state with the pump turning forwards, within the pump speed limit.
    Ok = 0,
    /// Both speeds and the torque are zero: the converter at rest (SR, TR, efficiency NaN).
    AtRest = 1,
    /// Turbine speed or torque not a finite number: every value NaN.
    NonFiniteInput = 2,
    /// The steady state needs a pump speed above the limit (values given).
    AbovePumpSpeedLimit = 3,
    /// Only a pump turning backwards, against the engine, gives this torque (values given).
    PumpBackwards = 4,
    /// The model has no steady state with this torque at this turbine speed: every value NaN.
    NoSteadyState = 5,
    /// The steady state's speeds or torques overflow: every value NaN.
    Overflow = 6,
    /// A turbine power given at zero turbine speed: no torque follows from it (every value NaN).
    PowerAtStandstill = 7,
}

impl Reason {
    pub const ALL: [Reason; 8] = [
        Self::Ok,
        Self::AtRest,
        Self::NonFiniteInput,
        Self::AbovePumpSpeedLimit,
        Self::PumpBackwards,
        Self::NoSteadyState,
        Self::Overflow,
        Self::PowerAtStandstill,
    ];
    /// The code in batch outputs.
    pub fn code(self) -> u8 {
        self as u8
    }
    /// The name in outputs (the `reason` column).
    pub fn key(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::AtRest => "at-rest",
            Self::NonFiniteInput => "non-finite-input",
            Self::AbovePumpSpeedLimit => "above-pump-speed-limit",
            Self::PumpBackwards => "pump-backwards",
            Self::NoSteadyState => "no-steady-state",
            Self::Overflow => "overflow",
            Self::PowerAtStandstill => "power-at-standstill",
        }
    }
    /// Whether a point with this reason is a valid operating point (`valid` column).
    pub fn valid(self) -> bool {
        matches!(self, Self::Ok | Self::AtRest)
    }
}

/// One backward operating point. Speeds in rad/s, torques in N·m (pump torque: the external
/// torque on the pump, positive in drive); `speed_ratio = ω_t/ω_p`, `torque_ratio = T/T_p` by the
/// forward model's rule, `efficiency = SR·TR`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BackwardPoint {
    pub pump_speed_rad_s: f64,
    pub pump_torque_nm: f64,
    pub speed_ratio: f64,
    pub torque_ratio: f64,
    pub efficiency: f64,
    pub reason: Reason,
}

impl BackwardPoint {
    fn empty(reason: Reason) -> Self {
        let nan = f64::NAN;
        Self {
            pump_speed_rad_s: nan,
            pump_torque_nm: nan,
            speed_ratio: nan,
            torque_ratio: nan,
            efficiency: nan,
            reason,
        }
    }
}

/// A monotone piece of `F_s` on `[lo, hi]` (either end may be infinite), `F_s(u) = q0 + q1·u + q2·u²`
/// there when `quad` is set.
#[derive(Debug, Clone, Copy)]
struct Piece {
    lo: f64,
    hi: f64,
    f_lo: f64,
    f_hi: f64,
    quad: Option<[f64; 3]>,
}

/// The forward model behind a [`Backward`].
#[derive(Debug, Clone)]
enum Model {
    Table(Characteristic),
    /// The geometry's steady-state constants, computed once ([`steady_state_with`]; they were
    /// computed at each of the thousands of steady states a backward model is built from).
    HrovatTobler(HtConstants<f64>),
}

/// Forward steady state at one point: delivered torque, pump torque and torque ratio.
#[derive(Debug, Clone, Copy)]
struct Forward {
    delivered_nm: f64,
    pump_nm: f64,
    torque_ratio: f64,
    /// ∂T_del/∂ω_p where the model gives it.
    slope: Option<f64>,
}

impl Model {
    fn forward(&self, wp: f64, wt: f64) -> Option<Forward> {
        match self {
            Self::Table(c) => {
                let t = c.torques(wp, wt);
                Some(Forward {
                    delivered_nm: t.delivered_nm,
                    pump_nm: t.pump_nm,
                    torque_ratio: t.torque_ratio,
                    slope: Some(t.d_delivered[0]),
                })
            }
            Self::HrovatTobler(k) => {
                let s = steady_state_with(k, wp, wt).ok()?;
                Some(Forward {
                    delivered_nm: s.turbine_torque_nm,
                    pump_nm: s.pump_torque_nm,
                    torque_ratio: steady_torque_ratio(s.mode.code(), s.pump_torque_nm, s.turbine_torque_nm),
                    slope: None,
                })
            }
        }
    }
    /// `F_s(u)`, NaN where the model has no steady state.
    fn f(&self, u: f64, s: f64) -> f64 {
        self.forward(u, s).map_or(f64::NAN, |f| f.delivered_nm)
    }
}

/// A converter model prepared for backward operating points: `F_s` split into monotone pieces
/// for both turbine directions, in the order the roots are preferred.
#[derive(Debug, Clone)]
pub struct Backward {
    model: Model,
    /// Pieces for s = +1 and s = −1.
    pieces: [Vec<Piece>; 2],
}

/// Interior samples per interval between two knots when looking for extrema.
const SAMPLES: usize = 12;
/// Relative tolerance of a root's torque residual (piece check) and of a closed form's check.
const RESIDUAL_TOL: f64 = 1e-10;

impl Backward {
    /// The table model (and the quasi-dynamic model, whose steady state is its table).
    pub fn table(c: &Characteristic) -> Self {
        let s_e = c.pump_referred_limit();
        let mut knots = vec![0.0, -1.0, 1.0 / s_e];
        for &sr in c.speed_ratio() {
            if sr > 0.0 && sr <= s_e {
                knots.push(1.0 / sr);
            }
            if (-1.0..0.0).contains(&sr) {
                knots.push(1.0 / sr);
            }
            if sr > 0.0 && sr < 1.0 / s_e {
                knots.push(sr); // the mirror's knots in x = ω_p/ω_t
            }
        }
        // where the passivity projection may start in the held regions: TR = 1/SR, u = TR
        let tr = c.torque_ratio();
        knots.extend([tr[0], tr[tr.len() - 1]].iter().filter(|v| v.is_finite() && **v > 0.0));
        let model = Model::Table(c.clone());
        let pieces = [1.0, -1.0].map(|s| pieces_of(&model, s, &knots));
        Self { model, pieces }
    }

    /// The Hrovat & Tobler model at steady state ([`steady_state_with`], its constants computed once).
    pub fn hrovat_tobler(g: &HtGeometry<f64>) -> Self {
        let mut knots = vec![0.0, 1.0, -1.0];
        for i in 1..=150 {
            let sr = f64::from(i) / 50.0; // SR 0.02 … 3
            knots.extend([1.0 / sr, -1.0 / sr]);
            if sr < 1.0 {
                knots.extend([sr, -sr]);
            }
        }
        let model = Model::HrovatTobler(HtConstants::new(g));
        let pieces = [1.0, -1.0].map(|s| pieces_of(&model, s, &knots));
        Self { model, pieces }
    }

    /// The operating point at turbine speed `wt` (rad/s) delivering torque `t` (N·m) with the pump
    /// speed at most `limit` (rad/s, `f64::INFINITY` for none).
    pub fn point(&self, wt: f64, t: f64, limit: f64) -> BackwardPoint {
        if !(wt.is_finite() && t.is_finite()) {
            return BackwardPoint::empty(Reason::NonFiniteInput);
        }
        if wt == 0.0 && t == 0.0 {
            let mut p = BackwardPoint::empty(Reason::AtRest);
            p.pump_speed_rad_s = 0.0;
            p.pump_torque_nm = 0.0;
            return p;
        }
        let found = if wt == 0.0 { self.stall(t) } else { self.solve(wt, t) };
        let Some((wp, fw)) = found else { return BackwardPoint::empty(Reason::NoSteadyState) };
        let (wp, fw) = at_rest_if_round_off(wp, fw, wt, |w| self.model.forward(w, wt));
        if !(wp.is_finite() && fw.pump_nm.is_finite() && fw.delivered_nm.is_finite()) {
            return BackwardPoint::empty(Reason::Overflow);
        }
        let reason = if wp < 0.0 {
            Reason::PumpBackwards
        } else if wp.abs() > limit {
            Reason::AbovePumpSpeedLimit
        } else {
            Reason::Ok
        };
        let sr = wt / wp;
        BackwardPoint {
            pump_speed_rad_s: wp,
            pump_torque_nm: fw.pump_nm,
            speed_ratio: sr,
            torque_ratio: fw.torque_ratio,
            efficiency: sr * fw.torque_ratio,
            reason,
        }
    }

    /// Turbine at rest: `T = k_±·ω_p²` on either side of ω_p = 0, `k_± = T_del(±1, 0)`; the pump
    /// turning forwards preferred (a negative torque at rest needs it turned backwards).
    fn stall(&self, t: f64) -> Option<(f64, Forward)> {
        let side = |sign: f64| {
            let k = self.model.f(sign, 0.0);
            let w2 = t / k;
            (w2.is_finite() && w2 > 0.0).then(|| sign * w2.sqrt())
        };
        let wp = side(1.0).or_else(|| side(-1.0))?;
        self.polish(wp, 0.0, t, f64::NEG_INFINITY, f64::INFINITY)
    }

    /// `F_s(u) = τ` over the pieces in their order of preference, then `ω_p = u·|ω_t|`.
    fn solve(&self, wt: f64, t: f64) -> Option<(f64, Forward)> {
        let (s, lambda) = (wt.signum(), wt.abs());
        let tau = t / lambda / lambda;
        if !tau.is_finite() {
            // a torque too large for this turbine speed: overflow
            let inf = f64::INFINITY;
            return Some((inf, Forward { delivered_nm: inf, pump_nm: inf, torque_ratio: inf, slope: None }));
        }
        let pieces = &self.pieces[usize::from(s < 0.0)];
        for p in pieces {
            let (lo, hi) = if p.f_lo <= p.f_hi { (p.f_lo, p.f_hi) } else { (p.f_hi, p.f_lo) };
            if !(lo <= tau && tau <= hi) {
                continue;
            }
            let Some(u) = self.root_in(p, s, tau) else { continue };
            let wp = u * lambda;
            return self.polish(wp, wt, t, p.lo * lambda, p.hi * lambda);
        }
        None
    }

    /// The root of `F_s(u) = τ` in piece `p`: its closed form where it has one, else Brent's method;
    /// None where the forward model does not confirm it (a jump, not a root).
    fn root_in(&self, p: &Piece, s: f64, tau: f64) -> Option<f64> {
        let g = |u: f64| self.model.f(u, s) - tau;
        let u = match p.quad.and_then(|q| quadratic_root(q, tau, p.lo, p.hi)) {
            Some(u) => return Some(u), // a continuous piece: checked by the Newton step that follows
            None => {
                let (mut a, mut b) = (p.lo, p.hi);
                let (mut ga, mut gb) = (p.f_lo - tau, p.f_hi - tau);
                // an infinite end: step out until the sign changes
                if a.is_infinite() {
                    (a, ga) = expand(&g, b, gb, -1.0)?;
                } else if b.is_infinite() {
                    (b, gb) = expand(&g, a, ga, 1.0)?;
                }
                brent(&g, a, b, ga, gb)
            }
        };
        // the forward model confirms the root (at a jump of F_s the residual is the jump)
        let scale = [p.f_lo, p.f_hi].iter().filter(|f| f.is_finite()).fold(tau.abs(), |m, f| m.max(f.abs()));
        (g(u).abs() <= RESIDUAL_TOL * scale.max(f64::MIN_POSITIVE)).then_some(u)
    }

    /// One Newton step on the forward torques at the real speeds, kept if it stays in `[lo, hi]` and
    /// lowers the residual (the table gives the exact slope; Hrovat & Tobler's root is Brent's).
    /// Returns the pump speed and the forward steady state there; None without one.
    fn polish(&self, wp: f64, wt: f64, t: f64, lo: f64, hi: f64) -> Option<(f64, Forward)> {
        let f0 = self.model.forward(wp, wt)?;
        let Some(d) = f0.slope.filter(|d| *d != 0.0 && d.is_finite()) else { return Some((wp, f0)) };
        let r0 = f0.delivered_nm - t;
        let next = wp - r0 / d;
        if !(next.is_finite() && lo <= next && next <= hi) || next == wp {
            return Some((wp, f0));
        }
        match self.model.forward(next, wt) {
            Some(f1) if (f1.delivered_nm - t).abs() < r0.abs() => Some((next, f1)),
            _ => Some((wp, f0)),
        }
    }
}

/// A pump speed within round-off of rest (|ω_p| ≤ 1e-12·|ω_t|: the root of the torque the converter
/// gives with the pump at rest, found as ±3e-13 rad/s at 100 rad/s) as the pump at rest, with the
/// forward state there: its sign is noise, and a negative one would flag the point as a backward pump.
fn at_rest_if_round_off(wp: f64, fw: Forward, wt: f64, forward: impl Fn(f64) -> Option<Forward>) -> (f64, Forward) {
    if wp == 0.0 || wp.abs() > PUMP_AT_REST * wt.abs() {
        return (wp, fw);
    }
    forward(0.0).map_or((wp, fw), |at_rest| (0.0, at_rest))
}

/// [`at_rest_if_round_off`]'s bound on |ω_p|/|ω_t|.
const PUMP_AT_REST: f64 = 1e-12;

/// Step from `(a, ga)` in direction `dir` (doubling the distance) until `g` changes sign.
fn expand(g: &dyn Fn(f64) -> f64, a: f64, ga: f64, dir: f64) -> Option<(f64, f64)> {
    let mut step = a.abs().max(1.0);
    for _ in 0..1100 {
        let b = a + dir * step;
        let gb = g(b);
        if !gb.is_finite() || !b.is_finite() {
            return None;
        }
        if gb == 0.0 || (gb > 0.0) != (ga > 0.0) {
            return Some((b, gb));
        }
        step *= 2.0;
    }
    None
}

/// The root in `[lo, hi]` of `q0 + q1 u + q2 u² = τ` (cancellation-free form), None without one.
fn quadratic_root(q: [f64; 3], tau: f64, lo: f64, hi: f64) -> Option<f64> {
    let (c, b, a) = (q[0] - tau, q[1], q[2]);
    let roots: Vec<f64> = if a == 0.0 {
        if b == 0.0 {
            return None;
        }
        vec![-c / b]
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            // a double root that round-off pushed below zero: the vertex
            vec![-b / (2.0 * a)]
        } else {
            let w = -0.5 * (b + disc.sqrt().copysign(b));
            if w == 0.0 {
                vec![0.0]
            } else {
                vec![w / a, c / w]
            }
        }
    };
    let slack = 1e-9 * (hi - lo).abs().min(lo.abs().max(hi.abs()).max(1.0));
    roots.into_iter().filter(|r| r.is_finite() && lo - slack <= *r && *r <= hi + slack).map(|r| r.clamp(lo, hi)).next()
}

/// Brent's method for `g(u) = 0` on `[a, b]` with `g(a)`, `g(b)` of opposite signs (or zero), to
/// round-off in u.
fn brent(g: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64, mut fa: f64, mut fb: f64) -> f64 {
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..300 {
        if (fb > 0.0) == (fc > 0.0) {
            (c, fc) = (a, fa);
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            (a, fa) = (b, fb);
            (b, fb) = (c, fc);
            (c, fc) = (a, fa);
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 1e-300;
        let xm = 0.5 * (c - b);
        if xm.abs() <= tol || fb == 0.0 {
            return b;
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q) = if a == c {
                (2.0 * xm * s, 1.0 - s)
            } else {
                let (qq, r) = (fa / fc, fb / fc);
                (s * (2.0 * xm * qq * (qq - r) - (b - a) * (r - 1.0)), (qq - 1.0) * (r - 1.0) * (s - 1.0))
            };
            if p > 0.0 {
                q = -q;
            }
            p = p.abs();
            if 2.0 * p < (3.0 * xm * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = xm;
                e = d;
            }
        } else {
            d = xm;
            e = d;
        }
        (a, fa) = (b, fb);
        b += if d.abs() > tol { d } else { tol.copysign(xm) };
        fb = g(b);
        if fb.is_nan() {
            return f64::NAN;
        }
    }
    b
}

/// The monotone pieces of `F_s` in the order the roots are preferred: u ≥ 0 upwards, then u < 0
/// downwards (the pump turning forwards first, each side from the smallest |ω_p|).
fn pieces_of(model: &Model, s: f64, knots: &[f64]) -> Vec<Piece> {
    // the knots are given for s = +1; the regions depend on SR = s/u, so for s = −1 they mirror
    let mut k: Vec<f64> = knots.iter().map(|v| s * v).filter(|v| v.is_finite()).collect();
    k.sort_by(f64::total_cmp);
    k.dedup();
    let (first, last) = (k[0], k[k.len() - 1]);
    // the unbounded ends are sampled geometrically
    let mut grid: Vec<f64> = Vec::new();
    for i in 1..=8 {
        let m = f64::from(1 << i);
        grid.push(first - m * first.abs().max(1.0));
        grid.push(last + m * last.abs().max(1.0));
    }
    grid.extend_from_slice(&k);
    grid.sort_by(f64::total_cmp);
    let mut splits = Vec::new();
    for w in grid.windows(2) {
        splits.push(w[0]);
        splits.extend(extrema(model, s, w[0], w[1]));
    }
    splits.push(grid[grid.len() - 1]);
    let mut bounds = vec![f64::NEG_INFINITY];
    bounds.extend(splits);
    bounds.push(f64::INFINITY);
    let mut pieces = Vec::new();
    for w in bounds.windows(2) {
        if let Some(p) = piece(model, s, w[0], w[1]) {
            pieces.push(p);
        }
    }
    // the pump turning forwards (u ≥ 0) first, each side from u = 0 outwards
    let (mut with, mut against): (Vec<Piece>, Vec<Piece>) = pieces.into_iter().partition(|p| p.lo >= 0.0);
    let outwards = |a: &Piece, b: &Piece| {
        let key = |p: &Piece| p.lo.abs().min(p.hi.abs());
        key(a).total_cmp(&key(b))
    };
    with.sort_by(outwards);
    against.sort_by(outwards);
    with.extend(against);
    with
}

/// The extrema of `F_s` strictly inside `(a, b)`, found on [`SAMPLES`] samples and refined by
/// golden-section search.
fn extrema(model: &Model, s: f64, a: f64, b: f64) -> Vec<f64> {
    let n = SAMPLES + 1;
    let xs: Vec<f64> = (0..=n).map(|i| a + (b - a) * (i as f64) / (n as f64)).collect();
    let fs: Vec<f64> = xs.iter().map(|&u| model.f(u, s)).collect();
    let mut out = Vec::new();
    for i in 1..n {
        let (d0, d1) = (fs[i] - fs[i - 1], fs[i + 1] - fs[i]);
        if d0 * d1 < 0.0 {
            let sign = if d0 > 0.0 { 1.0 } else { -1.0 }; // a maximum: maximise sign·F
            out.push(golden(|u| sign * model.f(u, s), xs[i - 1], xs[i + 1]));
        }
    }
    out
}

/// The maximum of `h` on `[a, b]` by golden-section search, to round-off.
fn golden(h: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut hc, mut hd) = (h(c), h(d));
    for _ in 0..200 {
        if (b - a).abs() <= 4.0 * f64::EPSILON * a.abs().max(b.abs()) {
            break;
        }
        if hc > hd {
            (b, d, hd) = (d, c, hc);
            c = b - r * (b - a);
            hc = h(c);
        } else {
            (a, c, hc) = (c, d, hd);
            d = a + r * (b - a);
            hd = h(d);
        }
    }
    0.5 * (a + b)
}

/// The piece `[lo, hi]` with its end values (the limits at an infinite end: ±∞ in the direction of
/// the last samples), and its closed form where the table has one; None where `F_s` is not defined
/// at an end (Hrovat & Tobler without a steady state).
fn piece(model: &Model, s: f64, lo: f64, hi: f64) -> Option<Piece> {
    if lo >= hi {
        return None;
    }
    // an infinite end: the limit ±∞ in the direction F_s takes far beyond the last sample
    let limit = |at: f64, inner: f64| {
        let near = model.f(inner, s);
        let far = model.f(inner + at.signum() * 1e3 * inner.abs().max(1.0), s);
        if far > near {
            f64::INFINITY
        } else if far < near {
            f64::NEG_INFINITY
        } else {
            near
        }
    };
    let f_lo = if lo.is_infinite() { limit(lo, hi) } else { model.f(lo, s) };
    let f_hi = if hi.is_infinite() { limit(hi, lo) } else { model.f(hi, s) };
    if f_lo.is_nan() || f_hi.is_nan() {
        return None;
    }
    Some(Piece { lo, hi, f_lo, f_hi, quad: closed_form(model, s, lo, hi) })
}

/// `F_s = sign(u)·(αu + β)(γu + δ)` on a pump-referred piece of a capacity-factor table, checked
/// against the forward model at two inner points (not where the passivity projection bounds TR).
fn closed_form(model: &Model, s: f64, lo: f64, hi: f64) -> Option<[f64; 3]> {
    let Model::Table(c) = model else { return None };
    if c.interpolation() != Interpolation::CapacityFactor {
        return None;
    }
    let (a, b) = (if lo.is_infinite() { hi * 4.0 } else { lo }, if hi.is_infinite() { lo * 4.0 } else { hi });
    let (a, b) = (a.min(b), a.max(b));
    let mid = 0.5 * (a + b);
    if mid == 0.0 {
        return None;
    }
    let sr = s / mid;
    if !(-1.0..=c.pump_referred_limit()).contains(&sr) {
        return None;
    }
    let l = c.lookup(sr);
    let (alpha, beta) = (l.torque_ratio - l.d_torque_ratio * sr, l.d_torque_ratio);
    let (gamma, delta) = (l.capacity_factor_nm_s2 - l.d_capacity_factor * sr, l.d_capacity_factor);
    // T = TR·CF·ω_p|ω_p| at ω_t = s: with SR = s/u, TR·u = αu + βs and CF·u = γu + δs
    let sign = mid.signum();
    let (beta, delta) = (beta * s, delta * s);
    let q = [sign * beta * delta, sign * (alpha * delta + beta * gamma), sign * alpha * gamma];
    let ok = [0.3, 0.7].iter().all(|w| {
        let u = a + w * (b - a);
        let exact = model.f(u, s);
        let closed = q[0] + q[1] * u + q[2] * u * u;
        (exact - closed).abs() <= RESIDUAL_TOL * exact.abs().max(q[2].abs() * u * u).max(f64::MIN_POSITIVE)
    });
    ok.then_some(q)
}

/// Points of a batch between two looks at the cancel flag (a worker takes them at once).
pub const POINTS_PER_CHUNK: usize = 16_384;

/// Columns of a batch of backward operating points.
#[derive(Debug, Clone, Default)]
pub struct BackwardColumns {
    /// The torque delivered, N·m: the input torque, or `P/ω_t` for a power input.
    pub turbine_torque_nm: Vec<f64>,
    pub pump_speed_rad_s: Vec<f64>,
    pub pump_torque_nm: Vec<f64>,
    pub speed_ratio: Vec<f64>,
    pub torque_ratio: Vec<f64>,
    pub efficiency: Vec<f64>,
    /// [`Reason::code`] per point.
    pub reason: Vec<u8>,
}

/// Check a pump speed limit, rad/s: positive (infinity for none), not NaN.
pub fn check_pump_speed_limit(limit: f64) -> CoreResult<()> {
    if limit.is_nan() || limit <= 0.0 {
        return Err(CoreError::of(
            InputSource::Options,
            "pump_speed_limit_rad_s",
            limit,
            "a positive pump speed limit in rad/s (infinity for none)",
        ));
    }
    Ok(())
}

/// What the second input of [`backward_points`] holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Load {
    /// The torque delivered to the transmission, N·m.
    TorqueNm,
    /// The power delivered to the transmission, W: the torque is `P/ω_t`.
    PowerW,
}

/// The torque of a load value at turbine speed `wt`, or the reason there is none.
fn load_torque(load: Load, wt: f64, value: f64) -> Result<f64, Reason> {
    match load {
        Load::TorqueNm => Ok(value),
        Load::PowerW if !(wt.is_finite() && value.is_finite()) => Err(Reason::NonFiniteInput),
        Load::PowerW if wt == 0.0 => Err(Reason::PowerAtStandstill),
        Load::PowerW => Ok(value / wt),
    }
}

/// Backward operating points at `turbine_speed_rad_s[i]` with torque (or power, by `load`)
/// `load_values[i]` on `threads` worker threads (0: one per core), in order; `None` once `cancel`
/// is set.
pub fn backward_points(
    b: &Backward,
    turbine_speed_rad_s: &[f64],
    load_values: &[f64],
    load: Load,
    pump_speed_limit_rad_s: f64,
    threads: usize,
    cancel: &AtomicBool,
) -> CoreResult<Option<BackwardColumns>> {
    check_pump_speed_limit(pump_speed_limit_rad_s)?;
    let n = turbine_speed_rad_s.len();
    if load_values.len() != n {
        let name = if load == Load::TorqueNm { "turbine_torque_nm" } else { "turbine_power_w" };
        return Err(CoreError::of(
            InputSource::Drive,
            name,
            format!("{} points", load_values.len()),
            format!("{n} points, as many as turbine_speed_rad_s"),
        ));
    }
    let chunks: Vec<(usize, usize)> =
        (0..n).step_by(POINTS_PER_CHUNK).map(|i| (i, (i + POINTS_PER_CHUNK).min(n))).collect();
    let done = parallel_map_cancellable(&chunks, threads, cancel, |&(i, j)| {
        let one = |k: usize| match load_torque(load, turbine_speed_rad_s[k], load_values[k]) {
            Ok(t) => (t, b.point(turbine_speed_rad_s[k], t, pump_speed_limit_rad_s)),
            Err(reason) => (f64::NAN, BackwardPoint::empty(reason)),
        };
        (i..j).map(one).collect::<Vec<_>>()
    });
    let mut out = BackwardColumns::default();
    for chunk in done {
        let Some(points) = chunk else { return Ok(None) };
        for (t, p) in points {
            out.turbine_torque_nm.push(t);
            out.pump_speed_rad_s.push(p.pump_speed_rad_s);
            out.pump_torque_nm.push(p.pump_torque_nm);
            out.speed_ratio.push(p.speed_ratio);
            out.torque_ratio.push(p.torque_ratio);
            out.efficiency.push(p.efficiency);
            out.reason.push(p.reason.code());
        }
    }
    Ok(Some(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::converter::dynamics::tests::c1;
    use crate::converter::hrovat_tobler::steady_state;

    /// JAMBE/TRAMI 9AT: coast rows up to SR 2.1, CF not monotone in coast.
    fn jambe() -> Characteristic {
        let c = |v: f64| v * crate::units::RPM_PER_RAD_S.powi(2) * 1e-6;
        let sr: Vec<f64> = (-1..=21).map(|i| f64::from(i) / 10.0).collect();
        let mut tr = vec![1.81, 1.81, 1.72, 1.63, 1.54, 1.45, 1.36, 1.27, 1.18, 1.09];
        tr.extend([1.0; 13]);
        let cap = [
            38.0, 38.0, 39.0, 40.0, 41.0, 42.0, 43.0, 44.0, 40.0, 35.0, 30.0, 0.0, -5.0, -10.0, -12.0, -14.0, -16.0,
            -18.0, -20.0, -22.0, -24.0, -26.0, -26.0,
        ];
        Characteristic::new(sr, tr, cap.iter().map(|&v| c(v)).collect()).unwrap()
    }

    fn tables() -> Vec<(&'static str, Characteristic)> {
        let k = c1().with_rules(None, Some("k_factor")).unwrap();
        let short = Characteristic::new(vec![0.0, 0.5, 0.8], vec![2.0, 1.4, 1.1], vec![3e-3, 2.8e-3, 2.0e-3]).unwrap();
        vec![("C.1", c1()), ("C.1 k_factor", k), ("JAMBE", jambe()), ("short", short)]
    }

    /// Speed pairs over every quadrant: SR from −3 to 3 and the pump or turbine at rest.
    fn grid() -> Vec<(f64, f64)> {
        let mut points = Vec::new();
        for wt in [250.0, 37.5, -180.0] {
            for i in -60..=60 {
                let sr = f64::from(i) / 20.0;
                if sr != 0.0 {
                    points.push((wt / sr, wt));
                }
            }
            points.push((0.0, wt));
            points.push((wt, 0.0));
        }
        points
    }

    /// The backward point reproduces the forward torque at its speeds, relative to the torques there.
    fn assert_round_trip(name: &str, f: impl Fn(f64, f64) -> (f64, f64), b: &Backward, wp: f64, wt: f64) -> f64 {
        let (_, t) = f(wp, wt);
        let p = b.point(wt, t, f64::INFINITY);
        assert!(p.pump_speed_rad_s.is_finite(), "{name} ({wp}, {wt}) T {t}: {p:?}");
        let (tp, back) = f(p.pump_speed_rad_s, wt);
        let scale = t.abs().max(tp.abs());
        assert!((back - t).abs() <= 1e-9 * scale, "{name} ({wp}, {wt}): T {t} back {back}, {p:?}");
        assert_eq!(p.pump_torque_nm, tp, "{name}");
        p.pump_speed_rad_s
    }

    #[test]
    fn table_round_trips_in_every_quadrant() {
        for (name, c) in tables() {
            let b = Backward::table(&c);
            let f = |wp: f64, wt: f64| {
                let t = c.torques(wp, wt);
                (t.pump_nm, t.delivered_nm)
            };
            for (wp, wt) in grid() {
                let back = assert_round_trip(name, f, &b, wp, wt);
                // the lowest pump speed turning forwards: never above the grid's own, whichever way the
                // turbine turns (the pump at rest comes back as round-off of either sign); a torque only
                // a backward pump gives (both speeds negative) comes back with the smallest backward one
                if wp == 0.0 {
                    // the pump at rest comes back at rest, a valid point (round-off of either sign
                    // made it a backward pump)
                    let p = b.point(wt, f(wp, wt).1, f64::INFINITY);
                    assert!(back == 0.0 && p.reason == Reason::Ok, "{name} ({wp}, {wt}): {p:?}");
                } else if wp > 0.0 {
                    assert!(back >= 0.0 && back <= wp * (1.0 + 1e-9), "{name} ({wp}, {wt}): {back}");
                } else if wt < 0.0 {
                    assert!(back < 0.0 && back >= wp * (1.0 + 1e-9), "{name} ({wp}, {wt}): {back}");
                }
                // where F is monotone (Table C.1 with the pump turning with the turbine) the point itself
                if name.starts_with("C.1") && wp * wt > 0.0 {
                    assert!((back - wp).abs() <= 1e-9 * wp.abs(), "{name} ({wp}, {wt}): {back}");
                }
            }
        }
    }

    #[test]
    fn table_closed_form_matches_hand_values() {
        let b = Backward::table(&c1());
        // SR 0.5 at ω_p = 200 rad/s: T = TR·CF·ω_p² = 1.43 · 3.017e-3 · 200²
        let p = b.point(100.0, 1.43 * 3.017e-3 * 200.0 * 200.0, f64::INFINITY);
        assert!((p.pump_speed_rad_s - 200.0).abs() < 1e-10, "{p:?}");
        assert!((p.speed_ratio - 0.5).abs() < 1e-12 && (p.torque_ratio - 1.43).abs() < 1e-12, "{p:?}");
        assert!((p.efficiency - 0.715).abs() < 1e-12 && p.reason == Reason::Ok, "{p:?}");
        // stall: ω_p = √(T/(TR(0)·CF(0)))
        let p = b.point(0.0, 300.0, f64::INFINITY);
        assert!((p.pump_speed_rad_s - (300.0f64 / (2.14 * 3.272e-3)).sqrt()).abs() < 1e-9, "{p:?}");
        assert_eq!((p.speed_ratio, p.torque_ratio, p.reason), (0.0, 2.14, Reason::Ok));
        // between two rows: SR 0.25 is halfway between rows 0.2 and 0.3
        let (tr, cf) = (0.5 * (1.84 + 1.70), 0.5 * (3.228e-3 + 3.181e-3));
        let p = b.point(50.0, tr * cf * 200.0 * 200.0, f64::INFINITY);
        assert!((p.pump_speed_rad_s - 200.0).abs() < 1e-9, "{p:?}");
        // the same point in reverse (both speeds negative): only a pump turned backwards gives it
        let q = b.point(-50.0, -tr * cf * 200.0 * 200.0, f64::INFINITY);
        assert!((q.pump_speed_rad_s + 200.0).abs() < 1e-9 && q.reason == Reason::PumpBackwards, "{q:?}");
    }

    /// The pump is the engine's: a vehicle rolling back in drive (ω_t < 0, T > 0) has it turning
    /// forwards, a valid point; a negative torque at standstill or while rolling back needs it turned
    /// backwards, flagged (it was the mirror image, ω_p < 0, called valid, and the rollback point
    /// flagged).
    #[test]
    fn the_pump_turns_forwards_when_rolling_back_and_a_backward_pump_is_flagged() {
        let g = HtGeometry::appendix_d();
        let ht = |wp: f64, wt: f64| {
            let s = steady_state(&g, wp, wt).unwrap();
            (s.pump_torque_nm, s.turbine_torque_nm)
        };
        let table = |wp: f64, wt: f64| {
            let t = c1().torques(wp, wt);
            (t.pump_nm, t.delivered_nm)
        };
        for (name, b) in [("C.1", Backward::table(&c1())), ("H&T", Backward::hrovat_tobler(&g))] {
            let f = |wp: f64, wt: f64| if name == "H&T" { ht(wp, wt) } else { table(wp, wt) };
            // rolling back at 20 rad/s with 100 N·m to hold: the pump forwards, the torque met
            let p = b.point(-20.0, 100.0, f64::INFINITY);
            assert!(p.reason == Reason::Ok && p.pump_speed_rad_s > 20.0, "{name} {p:?}");
            assert!((f(p.pump_speed_rad_s, -20.0).1 - 100.0).abs() < 1e-9 * 100.0, "{name} {p:?}");
            assert!(p.speed_ratio < 0.0 && p.efficiency < 0.0, "{name} {p:?}");
            // the round trip of a forward pump against a rolling-back turbine gives the pump speed back
            // or a lower forward one
            let t = f(150.0, -30.0).1;
            let back = b.point(-30.0, t, f64::INFINITY);
            assert!(back.reason == Reason::Ok && back.pump_speed_rad_s <= 150.0 * (1.0 + 1e-9), "{name} {back:?}");
            // the torque with the pump at rest, at 60 turbine speeds of either sign: a forward pump,
            // valid (the round-off of the pump at rest was flagged as a backward pump at 13 to 15 of 60
            // speeds); the table's is the pump at rest itself (Hrovat & Tobler's steady state may jump
            // at ω_p = 0 when rolling back, and a forward pump a little faster gives the torque again)
            for k in 1..=60 {
                for wt in [f64::from(k) * 7.3, -f64::from(k) * 7.3] {
                    let t = f(0.0, wt).1;
                    let p = b.point(wt, t, f64::INFINITY);
                    assert!(p.reason == Reason::Ok && p.pump_speed_rad_s >= 0.0, "{name} {wt}: {p:?}");
                    assert!((f(p.pump_speed_rad_s, wt).1 - t).abs() <= 1e-9 * t.abs(), "{name} {wt}: {p:?}");
                    assert!(name == "H&T" || p.pump_speed_rad_s == 0.0, "{name} {wt}: {p:?}");
                }
            }
            // a negative torque at standstill and while rolling back: only a backward pump gives it
            for (wt, t) in [(0.0, -50.0), (-20.0, -100.0)] {
                let p = b.point(wt, t, f64::INFINITY);
                assert!(p.reason == Reason::PumpBackwards && p.pump_speed_rad_s < 0.0, "{name} ({wt}, {t}) {p:?}");
                assert!((f(p.pump_speed_rad_s, wt).1 - t).abs() < 1e-9 * t.abs(), "{name} {p:?}");
                assert!(!p.reason.valid());
            }
        }
    }

    #[test]
    fn reasons_flag_every_point_without_a_plain_answer() {
        let b = Backward::table(&c1());
        for (wt, t) in [(f64::NAN, 1.0), (1.0, f64::INFINITY), (f64::NEG_INFINITY, 0.0)] {
            let p = b.point(wt, t, f64::INFINITY);
            assert_eq!(p.reason, Reason::NonFiniteInput);
            assert!(p.pump_speed_rad_s.is_nan() && !p.reason.valid());
        }
        let rest = b.point(0.0, 0.0, f64::INFINITY);
        assert_eq!((rest.reason, rest.pump_speed_rad_s, rest.pump_torque_nm), (Reason::AtRest, 0.0, 0.0));
        assert!(rest.reason.valid());
        // 200 rad/s needed, 150 allowed: the values are given, flagged
        let p = b.point(100.0, 1.43 * 3.017e-3 * 200.0 * 200.0, 150.0);
        assert_eq!(p.reason, Reason::AbovePumpSpeedLimit);
        assert!((p.pump_speed_rad_s - 200.0).abs() < 1e-9 && !p.reason.valid());
        // the most coast torque the converter takes with the pump at rest is CF(0)·ω_t² (TR_m = 1 there)
        let stall = 3.272e-3 * 100.0 * 100.0;
        let p = b.point(100.0, -0.99 * stall, f64::INFINITY);
        assert!(p.reason == Reason::Ok && p.pump_speed_rad_s > 0.0 && p.pump_speed_rad_s < 100.0, "{p:?}");
        let p = b.point(100.0, -stall, f64::INFINITY);
        assert!(p.reason == Reason::Ok && p.pump_speed_rad_s.abs() < 1e-6, "{p:?}");
        let p = b.point(100.0, -1.01 * stall, f64::INFINITY);
        assert!(p.reason == Reason::PumpBackwards && p.pump_speed_rad_s < 0.0, "{p:?}");
        // beyond TR(0)·CF(0)·ω_t² the pump turns backwards faster than the turbine (SR ∈ (−1, 0))
        let p = b.point(100.0, -3.0 * stall, f64::INFINITY);
        assert!(p.reason == Reason::PumpBackwards && p.pump_speed_rad_s < -100.0, "{p:?}");
        // a torque that overflows at this turbine speed
        let p = b.point(1e-160, 1e300, f64::INFINITY);
        assert_eq!(p.reason, Reason::Overflow);
        // NaN only with a reason that says so
        for r in Reason::ALL {
            assert_eq!(r.valid(), matches!(r, Reason::Ok | Reason::AtRest));
        }
        assert!(check_pump_speed_limit(0.0).is_err() && check_pump_speed_limit(f64::NAN).is_err());
        assert!(check_pump_speed_limit(f64::INFINITY).is_ok());
    }

    #[test]
    fn hrovat_tobler_round_trips() {
        let g = HtGeometry::appendix_d();
        let b = Backward::hrovat_tobler(&g);
        let f = |wp: f64, wt: f64| {
            let s = steady_state(&g, wp, wt).unwrap();
            (s.pump_torque_nm, s.turbine_torque_nm)
        };
        for i in 0..=19 {
            // drive, SR 0 … 0.95: the steady state is monotone in ω_p there
            let sr = f64::from(i) / 20.0;
            let (wp, wt) = (209.4, 209.4 * sr);
            let back = assert_round_trip("H&T", f, &b, wp, wt);
            assert!((back - wp).abs() <= 1e-9 * wp, "SR {sr}: {back}");
        }
        for sr in [1.05, 1.2, 1.5, 2.0] {
            assert_round_trip("H&T coast", f, &b, 200.0, 200.0 * sr);
            assert_round_trip("H&T coast reversed", f, &b, -200.0, -200.0 * sr);
        }
    }

    #[test]
    fn batch_matches_pointwise_and_can_be_cancelled() {
        let b = Backward::table(&jambe());
        let wt: Vec<f64> = (0..40_000).map(|i| f64::from(i % 400) - 100.0).collect();
        let t: Vec<f64> = (0..40_000).map(|i| f64::from(i % 317) - 80.0).collect();
        let go = AtomicBool::new(false);
        let cols = backward_points(&b, &wt, &t, Load::TorqueNm, 600.0, 2, &go).unwrap().unwrap();
        for k in [0, 1, 12_345, 39_999] {
            let p = b.point(wt[k], t[k], 600.0);
            assert_eq!(cols.pump_speed_rad_s[k].to_bits(), p.pump_speed_rad_s.to_bits());
            assert_eq!(cols.reason[k], p.reason.code());
        }
        for (k, &r) in cols.reason.iter().enumerate() {
            let nan = cols.pump_speed_rad_s[k].is_nan() || cols.pump_torque_nm[k].is_nan();
            assert!(!nan || !Reason::ALL[r as usize].valid() || r == Reason::AtRest.code(), "point {k}");
        }
        let stop = AtomicBool::new(true);
        assert!(backward_points(&b, &wt, &t, Load::TorqueNm, 600.0, 2, &stop).unwrap().is_none());
        assert!(backward_points(&b, &wt, &t[1..], Load::TorqueNm, 600.0, 2, &go).is_err());
        assert!(backward_points(&b, &wt, &t, Load::TorqueNm, -1.0, 2, &go).is_err());
        // a power: T = P/ω_t; at standstill no torque follows
        let cols =
            backward_points(&b, &[100.0, 0.0, 0.0], &[2e4, 1e3, 0.0], Load::PowerW, 600.0, 1, &go).unwrap().unwrap();
        assert_eq!(cols.turbine_torque_nm[0], 200.0);
        assert_eq!(cols.pump_speed_rad_s[0], b.point(100.0, 200.0, 600.0).pump_speed_rad_s);
        assert_eq!(cols.reason[1..], [Reason::PowerAtStandstill.code(); 2]);
        assert!(cols.turbine_torque_nm[1].is_nan() && cols.pump_speed_rad_s[2].is_nan());
    }
}
