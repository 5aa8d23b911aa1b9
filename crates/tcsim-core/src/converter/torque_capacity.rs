//! Torque-dependent capacity: one or several characteristic tables, each measured at one input
//! (pump) torque (Li & Sundén 2016 §4.3.2; Kietlinski & Fingerman 2007), docs/torque_capacity.md.
//!
//! **Between tables** the torques of the two neighbouring tables *at the same speeds* are
//! interpolated linearly in the input torque T: `T_p = (1−w)·T_p,k + w·T_p,k+1` and
//! `T_del = (1−w)·T_del,k + w·T_del,k+1`, `w = (T − T_k)/(T_k+1 − T_k)`. In the pump-referred
//! region this is CF linear in T at the same SR, and TR·CF linear in T (TR is then the
//! CF-weighted mean of the two tables' TR, between them). Interpolating the torques rather than TR
//! keeps the converter passive without a new projection: the absorbed power is the same convex
//! combination of the two tables' absorbed powers. **Outside** the tables' torques the nearest
//! table is held.
//!
//! **The fixed point.** The input torque is the pump torque itself, so at given speeds
//! `T = P(T)`, with `P` the interpolated pump torque: continuous and piecewise linear in T, with
//! `P(T) − T → ±∞` as `T → ∓∞`, so a solution always exists. It is found exactly: the smallest
//! T with `P(T) = T`, by scanning the intervals from the lowest torque (on the interval where
//! `P(T) − T` changes sign, `T = T_k + w·h` with `w = a/(a + b)`, `a = P(T_k) − T_k > 0`,
//! `b = T_k+1 − P(T_k+1) ≥ 0`). The smallest solution is unique wherever the slope
//! `s = ∂P/∂T` of every interval is below 1; where a steep capacity increase with torque gives
//! several solutions, the smallest is the branch that continues from rest (docs/models.md). The
//! gradient of the solved torque follows from the implicit function theorem,
//! `dT/dω = (∂P/∂ω)/(1 − s)`, with `1 − s = (a + b)/h > 0` at the chosen solution.
//!
//! A single table is the plain [`Characteristic`], bit for bit.

use super::table::{operating_point_from, Characteristic, TableOperatingPoint, TableTorques};
use crate::error::{CoreError, CoreResult, InputSource};

/// One characteristic table, or several with the input torques they were measured at.
#[derive(Debug, Clone, PartialEq)]
pub struct TorqueCharacteristic {
    tables: Vec<Characteristic>,
    /// Empty for a single table; else one strictly increasing positive torque per table, N·m.
    input_torque_nm: Vec<f64>,
}

impl From<Characteristic> for TorqueCharacteristic {
    fn from(c: Characteristic) -> Self {
        Self { tables: vec![c], input_torque_nm: Vec::new() }
    }
}

/// Where the fixed point lies: held at table `k` (w = 0), or between tables k and k+1.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Solved {
    k: usize,
    /// Weight of table k+1.
    w: f64,
    /// `∂P/∂T` on the interval (0 where a table is held).
    slope: f64,
}

fn prefixed(i: usize, e: CoreError) -> CoreError {
    CoreError { field: format!("characteristic[{i}].{}", e.field), ..e }
}

impl TorqueCharacteristic {
    /// Several tables with the input torques (N·m) they were measured at: at least two tables,
    /// torques finite, positive and strictly increasing, and the same overrun rule and
    /// interpolation in every table (they are the converter's, not a table's).
    pub fn new(input_torque_nm: Vec<f64>, tables: Vec<Characteristic>) -> CoreResult<Self> {
        if tables.len() < 2 || tables.len() != input_torque_nm.len() {
            return Err(CoreError::new(
                "input_torque_nm",
                format!("{} torques for {} tables", input_torque_nm.len(), tables.len()),
                "one input torque per table and at least two tables",
            ));
        }
        for (i, &t) in input_torque_nm.iter().enumerate() {
            if !(t.is_finite() && t > 0.0) {
                return Err(CoreError::new(
                    format!("characteristic[{i}].input_torque_nm"),
                    t,
                    "a finite, positive input torque in N·m",
                ));
            }
            if i > 0 && t <= input_torque_nm[i - 1] {
                return Err(CoreError::new(
                    format!("characteristic[{i}].input_torque_nm"),
                    t,
                    format!("strictly increasing input torques (previous table at {} N·m)", input_torque_nm[i - 1]),
                ));
            }
        }
        for (i, c) in tables.iter().enumerate().skip(1) {
            if c.overrun() != tables[0].overrun() {
                return Err(CoreError::new(
                    format!("characteristic[{i}].overrun"),
                    format!("\"{}\"", c.overrun().key()),
                    format!(
                        "the overrun rule of the other tables, \"{}\" (one rule for the converter: every table \
                         has overrun rows above SR 1, or none has)",
                        tables[0].overrun().key()
                    ),
                ));
            }
            if c.interpolation() != tables[0].interpolation() {
                return Err(CoreError::new(
                    format!("characteristic[{i}].interpolation"),
                    format!("\"{}\"", c.interpolation().key()),
                    format!("the interpolation of the other tables, \"{}\"", tables[0].interpolation().key()),
                ));
            }
        }
        Ok(Self { tables, input_torque_nm })
    }

    /// Tables given as concatenated columns (the model specification's form): `table_rows[i]`
    /// rows for table i, measured at `input_torque_nm[i]`; each table is checked by
    /// [`Characteristic::new`] and [`Characteristic::with_rules`] (errors name
    /// `characteristic[i].field`).
    pub fn from_columns(
        input_torque_nm: Vec<f64>,
        table_rows: &[f64],
        columns: [&[f64]; 3],
        overrun: Option<&str>,
        interpolation: Option<&str>,
    ) -> CoreResult<Self> {
        let n = columns[0].len();
        let total: f64 = table_rows.iter().sum();
        let whole = table_rows.iter().all(|&r| r.fract() == 0.0 && r >= 2.0);
        if table_rows.len() != input_torque_nm.len() || !whole || total != n as f64 {
            return Err(CoreError::new(
                "table_rows",
                format!("{table_rows:?}"),
                format!("one whole row count of at least 2 per input torque, {n} rows in all"),
            ));
        }
        let mut tables = Vec::with_capacity(table_rows.len());
        let mut start = 0;
        for (i, &rows) in table_rows.iter().enumerate() {
            let end = start + rows as usize;
            let col = |c: &[f64]| c.get(start..end).map(<[f64]>::to_vec).unwrap_or_default();
            let table = Characteristic::new(col(columns[0]), col(columns[1]), col(columns[2]))
                .and_then(|c| c.with_rules(overrun, interpolation))
                .map_err(|e| prefixed(i, e))?;
            tables.push(table);
            start = end;
        }
        Self::new(input_torque_nm, tables)
    }

    /// The tables, by increasing input torque.
    pub fn tables(&self) -> &[Characteristic] {
        &self.tables
    }
    /// The input torques of the tables, N·m (empty for a single table).
    pub fn input_torque_nm(&self) -> &[f64] {
        &self.input_torque_nm
    }
    /// The table of a single-table characteristic (None for several).
    pub fn single(&self) -> Option<&Characteristic> {
        if self.tables.len() == 1 {
            self.tables.first()
        } else {
            None
        }
    }

    /// The smallest solution of `T = P(T)` given each table's pump torque `p[i]` at the speeds
    /// (module docs).
    fn solve(&self, p: &[f64]) -> Solved {
        let t = &self.input_torque_nm;
        let held = |k: usize| Solved { k, w: 0.0, slope: 0.0 };
        // P(T_1) ≤ T_1 (or NaN): the first table is held
        if p[0] <= t[0] || p[0].is_nan() {
            return held(0);
        }
        for k in 0..t.len() - 1 {
            let b = t[k + 1] - p[k + 1];
            if b >= 0.0 {
                let a = p[k] - t[k];
                return Solved { k, w: a / (a + b), slope: (p[k + 1] - p[k]) / (t[k + 1] - t[k]) };
            }
        }
        held(t.len() - 1)
    }

    /// The weight of the tables at input torque `torque_nm` (no fixed point: the torque given).
    fn at_torque(&self, torque_nm: f64) -> Solved {
        let t = &self.input_torque_nm;
        let n = t.len();
        if n < 2 || torque_nm <= t[0] || torque_nm.is_nan() {
            return Solved { k: 0, w: 0.0, slope: 0.0 };
        }
        if torque_nm >= t[n - 1] {
            return Solved { k: n - 1, w: 0.0, slope: 0.0 };
        }
        let k = t.partition_point(|&x| x <= torque_nm) - 1;
        Solved { k, w: (torque_nm - t[k]) / (t[k + 1] - t[k]), slope: 0.0 }
    }

    /// The torques at pump and turbine speeds `wp`, `wt` (rad/s, any signs) with the input torque
    /// solved (module docs), and their gradients including that of the solved torque.
    pub fn torques(&self, wp: f64, wt: f64) -> TableTorques {
        if let Some(c) = self.single() {
            return c.torques(wp, wt);
        }
        let ts: Vec<TableTorques> = self.tables.iter().map(|c| c.torques(wp, wt)).collect();
        let p: Vec<f64> = ts.iter().map(|t| t.pump_nm).collect();
        let s = self.solve(&p);
        self.blend(&ts, s, true)
    }

    /// The two tables' torques `ts[k]`, `ts[k+1]` mixed with weight `s.w`; with `solved`, the
    /// weight's gradient through the fixed point, else the weight held.
    fn blend(&self, ts: &[TableTorques], s: Solved, solved: bool) -> TableTorques {
        if s.w == 0.0 {
            return ts[s.k];
        }
        let (a, b, w) = (&ts[s.k], &ts[s.k + 1], s.w);
        let mix = |x: f64, y: f64| (1.0 - w) * x + w * y;
        let mix2 = |x: [f64; 2], y: [f64; 2]| [mix(x[0], y[0]), mix(x[1], y[1])];
        // dw = dT/h, dT = (∂P/∂ω)/(1 − s): the implicit function theorem on T = P(T, ω)
        let h = self.input_torque_nm[s.k + 1] - self.input_torque_nm[s.k];
        let dp = mix2(a.d_pump, b.d_pump);
        let dw = if solved { [dp[0] / (1.0 - s.slope) / h, dp[1] / (1.0 - s.slope) / h] } else { [0.0; 2] };
        let with_dw = |x: [f64; 2], y: [f64; 2], qa: f64, qb: f64| {
            let m = mix2(x, y);
            [m[0] + (qb - qa) * dw[0], m[1] + (qb - qa) * dw[1]]
        };
        let pump_nm = mix(a.pump_nm, b.pump_nm);
        let delivered_nm = mix(a.delivered_nm, b.delivered_nm);
        let d_pump = with_dw(a.d_pump, b.d_pump, a.pump_nm, b.pump_nm);
        let d_delivered = with_dw(a.d_delivered, b.d_delivered, a.delivered_nm, b.delivered_nm);
        // TR = delivered/pump of the mix; where the pump torque is 0, the tables' TR mixed
        let (torque_ratio, d_torque_ratio) = if pump_nm != 0.0 {
            let tr = delivered_nm / pump_nm;
            (tr, std::array::from_fn(|i| (d_delivered[i] - tr * d_pump[i]) / pump_nm))
        } else {
            let tr = with_dw(a.d_torque_ratio, b.d_torque_ratio, a.torque_ratio, b.torque_ratio);
            (mix(a.torque_ratio, b.torque_ratio), tr)
        };
        let (qa, qb) = (a.flow_factor * a.flow_speed, b.flow_factor * b.flow_speed);
        let (flow_factor, flow_speed) = if a.flow_speed == b.flow_speed {
            (mix(a.flow_factor, b.flow_factor), a.flow_speed)
        } else {
            (mix(qa, qb), 1.0)
        };
        TableTorques {
            pump_nm,
            delivered_nm,
            d_pump,
            d_delivered,
            torque_ratio,
            d_torque_ratio,
            flow_factor,
            flow_speed,
            d_flow: with_dw(a.d_flow, b.d_flow, qa, qb),
            region: if w < 0.5 { a.region } else { b.region },
            extrapolated: a.extrapolated || b.extrapolated,
            extension: a.extension || b.extension,
        }
    }

    /// The input torque (= pump torque) the fixed point gives at speeds `wp`, `wt`, N·m.
    pub fn solved_input_torque_nm(&self, wp: f64, wt: f64) -> f64 {
        self.torques(wp, wt).pump_nm
    }

    /// Steady state at pump and turbine speeds in rad/s, the input torque solved; a single table
    /// is [`Characteristic::operating_point`].
    pub fn operating_point(&self, pump_speed_rad_s: f64, turbine_speed_rad_s: f64) -> CoreResult<TableOperatingPoint> {
        if let Some(c) = self.single() {
            return c.operating_point(pump_speed_rad_s, turbine_speed_rad_s);
        }
        check_speeds(pump_speed_rad_s, turbine_speed_rad_s)?;
        operating_point_from(
            pump_speed_rad_s,
            turbine_speed_rad_s,
            &self.torques(pump_speed_rad_s, turbine_speed_rad_s),
        )
    }

    /// The steady state at input (pump) torque `pump_torque_nm` and speed ratio `speed_ratio`
    /// with a positive pump speed: the tables' weight is that of the given torque, and the pump
    /// speed solves `T = c·ω_p²`, `c` the mixed pump torque at ω_p = 1 rad/s (the torques are
    /// homogeneous of degree 2 in the speeds), so `ω_p = √(T/c)`. Returns the pump speed (rad/s)
    /// and the operating point. An error where T and c differ in sign or c is 0 (no positive pump
    /// speed carries T at this speed ratio).
    pub fn at_pump_torque(&self, pump_torque_nm: f64, speed_ratio: f64) -> CoreResult<(f64, TableOperatingPoint)> {
        if !(pump_torque_nm.is_finite() && pump_torque_nm != 0.0) {
            return Err(CoreError::of(
                InputSource::Drive,
                "input_torque_nm",
                pump_torque_nm,
                "a finite, non-zero torque",
            ));
        }
        if !speed_ratio.is_finite() {
            return Err(CoreError::of(InputSource::Drive, "speed_ratio", speed_ratio, "a finite speed ratio"));
        }
        let s = self.at_torque(pump_torque_nm);
        let at =
            |wp: f64| -> Vec<TableTorques> { self.tables.iter().map(|c| c.torques(wp, speed_ratio * wp)).collect() };
        let c = self.blend(&at(1.0), s, false).pump_nm;
        let w2 = pump_torque_nm / c;
        if !(w2 > 0.0 && w2.is_finite()) {
            return Err(CoreError::of(
                InputSource::Drive,
                "input_torque_nm",
                pump_torque_nm,
                format!(
                    "a torque of the sign of the pump torque at speed ratio {speed_ratio} (here {c} N·m at 1 rad/s: \
                     no positive pump speed carries it)"
                ),
            ));
        }
        let wp = w2.sqrt();
        check_speeds(wp, speed_ratio * wp)?;
        let op = operating_point_from(wp, speed_ratio * wp, &self.blend(&at(wp), s, false))?;
        Ok((wp, op))
    }
}

fn check_speeds(wp: f64, wt: f64) -> CoreResult<()> {
    if !wp.is_finite() {
        return Err(CoreError::new("pump_speed_rad_s", wp, "a finite pump speed"));
    }
    if !wt.is_finite() {
        return Err(CoreError::new("turbine_speed_rad_s", wt, "a finite turbine speed"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Li & Sundén (2016) Table C.1 with its CF scaled by `scale` and TR shifted towards 1 by
    /// `tr_shift` (a synthetic torque dependence).
    fn table(scale: f64, tr_shift: f64) -> Characteristic {
        let sr = vec![0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0];
        let tr: Vec<f64> = [2.14, 1.99, 1.84, 1.70, 1.56, 1.43, 1.30, 1.18, 1.06, 1.00, 1.00, 1.00, 1.00]
            .iter()
            .map(|&t| 1.0 + (t - 1.0) * (1.0 - tr_shift))
            .collect();
        let cf = [3.272, 3.257, 3.228, 3.181, 3.112, 3.017, 2.887, 2.713, 2.481, 2.370, 1.842, 1.237, 0.187]
            .iter()
            .map(|v| v * 1e-3 * scale)
            .collect();
        Characteristic::new(sr, tr, cf).unwrap()
    }

    fn two() -> TorqueCharacteristic {
        TorqueCharacteristic::new(vec![100.0, 300.0], vec![table(1.0, 0.0), table(1.15, 0.2)]).unwrap()
    }

    fn three() -> TorqueCharacteristic {
        TorqueCharacteristic::new(vec![100.0, 200.0, 300.0], vec![table(0.9, 0.0), table(1.0, 0.1), table(1.1, 0.2)])
            .unwrap()
    }

    #[test]
    fn a_single_table_is_the_table_bit_for_bit() {
        let c = table(1.0, 0.0);
        let t = TorqueCharacteristic::from(c.clone());
        for (wp, wt) in [(200.0, 50.0), (-150.0, 30.0), (0.0, 100.0), (100.0, 250.0), (0.0, 0.0)] {
            // compared as text: bit-equal, NaN included
            assert_eq!(format!("{:?}", t.torques(wp, wt)), format!("{:?}", c.torques(wp, wt)));
            assert_eq!(format!("{:?}", t.operating_point(wp, wt)), format!("{:?}", c.operating_point(wp, wt)));
        }
    }

    #[test]
    fn each_tables_own_torque_reproduces_it() {
        for tc in [two(), three()] {
            for (i, (&t, c)) in tc.input_torque_nm().iter().zip(tc.tables()).enumerate() {
                for (j, &sr) in c.speed_ratio().iter().enumerate() {
                    let (wp, op) = tc.at_pump_torque(t, sr).unwrap();
                    assert!((op.pump_torque_nm - t).abs() <= 1e-12 * t, "table {i} row {j}: {op:?}");
                    let cf = c.capacity_factor_nm_s2()[j];
                    assert!((op.capacity_factor_nm_s2 - cf).abs() <= 1e-12 * cf, "table {i} row {j}: {op:?}");
                    assert!((op.torque_ratio - c.torque_ratio()[j]).abs() <= 1e-12, "table {i} row {j}: {op:?}");
                    // the forward fixed point at these speeds finds the same torque
                    let fwd = tc.operating_point(wp, sr * wp).unwrap();
                    assert!((fwd.pump_torque_nm - t).abs() <= 1e-9 * t, "table {i} row {j}: {fwd:?}");
                    assert!((fwd.torque_ratio - c.torque_ratio()[j]).abs() <= 1e-9, "table {i} row {j}: {fwd:?}");
                }
            }
        }
    }

    #[test]
    fn between_tables_the_point_lies_between_them_and_outside_holds_the_nearest() {
        let tc = three();
        let (lo, hi) = (&tc.tables()[1], &tc.tables()[2]);
        for sr in [0.0, 0.35, 0.8, 0.97] {
            let (_, op) = tc.at_pump_torque(250.0, sr).unwrap();
            let (a, b) = (lo.lookup(sr), hi.lookup(sr));
            let between = |x: f64, p: f64, q: f64| p.min(q) < x && x < p.max(q);
            assert!(between(op.capacity_factor_nm_s2, a.capacity_factor_nm_s2, b.capacity_factor_nm_s2), "{op:?}");
            if a.torque_ratio != b.torque_ratio {
                assert!(between(op.torque_ratio, a.torque_ratio, b.torque_ratio), "{op:?}");
            }
            for (torque, held) in [(20.0, &tc.tables()[0]), (900.0, &tc.tables()[2])] {
                let (wp, op) = tc.at_pump_torque(torque, sr).unwrap();
                assert_eq!(op, held.operating_point(wp, sr * wp).unwrap());
                let fwd = tc.torques(wp, sr * wp);
                assert_eq!(fwd, held.torques(wp, sr * wp), "held at {torque} N·m, SR {sr}");
            }
        }
    }

    #[test]
    fn the_fixed_point_is_solved_exactly() {
        let tc = three();
        for wp in [50.0, 150.0, 200.0, 260.0, 320.0, 400.0, -250.0] {
            for sr in [0.0, 0.4, 0.9, 1.5, -0.5] {
                let t = tc.torques(wp, sr * wp);
                // P(T) computed afresh at the solved torque
                let s = tc.at_torque(t.pump_nm);
                let ts: Vec<TableTorques> = tc.tables().iter().map(|c| c.torques(wp, sr * wp)).collect();
                let p = tc.blend(&ts, s, false).pump_nm;
                assert!((p - t.pump_nm).abs() <= 1e-12 * t.pump_nm.abs().max(1.0), "{wp} {sr}: {p} {t:?}");
            }
        }
    }

    #[test]
    fn the_gradient_includes_the_solved_torque() {
        for tc in [two(), three()] {
            for (wp, wt) in
                [(230.0, 40.0), (250.0, 180.0), (180.0, 172.0), (300.0, 330.0), (-220.0, -60.0), (20.0, 300.0)]
            {
                let t = tc.torques(wp, wt);
                for (j, (dp, dt)) in [(1.0, 0.0), (0.0, 1.0)].into_iter().enumerate() {
                    let h = 1e-6 * f64::max(wp.abs(), wt.abs());
                    let (up, dn) = (tc.torques(wp + h * dp, wt + h * dt), tc.torques(wp - h * dp, wt - h * dt));
                    let scale = 1e-6 * t.pump_nm.abs().max(1.0) / f64::max(wp.abs(), wt.abs());
                    for (name, d, fd) in [
                        ("pump", t.d_pump[j], (up.pump_nm - dn.pump_nm) / (2.0 * h)),
                        ("delivered", t.d_delivered[j], (up.delivered_nm - dn.delivered_nm) / (2.0 * h)),
                        (
                            "flow",
                            t.d_flow[j],
                            (up.flow_factor * up.flow_speed - dn.flow_factor * dn.flow_speed) / (2.0 * h),
                        ),
                    ] {
                        assert!((d - fd).abs() <= scale, "{name} d/dω[{j}] at ({wp}, {wt}): {d} vs {fd}");
                    }
                }
            }
        }
    }

    #[test]
    fn passive_on_a_grid_of_every_quadrant() {
        for tc in [two(), three()] {
            for i in -40..=40 {
                for j in -40..=40 {
                    let (wp, wt) = (12.5 * f64::from(i), 12.5 * f64::from(j));
                    let t = tc.torques(wp, wt);
                    let p = t.pump_nm * wp - t.delivered_nm * wt;
                    assert!(p >= -1e-12 * 4e-3 * wp.abs().max(wt.abs()).powi(3), "({wp}, {wt}): {p} W");
                }
            }
        }
    }

    #[test]
    fn bad_tables_are_refused() {
        let e = TorqueCharacteristic::new(vec![100.0, 100.0], vec![table(1.0, 0.0), table(1.1, 0.0)]).unwrap_err();
        assert_eq!(e.field, "characteristic[1].input_torque_nm");
        let e = TorqueCharacteristic::new(vec![-1.0, 100.0], vec![table(1.0, 0.0), table(1.1, 0.0)]).unwrap_err();
        assert_eq!(e.field, "characteristic[0].input_torque_nm");
        let k = table(1.1, 0.0).with_rules(None, Some("k_factor")).unwrap();
        let e = TorqueCharacteristic::new(vec![100.0, 200.0], vec![table(1.0, 0.0), k]).unwrap_err();
        assert_eq!(e.field, "characteristic[1].interpolation");
        let sr = [0.0, 0.5, 1.0, 0.0, 0.5];
        let e = TorqueCharacteristic::from_columns(
            vec![1.0, 2.0],
            &[3.0, 2.0],
            [&sr, &[1.0, 1.0, 3.0, 1.0, 1.0], &[1e-3; 5]],
            None,
            None,
        )
        .unwrap_err();
        assert_eq!(e.field, "characteristic[0].torque_ratio[2]", "{e}");
        let e =
            TorqueCharacteristic::from_columns(vec![1.0, 2.0], &[3.0, 3.0], [&sr, &sr, &sr], None, None).unwrap_err();
        assert_eq!(e.field, "table_rows");
        assert!(two().at_pump_torque(f64::NAN, 0.5).is_err());
        // overrun (SR 1.5 beyond the mirror): the pump torque is negative, no pump speed carries +100 N·m
        assert_eq!(two().at_pump_torque(100.0, 1.5).unwrap_err().field, "input_torque_nm");
        assert!(two().at_pump_torque(-100.0, 1.5).is_ok());
    }
}
