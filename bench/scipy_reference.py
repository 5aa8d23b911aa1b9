"""Plain NumPy/SciPy reference: Hrovat & Tobler converter in an isolated take-off.

Benchmark baseline and independent oracle for tcsim's transient engine. Equations of Li & Sundén
(2016), Chalmers MSc thesis 2016:74, eqs 2.12–2.15 (torque and power balances), 2.19 (losses),
2.20–2.22 (shock velocities) and 2.23–2.25 (|V_re,x|² = q²(1 + tan²α_x)); signs as in tcsim's
physics notes §2 (external torques; `turbine_torque_nm` is the torque delivered to the load).

The model is piecewise smooth. A *mode* is (stator, σ): the stator LOCKED (ω_s ≡ 0 held, the
one-way clutch supplies the holding torque T_s) or FREE (ω_s a state, T_s = 0); the flow sign
σ = +1 or −1 (Q a state) or 0, STUCK (Q ≡ 0 held, the loss term replaced by its reaction). Each mode
is a smooth ODE M_xx ẋ = F_x + T_ext,x in its free coordinates x, integrated by `solve_ivp` with an
analytic Jacobian and terminal events; after an event the run restarts in the new mode with the
state carried over. Runs also restart at the kinks of the pump-torque table (documented choice).

Run: ``python3 bench/scipy_reference.py`` (needs only NumPy and SciPy).
"""

from __future__ import annotations

import math
import statistics
import time
import tomllib
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

DEFAULT = Path(__file__).resolve().parents[1] / "python/tcsim/data/converters/li-sunden-2016.toml"
LOCKED, FREE = 0, 1
MAX_EVENTS = 200
# Reference magnitudes of u = [ωp, ωt, ωs, Q] (rad/s ×3, m³/s). Default atol = 1e-6 · REF.
REF = np.array([100.0, 100.0, 100.0, 0.05])
STATE = ("pump_speed_rad_s", "turbine_speed_rad_s", "stator_speed_rad_s", "flow_m3_s")


def load_parameters(path=DEFAULT) -> dict:
    """Sections [inertia] and [geometry] of a converter file, in SI units.

    Keys: Ip, It, Is (kg m²); rho (kg/m³); A (m²); Rp, Rt, Rs (exit radii, m); tp, tt, ts (tan of
    the exit angles) and tpp, ttt, tss (tan of the inlet angles), angles converted from degrees;
    Cp, Ct, Cs (shock loss coefficients) and f (friction), dimensionless; Lf (fluid length, m);
    Sp, St, Ss (shape effects of eqs 2.16–2.18, m²).
    """
    with open(path, "rb") as fh:
        d = tomllib.load(fh)
    i, g = d["inertia"], d["geometry"]
    tan = lambda key: math.tan(math.radians(g[key]))  # noqa: E731
    return dict(
        Ip=i["pump_kg_m2"],
        It=i["turbine_kg_m2"],
        Is=i["stator_kg_m2"],
        rho=g["fluid_density_kg_m3"],
        A=g["flow_area_m2"],
        Rp=g["pump_exit_radius_m"],
        Rt=g["turbine_exit_radius_m"],
        Rs=g["stator_exit_radius_m"],
        tp=tan("pump_exit_angle_deg"),
        tt=tan("turbine_exit_angle_deg"),
        ts=tan("stator_exit_angle_deg"),
        tpp=tan("pump_inlet_angle_deg"),
        ttt=tan("turbine_inlet_angle_deg"),
        tss=tan("stator_inlet_angle_deg"),
        Cp=g["pump_shock_loss"],
        Ct=g["turbine_shock_loss"],
        Cs=g["stator_shock_loss"],
        f=g["friction_loss"],
        Lf=g["fluid_length_m"],
        Sp=g["pump_shape_effect_m2"],
        St=g["turbine_shape_effect_m2"],
        Ss=g["stator_shape_effect_m2"],
    )


def takeoff_scenario(tip_out: bool = False) -> dict:
    """Take-off from turbine standstill, 0–10 s; optional tip-out to engine drag at 5.0–5.1 s.

    Pump torque: piecewise linear table (N·m); 40 until 0.1 s, ramp to 250 at 0.3 s. Load on the
    turbine shaft: inertia I_L plus torque T_load0 + c_drag·ωt². The initial state (ωt = 0, stator
    locked, ωp and Q steady under Tp(0)) is computed by `initial_state`.
    """
    times, torques = [0.0, 0.1, 0.3, 10.0], [40.0, 40.0, 250.0, 250.0]
    if tip_out:
        times, torques = [0.0, 0.1, 0.3, 5.0, 5.1, 10.0], [40.0, 40.0, 250.0, 250.0, -30.0, -30.0]
    return dict(
        t_span=(0.0, 10.0),
        pump_torque_times_s=times,
        pump_torque_nm=torques,
        load_inertia_kg_m2=1.2,
        load_torque_nm=10.0,
        load_drag_nm_s2=0.002,
        turbine_speed0_rad_s=0.0,
    )


class Model:
    """Eqs 2.12–2.25 for one parameter set and scenario; full coordinates u = [ωp, ωt, ωs, Q]."""

    def __init__(self, p: dict, sc: dict):
        self.p, self.sc = p, sc
        for k, v in p.items():
            setattr(self, k, v)
        rho, A = self.rho, self.A
        self.IL, self.T0, self.cd = sc["load_inertia_kg_m2"], sc["load_torque_nm"], sc["load_drag_nm_s2"]
        self.tq_t, self.tq_v = np.asarray(sc["pump_torque_times_s"]), np.asarray(sc["pump_torque_nm"])
        # mass matrix (left-hand sides of eqs 2.12–2.15), load inertia added to the turbine
        self.M = np.array(
            [
                [self.Ip, 0, 0, rho * self.Sp],
                [0, self.It + self.IL, 0, rho * self.St],
                [0, 0, self.Is, rho * self.Ss],
                [rho * self.Sp, rho * self.St, rho * self.Ss, rho * self.Lf / A],
            ],
            float,
        )
        np.linalg.cholesky(self.M)  # raises unless M is positive definite (physics notes §4)
        # Euler-head coefficients of eq 2.15 and the friction constant of eqs 2.19, 2.23–2.25
        self.a = self.Rp * self.tp - self.Rs * self.ts
        self.b = self.Rt * self.tt - self.Rp * self.tp
        self.c = self.Rs * self.ts - self.Rt * self.tt
        self.kf = 0.5 * rho * self.f * (3 + self.tp**2 + self.tt**2 + self.ts**2)
        # shock velocities (eqs 2.20–2.22) are linear in u: V = dV @ u
        self.dV = np.array(
            [
                [-self.Rs, 0, self.Rs, (self.ts - self.tpp) / A],
                [self.Rp, -self.Rp, 0, (self.tp - self.ttt) / A],
                [0, self.Rt, -self.Rt, (self.tt - self.tss) / A],
            ]
        )
        self.C = np.array([self.Cp, self.Ct, self.Cs])
        self._modes = {}

    def pump_torque(self, t):
        return np.interp(t, self.tq_t, self.tq_v)

    def head(self, u):
        """Eq 2.15 right-hand side without P_loss (Euler heads). u: (4,) or (4, n)."""
        wp, wt, ws, Q = u
        Rp2, Rt2, Rs2 = self.Rp**2, self.Rt**2, self.Rs**2
        return self.rho * (
            Rp2 * wp * wp
            + Rt2 * wt * wt
            + Rs2 * ws * ws
            - Rs2 * wp * ws
            - Rp2 * wt * wp
            - Rt2 * ws * wt
            + Q / self.A * (wp * self.a + wt * self.b + ws * self.c)
        )

    def shock(self, u):
        """(ρ/2) Σ C_sh,x V_sh,x², eqs 2.19–2.22 (P0 of the stuck test when Q = 0)."""
        V = self.dV @ u  # [V_sh,p, V_sh,t, V_sh,s]
        return 0.5 * self.rho * (self.C @ (V * V))

    def forces(self, u, sigma):
        """Right-hand sides F of eqs 2.12–2.15 without external torques, and P_loss (eq 2.19)."""
        wp, wt, ws, Q = u
        q = Q / self.A
        hp = wp * self.Rp**2 + self.Rp * self.tp * q
        ht = wt * self.Rt**2 + self.Rt * self.tt * q
        hs = ws * self.Rs**2 + self.Rs * self.ts * q
        ploss = sigma * (self.shock(u) + self.kf * q * q)
        rq = self.rho * Q
        return np.array([-rq * (hp - hs), -rq * (ht - hp), -rq * (hs - ht), self.head(u) - ploss]), ploss

    def jacobian(self, u, sigma):
        """∂F/∂u (4×4) of `forces`, analytic, σ held constant."""
        wp, wt, ws, Q = u
        rho, A, q = self.rho, self.A, Q / self.A
        Rp2, Rt2, Rs2 = self.Rp**2, self.Rt**2, self.Rs**2
        hp, ht = wp * Rp2 + self.Rp * self.tp * q, wt * Rt2 + self.Rt * self.tt * q
        hs = ws * Rs2 + self.Rs * self.ts * q
        rq = rho * Q
        V = self.dV @ u
        dP = sigma * rho * (self.C * V) @ self.dV
        dP[3] += sigma * 2 * self.kf * q / A
        return np.array(
            [
                [-rq * Rp2, 0.0, rq * Rs2, -rho * (hp - hs) - rq * self.a / A],
                [rq * Rp2, -rq * Rt2, 0.0, -rho * (ht - hp) - rq * self.b / A],
                [0.0, rq * Rt2, -rq * Rs2, -rho * (hs - ht) - rq * self.c / A],
                [
                    rho * (2 * Rp2 * wp - Rs2 * ws - Rp2 * wt + q * self.a) - dP[0],
                    rho * (2 * Rt2 * wt - Rp2 * wp - Rt2 * ws + q * self.b) - dP[1],
                    rho * (2 * Rs2 * ws - Rs2 * wp - Rt2 * wt + q * self.c) - dP[2],
                    rho * (wp * self.a + wt * self.b + ws * self.c) / A - dP[3],
                ],
            ]
        )

    def mode(self, stator, sigma) -> Mode:
        key = (stator, sigma)
        if key not in self._modes:
            self._modes[key] = Mode(self, stator, sigma)
        return self._modes[key]

    def flow_decision(self, t, u, stator):
        """σ at a state with Q = 0: +1 if d > P0, −1 if d < −P0, else 0 (stuck)."""
        d, p0 = self.mode(stator, 0).stuck_balance(t, u)
        return 1 if d > p0 else (-1 if d < -p0 else 0)


class Mode:
    """One smooth mode: M_xx ẋ = F_x + T_ext,x over the free coordinates x (M_xx⁻¹ precomputed)."""

    def __init__(self, m: Model, stator, sigma):
        self.m, self.stator, self.sigma = m, stator, sigma
        self.free = [0, 1] + ([2] if stator == FREE else []) + ([3] if sigma else [])
        self.Minv = np.linalg.inv(m.M[np.ix_(self.free, self.free)])

    def full(self, x):
        u = np.zeros((4,) + np.shape(x)[1:])
        u[self.free] = x
        return u

    def _rhs_full(self, t, u):
        F, ploss = self.m.forces(u, self.sigma)
        F[0] += self.m.pump_torque(t)
        F[1] -= self.m.T0 + self.m.cd * u[1] ** 2
        return F, ploss

    def rhs(self, t, x):
        F, _ = self._rhs_full(t, self.full(x))
        return self.Minv @ F[self.free]

    def jac(self, t, x):
        u = self.full(x)
        J = self.m.jacobian(u, self.sigma)  # plus the derivative of the turbine load:
        J[1, 1] -= 2 * self.m.cd * u[1]
        return self.Minv @ J[np.ix_(self.free, self.free)]

    def rates(self, t, u):
        """u̇ in full coordinates (zero for held ones) and F, P_loss; u: (4,) or (4, n)."""
        F, ploss = self._rhs_full(t, u)
        ud = np.zeros_like(u)
        ud[self.free] = self.Minv @ F[self.free]
        return ud, F, ploss

    def holding_torque(self, t, u):
        """Locked-stator reaction T_s = ρSs Q̇ − Fs (eq 2.14 with ω̇s = 0)."""
        ud, F, _ = self.rates(t, u)
        return self.m.rho * self.m.Ss * ud[3] - F[2]

    def stuck_balance(self, t, u):
        """d = FQ without P_loss − M[Q, free]·u̇_free at Q = 0, and P0 = (ρ/2) Σ C V² at q = 0."""
        ud, _, _ = self.rates(t, u)
        return self.m.head(u) - self.m.M[3] @ ud, self.m.shock(u)

    def events(self):
        """Terminal event functions of this mode, each with a `kind`."""

        def ev(fun, direction, kind):
            fun.terminal, fun.direction, fun.kind = True, direction, kind
            return fun

        full, out = self.full, []
        if self.stator == LOCKED and self.sigma:  # with Q ≡ 0 the holding torque is identically 0
            out.append(ev(lambda t, x: self.holding_torque(t, full(x)), -1, "stator_release"))
        if self.stator == FREE:
            out.append(ev(lambda t, x: x[2], -1, "stator_lock"))
        if self.sigma:
            out.append(ev(lambda t, x: x[-1], -self.sigma, "flow_zero"))
        else:
            out.append(ev(lambda t, x: np.subtract(*self.stuck_balance(t, full(x))), 1, "flow_start+"))
            out.append(ev(lambda t, x: np.add(*self.stuck_balance(t, full(x))), -1, "flow_start-"))
        return out


def initial_state(m: Model) -> np.ndarray:
    """ωp and Q steady under Tp(t0) with ωt = ωt0, ωs = 0, σ = +1: FQ = 0 and ρ(hp − hs)Q = Tp."""
    wt0, tp0 = m.sc["turbine_speed0_rad_s"], float(m.pump_torque(m.sc["t_span"][0]))
    if tp0 <= 0:
        raise ValueError("initial pump torque must be positive")

    def flow(wp):  # FQ(Q) is a quadratic: coefficients from three exact evaluations
        fq = [m.forces(np.array([wp, wt0, 0.0, s * m.A]), 1)[0][3] for s in (-1.0, 0.0, 1.0)]
        roots = np.roots([0.5 * (fq[2] + fq[0]) - fq[1], 0.5 * (fq[2] - fq[0]), fq[1]])
        return m.A * max(r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0)

    def residual(wp):  # −Fp − Tp = ρ(hp − hs)Q − Tp
        return -m.forces(np.array([wp, wt0, 0.0, flow(wp)]), 1)[0][0] - tp0

    wp = brentq(residual, max(wt0, 1.0), 5000.0, xtol=1e-13)
    return np.array([wp, wt0, 0.0, flow(wp)])


def simulate(params, scenario, method="LSODA", rtol=1e-6, atol=None, t_eval=None) -> dict:
    """Integrate mode by mode; outputs at t_eval (default 1001 points) from each segment's dense output.

    atol default: 1e-6 · [100, 100, 100 rad/s, 0.05 m³/s] whatever rtol (pass atol=rtol·REF for tight
    runs). Returns time_s, pump/turbine/stator_speed_rad_s, flow_m3_s, pump_torque_nm (input),
    turbine_torque_nm (to the load shaft: Ft − It ω̇t − ρSt Q̇), stator_torque_nm (holding torque,
    0 when free), stator_mode (0 locked, 1 free), flow_sign (+1, −1, 0 stuck), loss_power_w (Q·P_loss),
    events [(time, kind)], and nfev, njev (summed over segments; event-function calls not counted).
    """
    m = Model(params, scenario)
    t0, t1 = scenario["t_span"]
    t_eval = np.linspace(t0, t1, 1001) if t_eval is None else np.asarray(t_eval, float)
    atol = 1e-6 * REF if atol is None else np.broadcast_to(np.asarray(atol, float), (4,))
    u = initial_state(m)
    sigma = int(np.sign(u[3])) or m.flow_decision(t0, u, LOCKED)
    locked_ok = u[2] == 0 and (not sigma or m.mode(LOCKED, sigma).holding_torque(t0, u) >= 0)
    stator = LOCKED if locked_ok else FREE
    stops = sorted({b for b in m.tq_t if t0 < b < t1} | {t1})
    segments, events, nfev, njev, t = [], [], 0, 0, t0
    while t < t1:
        mode = m.mode(stator, sigma)
        evs = mode.events()
        sol = solve_ivp(
            mode.rhs,
            (t, next(b for b in stops if b > t)),
            u[mode.free],
            method=method,
            jac=mode.jac,
            events=evs,
            dense_output=True,
            rtol=rtol,
            atol=atol[mode.free],
        )
        if sol.status < 0:
            raise RuntimeError(f"{method} failed at t = {t}: {sol.message}")
        nfev, njev = nfev + sol.nfev, njev + sol.njev
        segments.append((t, sol.t[-1], mode, sol.sol))
        t, u = sol.t[-1], mode.full(sol.y[:, -1])
        if sol.status == 1:  # a terminal event: switch mode, state continuous
            kind = evs[next(i for i, te in enumerate(sol.t_events) if len(te))].kind
            if kind == "stator_release":
                stator = FREE
            elif kind == "stator_lock":
                stator, u[2] = LOCKED, 0.0
            elif kind == "flow_zero":
                u[3] = 0.0
                sigma = m.flow_decision(t, u, stator)
                kind = {1: "flow_zero->+1", -1: "flow_zero->-1", 0: "flow_zero->stuck"}[sigma]
            else:
                sigma = 1 if kind == "flow_start+" else -1
            events.append((t, kind))
            if (
                kind != "stator_release"
                and stator == LOCKED
                and sigma
                and m.mode(LOCKED, sigma).holding_torque(t, u) < 0
            ):
                stator = FREE  # flow restarted against the clutch: it cannot hold a negative torque
                events.append((t, "stator_release"))
            if len(events) > MAX_EVENTS:
                raise RuntimeError(f"more than {MAX_EVENTS} events (chattering) by t = {t}")

    n = len(t_eval)
    U = np.zeros((4, n))
    tt, ts, loss, smode, fsign = (np.zeros(n) for _ in range(5))
    for ta, tb, mode, dense in segments:  # later segments overwrite shared boundary points
        sel = (t_eval >= ta) & (t_eval <= tb)
        if not sel.any():
            continue
        us = mode.full(dense(t_eval[sel]))
        ud, F, ploss = mode.rates(t_eval[sel], us)
        U[:, sel] = us
        tt[sel] = F[1] + m.T0 + m.cd * us[1] ** 2 - m.It * ud[1] - m.rho * m.St * ud[3]  # F[1] has the load
        if mode.stator == LOCKED:  # holding torque; with Q ≡ 0 (stuck) F[2] = 0 and Q̇ = 0
            ts[sel] = m.rho * m.Ss * ud[3] - F[2]
        loss[sel] = us[3] * ploss if mode.sigma else 0.0
        smode[sel], fsign[sel] = mode.stator, mode.sigma
    return dict(
        time_s=t_eval,
        pump_speed_rad_s=U[0],
        turbine_speed_rad_s=U[1],
        stator_speed_rad_s=U[2],
        flow_m3_s=U[3],
        pump_torque_nm=m.pump_torque(t_eval),
        turbine_torque_nm=tt,
        stator_torque_nm=ts,
        stator_mode=smode.astype(int),
        flow_sign=fsign.astype(int),
        loss_power_w=loss,
        events=events,
        nfev=nfev,
        njev=njev,
    )


def energy_residual(params, scenario, r) -> float:
    """(∫ power in − ΔE) / ∫|Tp ωp| dt with E = ½ uᵀ M u (physics notes §4), trapezoid rule."""
    m, U, t = Model(params, scenario), np.array([r[k] for k in STATE]), r["time_s"]
    wp, wt = U[0], U[1]
    power = r["pump_torque_nm"] * wp - (m.T0 + m.cd * wt**2) * wt + r["stator_torque_nm"] * U[2] - r["loss_power_w"]
    E = 0.5 * np.einsum("in,ij,jn->n", U, m.M, U)
    return (np.trapezoid(power, t) - (E[-1] - E[0])) / np.trapezoid(np.abs(r["pump_torque_nm"] * wp), t)


def _fd(fun, x, h):
    """Central finite-difference Jacobian of fun at x with steps h."""
    return np.column_stack([(fun(x + h[k] * e) - fun(x - h[k] * e)) / (2 * h[k]) for k, e in enumerate(np.eye(len(x)))])


def _self_check(p, sc):
    """Finite-difference check of ∂F/∂u and of each mode's Jacobian; power identity (eq 2.15 ×Q)."""
    m, rng, h = Model(p, sc), np.random.default_rng(1), 1e-6 * REF
    rel = lambda fd, an: np.max(np.abs(fd - an) / (np.abs(fd) + 1e-3))  # noqa: E731
    for sigma in (1, -1):
        u = np.array([150.0, 90.0, 20.0, 0.03 * sigma]) * (1 + 0.1 * rng.standard_normal(4))
        F, ploss = m.forces(u, sigma)
        err_f = rel(_fd(lambda v, sigma=sigma: m.forces(v, sigma)[0], u, h), m.jacobian(u, sigma))
        err_mode = max(
            rel(_fd(lambda x, md=md: md.rhs(0.5, x), u[md.free], h[md.free]), md.jac(0.5, u[md.free]))
            for md in (m.mode(st, sg) for st in (LOCKED, FREE) for sg in (sigma, 0))
        )
        print(
            f"  sigma={sigma:+d}: dF/du vs FD {err_f:.1e}, mode Jacobians vs FD {err_mode:.1e}, power identity "
            f"u·F + Q·Ploss = {u @ F + u[3] * ploss:.1e} (of Q·Ploss {u[3] * ploss:.3e})"
        )


def main():
    p = load_parameters()
    print("Self-check (relative errors):")
    _self_check(p, takeoff_scenario())
    u0 = initial_state(Model(p, takeoff_scenario()))
    print(f"Initial state: wp = {u0[0]:.6f} rad/s, Q = {u0[3]:.8f} m3/s (Tp = 40 N m, wt = 0)")
    fine_t = np.linspace(0.0, 10.0, 20001)
    for tip in (False, True):
        sc = takeoff_scenario(tip)
        print(f"\n=== take-off{' with tip-out' if tip else ''} ===")
        for method in ("LSODA", "Radau"):
            times = []
            for _ in range(5):
                start = time.perf_counter()
                r = simulate(p, sc, method=method)
                times.append(time.perf_counter() - start)
            fine = simulate(p, sc, method=method, rtol=1e-8, atol=1e-8 * REF, t_eval=fine_t)
            print(
                f"{method}: rtol 1e-6, median wall {1e3 * statistics.median(times):.1f} ms (of 5), "
                f"nfev {r['nfev']}, njev {r['njev']}"
            )
            for te, kind in r["events"]:
                k = np.searchsorted(fine_t, te)
                sr = fine["turbine_speed_rad_s"][k] / fine["pump_speed_rad_s"][k]
                print(f"  event t = {te:.6f} s  {kind}  (SR ~ {sr:.4f})")
            print(
                "  final (rtol 1e-6): wp {:.6f} wt {:.6f} ws {:.6f} rad/s, Q {:.8f} m3/s".format(
                    *tuple(r[k][-1] for k in STATE)
                )
            )
            print(
                "  final (rtol 1e-8): wp {:.6f} wt {:.6f} ws {:.6f} rad/s, Q {:.8f} m3/s; "
                "Tt {:.4f} Ts {:.4f} N m".format(
                    *(fine[k][-1] for k in STATE), fine["turbine_torque_nm"][-1], fine["stator_torque_nm"][-1]
                )
            )
            coarse = simulate(p, sc, method=method, t_eval=fine_t)
            print(
                f"  energy residual / int|Tp wp|dt: rtol 1e-6 {energy_residual(p, sc, coarse):.2e}, "
                f"rtol 1e-8 {energy_residual(p, sc, fine):.2e}"
            )
            kinds = [k for _, k in fine["events"]]
            print(
                f"  stator released: {'stator_release' in kinds}, relocked: {'stator_lock' in kinds}, "
                f"Q reversed: {any(k in ('flow_zero->-1', 'flow_start-') for k in kinds)} "
                f"({len(kinds)} events at rtol 1e-8)"
            )


if __name__ == "__main__":
    main()
