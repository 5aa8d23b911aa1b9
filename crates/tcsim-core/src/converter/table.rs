//! Steady-state look-up-table model, Li & Sundén (2016) §2.2.1, eqs 2.8–2.11, in every quadrant.
//!
//! In drive `T_p = CF(SR)·ω_p·|ω_p|` and `T_del = TR(SR)·T_p` (torque delivered to the
//! transmission), with ω in rad/s and CF in N·m/(rad/s)² (docs/physics.md §1, §3).
//!
//! **Interpolation** is piecewise linear in SR between the table's points, in the capacity factor
//! (default) or in the K-factor `K = 1/√CF` ([`Interpolation`]).
//!
//! **Every quadrant** (docs/models.md, "The table models in every quadrant"). With
//! `s_e = max(1, last SR)`:
//!
//! * *pump-referred* where `SR = ω_t/ω_p ∈ [−1, s_e]`: the law above, CF and TR held at the end
//!   rows outside the table (below the first row; above the last one when it ends below SR 1);
//! * *turbine-referred* elsewhere (|ω_t| beyond those bounds, including ω_p = 0 with ω_t ≠ 0):
//!   with `x = ω_p/ω_t`, `T_p = −C(x)·ω_t·|ω_t|` and `T_del = TR_m(x)·T_p`. For x ∈ [−1, 0] the
//!   turbine drives the fluid as a pump at the stall capacity; for x ∈ (0, 1/s_e) the
//!   [`OverrunRule`] applies (the table's own coast rows, or the mirror extension);
//! * ω_p = ω_t = 0: no torque.
//!
//! Both torques are continuous over the whole (ω_p, ω_t) plane, and the **passivity projection**
//! (TR limited to 1/SR where the pump absorbs power, raised to it where the pump is driven) makes
//! the converter absorb power, `T_p·ω_p − T_del·ω_t ≥ 0`, everywhere. On a table that passes
//! [`Characteristic::new`]'s passivity check it changes nothing on the table's own rows.

use crate::error::{CoreError, CoreResult, InputSource};
use crate::interp;

/// Relative round-off allowed in the passivity check of a table's rows.
const PASSIVITY_ROUND_OFF: f64 = 1e-12;

/// How a table that has no coast rows is continued into overrun (ω_t beyond ω_p).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OverrunRule {
    /// The table's own coast rows (last SR > 1, negative capacity, as in JAMBE and VECTO files):
    /// past the last row, the turbine-referred capacity goes linearly in x = ω_p/ω_t from the
    /// value that matches the last row to the stall capacity at x = 0.
    Table,
    /// For tables that end at SR ≤ 1: the turbine acts as the pump, `C(x) = CF(x)` with TR = 1,
    /// blended on the table's last segment below SR 1 so that both torques are continuous at
    /// SR = 1 (docs/models.md; compare Project Chrono's `ChShaftsTorqueConverter`).
    Mirror,
}

impl OverrunRule {
    pub const ALL: [OverrunRule; 2] = [Self::Table, Self::Mirror];
    pub fn key(self) -> &'static str {
        match self {
            Self::Table => "table",
            Self::Mirror => "mirror",
        }
    }
    /// Whether the rule continues the table beyond its data (and so warrants a warning).
    pub fn is_extension(self) -> bool {
        self == Self::Mirror
    }
}

/// The quantity interpolated linearly in SR between a table's rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// CF linear in SR (tcsim's default).
    CapacityFactor,
    /// `K = 1/√CF` linear in SR where both rows have CF > 0, else CF-linear on that segment
    /// (Project Chrono, Simscape Driveline).
    KFactor,
}

impl Interpolation {
    pub const ALL: [Interpolation; 2] = [Self::CapacityFactor, Self::KFactor];
    pub fn key(self) -> &'static str {
        match self {
            Self::CapacityFactor => "capacity_factor",
            Self::KFactor => "k_factor",
        }
    }
}

fn quoted_keys(keys: &[&str]) -> String {
    let q: Vec<String> = keys.iter().map(|k| format!("\"{k}\"")).collect();
    q.join(", ")
}

/// A torque-converter characteristic: TR and CF against SR, with its overrun rule and
/// interpolation domain.
#[derive(Debug, Clone, PartialEq)]
pub struct Characteristic {
    speed_ratio: Vec<f64>,
    torque_ratio: Vec<f64>,
    capacity_factor_nm_s2: Vec<f64>,
    overrun: OverrunRule,
    interpolation: Interpolation,
}

/// The characteristic evaluated at one speed ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lookup {
    pub torque_ratio: f64,
    pub capacity_factor_nm_s2: f64,
    /// d TR / d SR of the segment used (0 outside the table).
    pub d_torque_ratio: f64,
    /// d CF / d SR of the segment used (0 outside the table).
    pub d_capacity_factor: f64,
    /// True when SR lies outside the table and the end values were held.
    pub extrapolated: bool,
}

/// Which part of the (ω_p, ω_t) plane a point lies in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Region {
    /// ω_p = ω_t = 0.
    Rest,
    /// SR ∈ [−1, s_e]: the table's law referred to the pump speed.
    Pump,
    /// x = ω_p/ω_t ∈ [−1, 0]: the turbine drives the fluid (roll-back faster than the pump, or
    /// the pump at rest).
    TurbineReversed,
    /// x ∈ (0, 1/s_e): overrun beyond the table's last row, by the [`OverrunRule`].
    Overrun,
}

/// The table's torques at one (ω_p, ω_t) and their gradients with respect to (ω_p, ω_t).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableTorques {
    /// External torque on the pump, N·m (positive in drive).
    pub pump_nm: f64,
    /// Torque delivered to the transmission, `−T_t`, N·m (positive in drive).
    pub delivered_nm: f64,
    pub d_pump: [f64; 2],
    pub d_delivered: [f64; 2],
    /// The torque ratio used, after the passivity projection.
    pub torque_ratio: f64,
    /// Gradient of `torque_ratio` with respect to (ω_p, ω_t) (the table model's lag,
    /// [`crate::converter::dynamics::TorqueLag`], carries it).
    pub d_torque_ratio: [f64; 2],
    /// `Q_ss·ρR_p² = flow_factor·flow_speed`, N·m/(rad/s): the quasi-dynamic model's steady flow
    /// scaled (see [`Characteristic::torques`]): `flow_factor` is CF or −C·m, N·m/(rad/s)², and
    /// `flow_speed` is |ω_p| or |ω_t|, rad/s.
    pub flow_factor: f64,
    pub flow_speed: f64,
    /// Gradient of `flow_factor·flow_speed` with respect to (ω_p, ω_t).
    pub d_flow: [f64; 2],
    pub region: Region,
    /// Outside the table's rows (held end values or a turbine-referred region).
    pub extrapolated: bool,
    /// In the overrun region under a rule that extends the table ([`OverrunRule::is_extension`]).
    pub extension: bool,
}

/// Steady-state torques of the table model at one operating point (docs/physics.md §2 signs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableOperatingPoint {
    pub speed_ratio: f64,
    /// The torque ratio used (`T_del/T_p`, after the passivity projection).
    pub torque_ratio: f64,
    /// `T_p/(ω_p|ω_p|)`; NaN at ω_p = 0.
    pub capacity_factor_nm_s2: f64,
    /// External torque on the pump (engine torque), positive in drive.
    pub pump_torque_nm: f64,
    /// Torque delivered to the transmission, `−T_t`, positive in drive.
    pub turbine_torque_nm: f64,
    /// External torque on the stator from the housing, `T_s = −(T_p + T_t)`.
    pub stator_torque_nm: f64,
    pub extrapolated: bool,
    /// The overrun rule extended the table here (a warning to the user).
    pub extension: bool,
}

impl Characteristic {
    /// Build a characteristic, checking that it can be interpolated (at least two points, equal
    /// lengths, finite values, strictly increasing SR) and that it is passive on its own rows
    /// ([`Self::check_passive`]). The overrun rule is `table` when the table has coast rows
    /// (last SR > 1) and `mirror` otherwise; the interpolation is in the capacity factor
    /// ([`Self::with_rules`] chooses others). Physical plausibility (positive TR and CF in drive)
    /// is checked by the caller, who knows the file and convention.
    pub fn new(speed_ratio: Vec<f64>, torque_ratio: Vec<f64>, capacity_factor_nm_s2: Vec<f64>) -> CoreResult<Self> {
        let n = speed_ratio.len();
        if n < 2 {
            return Err(CoreError::new("speed_ratio", format!("{n} points"), "at least 2 points"));
        }
        for (name, v) in [("torque_ratio", &torque_ratio), ("capacity_factor_nm_s2", &capacity_factor_nm_s2)] {
            if v.len() != n {
                return Err(CoreError::new(
                    name,
                    format!("{} points", v.len()),
                    format!("{n} points, as many as speed_ratio"),
                ));
            }
        }
        for (name, v) in [
            ("speed_ratio", &speed_ratio),
            ("torque_ratio", &torque_ratio),
            ("capacity_factor_nm_s2", &capacity_factor_nm_s2),
        ] {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(CoreError::new(format!("{name}[{i}]"), v[i], "a finite number"));
            }
        }
        if let Some(i) = (1..n).find(|&i| speed_ratio[i] <= speed_ratio[i - 1]) {
            return Err(CoreError::new(
                format!("speed_ratio[{i}]"),
                speed_ratio[i],
                format!("strictly increasing speed ratio (previous value {})", speed_ratio[i - 1]),
            ));
        }
        let overrun = if speed_ratio[n - 1] > 1.0 { OverrunRule::Table } else { OverrunRule::Mirror };
        let c = Self {
            speed_ratio,
            torque_ratio,
            capacity_factor_nm_s2,
            overrun,
            interpolation: Interpolation::CapacityFactor,
        };
        c.check_passive()?;
        Ok(c)
    }

    /// The same table with the overrun rule and interpolation domain named by their keys (None:
    /// the default). `overrun = "mirror"` is refused on a table with its own coast rows, and
    /// `"table"` on one without them.
    pub fn with_rules(mut self, overrun: Option<&str>, interpolation: Option<&str>) -> CoreResult<Self> {
        if let Some(key) = interpolation {
            self.interpolation = Interpolation::ALL.into_iter().find(|i| i.key() == key).ok_or_else(|| {
                CoreError::new(
                    "interpolation",
                    format!("\"{key}\""),
                    format!("one of {}", quoted_keys(&["capacity_factor", "k_factor"])),
                )
            })?;
        }
        if let Some(key) = overrun {
            let rule = OverrunRule::ALL.into_iter().find(|r| r.key() == key).ok_or_else(|| {
                CoreError::new("overrun", format!("\"{key}\""), format!("one of {}", quoted_keys(&["mirror", "table"])))
            })?;
            let last = self.speed_ratio[self.speed_ratio.len() - 1];
            if rule == OverrunRule::Mirror && self.has_coast_rows() {
                return Err(CoreError::new(
                    "overrun",
                    "\"mirror\"",
                    format!("\"table\" (the default): the table has its own overrun rows up to SR {last}"),
                ));
            }
            if rule == OverrunRule::Table && !self.has_coast_rows() {
                return Err(CoreError::new(
                    "overrun",
                    "\"table\"",
                    format!("\"mirror\" (the default): the table ends at SR {last} and has no overrun rows (SR > 1) of its own"),
                ));
            }
            self.overrun = rule;
        }
        self.check_passive()?;
        Ok(self)
    }

    pub fn speed_ratio(&self) -> &[f64] {
        &self.speed_ratio
    }
    pub fn torque_ratio(&self) -> &[f64] {
        &self.torque_ratio
    }
    pub fn capacity_factor_nm_s2(&self) -> &[f64] {
        &self.capacity_factor_nm_s2
    }
    pub fn overrun(&self) -> OverrunRule {
        self.overrun
    }
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }
    /// Whether the table has overrun rows of its own (last SR > 1).
    pub fn has_coast_rows(&self) -> bool {
        self.last_speed_ratio() > 1.0
    }
    fn last_speed_ratio(&self) -> f64 {
        self.speed_ratio[self.speed_ratio.len() - 1]
    }
    /// `s_e = max(1, last SR)`: the upper end of the pump-referred region.
    pub fn pump_referred_limit(&self) -> f64 {
        self.last_speed_ratio().max(1.0)
    }

    /// Interpolation of TR and CF at `sr` (in the table's [`Interpolation`] domain), end values
    /// held outside the table.
    pub fn lookup(&self, sr: f64) -> Lookup {
        let x = &self.speed_ratio;
        let n = x.len();
        let held = |i: usize| Lookup {
            torque_ratio: self.torque_ratio[i],
            capacity_factor_nm_s2: self.capacity_factor_nm_s2[i],
            d_torque_ratio: 0.0,
            d_capacity_factor: 0.0,
            extrapolated: true,
        };
        if sr.is_nan() {
            return Lookup {
                torque_ratio: f64::NAN,
                capacity_factor_nm_s2: f64::NAN,
                d_torque_ratio: f64::NAN,
                d_capacity_factor: f64::NAN,
                extrapolated: true,
            };
        }
        if sr < x[0] {
            return held(0);
        }
        if sr > x[n - 1] {
            return held(n - 1);
        }
        let (i, w) = interp::segment(x, sr);
        let h = x[i] - x[i - 1];
        let lerp = |y: &[f64]| (interp::mix(y, i, w), (y[i] - y[i - 1]) / h);
        let (tr, dtr) = lerp(&self.torque_ratio);
        let (ca, cb) = (self.capacity_factor_nm_s2[i - 1], self.capacity_factor_nm_s2[i]);
        let (cf, dcf) = if self.interpolation == Interpolation::KFactor && ca > 0.0 && cb > 0.0 {
            // K = 1/√CF linear in SR; CF = 1/K², dCF/dSR = −2 K'/K³
            let (ka, kb) = (1.0 / ca.sqrt(), 1.0 / cb.sqrt());
            let k = (1.0 - w) * ka + w * kb;
            let cf = if w == 0.0 {
                ca
            } else if w == 1.0 {
                cb
            } else {
                1.0 / (k * k)
            };
            (cf, -2.0 * (kb - ka) / h / (k * k * k))
        } else {
            lerp(&self.capacity_factor_nm_s2)
        };
        Lookup {
            torque_ratio: tr,
            capacity_factor_nm_s2: cf,
            d_torque_ratio: dtr,
            d_capacity_factor: dcf,
            extrapolated: false,
        }
    }

    /// Check that the table is passive on its own rows: `CF·(1 − SR·TR) ≥ 0` at every row and
    /// everywhere between rows (the efficiency SR·TR at most 1 where the pump absorbs power,
    /// CF > 0, and at least 1 where it is driven, CF < 0). Between rows the check is exact: each
    /// segment is split where CF changes sign, and SR·TR (a quadratic in SR) is checked at the
    /// ends and at its vertex. Only round-off (1e-12 relative) is tolerated.
    pub fn check_passive(&self) -> CoreResult<()> {
        let (s, tr, cf) = (&self.speed_ratio, &self.torque_ratio, &self.capacity_factor_nm_s2);
        for i in 0..s.len() {
            let e = s[i] * tr[i];
            if violates(cf[i], e) {
                return Err(passivity_error(i, tr[i], e, s[i], cf[i], None));
            }
        }
        for i in 1..s.len() {
            let (a, b) = (s[i - 1], s[i]);
            let slope = (tr[i] - tr[i - 1]) / (b - a);
            let efficiency = |x: f64| x * (tr[i - 1] + (x - a) * slope);
            let mut cuts = vec![a, b];
            let k_domain = self.interpolation == Interpolation::KFactor && cf[i - 1] > 0.0 && cf[i] > 0.0;
            if !k_domain && cf[i - 1] * cf[i] < 0.0 {
                cuts.insert(1, a + cf[i - 1] / (cf[i - 1] - cf[i]) * (b - a));
            }
            for w in cuts.windows(2) {
                let (lo, hi) = (w[0], w[1]);
                let sign = self.lookup(0.5 * (lo + hi)).capacity_factor_nm_s2;
                // vertex of x·(tr_a + (x − a)·slope): x* = (a·slope − tr_a)/(2·slope)
                let vertex = if slope != 0.0 { (a * slope - tr[i - 1]) / (2.0 * slope) } else { lo };
                let candidates = [lo, hi, vertex.clamp(lo, hi)];
                if let Some(&x) = candidates.iter().find(|&&x| violates(sign, efficiency(x))) {
                    // the row that pushes the efficiency the wrong way: the larger TR where the
                    // pump absorbs power, the smaller where it is driven
                    let j = if (tr[i - 1] > tr[i]) == (sign > 0.0) { i - 1 } else { i };
                    return Err(passivity_error(j, tr[j], efficiency(x), x, sign, Some((a, b))));
                }
            }
        }
        Ok(())
    }

    /// The torques at pump and turbine speeds `wp`, `wt` (rad/s, any signs), their gradients,
    /// and the scaled steady flow of the quasi-dynamic model, in every region (module docs):
    ///
    /// * pump-referred: `T_p = CF(SR) ω_p|ω_p|`, flow `CF(SR)|ω_p|`;
    /// * turbine-referred: `T_p = −C(x) ω_t|ω_t|`, flow `−C(x) m(x) |ω_t|`, where m goes linearly
    ///   from −1 at x = −1 to 1 at x = 0 and from 1 at x = 0 to s_e at x = 1/s_e, so that the flow
    ///   is continuous at SR = −1, across ω_p = 0 and at SR = s_e;
    ///
    /// and `T_del = TR_eff·T_p` with the passivity projection of TR.
    pub fn torques(&self, wp: f64, wt: f64) -> TableTorques {
        let s_e = self.pump_referred_limit();
        if wp == 0.0 && wt == 0.0 {
            return TableTorques {
                pump_nm: 0.0,
                delivered_nm: 0.0,
                d_pump: [0.0; 2],
                d_delivered: [0.0; 2],
                torque_ratio: self.torque_ratio[0],
                d_torque_ratio: [0.0; 2],
                flow_factor: 0.0,
                flow_speed: 0.0,
                d_flow: [0.0; 2],
                region: Region::Rest,
                extrapolated: true,
                extension: false,
            };
        }
        if wp != 0.0 {
            let sr = wt / wp;
            if (-1.0..=s_e).contains(&sr) {
                return self.pump_referred(wp, wt);
            }
        }
        self.turbine_referred(wp, wt)
    }

    fn pump_referred(&self, wp: f64, wt: f64) -> TableTorques {
        let sr = wt / wp;
        let dsr = [-wt / (wp * wp), 1.0 / wp];
        let l = self.lookup(sr);
        let (cf, dcf) = (l.capacity_factor_nm_s2, l.d_capacity_factor);
        let w2 = wp * wp.abs();
        let tp = cf * w2;
        let d_pump = [dcf * dsr[0] * w2 + cf * 2.0 * wp.abs(), dcf * dsr[1] * w2];
        let dtr = [l.d_torque_ratio * dsr[0], l.d_torque_ratio * dsr[1]];
        let (tr, dtr) = if sr > 0.0 {
            project(l.torque_ratio, dtr, cf >= 0.0, wp / wt, [1.0 / wt, -(wp / wt) / wt])
        } else {
            (l.torque_ratio, dtr)
        };
        TableTorques {
            pump_nm: tp,
            delivered_nm: tr * tp,
            d_pump,
            d_delivered: [dtr[0] * tp + tr * d_pump[0], dtr[1] * tp + tr * d_pump[1]],
            torque_ratio: tr,
            d_torque_ratio: dtr,
            flow_factor: cf,
            flow_speed: wp.abs(),
            d_flow: [dcf * dsr[0] * wp.abs() + cf * wp.signum(), dcf * dsr[1] * wp.abs()],
            region: Region::Pump,
            extrapolated: l.extrapolated,
            extension: false,
        }
    }

    fn turbine_referred(&self, wp: f64, wt: f64) -> TableTorques {
        let x = wp / wt;
        let dx = [1.0 / wt, -x / wt];
        let o = self.turbine_capacity(x);
        let v2 = wt * wt.abs();
        let tp = -o.c * v2;
        let d_pump = [-o.dc * dx[0] * v2, -o.dc * dx[1] * v2 - o.c * 2.0 * wt.abs()];
        let dtr = [o.dtr * dx[0], o.dtr * dx[1]];
        let (tr, dtr) = if x > 0.0 { project(o.tr, dtr, o.c <= 0.0, x, dx) } else { (o.tr, dtr) };
        let (g, dg) = (o.c * o.m, o.dc * o.m + o.c * o.dm);
        let overrun = x > 0.0;
        TableTorques {
            pump_nm: tp,
            delivered_nm: tr * tp,
            d_pump,
            d_delivered: [dtr[0] * tp + tr * d_pump[0], dtr[1] * tp + tr * d_pump[1]],
            torque_ratio: tr,
            d_torque_ratio: dtr,
            flow_factor: -g,
            flow_speed: wt.abs(),
            d_flow: [-dg * dx[0] * wt.abs(), -dg * dx[1] * wt.abs() - g * wt.signum()],
            region: if overrun { Region::Overrun } else { Region::TurbineReversed },
            extrapolated: true,
            extension: overrun && self.overrun.is_extension(),
        }
    }

    /// Turbine-referred capacity C, torque ratio TR_m and flow factor m at x = ω_p/ω_t ∈
    /// (−1, 1/s_e), with their derivatives in x.
    fn turbine_capacity(&self, x: f64) -> TurbineSide {
        if x <= 0.0 {
            // the turbine drives the fluid: from the table at SR = −1 to the stall values at x = 0
            let (a, b) = (self.lookup(-1.0), self.lookup(0.0));
            let w = x + 1.0;
            let dc = b.capacity_factor_nm_s2 - a.capacity_factor_nm_s2;
            let dtr = 1.0 - a.torque_ratio;
            return TurbineSide {
                c: a.capacity_factor_nm_s2 + w * dc,
                dc,
                tr: a.torque_ratio + w * dtr,
                dtr,
                m: 1.0 + 2.0 * x,
                dm: 2.0,
            };
        }
        let c0 = self.lookup(0.0).capacity_factor_nm_s2;
        match self.overrun {
            OverrunRule::Table => {
                let n = self.speed_ratio.len();
                let s_n = self.speed_ratio[n - 1];
                let c1 = -self.capacity_factor_nm_s2[n - 1] / (s_n * s_n);
                let dc = (c1 - c0) * s_n;
                let dtr = (self.torque_ratio[n - 1] - 1.0) * s_n;
                let dm = (s_n - 1.0) * s_n;
                TurbineSide { c: c0 + dc * x, dc, tr: 1.0 + dtr * x, dtr, m: 1.0 + dm * x, dm }
            }
            OverrunRule::Mirror => {
                let xa = self.speed_ratio.iter().copied().filter(|&s| s < 1.0).fold(0.0, f64::max);
                if x < xa {
                    let l = self.lookup(x);
                    return TurbineSide {
                        c: l.capacity_factor_nm_s2,
                        dc: l.d_capacity_factor,
                        tr: 1.0,
                        dtr: 0.0,
                        m: 1.0,
                        dm: 0.0,
                    };
                }
                // the last segment below SR 1: C from CF(x_a) to −CF(1), TR from 1 to TR(1)
                let (ca, one) = (self.lookup(xa).capacity_factor_nm_s2, self.lookup(1.0));
                let h = 1.0 - xa;
                let w = (x - xa) / h;
                let dc = (-one.capacity_factor_nm_s2 - ca) / h;
                let dtr = (one.torque_ratio - 1.0) / h;
                TurbineSide { c: ca + w * h * dc, dc, tr: 1.0 + w * h * dtr, dtr, m: 1.0, dm: 0.0 }
            }
        }
    }

    /// Steady state at pump and turbine speeds in rad/s (eqs 2.8–2.9, no inertia terms), in
    /// every quadrant ([`Self::torques`]).
    pub fn operating_point(&self, pump_speed_rad_s: f64, turbine_speed_rad_s: f64) -> CoreResult<TableOperatingPoint> {
        if !pump_speed_rad_s.is_finite() {
            return Err(CoreError::new("pump_speed_rad_s", pump_speed_rad_s, "a finite pump speed"));
        }
        if !turbine_speed_rad_s.is_finite() {
            return Err(CoreError::new("turbine_speed_rad_s", turbine_speed_rad_s, "a finite turbine speed"));
        }
        operating_point_from(
            pump_speed_rad_s,
            turbine_speed_rad_s,
            &self.torques(pump_speed_rad_s, turbine_speed_rad_s),
        )
    }
}

/// The steady state at finite speeds `pump_speed_rad_s`, `turbine_speed_rad_s` (rad/s) whose
/// torques are `t` (an error where they overflow).
pub(crate) fn operating_point_from(
    pump_speed_rad_s: f64,
    turbine_speed_rad_s: f64,
    t: &TableTorques,
) -> CoreResult<TableOperatingPoint> {
    let (tp, t_delivered) = (t.pump_nm, t.delivered_nm);
    if !(tp.is_finite() && t_delivered.is_finite() && (t_delivered - tp).is_finite()) {
        let (field, value) = if pump_speed_rad_s.abs() >= turbine_speed_rad_s.abs() {
            ("pump_speed_rad_s", pump_speed_rad_s)
        } else {
            ("turbine_speed_rad_s", turbine_speed_rad_s)
        };
        return Err(CoreError::of(
            InputSource::Drive,
            field,
            value,
            "a speed at which the steady torques are finite (they grow as the speed squared and overflow)",
        ));
    }
    let capacity = if pump_speed_rad_s == 0.0 { f64::NAN } else { tp / (pump_speed_rad_s * pump_speed_rad_s.abs()) };
    Ok(TableOperatingPoint {
        speed_ratio: turbine_speed_rad_s / pump_speed_rad_s,
        torque_ratio: t.torque_ratio,
        capacity_factor_nm_s2: capacity,
        pump_torque_nm: tp,
        turbine_torque_nm: t_delivered,
        stator_torque_nm: t_delivered - tp,
        extrapolated: t.extrapolated,
        extension: t.extension,
    })
}

/// C, TR_m and m of the turbine-referred region and their derivatives in x.
struct TurbineSide {
    c: f64,
    dc: f64,
    tr: f64,
    dtr: f64,
    m: f64,
    dm: f64,
}

/// The passivity projection of a torque ratio `tr` (gradient `dtr` in (ω_p, ω_t)) against
/// `inv = 1/SR` (gradient `dinv`): at most 1/SR where the pump absorbs power, at least 1/SR where
/// it is driven.
fn project(tr: f64, dtr: [f64; 2], pump_absorbs: bool, inv: f64, dinv: [f64; 2]) -> (f64, [f64; 2]) {
    if (pump_absorbs && tr > inv) || (!pump_absorbs && tr < inv) {
        (inv, dinv)
    } else {
        (tr, dtr)
    }
}

/// Whether capacity `cf` with efficiency `e = SR·TR` creates energy (beyond round-off).
fn violates(cf: f64, e: f64) -> bool {
    let tol = PASSIVITY_ROUND_OFF * e.abs().max(1.0);
    (cf > 0.0 && e > 1.0 + tol) || (cf < 0.0 && e < 1.0 - tol)
}

fn passivity_error(i: usize, tr: f64, e: f64, sr: f64, cf: f64, segment: Option<(f64, f64)>) -> CoreError {
    let place = match segment {
        None => format!("here SR·TR = {e} at SR {sr}"),
        Some((a, b)) => format!("between the rows at SR {a} and {b} the interpolation reaches SR·TR = {e} at SR {sr}"),
    };
    let side = if cf > 0.0 { "the pump absorbs power (CF > 0)" } else { "the pump is driven (CF < 0)" };
    CoreError::new(
        format!("torque_ratio[{i}]"),
        tr,
        format!(
            "a passive table: efficiency SR·TR at most 1 where the pump absorbs power (CF > 0) and at least 1 where it \
             is driven (CF < 0), on every row and between rows ({place}, where {side}: the converter would deliver more \
             power than it absorbs)"
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::converter::dynamics::tests::c1;

    #[test]
    fn reproduces_table_points_exactly() {
        let t = c1();
        for i in 0..t.speed_ratio().len() {
            let l = t.lookup(t.speed_ratio()[i]);
            assert_eq!(l.torque_ratio, t.torque_ratio()[i]);
            assert_eq!(l.capacity_factor_nm_s2, t.capacity_factor_nm_s2()[i]);
            assert!(!l.extrapolated);
        }
    }

    #[test]
    fn interpolates_linearly_between_points() {
        let l = c1().lookup(0.825);
        assert!((l.torque_ratio - 1.03).abs() < 1e-12);
        assert!((l.capacity_factor_nm_s2 - 0.5 * (2.481e-3 + 2.370e-3)).abs() < 1e-15);
    }

    #[test]
    fn holds_end_values_outside_the_table() {
        let t = c1();
        let below = t.lookup(-0.2);
        assert!(
            below.extrapolated
                && below.torque_ratio == 2.14
                && below.capacity_factor_nm_s2 == t.capacity_factor_nm_s2()[0]
        );
        let above = t.lookup(1.3);
        assert!(
            above.extrapolated
                && above.torque_ratio == 1.0
                && above.capacity_factor_nm_s2 == t.capacity_factor_nm_s2()[12]
        );
        assert_eq!(above.d_capacity_factor, 0.0);
    }

    #[test]
    fn overrun_rows_reverse_the_pump_torque() {
        // JAMBE/TRAMI 9AT excerpt: negative capacity above SR = 1 (turbine drives the pump).
        let c = |v: f64| v * crate::units::RPM_PER_RAD_S.powi(2);
        let t = Characteristic::new(vec![0.9, 1.0, 1.1, 1.2], vec![1.0; 4], vec![c(30e-6), 0.0, c(-5e-6), c(-10e-6)])
            .unwrap();
        let op = t.operating_point(200.0, 230.0).unwrap();
        assert!(!op.extrapolated);
        assert!(op.pump_torque_nm < 0.0 && op.turbine_torque_nm < 0.0, "{op:?}");
        assert!((op.capacity_factor_nm_s2 - c(-7.5e-6)).abs() < 1e-12);
    }

    #[test]
    fn torques_balance_and_follow_eq_2_8_and_2_9() {
        let t = c1();
        let wp = crate::units::REFERENCE_PUMP_SPEED_RAD_S;
        let op = t.operating_point(wp, 0.3 * wp).unwrap();
        assert!((op.pump_torque_nm - 3.181e-3 * wp * wp).abs() < 1e-9);
        assert!((op.turbine_torque_nm - 1.70 * op.pump_torque_nm).abs() < 1e-9);
        // external torques: T_p + T_t + T_s = 0 with T_t = −delivered
        assert!((op.pump_torque_nm - op.turbine_torque_nm + op.stator_torque_nm).abs() < 1e-12);
        // negative pump speed: torque follows ω|ω|
        let back = t.operating_point(-wp, -0.3 * wp).unwrap();
        assert!((back.pump_torque_nm + op.pump_torque_nm).abs() < 1e-9);
    }

    #[test]
    fn slopes_agree_with_finite_differences() {
        let t = c1();
        for sr in [0.05, 0.33, 0.81, 0.87, 0.97] {
            let h = 1e-6;
            let (a, b) = (t.lookup(sr - h), t.lookup(sr + h));
            let l = t.lookup(sr);
            assert!((l.d_torque_ratio - (b.torque_ratio - a.torque_ratio) / (2.0 * h)).abs() < 1e-6);
            assert!(
                (l.d_capacity_factor - (b.capacity_factor_nm_s2 - a.capacity_factor_nm_s2) / (2.0 * h)).abs() < 1e-9
            );
        }
    }

    #[test]
    fn rejects_malformed_tables() {
        let e = Characteristic::new(vec![0.0, 0.5, 0.4], vec![2.0; 3], vec![1e-3; 3]).unwrap_err();
        assert_eq!(e.field, "speed_ratio[2]");
        assert!(e.expected.contains("strictly increasing"));
        let e = Characteristic::new(vec![0.0, 0.5], vec![2.0, f64::NAN], vec![1e-3; 2]).unwrap_err();
        assert_eq!(e.field, "torque_ratio[1]");
        assert!(Characteristic::new(vec![0.0], vec![2.0], vec![1e-3]).is_err());
        assert!(Characteristic::new(vec![0.0, 1.0], vec![2.0], vec![1e-3; 2]).is_err());
        assert!(c1().operating_point(f64::NAN, 1.0).is_err());
    }

    /// JAMBE/TRAMI 9AT (tests/data/converters/jambe_trami_9at.csv), CF in N·m/(rad/s)²: coast rows
    /// up to SR 2.1.
    fn jambe() -> Characteristic {
        let c = |v: f64| v * crate::units::RPM_PER_RAD_S.powi(2);
        let sr: Vec<f64> = (-1..=21).map(|i| f64::from(i) / 10.0).collect();
        let tr = vec![
            1.81, 1.81, 1.72, 1.63, 1.54, 1.45, 1.36, 1.27, 1.18, 1.09, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0,
            1.0, 1.0, 1.0, 1.0,
        ];
        let cap = [
            38.0, 38.0, 39.0, 40.0, 41.0, 42.0, 43.0, 44.0, 40.0, 35.0, 30.0, 0.0, -5.0, -10.0, -12.0, -14.0, -16.0,
            -18.0, -20.0, -22.0, -24.0, -26.0, -26.0,
        ];
        Characteristic::new(sr, tr, cap.iter().map(|&v| c(v * 1e-6)).collect()).unwrap()
    }

    fn tables() -> Vec<(&'static str, Characteristic)> {
        let k = c1().with_rules(None, Some("k_factor")).unwrap();
        // a table ending below SR 1 (held up to 1, then mirrored)
        let short = Characteristic::new(vec![0.0, 0.5, 0.8], vec![2.0, 1.4, 1.1], vec![3e-3, 2.8e-3, 2.0e-3]).unwrap();
        vec![("C.1", c1()), ("C.1 k_factor", k), ("JAMBE", jambe()), ("short", short)]
    }

    /// Absorbed power `T_p ω_p − T_del ω_t`, W.
    fn absorbed(t: &TableTorques, wp: f64, wt: f64) -> f64 {
        t.pump_nm * wp - t.delivered_nm * wt
    }

    #[test]
    fn defaults_follow_the_tables_rows() {
        assert_eq!(c1().overrun(), OverrunRule::Mirror);
        assert_eq!(jambe().overrun(), OverrunRule::Table);
        assert_eq!(c1().interpolation(), Interpolation::CapacityFactor);
        let e = jambe().with_rules(Some("mirror"), None).unwrap_err();
        assert_eq!(e.field, "overrun");
        assert!(e.expected.contains("own overrun rows up to SR 2.1"), "{e}");
        let e = c1().with_rules(Some("table"), None).unwrap_err();
        assert!(e.expected.contains("ends at SR 1"), "{e}");
        let e = c1().with_rules(Some("chrono"), None).unwrap_err();
        assert_eq!((e.field.as_str(), e.expected.as_str()), ("overrun", "one of \"mirror\", \"table\""));
        let e = c1().with_rules(None, Some("K")).unwrap_err();
        assert_eq!(e.expected, "one of \"capacity_factor\", \"k_factor\"");
    }

    #[test]
    fn a_table_that_creates_energy_is_refused() {
        // a row with SR·TR = 1.1 > 1 where CF > 0
        let e = Characteristic::new(vec![0.0, 0.5, 1.0], vec![2.0, 1.5, 1.1], vec![3e-3, 2e-3, 1e-3]).unwrap_err();
        assert_eq!(e.field, "torque_ratio[2]", "{e}");
        assert!(e.expected.contains("SR·TR = 1.1"), "{e}");
        // rows fine, but between them SR·TR = SR·(3 − 2 SR) reaches 1.125 at SR 0.75
        let e = Characteristic::new(vec![0.5, 1.0], vec![2.0, 1.0], vec![3e-3, 1e-3]).unwrap_err();
        assert_eq!(e.field, "torque_ratio[0]", "{e}");
        assert!(e.expected.contains("between the rows at SR 0.5 and 1") && e.expected.contains("1.125"), "{e}");
        // a coast row (CF < 0) must have SR·TR ≥ 1: TR 0.8 at SR 1.1 would drive the turbine
        let e = Characteristic::new(vec![0.0, 1.0, 1.1], vec![2.0, 1.0, 0.8], vec![3e-3, 0.0, -1e-3]).unwrap_err();
        assert_eq!(e.field, "torque_ratio[2]", "{e}");
        // the published tables pass
        for (_, t) in tables() {
            t.check_passive().unwrap();
        }
    }

    #[test]
    fn passive_on_a_dense_grid_of_every_quadrant() {
        for (name, t) in tables() {
            for i in -50..=50 {
                for j in -50..=50 {
                    let (wp, wt) = (10.0 * f64::from(i), 10.0 * f64::from(j));
                    let tq = t.torques(wp, wt);
                    let p = absorbed(&tq, wp, wt);
                    let scale = 3.5e-3 * wp.abs().max(wt.abs()).powi(3);
                    assert!(p >= -1e-12 * scale, "{name} at ({wp}, {wt}): {p} W, {tq:?}");
                }
            }
        }
    }

    #[test]
    fn overrun_brakes_the_pump() {
        // the cases: SR 2 (and 1.2, 3) used to drive the turbine with the pump's torque
        for (name, t) in tables() {
            for sr in [1.2, 2.0, 3.0] {
                for wp in [200.0, -200.0] {
                    let tq = t.torques(wp, sr * wp);
                    assert!(tq.pump_nm * wp < 0.0, "{name} SR {sr} ωp {wp}: {tq:?}");
                    assert!(absorbed(&tq, wp, sr * wp) > 0.0, "{name} SR {sr}: {tq:?}");
                }
            }
        }
    }

    #[test]
    fn torques_and_flow_are_continuous_on_the_whole_plane() {
        let eps = 1e-9;
        for (name, t) in tables() {
            let s_e = t.pump_referred_limit();
            let mut points = vec![(200.0, -200.0), (-200.0, 200.0), (200.0, 200.0 * s_e), (-150.0, -150.0 * s_e)];
            points.extend([(0.0, 300.0), (0.0, -300.0), (1e-3, 300.0), (300.0, 0.0)]);
            for &s in t.speed_ratio() {
                if s > 0.0 {
                    points.push((100.0, 100.0 * s));
                    points.push((300.0 * s.min(1.0 / s), 300.0)); // the mirror's knots
                }
            }
            for (wp, wt) in points {
                let at = t.torques(wp, wt);
                let scale = 3.5e-3 * f64::max(wp.abs(), wt.abs()).powi(2);
                for (dp, dt) in [(eps, 0.0), (-eps, 0.0), (0.0, eps), (0.0, -eps)] {
                    let (p, q) = (wp + dp * wp.abs().max(1.0), wt + dt * wt.abs().max(1.0));
                    let near = t.torques(p, q);
                    for (a, b, what) in [
                        (at.pump_nm, near.pump_nm, "pump"),
                        (at.delivered_nm, near.delivered_nm, "delivered"),
                        (at.flow_factor * at.flow_speed * 300.0, near.flow_factor * near.flow_speed * 300.0, "flow"),
                    ] {
                        assert!((a - b).abs() <= 1e-6 * scale, "{name} {what} at ({wp}, {wt}) vs ({p}, {q}): {a} {b}");
                    }
                }
            }
        }
    }

    #[test]
    fn mirror_follows_its_definition() {
        let t = c1();
        // x = ω_p/ω_t = 0.4: C = CF(0.4), TR = 1
        let tq = t.torques(100.0, 250.0);
        assert_eq!(tq.region, Region::Overrun);
        assert!(tq.extension && tq.extrapolated);
        assert!((tq.pump_nm - (-3.112e-3 * 250.0 * 250.0)).abs() < 1e-12 * 200.0, "{tq:?}");
        assert!((tq.delivered_nm - tq.pump_nm).abs() < 1e-12, "{tq:?}");
        // x = 0.975 on the last segment [0.95, 1]: C halfway from CF(0.95) to −CF(1)
        let tq = t.torques(390.0, 400.0);
        let c = 1.237e-3 + 0.5 * (-0.187e-3 - 1.237e-3);
        assert!((tq.pump_nm - (-c * 400.0 * 400.0)).abs() < 1e-9, "{tq:?}");
        // the pump at rest, the turbine turning: stall capacity referred to the turbine
        let tq = t.torques(0.0, -300.0);
        assert_eq!(tq.region, Region::TurbineReversed);
        assert!((tq.pump_nm - 3.272e-3 * 300.0 * 300.0).abs() < 1e-9, "{tq:?}");
        // roll-back at SR −2: x = −0.5, C = CF(0), TR halfway from TR(0) = 2.14 to 1
        let tq = t.torques(100.0, -200.0);
        assert!((tq.pump_nm - 3.272e-3 * 200.0 * 200.0).abs() < 1e-9, "{tq:?}");
        assert!((tq.torque_ratio - 0.5 * (2.14 + 1.0)).abs() < 1e-12, "{tq:?}");
        // both reversed mirror drive by the ω|ω| law
        let (f, b) = (t.torques(200.0, 80.0), t.torques(-200.0, -80.0));
        assert!((f.pump_nm + b.pump_nm).abs() < 1e-12 && (f.delivered_nm + b.delivered_nm).abs() < 1e-12);
        // at rest, nothing
        let tq = t.torques(0.0, 0.0);
        assert_eq!((tq.pump_nm, tq.delivered_nm, tq.region), (0.0, 0.0, Region::Rest));
        // the table's own rows are used where they exist, with no extension
        let j = jambe();
        let tq = j.torques(200.0, 300.0);
        assert_eq!(tq.region, Region::Pump);
        assert!(!tq.extension && !tq.extrapolated);
        let beyond = j.torques(100.0, 300.0);
        assert!(beyond.region == Region::Overrun && !beyond.extension);
    }

    #[test]
    fn k_factor_interpolation_is_linear_in_k() {
        let t = c1().with_rules(None, Some("k_factor")).unwrap();
        let cf = t.capacity_factor_nm_s2();
        let l = t.lookup(0.925);
        let k = 0.5 * (1.0 / cf[10].sqrt() + 1.0 / cf[11].sqrt());
        assert!((l.capacity_factor_nm_s2 - 1.0 / (k * k)).abs() <= 1e-15, "{l:?}");
        for (&sr, &c) in t.speed_ratio().iter().zip(cf) {
            assert_eq!(t.lookup(sr).capacity_factor_nm_s2, c);
        }
        let h = 1e-6;
        let d = (t.lookup(0.93 + h).capacity_factor_nm_s2 - t.lookup(0.93 - h).capacity_factor_nm_s2) / (2.0 * h);
        assert!((t.lookup(0.93).d_capacity_factor - d).abs() < 1e-9);
    }
}
