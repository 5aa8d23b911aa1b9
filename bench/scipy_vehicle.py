"""Plain NumPy/SciPy reference: the whole-vehicle launch with the table converter model.

Benchmark baseline and independent oracle for tcsim's vehicle plant (``crates/tcsim-core/src/vehicle/``:
``plant.rs``, ``components.rs``, ``launch.rs``; equations in ``docs/vehicle.md``), transcribed for the
**table** converter model only (``TableDynamics`` in ``crates/tcsim-core/src/converter/dynamics.rs``:
``I_p ω̇_p = T_p − CF(SR) ω_p|ω_p|``, ``I_t ω̇_t = TR(SR) CF(SR) ω_p|ω_p| + T_t``, the Table C.1
characteristic of ``li-sunden-2016.toml`` interpolated linearly in SR = ω_t/ω_p, end values held).

Coordinates. The core's twelve coordinates without ω_s and Q (the table model has neither), so ten:

====  ======================  ==========  =========================================
here  core index              unit        mass-matrix entry
====  ======================  ==========  =========================================
0     0  ω_p                  rad/s       I_engine + I_pump
1     1  ω_t                  rad/s       I_turbine + I_gear,k (k off-going gear in a shift)
2     4  ω_o gearbox output   rad/s       I_out
3, 4  5, 6  ω_f, ω_r axles    rad/s       I_axle
5     7  v                    m/s         m
6, 7  8, 9  θ_f, θ_r twist    rad         1
8, 9  10, 11  T_fast, T_boost N·m         1
====  ======================  ==========  =========================================

A *mode* (:class:`State`: gear, shift and its phase, lock-up state and its phase, wheels held, and
the sign of the slip to synchronise) links or holds coordinates: a gear in mesh links
ω_t = i_k ω_o, a locked lock-up clutch ω_p = ω_t, held wheels hold ω_f = ω_r = 0. The free
coordinates are ``x`` with ``u = P x``; each mode integrates ``(PᵀMP) ẋ = PᵀF(Px, t)`` with
``solve_ivp`` (LSODA or Radau, finite-difference Jacobian) and terminal events (the root functions
of the core, any sign change), then restarts in the next mode from the momentum-conserving
projection ``(PᵀMP) x = PᵀM u``. Before a mode is integrated, a switch whose condition already
holds fires at once (:meth:`Mode.due`: stop speed, a brake that cannot hold, lock-up release, a due
shift or lock-up engagement). Runs also restart (same mode, no such check) at the breakpoints of
the pedal signals, where the forcing has a kink (the core ends its steps there without a restart:
``run_segment_with_stops``).

Phases, as in the core: a shift hands the torque over during ``shift_handover_s`` (a time root);
if the on-coming slip is then within 0.5 rad/s the shift is over ("shift-end"), else it ends when
that slip, signed at the handover, falls below 0.5 rad/s. The lock-up clutch ramps its capacity in
over ``engage_time_s`` (a time root): it locks at once within 0.5 rad/s ("lockup-lock"), else it is
armed with the sign of the slip ("lockup-applied") and locks when the slip closes. A locked clutch
that breaks away ("lockup-slip") slips at full capacity for 0.1 s, then locks at once within
0.5 rad/s or is armed with the sign of the slip ("lockup-slipping"). It opens ("lockup-release") below 0.7 × its
engage speed and on a downshift. Braked axles that have (nearly) stopped are held again ("brake-hold").

The vehicle's values are not written down here: :func:`sedan_params` takes them from the core's
reading of the vehicle file (``tcsim._core.read_vehicle(...).to_dict()``), the same file the core's
tests read. Run: ``python3 bench/scipy_vehicle.py`` (NumPy, SciPy and the built ``tcsim._core``;
prints the events).
"""

from __future__ import annotations

import bisect
import math
import time
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from tcsim import _core

REPO = Path(__file__).resolve().parents[1]
CONVERTER = REPO / "python/tcsim/data/converters/li-sunden-2016.toml"

G = 9.81  # standard gravity, m/s²
# Regularisation scales of crates/tcsim-core/src/vehicle/ (components.rs, modes.rs)
CLUTCH_SLIP_RAD_S = 0.2  # tanh(slip/0.2) of the lock-up and shift clutches
SYNC_SLIP_RAD_S = 0.5  # a synchronising clutch locks below this slip
BRAKE_SPEED_RAD_S = 0.002  # tanh(ω/0.002) of the brake on a moving axle
REARM_DELAY_S = 0.1  # after a breakaway the lock-up clutch slips this long before it may lock again
LOCKUP_RELEASE_FRACTION = 0.7  # the lock-up clutch opens below 0.7 × its engage speed
HOLD_SPEED_RAD_S = 0.005  # braked axles are held again below this axle and wheel-rim speed
ROLL_SPEED_M_S = 0.01  # tanh(v/0.01) of the rolling resistance
SLIP_SPEED_M_S = 0.5  # v₀ of the tyre slip κ = (rω − v)/√(v² + v₀²)

# state coordinates: pump, turbine, gearbox-output, front and rear axle speeds, vehicle speed, front and rear
# shaft twists, the fast and boost parts of the engine torque build-up
WP, WT, WO, WF, WR, V, TF, TR_, QF, QB = range(10)
N = 10  # number of state coordinates
OPEN, ENGAGING, LOCKED = 0, 1, 2
MAX_EVENTS = 200

RPM = math.pi / 30.0

#: The test sedan of the core's tests (``sedan()`` of ``crates/tcsim-core/tests/vehicle.rs``): one
#: vehicle file, read by both.
SEDAN_FILE = REPO / "crates/tcsim-core/tests/data/sedan.toml"

#: The sections of a vehicle file that hold the vehicle's values.
SECTIONS = ("engine", "gearbox", "lockup", "driveline", "tyres", "body", "brake")


def read_vehicle(path: Path = SEDAN_FILE) -> _core.Vehicle:
    """A vehicle file read and validated by the core (``tcsim._core.read_vehicle``): the object
    ``launch_runs`` takes; its ``to_dict()`` gives the values this transcription uses."""
    return _core.read_vehicle(Path(path).read_text(encoding="utf-8"), str(path))


def load_table(path=CONVERTER) -> dict:
    """[characteristic] and [inertia] of a converter file: the table model's parameters."""
    with open(path, "rb") as fh:
        d = tomllib.load(fh)
    c, i = d["characteristic"], d["inertia"]
    return {
        "speed_ratio": list(c["speed_ratio"]),
        "torque_ratio": list(c["torque_ratio"]),
        "capacity_factor_nm_s2": list(c["capacity_factor_nm_s2"]),
        "pump_kg_m2": i["pump_kg_m2"],
        "turbine_kg_m2": i["turbine_kg_m2"],
    }


def sedan_params(converter_path=CONVERTER, vehicle_path: Path = SEDAN_FILE) -> dict:
    """The vehicle's sections as the core validated them, plus ``"converter"``: the table model of
    ``converter_path``. No parameter is written down here."""
    values = read_vehicle(vehicle_path).to_dict()
    return {**{k: values[k] for k in SECTIONS}, "converter": load_table(converter_path)}


def flip_flop(pedal: float = 1.0, end_time_s: float = 30.0, stop_speed_m_s: float | None = 100.0 / 3.6) -> dict:
    """``flip_flop`` of the core's tests: braked at idle for 5 s, then pedal 0→``pedal`` and brake
    1→0 together over 5.00–5.05 s; to ``stop_speed_m_s`` or ``end_time_s``. Keys as the binding's
    ``scenario_from``."""
    t = [0.0, 5.0, 5.05, end_time_s]
    return {
        "time_s": t,
        "accelerator_pedal": [0.0, 0.0, pedal, pedal],
        "brake_pedal": [1.0, 1.0, 0.0, 0.0],
        "end_time_s": end_time_s,
        "stop_speed_m_s": stop_speed_m_s,
    }


def coast_and_brake(end_time_s: float = 40.0) -> dict:
    """``coasting_slows_down_and_the_brake_stops_and_holds_the_vehicle`` of the core's tests: braked
    at idle for 5 s, full pedal from 5.05 s (brake off over 5.00–5.05 s), pedal off over 8.00–8.05 s,
    coasting, then the brake ramped to 0.6 over 20–20.5 s and held; no stop speed."""
    t = [0.0, 5.0, 5.05, 8.0, 8.05, 20.0, 20.5, end_time_s]
    return {
        "time_s": t,
        "accelerator_pedal": [0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        "brake_pedal": [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.6, 0.6],
        "end_time_s": end_time_s,
        "stop_speed_m_s": None,
    }


def _lerp_held(xs, ys, x):
    """Linear interpolation, end values held (``Curve::at``, ``Signal::value``, ``lookup``)."""
    n = len(xs)
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    i = min(max(bisect.bisect_right(xs, x), 1), n - 1)
    w = (x - xs[i - 1]) / (xs[i] - xs[i - 1])
    return (1.0 - w) * ys[i - 1] + w * ys[i]


class Vehicle:
    """Parameters as plain floats and lists, and the mode-independent component laws."""

    def __init__(self, p: dict, sc: dict):
        e, g, lu, d, ty, b, br, c = (
            p[k] for k in ("engine", "gearbox", "lockup", "driveline", "tyres", "body", "brake", "converter")
        )
        self.Ie, self.idle, self.K_gov = e["inertia_kg_m2"], e["idle_speed_rad_s"], e["idle_governor_gain_nm_s_per_rad"]
        self.fl_x, self.fl_y = list(e["full_load_speed_rad_s"]), list(e["full_load_torque_nm"])
        self.T0, self.c_drag = e["drag_torque_nm"], e["drag_nm_s_per_rad"]
        self.tau_f, self.tau_b, self.b_frac = e["fast_time_constant_s"], e["boost_time_constant_s"], e["boost_fraction"]
        self.ratios, self.eff, self.I_in = list(g["ratios"]), list(g["efficiencies"]), list(g["input_inertia_kg_m2"])
        self.I_out, self.C_shift, self.t_handover = (
            g["output_inertia_kg_m2"],
            g["shift_clutch_capacity_nm"],
            g["shift_handover_s"],
        )
        self.up0, self.up1 = g["upshift_speed_zero_pedal_m_s"], g["upshift_speed_full_pedal_m_s"]
        self.dn0, self.dn1 = g["downshift_speed_zero_pedal_m_s"], g["downshift_speed_full_pedal_m_s"]
        self.C_lu, self.lu_static, self.t_engage = lu["capacity_nm"], lu["static_to_kinetic"], lu["engage_time_s"]
        self.lu_min_gear, self.lu_v0, self.lu_v1 = (
            lu["min_gear"],
            lu["engage_speed_zero_pedal_m_s"],
            lu["engage_speed_full_pedal_m_s"],
        )
        self.i_fd = d["final_drive_ratio"]
        self.k = (d["front_shaft_stiffness_nm_per_rad"], d["rear_shaft_stiffness_nm_per_rad"])
        self.c = (d["front_shaft_damping_nm_s_per_rad"], d["rear_shaft_damping_nm_s_per_rad"])
        self.I_axle = (d["front_axle_inertia_kg_m2"], d["rear_axle_inertia_kg_m2"])
        self.r_w, self.mu, self.C_slip, self.front_load = (
            ty["rolling_radius_m"],
            ty["friction_coefficient"],
            ty["slip_stiffness"],
            ty["front_load_fraction"],
        )
        self.m, self.CdA, self.Crr, self.rho_air = (
            b["mass_kg"],
            b["drag_area_m2"],
            b["rolling_resistance"],
            b["air_density_kg_m3"],
        )
        a = math.atan(b["grade_percent"] / 100.0)
        self.sin_g, self.cos_g = math.sin(a), math.cos(a)
        self.C_brake, self.brake_front = br["capacity_nm"], br["front_fraction"]
        self.sr_x, self.tr_y, self.cf_y = (
            list(c["speed_ratio"]),
            list(c["torque_ratio"]),
            list(c["capacity_factor_nm_s2"]),
        )
        self.Ip, self.It = c["pump_kg_m2"], c["turbine_kg_m2"]
        self.sc_t = list(sc["time_s"])
        self.sc_pedal, self.sc_brake = list(sc["accelerator_pedal"]), list(sc["brake_pedal"])
        self.end_time_s, self.stop_speed = sc["end_time_s"], sc.get("stop_speed_m_s")

    # inputs
    def pedal(self, t):
        return _lerp_held(self.sc_t, self.sc_pedal, t)

    def brake(self, t):
        return _lerp_held(self.sc_t, self.sc_brake, t)

    def brake_torque(self, t):
        """b(t)·capacity, both axles together."""
        return min(max(self.brake(t), 0.0), 1.0) * self.C_brake

    # converter: table model
    def table_torques(self, wp, wt):
        """(T_p,tr, T_t,tr) = (CF ω_p|ω_p|, TR·CF ω_p|ω_p|), SR = ω_t/ω_p (0 when ω_p = 0)."""
        sr = 0.0 if wp == 0.0 else wt / wp
        tp = _lerp_held(self.sr_x, self.cf_y, sr) * wp * abs(wp)
        return tp, _lerp_held(self.sr_x, self.tr_y, sr) * tp

    # engine
    def drag(self, w):
        return self.T0 * math.tanh(w / 1.0) + self.c_drag * w

    def targets(self, p, w):
        # rev limiter: full load falls linearly to zero over the 5 % of speed above the curve's end
        top = self.fl_x[-1]
        fuel_cut = min(max((1.05 * top - w) / (0.05 * top), 0.0), 1.0)
        full = max(_lerp_held(self.fl_x, self.fl_y, w), 0.0) * fuel_cut
        governor = self.K_gov * max(self.idle - w, 0.0)
        boost = self.b_frac * p * full
        return min(p * full + governor, full) - boost, boost

    # schedules
    def upshift_speed(self, k, p):
        return self.up0[k] + min(max(p, 0.0), 1.0) * (self.up1[k] - self.up0[k])

    def downshift_speed(self, k, p):
        return self.dn0[k - 1] + min(max(p, 0.0), 1.0) * (self.dn1[k - 1] - self.dn0[k - 1])

    def engage_speed(self, p):
        return self.lu_v0 + min(max(p, 0.0), 1.0) * (self.lu_v1 - self.lu_v0)


@dataclass(frozen=True)
class State:
    """What a mode is: ``VehicleMode`` of the core plus the sync sign that ``simulate_launch`` carries."""

    gear: int = 0  # gear in mesh (0-based); during a shift, the off-going gear
    shift: tuple | None = None  # (from, to, since_s, handed_over) while shifting
    lockup: int = OPEN  # OPEN, ENGAGING or LOCKED
    lockup_since: float = 0.0  # ENGAGING: start of the capacity ramp
    ramped: bool = False  # ENGAGING: the ramp is over (full capacity)
    armed: bool = False  # ENGAGING: locks when the slip closes (after a breakaway: once it has slipped)
    wheels_held: bool = False
    sync: float = 1.0  # sign of the slip to synchronise (on-coming shift clutch, armed lock-up clutch)


#: Event name of each root (``event_name`` of the core). Two depend on the outcome (``switch``): a
#: handover that completes the shift is a "shift-end", a ramp end that locks is a "lockup-lock".
EVENT_NAME = {
    "brake-release": "brake-release",
    "brake-hold": "brake-hold",
    "upshift": "upshift-start",
    "downshift": "downshift-start",
    "shift-handover": "shift-handover",
    "shift-sync": "shift-end",
    "lockup-engage": "lockup-engage",
    "lockup-ramped": "lockup-applied",
    "lockup-arm": "lockup-slipping",
    "lockup-lock": "lockup-lock",
    "lockup-slip": "lockup-slip",
    "lockup-release": "lockup-release",
    "stop": "stop-speed",
}


class Mode:
    """One smooth mode: masses, generalised coordinates, forces, root functions and switches."""

    def __init__(self, veh: Vehicle, st: State):
        self.veh, self.st = veh, st
        gear, shift, lockup = st.gear, st.shift, st.lockup
        # mass matrix (diagonal for the table model); per-gear input inertia, the off-going gear
        # during a shift
        i_gear = veh.I_in[shift[0] if shift else gear]
        self.mdiag = np.array(
            [veh.Ip + veh.Ie, veh.It + i_gear, veh.I_out, veh.I_axle[0], veh.I_axle[1], veh.m, 1.0, 1.0, 1.0, 1.0]
        )
        # generalised coordinates u = P x, in the core's order of columns; coord_of[c] is (the column of
        # u that carries state c, the factor), e.g. the turbine speed as the output speed × the gear ratio
        coord_of = [None] * N
        cols = []

        def own(c):
            coord_of[c] = (len(cols), 1.0)
            cols.append(c)

        own(WO)
        if shift:
            own(WT)
        else:
            coord_of[WT] = (coord_of[WO][0], veh.ratios[gear])
        if lockup == LOCKED:
            coord_of[WP] = coord_of[WT]
        else:
            own(WP)
        if not st.wheels_held:
            own(WF)
            own(WR)
        for c in (V, TF, TR_, QF, QB):
            own(c)
        self.n = len(cols)
        P = np.zeros((N, self.n))
        for c, r in enumerate(coord_of):
            if r is not None:
                P[c, r[0]] = r[1]
        self.P = P
        self.PtMP = P.T @ (self.mdiag[:, None] * P)
        self.A = np.linalg.solve(self.PtMP, P.T)  # ẋ = A F
        self.Minv_full = P @ self.A  # u̇ = P ẋ = P A F
        # root functions, as Plant::new lists them
        roots = ["brake-release" if st.wheels_held else "brake-hold"]
        if shift:
            roots.append("shift-sync" if shift[3] else "shift-handover")
        else:
            if gear + 1 < len(veh.ratios):
                roots.append("upshift")
            if gear > 0:
                roots.append("downshift")
        if lockup == OPEN:
            if gear + 1 >= veh.lu_min_gear and not shift:
                roots.append("lockup-engage")
        elif lockup == ENGAGING:
            roots.append("lockup-ramped" if not st.ramped else "lockup-arm" if not st.armed else "lockup-lock")
        else:
            roots.append("lockup-slip")
        if lockup != OPEN:
            roots.append("lockup-release")
        if veh.stop_speed is not None:
            roots.append("stop")
        self.roots = roots
        self._cache_key = None

    # ---- state maps
    def full(self, x):
        return self.P @ x

    def state_of(self, u):
        """Momentum-conserving projection (PᵀMP) x = PᵀM u."""
        return np.linalg.solve(self.PtMP, self.P.T @ (self.mdiag * u))

    # ---- forces
    def lockup_capacity(self, t):
        if self.st.lockup == ENGAGING:
            return self.veh.C_lu * min(max((t - self.st.lockup_since) / self.veh.t_engage, 0.0), 1.0)
        return 0.0

    def forces(self, u, t):
        veh, st = self.veh, self.st
        wp, wt, wo, wf, wr, v, thf, thr, tq_f, tq_b = (float(a) for a in u)
        f = [0.0] * N
        # converter (table model)
        tp, tt = veh.table_torques(wp, wt)
        f[WP] = -tp
        f[WT] = tt
        # engine
        p = veh.pedal(t)
        drag = veh.drag(wp)
        indicated = tq_f + tq_b
        f[WP] += indicated - drag
        fast, boost = veh.targets(p, wp)
        f[QF] = (fast - tq_f) / veh.tau_f
        f[QB] = (boost - tq_b) / veh.tau_b
        # lock-up clutch while it slips
        slip = wp - wt
        t_lu = self.lockup_capacity(t) * math.tanh(slip / CLUTCH_SLIP_RAD_S)
        f[WP] -= t_lu
        f[WT] += t_lu
        # gearbox
        if st.shift is None:
            k = st.gear
            t_in = indicated - drag if st.lockup == LOCKED else tt + t_lu
            f[WT] -= (1.0 - veh.eff[k]) * max(t_in, 0.0) * math.tanh(wt / 1.0)
        else:
            frm, to, since, _ = st.shift
            w = min(max((t - since) / veh.t_handover, 0.0), 1.0)
            c_off, c_on = veh.C_shift * (1.0 - w), veh.C_shift * w
            t_off = c_off * math.tanh((wt - veh.ratios[frm] * wo) / CLUTCH_SLIP_RAD_S)
            t_on = c_on * math.tanh((wt - veh.ratios[to] * wo) / CLUTCH_SLIP_RAD_S)
            f[WT] -= t_off + t_on
            f[WO] += veh.ratios[frm] * t_off + veh.ratios[to] * t_on
        # shafts: twist at the propshaft side, θ̇ = ω_o − i_fd ω_axle
        for axle, twist, i in ((WF, TF, 0), (WR, TR_, 1)):
            rate = wo - veh.i_fd * u[axle]
            torque = veh.k[i] * u[twist] + veh.c[i] * rate
            f[twist] = rate
            f[WO] -= torque
            f[axle] += veh.i_fd * torque
        # tyres, brake, body
        weight = veh.m * G * veh.cos_g
        brake = veh.brake_torque(t)
        root = math.sqrt(v * v + SLIP_SPEED_M_S * SLIP_SPEED_M_S)
        for axle, load, share in (
            (WF, veh.front_load, veh.brake_front),
            (WR, 1.0 - veh.front_load, 1.0 - veh.brake_front),
        ):
            kappa = (veh.r_w * u[axle] - v) / root
            force = veh.mu * load * weight * math.tanh(veh.C_slip * kappa / veh.mu)
            f[axle] -= veh.r_w * force
            f[V] += force
            if not st.wheels_held:
                f[axle] -= brake * share * math.tanh(u[axle] / BRAKE_SPEED_RAD_S)
        aero = 0.5 * veh.rho_air * veh.CdA * v * abs(v)
        roll = veh.Crr * weight * math.tanh(v / ROLL_SPEED_M_S)
        climb = veh.m * G * veh.sin_g
        f[V] -= aero + roll + climb
        return np.array(f)

    def rhs(self, t, x):
        return self.A @ self.forces(self.P @ x, t)

    def kinematics(self, t, x):
        """u, u̇ and F at (t, x); one-entry cache (the event functions share it)."""
        key = (t, x.tobytes())
        if key != self._cache_key:
            u = self.P @ x
            f = self.forces(u, t)
            self._cache = (u, self.Minv_full @ f, f)
            self._cache_key = key
        return self._cache

    def reactions(self, ud, f):
        """M u̇ − F: the constraint torque on each coordinate (brake holding torque on a held
        axle, torque through a locked clutch on ω_p)."""
        return self.mdiag * ud - f

    def shaft_torques(self, u, f):
        veh = self.veh
        return [veh.k[i] * u[tw] + veh.c[i] * f[tw] for tw, i in ((TF, 0), (TR_, 1))]

    def brake_margin(self, ud, f, t):
        """Brake capacity left on the weaker held axle (negative: the brake cannot hold)."""
        r = self.reactions(ud, f)
        cap, s = self.veh.brake_torque(t), self.veh.brake_front
        return min(cap * s - abs(r[WF]), cap * (1.0 - s) - abs(r[WR]))

    # ---- root functions: positive while the mode holds, a switch at any sign change (as diffsol)
    def root_value(self, kind, t, x):
        veh, st = self.veh, self.st
        u, ud, f = self.kinematics(t, x)
        p = veh.pedal(t)
        if kind == "brake-release":
            return self.brake_margin(ud, f, t) + 1e-9
        if kind == "brake-hold":
            # axles and wheel rim (nearly) stopped, and the brake holds the shafts with 20 % margin
            rim = u[V] / veh.r_w
            spin = math.sqrt(u[WF] ** 2 + u[WR] ** 2 + rim * rim) - HOLD_SPEED_RAD_S
            cap, s = veh.brake_torque(t), veh.brake_front
            shaft = self.shaft_torques(u, f)
            short = max(veh.i_fd * abs(shaft[0]) - 0.8 * cap * s, veh.i_fd * abs(shaft[1]) - 0.8 * cap * (1.0 - s))
            return max(spin, short)
        if kind == "upshift":
            return veh.upshift_speed(st.gear, p) - u[V]
        if kind == "downshift":
            return u[V] - veh.downshift_speed(st.gear, p)
        if kind == "shift-handover":
            return st.shift[2] + veh.t_handover - t
        if kind == "shift-sync":
            return st.sync * (u[WT] - veh.ratios[st.shift[1]] * u[WO]) - SYNC_SLIP_RAD_S
        if kind == "lockup-engage":
            return veh.engage_speed(p) - u[V]
        if kind == "lockup-ramped":
            return st.lockup_since + veh.t_engage - t
        if kind == "lockup-arm":
            return st.lockup_since + veh.t_engage + REARM_DELAY_S - t
        if kind == "lockup-lock":
            return st.sync * (u[WP] - u[WT]) - SYNC_SLIP_RAD_S
        if kind == "lockup-slip":
            r = self.reactions(ud, f)
            return veh.lu_static * veh.C_lu - abs(r[WP])
        if kind == "lockup-release":
            return u[V] - LOCKUP_RELEASE_FRACTION * veh.engage_speed(p)
        if kind == "stop":
            return veh.stop_speed - u[V]
        raise ValueError(kind)

    def events(self):
        out = []
        for kind in self.roots:

            def ev(t, x, kind=kind):
                return self.root_value(kind, t, x)

            ev.terminal = True
            ev.direction = 0.0
            out.append(ev)
        return out

    def atol(self, scale=1.0):
        """Absolute tolerances per state, as the core's ``SmoothSegment::atol`` (default options)."""
        per = {V: 1e-6, TF: 1e-7, TR_: 1e-7, QF: 1e-4, QB: 1e-4}
        a = np.full(self.n, 1e-5)
        for c in range(N):
            col = np.nonzero(self.P[c])[0]
            if len(col):
                a[col[0]] = per.get(c, a[col[0]])
        return a * scale

    # ---- switches
    def due(self, t, x):
        """A switch whose condition already holds as the mode starts (``due`` of the core; root
        functions only see crossings), or None."""
        veh, st = self.veh, self.st
        u, ud, f = self.kinematics(t, x)
        p = veh.pedal(t)
        if veh.stop_speed is not None and u[V] >= veh.stop_speed:
            return "stop"
        if st.wheels_held and self.brake_margin(ud, f, t) < 0.0:
            return "brake-release"
        if st.lockup != OPEN and (
            st.gear + 1 < veh.lu_min_gear or u[V] < LOCKUP_RELEASE_FRACTION * veh.engage_speed(p)
        ):
            return "lockup-release"
        if st.shift is None and not st.wheels_held:
            if st.gear + 1 < len(veh.ratios) and u[V] > veh.upshift_speed(st.gear, p):
                return "upshift"
            if st.gear > 0 and u[V] < veh.downshift_speed(st.gear, p):
                return "downshift"
            if st.lockup == OPEN and st.gear + 1 >= veh.lu_min_gear and u[V] > veh.engage_speed(p):
                return "lockup-engage"
        return None

    def switch(self, kind, u, t):
        """The next state after root ``kind`` at (t, u), and the event's name."""
        veh, st = self.veh, self.st
        name = EVENT_NAME[kind]
        ramped_since = t - veh.t_engage  # an engaging clutch at full capacity
        if kind == "brake-release":
            return replace(st, wheels_held=False), name
        if kind == "brake-hold":
            return replace(st, wheels_held=True), name
        if kind in ("upshift", "downshift"):
            to = st.gear + 1 if kind == "upshift" else st.gear - 1
            new = replace(st, shift=(st.gear, to, t, False))
            # an engaging clutch restarts after an upshift; a downshift opens it
            if st.lockup != LOCKED or kind == "downshift":
                new = replace(new, lockup=OPEN)
            return new, name
        if kind == "shift-handover":
            slip = u[WT] - veh.ratios[st.shift[1]] * u[WO]
            if abs(slip) <= SYNC_SLIP_RAD_S:  # the on-coming clutch holds already: the shift is over
                return replace(st, gear=st.shift[1], shift=None), "shift-end"
            return replace(st, shift=st.shift[:3] + (True,), sync=math.copysign(1.0, slip)), name
        if kind == "shift-sync":
            return replace(st, gear=st.shift[1], shift=None), name
        if kind == "lockup-engage":
            return replace(st, lockup=ENGAGING, lockup_since=t, ramped=False, armed=False), name
        if kind == "lockup-ramped":
            slip = u[WP] - u[WT]
            if abs(slip) <= SYNC_SLIP_RAD_S:
                return replace(st, lockup=LOCKED), "lockup-lock"
            return replace(
                st, lockup=ENGAGING, lockup_since=ramped_since, ramped=True, armed=True, sync=math.copysign(1.0, slip)
            ), name
        if kind == "lockup-arm":
            slip = u[WP] - u[WT]
            if abs(slip) <= SYNC_SLIP_RAD_S:
                return replace(st, lockup=LOCKED), "lockup-lock"
            return replace(
                st, lockup=ENGAGING, lockup_since=ramped_since, ramped=True, armed=True, sync=math.copysign(1.0, slip)
            ), name
        if kind == "lockup-lock":
            return replace(st, lockup=LOCKED), name
        if kind == "lockup-release":
            return replace(st, lockup=OPEN), name
        if kind == "lockup-slip":
            # it slips for REARM_DELAY_S at full capacity before it may lock again
            return replace(st, lockup=ENGAGING, lockup_since=ramped_since, ramped=True, armed=False), name
        raise ValueError(kind)


def initial_state(veh: Vehicle) -> np.ndarray:
    """Braked standstill in first gear: engine speed where governor torque balances drag and the
    stalled converter (bisection, 200 halvings on [1 rad/s, last full-load speed]), shafts wound up
    equally by the stalled turbine torque times the first-gear ratio."""
    p = veh.pedal(0.0)

    def balance(w):
        fast, boost = veh.targets(p, w)
        return fast + boost - veh.drag(w) - veh.table_torques(w, 0.0)[0]

    lo, hi = 1.0, veh.fl_x[-1]
    if balance(lo) <= 0.0 or balance(hi) >= 0.0:
        raise ValueError("no engine speed balances the governor against the stalled converter")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if balance(mid) > 0.0:
            lo = mid
        else:
            hi = mid
    wp = 0.5 * (lo + hi)
    fast, boost = veh.targets(p, wp)
    turbine = veh.table_torques(wp, 0.0)[1]
    twist = turbine * veh.ratios[0] / (veh.k[0] + veh.k[1])
    u = np.zeros(N)
    u[WP], u[TF], u[TR_], u[QF], u[QB] = wp, twist, twist, fast, boost
    return u


def simulate(
    params: dict,
    scenario: dict,
    method: str = "LSODA",
    rtol: float = 1e-6,
    output_step_s: float = 0.01,
    atol_scale: float = 1.0,
) -> dict:
    """Launch from the braked standstill with the table converter model.

    ``params``: a vehicle's sections (:func:`sedan_params`) plus ``"converter"`` (:func:`load_table`);
    ``scenario``: :func:`flip_flop`-style dict. Samples every ``output_step_s`` up to the stop (and
    at the stop), as the core does. Returns arrays ``time_s``, ``vehicle_speed_m_s``,
    ``vehicle_accel_m_s2``, ``pump_speed_rad_s``, ``turbine_speed_rad_s``,
    ``gearbox_output_speed_rad_s``, ``front_axle_speed_rad_s``, ``rear_axle_speed_rad_s``, ``gear``
    (1-based, the off-going gear in a shift), ``lockup_state`` (0 open, 1 slipping, 2 locked), and
    ``events`` [(time_s, kind, gear after the event)], ``nfev``, ``segments``.
    """
    veh = Vehicle(params, scenario)
    end = veh.end_time_s
    n_out = int(round(end / output_step_s)) + 1
    times = np.minimum(np.arange(n_out) * output_step_s, end)
    breaks = sorted({b for b in veh.sc_t if 0.0 < b < end} | {end})
    u = initial_state(veh)
    state = State(wheels_held=veh.brake(0.0) > 0.0)
    t = 0.0
    rows, events = [], []
    nfev = segments = 0
    i_out = 0

    def record(mode, tt, xx):
        uu, ud, _ = mode.kinematics(tt, np.ascontiguousarray(xx))
        rows.append(
            (
                tt,
                uu[V],
                ud[V],
                uu[WP],
                uu[WT],
                uu[WO],
                uu[WF],
                uu[WR],
                mode.st.gear + 1,
                {OPEN: 0, ENGAGING: 1, LOCKED: 2}[mode.st.lockup],
            )
        )

    while True:
        mode = Mode(veh, state)
        x = mode.state_of(u)
        kind = mode.due(t, x)  # a switch already due fires before any integration
        t_root, x_root = t, x
        while kind is None:  # one mode, split at the input breakpoints
            t_stop = next(b for b in breaks if b > t)
            j = bisect.bisect_right(times, t_stop, lo=i_out)
            # the samples of the span, and its end (for the state there) unless it is a sample
            t_eval = times[i_out:j] if j > i_out and times[j - 1] == t_stop else np.append(times[i_out:j], t_stop)
            sol = solve_ivp(
                mode.rhs,
                (t, t_stop),
                x,
                method=method,
                rtol=rtol,
                atol=mode.atol(atol_scale),
                events=mode.events(),
                t_eval=t_eval,
                first_step=min(1e-5, t_stop - t),
            )
            segments += 1
            nfev += sol.nfev
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed at t = {sol.t[-1] if len(sol.t) else t}: {sol.message}")
            n_samples = min(len(sol.t), j - i_out)
            for k in range(n_samples):
                record(mode, sol.t[k], sol.y[:, k])
            i_out += n_samples
            if sol.status == 1:
                fired = [(te[0], k) for k, te in enumerate(sol.t_events) if len(te)]
                t_root, k = min(fired)
                t_root = float(t_root)
                kind = mode.roots[k]
                x_root = sol.y_events[k][0]
                break
            t, x = t_stop, sol.y[:, -1]
            if t >= end:
                return _result(rows, events, nfev, segments)
        u_root = mode.full(x_root)
        if kind == "stop":
            events.append((t_root, EVENT_NAME[kind], mode.st.gear + 1))
            record(mode, t_root, x_root)
            return _result(rows, events, nfev, segments)
        state, name = mode.switch(kind, u_root, t_root)
        events.append((t_root, name, state.gear + 1))
        if len(events) > MAX_EVENTS:
            raise RuntimeError(f"more than {MAX_EVENTS} events: events chatter")
        t, u = t_root, u_root


def _result(rows, events, nfev, segments) -> dict:
    cols = (
        "time_s",
        "vehicle_speed_m_s",
        "vehicle_accel_m_s2",
        "pump_speed_rad_s",
        "turbine_speed_rad_s",
        "gearbox_output_speed_rad_s",
        "front_axle_speed_rad_s",
        "rear_axle_speed_rad_s",
        "gear",
        "lockup_state",
    )
    a = np.array(rows, dtype=float).reshape(-1, len(cols))
    out = {c: a[:, i] for i, c in enumerate(cols)}
    out["events"] = events
    out["nfev"] = nfev
    out["segments"] = segments
    return out


def main():
    params = sedan_params()
    for label, sc in (
        ("flip-flop to 100 km/h", flip_flop(1.0, 30.0, 100.0 / 3.6)),
        ("coast and brake", coast_and_brake()),
    ):
        for method in ("LSODA", "Radau"):
            t0 = time.perf_counter()
            r = simulate(params, sc, method=method)
            dt = time.perf_counter() - t0
            print(
                f"{label}, {method}: {dt * 1e3:.0f} ms, {r['nfev']} RHS calls, {r['segments']} segments, "
                f"{len(r['time_s'])} samples, final speed {r['vehicle_speed_m_s'][-1]:.6g} m/s"
            )
            for e in r["events"]:
                print(f"  {e[0]:10.6f} s  {e[1]:<16} gear {e[2]}")


if __name__ == "__main__":
    main()
