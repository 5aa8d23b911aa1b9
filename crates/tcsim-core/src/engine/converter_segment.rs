//! One smooth piece of an isolated run ([`crate::engine::isolated`]): a mode, the roles of the
//! coordinates, the reduced mass matrix, the external torques (drive, load, lock-up clutch), the
//! root functions and the switches.
//!
//! The free coordinates `x` map onto `u` by `u = P x + z(t)`: a free coordinate has its own column
//! of `P`, a **linked** one shares its master's (the turbine of a locked lock-up in drive c turns
//! with the pump), a given one is `z(t)` (a measured speed; the pump of a locked lock-up in drive
//! a follows the measured turbine speed), a held one is zero. The reduced system is
//! `PᵀMP ẋ = Pᵀ(F + T_ext − M ż)`, and a closing link (a lock) projects the state so that the
//! momentum `PᵀM u` of the free coordinates is conserved (`Segment::project`).

use crate::converter::dynamics::{ConverterDynamics, Mat4, Vec4, FLOW, PUMP, STATOR, TURBINE};
use crate::engine::converter_events::{self, ConverterRoot, EventKind, LockupSample, Mode, Sample, SampleConstants};
use crate::engine::drive::{Drive, TurbineLoad};
use crate::engine::lockup::{self, ClutchMode, LockupCommand, LockupRoot};
use crate::engine::options::{named_state, Hysteresis, NamedState, Sampled, SolverOptions};
use crate::engine::segment::{SmoothSegment, SAMPLE_BLOCK};
use crate::engine::signal::Signal;

/// A root function of an isolated run: the converter's or the lock-up clutch's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Root {
    Converter(ConverterRoot),
    Lockup(LockupRoot),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    Free,
    Linked,
    Given,
    Held,
    Absent,
}

/// One smooth piece of a run: a mode, the roles of the coordinates and the reduced mass matrix.
pub(super) struct Segment<'a> {
    pub(super) model: &'a dyn ConverterDynamics,
    pub(super) drive: &'a Drive,
    /// The model's mass matrix.
    mass: Mat4,
    /// The mass matrix of the dynamics (with the load inertia on the turbine in drive c).
    dyn_mass: Mat4,
    pub(super) mode: Mode,
    role: [Role; 4],
    /// The state column of each free or linked coordinate.
    col: [Option<usize>; 4],
    n: usize,
    /// `PᵀMP` and its inverse.
    reduced: Mat4,
    inv: Mat4,
    pub(super) roots: Vec<Root>,
    /// The signal of each given coordinate (resolved once from the roles).
    given: [Option<&'a Signal>; 4],
    /// Whether any coordinate is given (else every rate of `z(t)` is zero).
    any_given: bool,
    /// Whether the state is the coordinates themselves (all four free: `P = I`, `z = 0`).
    identity: bool,
    /// The pump torque, when the pump is free.
    pump_torque: Option<&'a Signal>,
    /// The load, when the turbine is free or linked.
    load: Option<&'a TurbineLoad>,
    /// What every sample needs from the model in this mode.
    sampled: SampleConstants<'a>,
    /// Dissipation and impulse work of the lock events before this segment, J (cumulative).
    pub(super) lock_energy_j: (f64, f64),
    /// Whether a root function reads the rates and forces ([`needs_rates`]).
    roots_need_rates: bool,
}

/// Whether the root function `root` reads the rates and forces: the stator's holding torque, a
/// held flow's balance and the clutch's breakaway do; the stator's speed, the flow and the
/// clutch's slip need the coordinates alone.
fn needs_rates(root: Root) -> bool {
    match root {
        Root::Converter(r) => converter_events::root_needs_rates(r),
        Root::Lockup(r) => r == LockupRoot::Breakaway,
    }
}

/// The roles of the coordinates of `model` under `drive` in `mode`, and whether the pump follows
/// the turbine's signal.
fn roles(model: &dyn ConverterDynamics, drive: &Drive, mode: Mode) -> ([Role; 4], bool) {
    let present = model.coordinates();
    let locked = drive.lockup().is_some() && mode.lockup.is_locked();
    let speeds_given = (drive.given(PUMP).is_some(), drive.given(TURBINE).is_some());
    let pump_follows_turbine = locked && speeds_given == (false, true);
    let turbine_linked = locked && speeds_given == (false, false);
    let role = std::array::from_fn(|c| {
        if !present[c] {
            Role::Absent
        } else if drive.given(c).is_some() || (c == PUMP && pump_follows_turbine) {
            Role::Given
        } else if c == TURBINE && turbine_linked {
            Role::Linked
        } else if (c == STATOR && mode.stator_locked) || (c == FLOW && converter_events::flow_held(model, mode)) {
            Role::Held
        } else {
            Role::Free
        }
    });
    (role, pump_follows_turbine)
}

/// The roots of an isolated run in `mode`: the converter's, then the clutch's (not in drive b,
/// where both speeds are given and the clutch can only slip).
fn roots(model: &dyn ConverterDynamics, drive: &Drive, mode: Mode) -> Vec<Root> {
    let mut roots = Vec::with_capacity(4);
    roots.extend(converter_events::roots(model, mode).map(Root::Converter));
    if drive.lockup().is_some_and(LockupCommand::engages) && !matches!(drive, Drive::Speeds { .. }) {
        roots.push(Root::Lockup(match mode.lockup {
            ClutchMode::Armed => LockupRoot::Lock,
            ClutchMode::Unarmed { .. } => LockupRoot::Arm,
            ClutchMode::Locked => LockupRoot::Breakaway,
        }));
    }
    roots
}

impl<'a> Segment<'a> {
    pub(super) fn new(model: &'a dyn ConverterDynamics, drive: &'a Drive, mode: Mode) -> Self {
        let (role, pump_follows_turbine) = roles(model, drive, mode);
        let mut col = [None; 4];
        let mut n = 0;
        for c in (0..4).filter(|&c| role[c] == Role::Free) {
            col[c] = Some(n);
            n += 1;
        }
        if role[TURBINE] == Role::Linked {
            col[TURBINE] = col[PUMP];
        }
        let mass = model.mass();
        let mut dyn_mass = mass;
        if let Some(load) = drive.load() {
            dyn_mass[TURBINE][TURBINE] += load.inertia_kg_m2;
        }
        let mut reduced = [[0.0; 4]; 4];
        for r in 0..4 {
            for c in 0..4 {
                if let (Some(i), Some(k)) = (col[r], col[c]) {
                    reduced[i][k] += dyn_mass[r][c];
                }
            }
        }
        let inv = crate::linalg::invert_leading(n, &reduced)
            .expect("the reduced mass matrix of a positive-definite M is invertible");
        let roots = roots(model, drive, mode);
        let roots_need_rates = roots.iter().any(|r| needs_rates(*r));
        let given_signal =
            |c: usize| if c == PUMP && pump_follows_turbine { drive.given(TURBINE) } else { drive.given(c) };
        let given = std::array::from_fn(|c| if role[c] == Role::Given { given_signal(c) } else { None });
        let pump_torque = drive.pump_torque().filter(|_| role[PUMP] == Role::Free);
        let load = drive.load().filter(|_| matches!(role[TURBINE], Role::Free | Role::Linked));
        Self {
            model,
            drive,
            mass,
            dyn_mass,
            mode,
            role,
            col,
            n,
            reduced,
            inv,
            roots,
            given,
            any_given: given.iter().any(Option::is_some),
            identity: col == [Some(0), Some(1), Some(2), Some(3)],
            pump_torque,
            load,
            sampled: SampleConstants::new(model, mode),
            lock_energy_j: (0.0, 0.0),
            roots_need_rates,
        }
    }

    /// The segment with only the optional quantities `wanted` in its samples.
    pub(super) fn sampling(self, wanted: Sampled) -> Self {
        Self { sampled: self.sampled.wanting(wanted), ..self }
    }

    /// Number of ODE states (one dummy state when every coordinate is given or held).
    fn n_states(&self) -> usize {
        self.n.max(1)
    }

    #[inline(always)]
    pub(super) fn full(&self, x: &[f64], t: f64) -> Vec4 {
        if self.identity {
            return [x[0], x[1], x[2], x[3]];
        }
        let mut u = [0.0; 4];
        for (c, u) in u.iter_mut().enumerate() {
            *u = match (self.col[c], self.given[c]) {
                (Some(i), _) => x[i],
                (None, Some(s)) => s.value(t),
                (None, None) => 0.0,
            };
        }
        u
    }

    pub(super) fn state(&self, u: &Vec4) -> Vec<f64> {
        let mut x = vec![0.0; self.n_states()];
        for c in (0..4).filter(|&c| self.role[c] == Role::Free) {
            if let Some(i) = self.col[c] {
                x[i] = u[c];
            }
        }
        x
    }

    /// The state after a closing link from the coordinates `u` before it: `PᵀMP x = PᵀM (u − z)`
    /// with the given coordinates `z` at `t` (the momentum of the free coordinates is conserved).
    pub(super) fn project(&self, u: &Vec4, t: f64) -> Vec<f64> {
        let z = self.full(&vec![0.0; self.n_states()], t);
        let mut b = [0.0; 4];
        for r in 0..4 {
            if let Some(i) = self.col[r] {
                b[i] += (0..4).map(|c| self.dyn_mass[r][c] * (u[c] - z[c])).sum::<f64>();
            }
        }
        let mut x = vec![0.0; self.n_states()];
        for (i, xi) in x.iter_mut().enumerate().take(self.n) {
            *xi = (0..self.n).map(|k| self.inv[i][k] * b[k]).sum();
        }
        x
    }

    fn given_rates(&self, t: f64) -> Vec4 {
        if !self.any_given {
            return [0.0; 4];
        }
        std::array::from_fn(|c| self.given[c].map_or(0.0, |s| s.rate(t)))
    }

    /// The clutch's command while it slips (None without a clutch, or locked).
    fn slipping(&self) -> Option<&LockupCommand> {
        self.drive.lockup().filter(|_| !self.mode.lockup.is_locked())
    }

    /// External torques on the free coordinates (drive, load, slipping clutch), and their Jacobian
    /// into `jac` when asked (the right-hand side does not need it).
    #[inline(always)]
    fn external(&self, u: &Vec4, t: f64, mut jac: Option<&mut Mat4>) -> Vec4 {
        let mut e = [0.0; 4];
        if let Some(s) = self.pump_torque {
            e[PUMP] = s.value(t);
        }
        if let Some(load) = self.load {
            let w = u[TURBINE];
            e[TURBINE] = -(load.torque_nm.value(t) + load.drag_nm_s2 * w * w.abs());
            if let Some(de) = jac.as_deref_mut() {
                de[TURBINE][TURBINE] = -2.0 * load.drag_nm_s2 * w.abs();
            }
        }
        if let Some(cmd) = self.slipping() {
            let (cap, slip) = (cmd.capacity(t), u[PUMP] - u[TURBINE]);
            let torque = lockup::slipping_torque_nm(cap, slip);
            e[PUMP] -= torque;
            e[TURBINE] += torque;
            if let Some(de) = jac {
                let k = lockup::slipping_torque_slope(cap, slip);
                de[PUMP][PUMP] -= k;
                de[PUMP][TURBINE] += k;
                de[TURBINE][PUMP] += k;
                de[TURBINE][TURBINE] -= k;
            }
        }
        e
    }

    /// Right-hand side of the reduced system, `Pᵀ(F + T − M ż)`, given `u` and `f = F(u)`: its
    /// `n` values first, zeros after. Each value is summed over its coordinates in a register:
    /// summed in memory at the state's index, it stalled the vector loads that read it back
    /// ([`Self::rates`]) on store forwarding.
    #[inline(always)]
    fn reduced_rhs(&self, u: &Vec4, f: &Vec4, t: f64) -> Vec4 {
        let e = self.external(u, t, None);
        // loops, not `array::from_fn`: its closure was not inlined in the engine's hot paths
        let mut g = [0.0; 4];
        for r in 0..4 {
            g[r] = f[r] + e[r];
        }
        if self.any_given {
            let zd = self.given_rates(t);
            for (r, g) in g.iter_mut().enumerate() {
                let coupling: f64 = (0..4).map(|c| self.dyn_mass[r][c] * zd[c]).sum();
                *g -= coupling;
            }
        }
        let mut out = [0.0; 4];
        for (i, o) in out.iter_mut().enumerate() {
            *o = (0..4).filter(|&r| self.col[r] == Some(i)).fold(0.0, |sum, r| sum + g[r]);
        }
        out
    }

    fn rhs(&self, x: &[f64], t: f64, out: &mut [f64]) {
        if self.n == 0 {
            out[0] = 0.0;
            return;
        }
        let u = self.full(x, t);
        let f = self.model.forces(&u, self.mode.flow_sign);
        // element by element: `copy_from_slice` of a length known only at run time calls memmove
        for (o, r) in out.iter_mut().zip(self.reduced_rhs(&u, &f, t)) {
            *o = r;
        }
    }

    fn jacobian_times(&self, x: &[f64], t: f64, v: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        if self.n == 0 {
            return;
        }
        let u = self.full(x, t);
        let j = self.model.force_jacobian(&u, self.mode.flow_sign);
        let mut de = [[0.0; 4]; 4];
        self.external(&u, t, Some(&mut de));
        for r in 0..4 {
            let Some(i) = self.col[r] else { continue };
            for c in 0..4 {
                if let Some(k) = self.col[c] {
                    out[i] += (j[r][c] + de[r][c]) * v[k];
                }
            }
        }
    }

    fn mass_times(&self, v: &[f64], beta: f64, y: &mut [f64]) {
        if self.n == 0 {
            y[0] = v[0] + beta * y[0];
            return;
        }
        for (i, yi) in y.iter_mut().enumerate() {
            let mv: f64 = (0..self.n).map(|k| self.reduced[i][k] * v[k]).sum();
            *yi = mv + beta * *yi;
        }
    }

    /// All coordinates, their rates and the forces at (x, t).
    pub(super) fn kinematics(&self, x: &[f64], t: f64) -> (Vec4, Vec4, Vec4) {
        let u = self.full(x, t);
        let f = self.model.forces(&u, self.mode.flow_sign);
        (u, self.rates(&u, &f, t), f)
    }

    /// The rates `u̇` at (u, t) given the forces `f = F(u)`. Inlined: returned through memory,
    /// its scalar stores stalled the vector loads of the copy that followed (store forwarding).
    #[inline(always)]
    fn rates(&self, u: &Vec4, f: &Vec4, t: f64) -> Vec4 {
        let mut ud = self.given_rates(t);
        if self.n > 0 {
            let r = self.reduced_rhs(u, f, t);
            // over all 4 columns: `inv` and `r` are zero beyond the n states
            for (c, rate) in ud.iter_mut().enumerate() {
                if let Some(i) = self.col[c] {
                    *rate = (0..4).map(|k| self.inv[i][k] * r[k]).sum();
                }
            }
        }
        ud
    }

    /// `M u̇ − F` with the converter's own mass: the external torque on every coordinate, the
    /// clutch's included (`T_p,ext − T_lu` on the pump, `T_t,ext + T_lu` on the turbine).
    pub(super) fn external_torques(&self, ud: &Vec4, f: &Vec4) -> Vec4 {
        converter_events::external_torques(&self.mass, ud, f)
    }

    /// The torque the clutch transmits from pump to turbine at (u, t), N·m: the friction law while
    /// it slips, the constraint torque `T_p,ext − (M u̇ − F)_p` when locked, 0 without a clutch.
    fn lockup_torque(&self, u: &Vec4, ud: &Vec4, f: &Vec4, t: f64) -> f64 {
        match self.drive.lockup() {
            None => 0.0,
            Some(cmd) if !self.mode.lockup.is_locked() => {
                lockup::slipping_torque_nm(cmd.capacity(t), u[PUMP] - u[TURBINE])
            }
            Some(_) => {
                let pump = self.drive.pump_torque().map_or(0.0, |s| s.value(t));
                pump - self.external_torques(ud, f)[PUMP]
            }
        }
    }

    /// The net force on a held flow starting forwards and backwards, `d± = F_Q(0±) − (M u̇)_Q`.
    pub(super) fn held_flow_balance(&self, u: &Vec4, ud: &Vec4) -> (f64, f64) {
        converter_events::held_flow_balance(self.model, u, &self.mass[FLOW], ud)
    }

    /// Root functions, each positive while the mode holds (with the hysteresis `h`).
    /// The rates and forces are computed only for a root that needs them (the stator's torque, a
    /// held flow's balance, the clutch's breakaway): the stator's speed and the flow need `u` alone.
    pub(super) fn root_values(&self, x: &[f64], t: f64, h: &Hysteresis, out: &mut [f64]) {
        let u = self.full(x, t);
        // computed before the roots when one of them needs them (a lazy cell's initialiser was a
        // call that was not inlined, with the three vectors copied out of it)
        let kinematics =
            if self.roots_need_rates { self.kinematics(x, t) } else { ([f64::NAN; 4], [f64::NAN; 4], [f64::NAN; 4]) };
        let rates = || {
            debug_assert!(self.roots_need_rates, "a root that needs the rates is marked so in `new`");
            kinematics
        };
        let slip = u[PUMP] - u[TURBINE];
        let cap = self.drive.lockup().map_or(0.0, |c| c.capacity(t));
        for (k, root) in self.roots.iter().enumerate() {
            out[k] = match *root {
                Root::Converter(r) => converter_events::root_value(
                    r,
                    self.mode,
                    &u,
                    h,
                    || {
                        let (_, ud, f) = rates();
                        self.external_torques(&ud, &f)[STATOR]
                    },
                    || self.held_flow_balance(&u, &rates().1),
                ),
                Root::Lockup(LockupRoot::Lock) => lockup::lock_root(cap, slip),
                Root::Lockup(LockupRoot::Arm) => match self.mode.lockup {
                    ClutchMode::Unarmed { since_s } => lockup::arm_root(since_s, slip, t),
                    _ => 1.0,
                },
                Root::Lockup(LockupRoot::Breakaway) => {
                    let k_s = self.drive.lockup().map_or(1.0, |c| c.static_to_kinetic);
                    let (_, ud, f) = rates();
                    lockup::breakaway_root(cap, k_s, self.lockup_torque(&u, &ud, &f, t))
                }
            };
        }
    }

    pub(super) fn sample(&self, x: &[f64], t: f64) -> Sample {
        let (u, ud, f) = self.kinematics(x, t);
        self.sample_at(t, u, ud, f)
    }

    /// [`SmoothSegment::sample_block`] stage by stage: the coordinates, the forces of all
    /// ([`ConverterDynamics::forces_many`]), the rates, the samples; each as [`Self::sample`]'s.
    fn sample_block<const N: usize>(&self, xs: &[[f64; N]], n: usize, ts: &[f64], out: &mut Vec<Sample>) {
        let m = xs.len();
        let mut u = [[0.0; 4]; SAMPLE_BLOCK];
        let mut f = [[0.0; 4]; SAMPLE_BLOCK];
        let mut ud = [[0.0; 4]; SAMPLE_BLOCK];
        for k in 0..m {
            u[k] = self.full(&xs[k][..n], ts[k]);
        }
        self.model.forces_many(&u[..m], self.mode.flow_sign, &mut f[..m]);
        for k in 0..m {
            ud[k] = self.rates(&u[k], &f[k], ts[k]);
        }
        for k in 0..m {
            out.push(self.sample_at(ts[k], u[k], ud[k], f[k]));
        }
    }

    /// The sample at `t` from the coordinates, their rates and the forces.
    #[inline(always)]
    fn sample_at(&self, t: f64, u: Vec4, ud: Vec4, f: Vec4) -> Sample {
        let mut s = self.sampled.sample(t, u, ud, f);
        if let Some(cmd) = self.drive.lockup() {
            let torque = self.lockup_torque(&u, &ud, &f, t);
            let slip = u[PUMP] - u[TURBINE];
            s.torque[0] += torque;
            s.torque[1] -= torque;
            s.lockup = LockupSample {
                present: true,
                torque_nm: torque,
                state: lockup::state_code(self.mode.lockup, cmd.capacity(t)),
                loss_power_w: lockup::dissipation_w(torque, slip),
                lock_loss_j: self.lock_energy_j.0,
                lock_work_j: self.lock_energy_j.1,
            };
        }
        s
    }

    fn atol(&self, o: &SolverOptions) -> Vec<f64> {
        let mut a = vec![o.speed_atol_rad_s; self.n_states()];
        if let Some(i) = self.col[FLOW] {
            a[i] = o.flow_atol_m3_s;
        }
        a
    }
}

/// Sign of the flow that starts from Q = 0 in `mode` ([`converter_events::flow_sign_from_balance`]).
pub(super) fn flow_sign_at_zero(model: &dyn ConverterDynamics, drive: &Drive, u: &Vec4, t: f64, mode: Mode) -> f64 {
    let seg = Segment::new(model, drive, Mode { flow_sign: 0.0, ..mode });
    let mut u0 = *u;
    u0[FLOW] = 0.0;
    let (uu, ud, _) = seg.kinematics(&seg.state(&u0), t);
    converter_events::flow_sign_from_balance(seg.held_flow_balance(&uu, &ud))
}

/// The mode after `root` fired, with the state adjusted (a locking stator stops, a reversing flow
/// passes zero, a locking clutch joins pump and turbine).
pub(super) fn switch(seg: &Segment, root: Root, u: &mut Vec4, t: f64) -> (EventKind, Mode) {
    let mut mode = seg.mode;
    match root {
        Root::Converter(r) => {
            let before = seg.mode;
            let kind =
                converter_events::switch(r, &mut mode, u, |u| flow_sign_at_zero(seg.model, seg.drive, u, t, before));
            (kind, mode)
        }
        Root::Lockup(LockupRoot::Breakaway) => {
            mode.lockup = ClutchMode::Unarmed { since_s: t };
            (EventKind::LockupSlip, mode)
        }
        Root::Lockup(LockupRoot::Arm) => {
            let cap = seg.drive.lockup().map_or(0.0, |c| c.capacity(t));
            if cap > 0.0 && (u[PUMP] - u[TURBINE]).abs() < lockup::SYNC_SLIP_RAD_S {
                try_lock(seg, u, t)
            } else {
                mode.lockup = ClutchMode::Armed;
                (EventKind::LockupArm, mode)
            }
        }
        Root::Lockup(LockupRoot::Lock) => try_lock(seg, u, t),
    }
}

/// Lock the clutch if it can hold the torque at once (`lockup-lock`, with the momentum-conserving
/// projection of `u`); else it slips on, unarmed (`lockup-slip`).
fn try_lock(seg: &Segment, u: &mut Vec4, t: f64) -> (EventKind, Mode) {
    let locked_mode = Mode { lockup: ClutchMode::Locked, ..seg.mode };
    let locked = Segment::new(seg.model, seg.drive, locked_mode);
    let x = locked.project(u, t);
    let (uu, ud, f) = locked.kinematics(&x, t);
    let torque = locked.lockup_torque(&uu, &ud, &f, t);
    let (cap, k_s) = seg.drive.lockup().map_or((0.0, 1.0), |c| (c.capacity(t), c.static_to_kinetic));
    if lockup::holds(cap, k_s, torque) {
        *u = uu;
        (EventKind::LockupLock, locked_mode)
    } else {
        (EventKind::LockupSlip, Mode { lockup: ClutchMode::Unarmed { since_s: t }, ..seg.mode })
    }
}

/// The energy of a lock that took the coordinates from `before` to `after` at `t`: the clutch's
/// dissipation `D = W − ΔE` and the work `W` of the impulses at the converter's shafts, J. In drive
/// (a) the given turbine takes the impulse `J = (M Δu)_p + (M Δu)_t` at its speed, `W = J·ω_t`; in
/// drive (c) the load inertia gives up its energy change, `W = −½ I_L (ω_t⁺² − ω_t⁻²)`; `ΔE` is
/// the change of the converter's stored energy.
pub(super) fn lock_energies(seg: &Segment, before: &Vec4, after: &Vec4) -> (f64, f64) {
    let (model, drive) = (seg.model, seg.drive);
    let de = model.stored_energy_j(after) - model.stored_energy_j(before);
    let work = if let Some(load) = drive.load() {
        -0.5 * load.inertia_kg_m2 * (after[TURBINE].powi(2) - before[TURBINE].powi(2))
    } else if drive.given(TURBINE).is_some() {
        let m = model.mass();
        let impulse = |r: usize| (0..4).map(|c| m[r][c] * (after[c] - before[c])).sum::<f64>();
        (impulse(PUMP) + impulse(TURBINE)) * after[TURBINE]
    } else {
        0.0
    };
    (work - de, work)
}

impl SmoothSegment for Segment<'_> {
    type Root = Root;
    type Sample = Sample;
    fn n_states(&self) -> usize {
        Segment::n_states(self)
    }
    fn atol(&self, o: &SolverOptions) -> Vec<f64> {
        Segment::atol(self, o)
    }
    fn rhs(&self, x: &[f64], t: f64, out: &mut [f64]) {
        Segment::rhs(self, x, t, out)
    }
    fn jacobian_times(&self, x: &[f64], t: f64, v: &[f64], out: &mut [f64]) {
        Segment::jacobian_times(self, x, t, v, out)
    }
    fn mass_times(&self, v: &[f64], beta: f64, y: &mut [f64]) {
        Segment::mass_times(self, v, beta, y)
    }
    fn roots(&self) -> &[Root] {
        &self.roots
    }
    fn root_values(&self, x: &[f64], t: f64, h: &Hysteresis, out: &mut [f64]) {
        Segment::root_values(self, x, t, h, out)
    }
    fn sample(&self, x: &[f64], t: f64) -> Sample {
        Segment::sample(self, x, t)
    }
    fn sample_block<const N: usize>(&self, xs: &[[f64; N]], n: usize, ts: &[f64], out: &mut Vec<Sample>) {
        Segment::sample_block(self, xs, n, ts, out)
    }
    fn coordinates(&self, x: &[f64], t: f64) -> NamedState {
        named_state(Some(self.model), &self.full(x, t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(v: &[f64]) -> Signal {
        Signal::new("s", vec![0.0, 0.5, 1.0, 3.0], v.to_vec(), 0.0).unwrap()
    }

    #[test]
    fn a_block_of_samples_is_each_sample_bit_for_bit() {
        // the engine samples in blocks (`sample_block`, stage by stage): each sample must be the
        // one `sample` takes alone, in every drive, mode and clutch state, given speeds included
        let model = crate::converter::dynamics::tests::bundled_ht();
        let clutch = || Some(LockupCommand::new(signal(&[0.0, 50.0, 400.0, 400.0]), 1.2).unwrap());
        let load = TurbineLoad { torque_nm: signal(&[10.0, 12.0, 30.0, 5.0]), inertia_kg_m2: 1.2, drag_nm_s2: 0.002 };
        let pump = signal(&[40.0, 60.0, 250.0, 250.0]);
        let speed = |v: f64| signal(&[v, 1.3 * v, 0.7 * v, v]);
        let mut drives = vec![];
        for lockup in [None, clutch()] {
            drives.push(Drive::PumpTorqueLoad {
                pump_torque_nm: pump.clone(),
                load: load.clone(),
                lockup: lockup.clone(),
            });
            drives.push(Drive::PumpTorqueTurbineSpeed {
                pump_torque_nm: pump.clone(),
                turbine_speed_rad_s: speed(80.0),
                lockup: lockup.clone(),
            });
            drives.push(Drive::Speeds { pump_speed_rad_s: speed(200.0), turbine_speed_rad_s: speed(-90.0), lockup });
        }
        let clutch_modes = [ClutchMode::Armed, ClutchMode::Unarmed { since_s: 0.2 }, ClutchMode::Locked];
        let ts: Vec<f64> = (0..SAMPLE_BLOCK).map(|k| 0.37 * k as f64).collect();
        for drive in &drives {
            for (stator_locked, flow_sign, lockup) in [false, true]
                .into_iter()
                .flat_map(|s| [1.0, 0.0, -1.0].map(|f| (s, f)))
                .flat_map(|(s, f)| clutch_modes.map(|c| (s, f, c)))
            {
                let seg = Segment::new(&model, drive, Mode { stator_locked, flow_sign, lockup });
                let n = seg.n_states();
                let xs: Vec<[f64; 4]> = (0..SAMPLE_BLOCK)
                    .map(|k| std::array::from_fn(|i| [150.0, -40.0, 7.0, 0.012][i] * (1.0 - 0.3 * k as f64)))
                    .collect();
                for m in [1, 3, SAMPLE_BLOCK] {
                    let mut block = vec![];
                    SmoothSegment::sample_block(&seg, &xs[..m], n, &ts[..m], &mut block);
                    let alone: Vec<Sample> = (0..m).map(|k| seg.sample(&xs[k][..n], ts[k])).collect();
                    assert_eq!(format!("{block:?}"), format!("{alone:?}"), "{drive:?} {:?}", seg.mode);
                }
            }
        }
    }
}
