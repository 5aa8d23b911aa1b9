//! Named output channels of a transient run (names per tcsim conventions: unit in every name).
//!
//! Effective torques follow Li & Sundén (2016) eqs 3.1–3.4 and figure 3.15:
//!
//! ```text
//!     T_p = T_inertia,p + T_fluid,p + T_transfer,p          T_inertia,p = I_p ω̇_p, T_fluid,p = ρS_p Q̇
//!     T_transfer,t = T_inertia,t + T_fluid,t + T_t          T_inertia,t = I_t ω̇_t, T_fluid,t = ρS_t Q̇
//!     effective pump input torque     = T_p − I_p ω̇_p  = T_fluid,p + T_transfer,p
//!     effective turbine output torque = T_t + I_t ω̇_t  = T_transfer,t − T_fluid,t
//!     effective TR = effective turbine output torque / effective pump input torque
//! ```
//!
//! `T_t` is the torque delivered to the transmission (`turbine_torque_nm`). With the lock-up clutch
//! ([`crate::engine::lockup`]) `T_p` and `T_t` are the torques at the converter's shafts, the
//! clutch's torque included; the energy identity of the columns is
//!
//! ```text
//!     ∫ converter_input_power_w dt + lockup_lock_work_j(end)
//!         = Δ stored_energy_j + ∫ (fluid_loss_power_w + lockup_loss_power_w) dt + lockup_lock_loss_j(end)
//! ```

use crate::converter::dynamics::{ConverterDynamics, FLOW, PUMP, STATOR, TURBINE};
use crate::engine::converter_events::Sample;
use crate::engine::isolated::Trajectory;
use crate::engine::options::{try_reserve, OutputSize, Sampled, SolverOptions, TransientResult};
use crate::error::{CoreError, CoreResult, InputSource};

/// Index in [`COLUMNS`] of the first lock-up clutch column (the clutch's columns come last).
pub const LOCKUP_COLUMNS_START: usize = 27;

/// Column names, in order.
pub const COLUMNS: [&str; 33] = [
    "time_s",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
    "stator_speed_rad_s",
    "flow_m3_s",
    "pump_accel_rad_s2",
    "turbine_accel_rad_s2",
    "flow_rate_of_change_m3_s2",
    "pump_torque_nm",
    "turbine_torque_nm",
    "stator_torque_nm",
    "speed_ratio",
    "torque_ratio",
    "stator_mode",
    "flow_direction",
    "pump_inertia_torque_nm",
    "pump_fluid_torque_nm",
    "pump_transferred_torque_nm",
    "turbine_inertia_torque_nm",
    "turbine_fluid_torque_nm",
    "turbine_transferred_torque_nm",
    "effective_pump_torque_nm",
    "effective_turbine_torque_nm",
    "effective_torque_ratio",
    "fluid_loss_power_w",
    "stored_energy_j",
    "converter_input_power_w",
    "lockup_torque_nm",
    "lockup_state",
    "lockup_slip_rad_s",
    "lockup_loss_power_w",
    "lockup_lock_loss_j",
    "lockup_lock_work_j",
];

fn ratio(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        f64::NAN
    } else {
        a / b
    }
}

/// Index in [`COLUMNS`] of each column that is a state coordinate or the time (`time_s` to
/// `flow_m3_s`): the overflow check ([`Overflow`]) looks at them whatever the selection.
const STATE_COLUMNS: std::ops::Range<usize> = 0..5;

/// Columns that may hold ±inf by definition (none of the transient columns: the K-factor of
/// characteristics is infinite where the capacity is zero, NaN where it is negative;
/// `conventions.md`). The rule of [`Overflow`]; also the rule of result files (Python
/// `tcsim.simulation.transient.INFINITE_ALLOWED`).
pub const INFINITE_ALLOWED: [&str; 1] = ["k_factor_rpm_per_sqrt_nm"];

/// Unit suffixes of physical quantities (speeds, torques, flows, powers, energies): a run that has
/// such a quantity never leaves it NaN at some samples; ratios, modes and times may be NaN where
/// undefined. The rule of [`Overflow`]; also the rule of result files (Python
/// `tcsim.simulation.transient.NAN_NOT_EXPECTED`).
pub const NAN_NOT_EXPECTED: [&str; 5] = ["_rad_s", "_nm", "_m3_s", "_w", "_j"];

/// Whether the column `name` must not be NaN at some samples while it is a number at others.
pub fn nan_not_expected(name: &str) -> bool {
    NAN_NOT_EXPECTED.iter().any(|suffix| name.ends_with(suffix)) && !INFINITE_ALLOWED.contains(&name)
}

/// A choice of output columns: indices into [`COLUMNS`], each once, in the caller's order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Selection {
    indices: Vec<usize>,
}

impl Selection {
    /// Every column, in the order of [`COLUMNS`].
    pub fn all() -> Self {
        Self { indices: (0..COLUMNS.len()).collect() }
    }

    /// The columns named `names`, in that order (none is allowed: a run's events and status only).
    /// An unknown or repeated name is an error about the solver option `columns[i]` listing the
    /// valid names.
    pub fn from_names<S: AsRef<str>>(names: &[S]) -> CoreResult<Self> {
        let mut indices = Vec::with_capacity(names.len());
        for (i, name) in names.iter().enumerate() {
            let name = name.as_ref();
            let field = || format!("columns[{i}]");
            let Some(c) = COLUMNS.iter().position(|&n| n == name) else {
                let expected = format!("an output column name, one of {}", COLUMNS.join(", "));
                return Err(CoreError::of(InputSource::Options, field(), name, expected));
            };
            if indices.contains(&c) {
                return Err(CoreError::of(InputSource::Options, field(), name, "each column named once"));
            }
            indices.push(c);
        }
        Ok(Self { indices })
    }

    /// The indices into [`COLUMNS`], in the selection's order.
    pub fn indices(&self) -> &[usize] {
        &self.indices
    }

    /// The names, in the selection's order.
    pub fn names(&self) -> Vec<&'static str> {
        self.indices.iter().map(|&c| COLUMNS[c]).collect()
    }

    /// The optional quantities of a sample the chosen columns read ([`column_reads`]).
    pub fn sampled(&self) -> Sampled {
        self.indices.iter().fold(Sampled::NONE, |w, &c| w.or(column_reads(c)))
    }

    /// The number of columns chosen.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// No column chosen.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }
}

/// The first column of a run that overflowed: ±inf (outside [`INFINITE_ALLOWED`]), or NaN in a
/// physical quantity ([`nan_not_expected`]) the run has as a number at other samples. Columns are
/// looked at in the order of [`COLUMNS`], the selected ones and always the state (`time_s` to
/// `flow_m3_s`); the sample is the column's first bad one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Overflow {
    /// Index in [`COLUMNS`].
    pub column: usize,
    pub value: f64,
    pub time_s: f64,
}

/// What is the same at every sample of a run: which coordinates the model has, its mass matrix's
/// inertias and fluid terms (I_p, I_t, ρS_p, ρS_t), and its stator clutch and flow sign.
#[derive(Debug, Clone, Copy)]
pub struct RunConstants {
    present: [bool; 4],
    inertia_p: f64,
    inertia_t: f64,
    fluid_p: f64,
    fluid_t: f64,
    stator_clutch: bool,
    flow_sign: bool,
}

impl RunConstants {
    /// The constants of `model`.
    pub fn new(model: &dyn ConverterDynamics) -> Self {
        let mut present = model.coordinates();
        present[FLOW] &= !model.lag_state();
        let m = model.mass();
        Self {
            present,
            inertia_p: m[PUMP][PUMP],
            inertia_t: m[TURBINE][TURBINE],
            fluid_p: m[PUMP][FLOW],
            fluid_t: m[TURBINE][FLOW],
            stator_clutch: model.has_stator_clutch(),
            flow_sign: model.has_flow_sign(),
        }
    }

    /// Column `c` of [`COLUMNS`] at sample `s` (see [`row`]): the one formula of every column.
    /// Inlined, so that for a constant `c` only that column's arithmetic remains (`fill_column!`).
    #[inline(always)]
    pub fn value(&self, c: usize, s: &Sample) -> f64 {
        let coord = |k: usize, v: f64| if self.present[k] { v } else { f64::NAN };
        let lockup = |v: f64| if s.lockup.present { v } else { f64::NAN };
        let (u, ud) = (&s.u, &s.u_dot);
        let pump = s.torque[0];
        let turbine = -s.torque[1];
        let inertia_p = || self.inertia_p * ud[PUMP];
        let inertia_t = || self.inertia_t * ud[TURBINE];
        let eff_p = || pump - inertia_p();
        let eff_t = || turbine + inertia_t();
        match c {
            0 => s.time_s,
            1 => u[PUMP],
            2 => u[TURBINE],
            3 => coord(STATOR, u[STATOR]),
            4 => coord(FLOW, u[FLOW]),
            5 => ud[PUMP],
            6 => ud[TURBINE],
            7 => coord(FLOW, ud[FLOW]),
            8 => pump,
            9 => turbine,
            10 => s.torque[2],
            11 => ratio(u[TURBINE], u[PUMP]),
            12 => ratio(turbine, pump),
            13 => match (self.stator_clutch, s.mode.stator_locked) {
                (false, _) => f64::NAN,
                (true, true) => 0.0,
                (true, false) => 1.0,
            },
            14 => {
                if self.flow_sign {
                    s.mode.flow_sign
                } else {
                    f64::NAN
                }
            }
            15 => inertia_p(),
            16 => self.fluid_p * ud[FLOW],
            17 => s.transferred.0,
            18 => inertia_t(),
            19 => self.fluid_t * ud[FLOW],
            20 => s.transferred.1,
            21 => eff_p(),
            22 => eff_t(),
            23 => ratio(eff_t(), eff_p()),
            24 => s.loss_power_w,
            25 => s.stored_energy_j,
            26 => {
                let stator = if self.present[STATOR] { s.torque[2] * u[STATOR] } else { 0.0 };
                pump * u[PUMP] + s.torque[1] * u[TURBINE] + stator
            }
            27 => lockup(s.lockup.torque_nm),
            28 => lockup(s.lockup.state),
            29 => lockup(u[PUMP] - u[TURBINE]),
            30 => lockup(s.lockup.loss_power_w),
            31 => lockup(s.lockup.lock_loss_j),
            32 => lockup(s.lockup.lock_work_j),
            _ => panic!("output column {c} of {}", COLUMNS.len()),
        }
    }
}

/// The optional quantities of a sample ([`Sampled`]) that column `c` of [`COLUMNS`] reads in
/// [`RunConstants::value`]: the transferred torques, the fluid's loss power, the stored energy.
pub fn column_reads(c: usize) -> Sampled {
    Sampled { transferred: matches!(c, 17 | 20), loss_power: c == 24, stored_energy: c == 25 }
}

/// One sample as a row in the order of [`COLUMNS`]. Coordinates the model lacks are NaN, and so
/// are the stator mode (0 locked, 1 free-wheeling) and the flow direction (+1, −1, 0 held) of
/// models without them. The table model's lag state (in the fourth coordinate,
/// [`ConverterDynamics::lag_state`]) is no flow: the flow columns stay NaN. The lock-up columns are
/// NaN without a clutch command (so a run without one has the columns of a converter without a
/// clutch).
pub fn row(model: &dyn ConverterDynamics, s: &Sample) -> [f64; 33] {
    let k = RunConstants::new(model);
    std::array::from_fn(|c| k.value(c, s))
}

/// Where a column's first ±inf and first NaN are, and whether it has a number that is not NaN.
#[derive(Debug, Clone, Copy)]
struct Watch {
    column: usize,
    first_inf: usize,
    first_nan: usize,
    has_number: bool,
}

impl Watch {
    fn new(column: usize) -> Self {
        Self { column, first_inf: usize::MAX, first_nan: usize::MAX, has_number: false }
    }

    fn see(&mut self, i: usize, v: f64) {
        if v.is_nan() {
            self.first_nan = self.first_nan.min(i);
        } else {
            self.has_number = true;
            if v.is_infinite() {
                self.first_inf = self.first_inf.min(i);
            }
        }
    }

    /// The first bad sample by the rule of [`Overflow`], if any.
    fn first_bad(&self) -> Option<usize> {
        let name = COLUMNS[self.column];
        let inf = if INFINITE_ALLOWED.contains(&name) { usize::MAX } else { self.first_inf };
        let nan = if self.has_number && nan_not_expected(name) { self.first_nan } else { usize::MAX };
        Some(inf.min(nan)).filter(|&i| i != usize::MAX)
    }
}

/// A row of an output column: a plain `f64`, or memory not yet written (`MaybeUninit<f64>`: the
/// batch's buffers, written once by [`write_columns`] instead of zeroed first and then written).
pub trait OutputRow {
    fn put(&mut self, v: f64);
}

impl OutputRow for f64 {
    #[inline(always)]
    fn put(&mut self, v: f64) {
        *self = v;
    }
}

impl OutputRow for std::mem::MaybeUninit<f64> {
    #[inline(always)]
    fn put(&mut self, v: f64) {
        self.write(v);
    }
}

/// Column `C` of the samples `block` (global indices `first..`) into its rows of `out` (the whole
/// column; sample `i` goes to row `i − skip`, the first `skip` samples are only looked at), the
/// values of all of them shown to `watch`. A loop per column, with the column's formula
/// ([`RunConstants::value`]) specialised by the constant `C`: no dispatch per value, contiguous
/// writes; the loop notes whether the values are all finite or all NaN, and the check looks closer
/// only when they are neither. Every row of the block's samples past `skip` is written.
fn fill<const C: usize, R: OutputRow>(
    k: &RunConstants,
    block: &[Sample],
    first: usize,
    skip: usize,
    out: Option<&mut [R]>,
    watch: &mut Watch,
) {
    let Some(out) = out else {
        block.iter().enumerate().for_each(|(i, s)| watch.see(first + i, k.value(C, s)));
        return;
    };
    let lead = skip.saturating_sub(first).min(block.len());
    block[..lead].iter().enumerate().for_each(|(i, s)| watch.see(first + i, k.value(C, s)));
    if lead == block.len() {
        return; // a block of skipped samples
    }
    let rows = &mut out[first + lead - skip..first + block.len() - skip];
    let (mut finite, mut nan) = (true, true);
    for (o, s) in rows.iter_mut().zip(&block[lead..]) {
        let v = k.value(C, s);
        finite &= v.is_finite();
        nan &= v.is_nan();
        o.put(v);
    }
    if finite {
        watch.has_number |= !rows.is_empty();
    } else if nan {
        // a column the run lacks (the clutch's without a clutch): its first NaN only
        watch.first_nan = watch.first_nan.min(first + lead);
    } else {
        block[lead..].iter().enumerate().for_each(|(i, s)| watch.see(first + lead + i, k.value(C, s)));
    }
}

/// Samples per block of [`write_columns`]: a block's samples (about 200 bytes each) stay in the L1
/// cache while every column is written from them, instead of all samples being read once per column.
const BLOCK: usize = 64;

// the arms of `fill_column!` in `write_columns` are the columns 0 to 32
const _: () = assert!(COLUMNS.len() == 33);

/// [`fill`] for the column `c`, a run-time index.
macro_rules! fill_column {
    ($c:expr, $k:expr, $block:expr, $first:expr, $skip:expr, $out:expr, $watch:expr; $($n:literal)*) => {
        match $c {
            $($n => fill::<$n, _>($k, $block, $first, $skip, $out, $watch),)*
            c => panic!("output column {c} of {}", COLUMNS.len()),
        }
    };
}

/// Write the selected columns of `samples`: `out[k]` (one slice per column of `selection`, in its
/// order) gets column `selection.indices()[k]` at samples `skip..` (the first `skip` samples are
/// computed and checked, not stored; every slice is `samples.len() - skip` long). The run's
/// constants are taken once; each column is one tight loop over the samples (`fill`). Returns the
/// run's [`Overflow`], if any: the check covers the selected columns and the state, at every sample.
/// Every row of every slice is written ([`OutputRow`]: the slices may be memory not yet written):
/// the batch's buffers (`batch::run_transient_columns`) and [`columns`] rely on it to set their
/// length, unsafely, after it; a change here must keep it (the test
/// `every_row_of_a_buffer_not_yet_written_is_written` checks it).
pub fn write_columns<R: OutputRow>(
    model: &dyn ConverterDynamics,
    samples: &[Sample],
    selection: &Selection,
    skip: usize,
    out: &mut [&mut [R]],
) -> Option<Overflow> {
    assert!(out.len() == selection.len(), "one output slice per selected column");
    assert!(out.iter().all(|c| c.len() + skip == samples.len()), "output slices fit the samples");
    let k = RunConstants::new(model);
    let state_only = STATE_COLUMNS.filter(|c| !selection.indices.contains(c));
    let mut columns: Vec<(usize, Option<&mut [R]>)> =
        selection.indices.iter().copied().zip(out.iter_mut().map(|c| Some(&mut **c))).collect();
    columns.extend(state_only.map(|c| (c, None)));
    let mut watch: Vec<Watch> = columns.iter().map(|&(c, _)| Watch::new(c)).collect();
    for (b, block) in samples.chunks(BLOCK).enumerate() {
        for ((c, col), w) in columns.iter_mut().zip(&mut watch) {
            let col = col.as_deref_mut();
            fill_column!(*c, &k, block, b * BLOCK, skip, col, w; 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32);
        }
    }
    watch.sort_by_key(|w| w.column);
    watch.iter().find_map(|w| {
        w.first_bad().map(|i| Overflow {
            column: w.column,
            value: k.value(w.column, &samples[i]),
            time_s: samples[i].time_s,
        })
    })
}

/// The size of the output of `runs` isolated runs of `samples` output times each with `columns`
/// selected output columns (see [`OutputSize`]): the binding checks a batch with it before running.
pub fn isolated_output_size(runs: usize, samples: usize, columns: usize, options: &SolverOptions) -> OutputSize {
    OutputSize {
        runs,
        samples: samples as f64,
        columns,
        state_bytes: std::mem::size_of::<Sample>(),
        max_events: options.max_events,
        event_bytes: std::mem::size_of::<crate::engine::isolated::Event>(),
    }
}

/// The run as columns in the order of [`COLUMNS`] (see [`row`]; its overflow is not looked at:
/// [`write_columns`] reports it); an error, not an abort, when their memory cannot be had.
pub fn columns(model: &dyn ConverterDynamics, traj: &Trajectory) -> TransientResult<Vec<Vec<f64>>> {
    let n = traj.samples.len();
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for _ in 0..COLUMNS.len() {
        let mut c = Vec::new();
        try_reserve(&mut c, n)?;
        cols.push(c);
    }
    let mut out: Vec<_> = cols.iter_mut().map(|c| &mut c.spare_capacity_mut()[..n]).collect();
    write_columns(model, &traj.samples, &Selection::all(), 0, &mut out);
    for c in &mut cols {
        // SAFETY: write_columns wrote every row of every slice, the first n of each column
        unsafe { c.set_len(n) };
    }
    Ok(cols)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::converter::dynamics::HtDynamics;
    use crate::engine::isolated::{simulate, Drive, InitialState, TurbineLoad};
    use crate::engine::lockup::LockupCommand;
    use crate::engine::signal::Signal;

    /// The rows as `row` computed them before columns could be chosen (issue 16): the reference the
    /// one-pass writer must match bit for bit.
    fn reference_row(model: &dyn ConverterDynamics, s: &Sample) -> [f64; 33] {
        let mut present = model.coordinates();
        present[FLOW] &= !model.lag_state();
        let m = model.mass();
        let coord = |c: usize, v: f64| if present[c] { v } else { f64::NAN };
        let lockup = |v: f64| if s.lockup.present { v } else { f64::NAN };
        let (u, ud) = (s.u, s.u_dot);
        let pump = s.torque[0];
        let turbine = -s.torque[1];
        let inertia_p = m[PUMP][PUMP] * ud[PUMP];
        let inertia_t = m[TURBINE][TURBINE] * ud[TURBINE];
        let fluid_p = m[PUMP][FLOW] * ud[FLOW];
        let fluid_t = m[TURBINE][FLOW] * ud[FLOW];
        let eff_p = pump - inertia_p;
        let eff_t = turbine + inertia_t;
        let input =
            pump * u[PUMP] + s.torque[1] * u[TURBINE] + if present[STATOR] { s.torque[2] * u[STATOR] } else { 0.0 };
        [
            s.time_s,
            u[PUMP],
            u[TURBINE],
            coord(STATOR, u[STATOR]),
            coord(FLOW, u[FLOW]),
            ud[PUMP],
            ud[TURBINE],
            coord(FLOW, ud[FLOW]),
            pump,
            turbine,
            s.torque[2],
            ratio(u[TURBINE], u[PUMP]),
            ratio(turbine, pump),
            if model.has_stator_clutch() {
                if s.mode.stator_locked {
                    0.0
                } else {
                    1.0
                }
            } else {
                f64::NAN
            },
            if model.has_flow_sign() { s.mode.flow_sign } else { f64::NAN },
            inertia_p,
            fluid_p,
            s.transferred.0,
            inertia_t,
            fluid_t,
            s.transferred.1,
            eff_p,
            eff_t,
            ratio(eff_t, eff_p),
            s.loss_power_w,
            s.stored_energy_j,
            input,
            lockup(s.lockup.torque_nm),
            lockup(s.lockup.state),
            lockup(u[PUMP] - u[TURBINE]),
            lockup(s.lockup.loss_power_w),
            lockup(s.lockup.lock_loss_j),
            lockup(s.lockup.lock_work_j),
        ]
    }

    fn takeoff(lockup: bool) -> (HtDynamics, Drive) {
        let model = crate::converter::dynamics::tests::bundled_ht();
        let torque = Signal::new("pump_torque_nm", vec![0.0, 0.1, 0.3, 10.0], vec![40.0, 40.0, 250.0, 250.0], 0.0);
        let capacity = Signal::new("lockup_capacity_nm", vec![0.0, 3.0, 3.5, 10.0], vec![0.0, 0.0, 600.0, 600.0], 0.0);
        let drive = Drive::PumpTorqueLoad {
            pump_torque_nm: torque.unwrap(),
            load: TurbineLoad { torque_nm: Signal::constant(10.0), inertia_kg_m2: 1.2, drag_nm_s2: 0.002 },
            lockup: lockup.then(|| LockupCommand::new(capacity.unwrap(), 1.2).unwrap()),
        };
        (model, drive)
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// Every column of a selection, at every sample, is the reference row's value bit for bit,
    /// whatever the selection (all, a few in another order, the skipped first sample), with and
    /// without the lock-up clutch.
    #[test]
    fn selected_columns_are_the_reference_rows_bit_for_bit() {
        let times: Vec<f64> = (0..401).map(|i| i as f64 * 0.025).collect();
        for lockup in [false, true] {
            let (model, drive) = takeoff(lockup);
            let traj = simulate(&model, &drive, &times, &InitialState::default(), &SolverOptions::default()).unwrap();
            assert!(!traj.events.is_empty(), "the run has events");
            let reference: Vec<[f64; 33]> = traj.samples.iter().map(|s| reference_row(&model, s)).collect();
            let lockup_locked = reference.iter().any(|r| r[28] == 2.0);
            assert_eq!(lockup_locked, lockup, "the clutch locks in the lock-up run");
            let all = columns(&model, &traj).unwrap();
            for (c, col) in all.iter().enumerate() {
                let want: Vec<f64> = reference.iter().map(|r| r[c]).collect();
                assert_eq!(bits(col), bits(&want), "{}", COLUMNS[c]);
            }
            let sel = Selection::from_names(&["effective_torque_ratio", "time_s", "lockup_lock_work_j", "flow_m3_s"])
                .unwrap();
            // skips within the first block, at a block's end, just past it, a few blocks in
            for skip in [1, BLOCK, BLOCK + 1, 2 * BLOCK + 3] {
                let mut bufs = vec![vec![0.0; times.len() - skip]; sel.len()];
                let mut out: Vec<&mut [f64]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
                assert_eq!(write_columns(&model, &traj.samples, &sel, skip, &mut out), None);
                for (k, &c) in sel.indices().iter().enumerate() {
                    assert_eq!(bits(&bufs[k]), bits(&all[c][skip..]), "{} (skip {skip})", COLUMNS[c]);
                }
            }
            for s in &traj.samples[..5] {
                assert_eq!(bits(&row(&model, s)), bits(&reference_row(&model, s)));
            }
        }
    }

    /// The batch's buffers are written once, never zeroed ([`OutputRow`]): every row of every
    /// slice is written, whatever the skip, so a poisoned row never survives, and the values are
    /// those written into plain `f64`s.
    #[test]
    fn every_row_of_a_buffer_not_yet_written_is_written() {
        let (model, drive) = takeoff(true);
        let times: Vec<f64> = (0..3 * BLOCK + 7).map(|i| i as f64 * 0.02).collect();
        let traj = simulate(&model, &drive, &times, &InitialState::default(), &SolverOptions::default()).unwrap();
        let sel = Selection::from_names(&["lockup_torque_nm", "time_s", "stator_torque_nm", "flow_m3_s"]).unwrap();
        let poison = f64::from_bits(0x7ff8_dead_beef_0001);
        for skip in [0, 1, BLOCK - 1, BLOCK, 2 * BLOCK + 5, times.len() - 1, times.len()] {
            let rows = times.len() - skip;
            let mut plain = vec![vec![0.0; rows]; sel.len()];
            let mut out: Vec<&mut [f64]> = plain.iter_mut().map(|b| b.as_mut_slice()).collect();
            let want = write_columns(&model, &traj.samples, &sel, skip, &mut out);
            let mut fresh = vec![vec![std::mem::MaybeUninit::new(poison); rows]; sel.len()];
            let mut out: Vec<&mut [std::mem::MaybeUninit<f64>]> = fresh.iter_mut().map(|b| b.as_mut_slice()).collect();
            assert_eq!(write_columns(&model, &traj.samples, &sel, skip, &mut out), want, "skip {skip}");
            for (f, p) in fresh.iter().zip(&plain) {
                // SAFETY: initialised with the poison above, and only ever written since
                let got: Vec<f64> = f.iter().map(|v| unsafe { v.assume_init() }).collect();
                assert!(got.iter().all(|v| v.to_bits() != poison.to_bits()), "skip {skip}: a row left unwritten");
                assert_eq!(bits(&got), bits(p), "skip {skip}");
            }
        }
    }

    #[test]
    fn a_selection_names_known_columns_once() {
        assert_eq!(Selection::all().len(), COLUMNS.len());
        assert!(Selection::from_names::<&str>(&[]).unwrap().is_empty());
        let e = Selection::from_names(&["time_s", "pump_speed"]).unwrap_err();
        assert_eq!((e.source, e.field.as_str(), e.value.as_str()), (InputSource::Options, "columns[1]", "pump_speed"));
        assert!(e.expected.starts_with("an output column name, one of time_s, pump_speed_rad_s,"), "{}", e.expected);
        let e = Selection::from_names(&["time_s", "flow_m3_s", "time_s"]).unwrap_err();
        assert_eq!((e.field.as_str(), e.expected.as_str()), ("columns[2]", "each column named once"));
    }

    /// The overflow rule: ±inf anywhere, NaN in a physical column that is a number elsewhere; never
    /// NaN in a column that is NaN throughout (a coordinate the model lacks) or in a ratio; the
    /// state is looked at even when not selected; the first column in the order of `COLUMNS` wins.
    #[test]
    fn overflow_is_found_in_the_one_pass() {
        let (model, drive) = takeoff(false);
        let times: Vec<f64> = (0..11).map(|i| i as f64 * 0.1).collect();
        let traj = simulate(&model, &drive, &times, &InitialState::default(), &SolverOptions::default()).unwrap();
        let check = |samples: &[Sample], names: &[&str]| {
            let sel = Selection::from_names(names).unwrap();
            let mut bufs = vec![vec![0.0; samples.len()]; sel.len()];
            let mut out: Vec<&mut [f64]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
            write_columns(&model, samples, &sel, 0, &mut out)
        };
        assert_eq!(check(&traj.samples, &COLUMNS), None);
        let mut bad = traj.samples.clone();
        bad[7].torque[2] = f64::NAN; // stator torque: NaN among numbers
        bad[4].loss_power_w = f64::INFINITY;
        bad[6].u_dot[PUMP] = f64::NEG_INFINITY; // pump acceleration: inf, and its derived columns
        let o = check(&bad, &COLUMNS).unwrap();
        assert_eq!((COLUMNS[o.column], o.value, o.time_s), ("pump_accel_rad_s2", f64::NEG_INFINITY, times[6]));
        let o = check(&bad, &["fluid_loss_power_w", "stator_torque_nm"]).unwrap();
        assert_eq!(
            (COLUMNS[o.column], o.value.to_bits(), o.time_s),
            ("stator_torque_nm", f64::NAN.to_bits(), times[7])
        );
        assert_eq!(check(&bad, &["time_s", "torque_ratio"]), None, "unselected derived columns are not computed");
        bad[9].u[TURBINE] = f64::NAN; // the state: found whatever the selection
        let o = check(&bad, &[]).unwrap();
        assert_eq!((COLUMNS[o.column], o.time_s), ("turbine_speed_rad_s", times[9]));
        let mut zero_pump = traj.samples.clone();
        zero_pump[0].u[PUMP] = 0.0; // a ratio may be NaN (0/0); no overflow
        zero_pump[0].u[TURBINE] = 0.0;
        assert!(check(&zero_pump, &["speed_ratio"]).is_none());
        assert!(nan_not_expected("pump_torque_nm") && !nan_not_expected("speed_ratio"));
        // over several blocks: the first bad sample of the run, in a later block or a skipped one
        let times: Vec<f64> = (0..301).map(|i| i as f64 * 0.01).collect();
        let traj = simulate(&model, &drive, &times, &InitialState::default(), &SolverOptions::default()).unwrap();
        let mut bad = traj.samples.clone();
        bad[2 * BLOCK + 5].torque[2] = f64::NAN;
        bad[BLOCK + 2].torque[2] = f64::INFINITY;
        bad[BLOCK + 9].torque[2] = f64::NAN;
        let sel = Selection::from_names(&["stator_torque_nm"]).unwrap();
        for skip in [0, BLOCK + 3, 2 * BLOCK + 7] {
            let mut buf = vec![0.0; times.len() - skip];
            let o = write_columns(&model, &bad, &sel, skip, &mut [buf.as_mut_slice()]).unwrap();
            assert_eq!((o.value, o.time_s), (f64::INFINITY, times[BLOCK + 2]), "skip {skip}");
        }
        assert!(!nan_not_expected("k_factor_rpm_per_sqrt_nm"));
    }
}
