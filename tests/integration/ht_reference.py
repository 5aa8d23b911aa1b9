"""Plain reference implementation of the Hrovat & Tobler torque-converter model.

Written independently of tcsim's core (from Li & Sundén 2016, section 2.2.2, eqs 2.12-2.25, Table D.1,
and physics notes sections 2, 4, 8), without reading it, to cross-check it (issue 11): steady states
by brute-force root finding on the full equations, not the core's closed-form quadratics.
numpy + scipy only.  Nothing clever: every quantity is written out as in the equations.

Conventions
-----------
* Speeds positive in the engine's direction of rotation, rad/s.  Q in m^3/s, q = Q/A in m/s.
* Forward flow (Q > 0): pump -> turbine -> stator -> pump.
* The model is written as   I*dw/dt + rho*S*dQ/dt = F + T_ext      (rows p, t, s)
                            rho*(S.dw/dt) + (rho*Lf/A)*dQ/dt = F_Q  (flow row)
  F = (F_p, F_t, F_s) are the internal (fluid) torques on the elements, F_Q the right-hand side
  of eq 2.15 (a pressure, Pa).  T_ext = (T_p, T_t, T_s) are the external torques of physics.md
  section 2 (T_p engine torque, T_t load on the turbine, T_s housing torque through the
  one-way clutch).  At steady state T_ext = -F.  Torque delivered to the transmission = -T_t = F_t.
* Power absorbed by the converter: P_abs = -(w.F + Q*F_Q) = rho*|Q|*loss >= 0.

Angle/radius bookkeeping (mean streamline)
------------------------------------------
element   exit radius  exit angle   inlet edge radius        inlet angle
pump      R_p          a_p          R_s (stator exit radius) a_pp
turbine   R_t          a_t          R_p (pump exit radius)   a_tt
stator    R_s          a_s          R_t (turbine exit radius) a_ss
A fluid particle leaving an edge follows the blade: meridional velocity q, relative tangential
velocity q*tan(angle), so its absolute tangential velocity is w*R + q*tan(angle) and its angular
momentum per unit mass is  h = w*R^2 + R*tan(angle)*q.
"""

import numpy as np
from scipy.optimize import brentq

ELEMENTS = ("p", "t", "s")


# ----------------------------------------------------------------------------------------------
# 1. Parameters
# ----------------------------------------------------------------------------------------------
def geometry_appendix_d():
    """Reference parameters of Li & Sundén (2016) Table D.1 (checked against the thesis text).

    Angles are returned in degrees (keys *_deg); the force functions convert them.
    The thesis writes the flow-area unit as [m3]; it is an area in m^2.
    Key names: a_p/a_t/a_s = exit angles of pump/turbine/stator, a_pp/a_tt/a_ss = inlet angles,
    C_p/C_t/C_s = shock-loss coefficients, f = fluid friction factor.
    """
    return {
        "A": 0.01,  # flow area [m^2]
        "rho": 840.0,  # fluid density [kg/m^3]
        "R_p": 0.12,  # impeller (pump) exit radius [m]
        "R_t": 0.065,  # turbine exit radius [m]
        "R_s": 0.06,  # stator exit radius [m]
        "a_p_deg": -20.0,  # impeller exit angle
        "a_t_deg": -50.0,  # turbine exit angle
        "a_s_deg": 60.0,  # stator exit angle
        "a_pp_deg": -50.0,  # impeller inlet angle
        "a_tt_deg": 55.0,  # turbine inlet angle
        "a_ss_deg": 15.0,  # stator inlet angle
        "C_p": 1.0,  # impeller shock-loss coefficient
        "C_t": 1.0,  # turbine shock-loss coefficient
        "C_s": 1.0,  # stator shock-loss coefficient
        "f": 0.2,  # fluid friction factor
    }


def _tans(g):
    """tan of the six blade angles: (exit p, t, s), (inlet p, t, s)."""

    def t(k):
        return np.tan(np.radians(g[k]))

    return (t("a_p_deg"), t("a_t_deg"), t("a_s_deg")), (t("a_pp_deg"), t("a_tt_deg"), t("a_ss_deg"))


# ----------------------------------------------------------------------------------------------
# 2. Forces (right-hand sides) - forward flow, literally from eqs 2.12-2.15, 2.19-2.25
# ----------------------------------------------------------------------------------------------
def forces_forward(w_p, w_t, w_s, Q, g, sigma=1.0):
    """Right-hand sides of eqs 2.12-2.15 with T_ext = 0, forward-flow form.

    F_p = -rho*(w_p Rp^2 + Rp tan(a_p) q - w_s Rs^2 - Rs tan(a_s) q) * Q        (2.12)
    F_t = -rho*(w_t Rt^2 + Rt tan(a_t) q - w_p Rp^2 - Rp tan(a_p) q) * Q        (2.13)
    F_s = -rho*(w_s Rs^2 + Rs tan(a_s) q - w_t Rt^2 - Rt tan(a_t) q) * Q        (2.14)
    F_Q = rho*(Rp^2 wp^2 + Rt^2 wt^2 + Rs^2 ws^2 - Rs^2 wp ws - Rp^2 wt wp - Rt^2 ws wt)
          + wp rho (Rp tan a_p - Rs tan a_s) q + wt rho (Rt tan a_t - Rp tan a_p) q
          + ws rho (Rs tan a_s - Rt tan a_t) q - P_loss                          (2.15)
    P_loss = sigma*rho/2*(C_p Vsh_p^2 + C_t Vsh_t^2 + C_s Vsh_s^2)
           + sigma*rho*f/2*(|Vre_p|^2 + |Vre_t|^2 + |Vre_s|^2)                    (2.19)
    Vsh_p = Rs (ws - wp) + q (tan a_s - tan a_pp)                                (2.20)
    Vsh_t = Rp (wp - wt) + q (tan a_p - tan a_tt)                                (2.21)
    Vsh_s = Rt (wt - ws) + q (tan a_t - tan a_ss)                                (2.22)
    |Vre_x|^2 = q^2 (1 + tan^2 a_x)   (exit angles, eqs 2.23-2.25)
    sigma stands for sgn(Q); the thesis form is meant for sigma = +1, Q >= 0.
    Works element-wise on numpy arrays.
    """
    rho, A = g["rho"], g["A"]
    Rp, Rt, Rs = g["R_p"], g["R_t"], g["R_s"]
    (tp, tt, ts), (tpp, ttt, tss) = _tans(g)
    q = Q / A

    F_p = -rho * (w_p * Rp**2 + Rp * tp * q - w_s * Rs**2 - Rs * ts * q) * Q
    F_t = -rho * (w_t * Rt**2 + Rt * tt * q - w_p * Rp**2 - Rp * tp * q) * Q
    F_s = -rho * (w_s * Rs**2 + Rs * ts * q - w_t * Rt**2 - Rt * tt * q) * Q

    V_sh_p = Rs * (w_s - w_p) + q * (ts - tpp)
    V_sh_t = Rp * (w_p - w_t) + q * (tp - ttt)
    V_sh_s = Rt * (w_t - w_s) + q * (tt - tss)
    V_re2 = q**2 * (1 + tp**2) + q**2 * (1 + tt**2) + q**2 * (1 + ts**2)
    P_loss = (
        sigma * rho / 2 * (g["C_p"] * V_sh_p**2 + g["C_t"] * V_sh_t**2 + g["C_s"] * V_sh_s**2)
        + sigma * rho * g["f"] / 2 * V_re2
    )

    F_Q = (
        rho
        * (Rp**2 * w_p**2 + Rt**2 * w_t**2 + Rs**2 * w_s**2 - Rs**2 * w_p * w_s - Rp**2 * w_t * w_p - Rt**2 * w_s * w_t)
        + w_p * rho * (Rp * tp - Rs * ts) * q
        + w_t * rho * (Rt * tt - Rp * tp) * q
        + w_s * rho * (Rs * ts - Rt * tt) * q
        - P_loss
    )
    return F_p, F_t, F_s, F_Q


# ----------------------------------------------------------------------------------------------
# 2b. Reverse flow (physics.md section 8 form, as given in the brief)
# ----------------------------------------------------------------------------------------------
def forces_reverse(w_p, w_t, w_s, Q, g, sigma=-1.0):
    """Reverse-flow form (Q < 0): fluid leaves each element across its inlet edge.

    h^r_p = w_p Rs^2 + Rs tan(a_pp) q      (pump leaves at R_s, pump inlet angle)
    h^r_t = w_t Rp^2 + Rp tan(a_tt) q      (turbine leaves at R_p, turbine inlet angle)
    h^r_s = w_s Rt^2 + Rt tan(a_ss) q      (stator leaves at R_t, stator inlet angle)
    Element x receives fluid from next(x): p <- t <- s <- p.
    Torque of x on the fluid = rho|Q| (h^r_x - h^r_next(x)); internal torque
    F_x = rho Q (h^r_x - h^r_next(x)).
    head^r = sum_x w_x (h^r_next(x) - h^r_x)  (so that sum w F + Q rho head^r = 0);
    F_Q = rho (head^r - sigma*loss^r),
    loss^r = 1/2 sum C_x (V^r_sh,x)^2 + 1/2 f sum q^2 (1 + tan^2 a_in,x),
    V^r_sh,p = Rp (w_t - w_p) + q (tan a_tt - tan a_p)
    V^r_sh,t = Rt (w_s - w_t) + q (tan a_ss - tan a_t)
    V^r_sh,s = Rs (w_p - w_s) + q (tan a_pp - tan a_s)

    Derivation check (done for this reference, all items agree with the brief):
    * leaving along the blade at an inlet edge: meridional q (< 0), relative tangential q tan(a_in),
      absolute tangential w R_in + q tan(a_in)  =>  h^r_x as above.
    * in the vaneless gaps angular momentum is conserved, so x receives h^r_next(x); the mass flow
      through x is rho|Q|; torque of x on the fluid rho|Q|(h^r_x - h^r_next), F_x = its negative
      = rho Q (h^r_x - h^r_next) (Q < 0).
    * sum_x w_x F_x = -rho Q head^r, so sum w F + Q F_Q = -rho |Q| loss^r <= 0 (passive).
      Wording only: rho*head^r is the pressure rise in the +Q (forward) direction; the work per
      unit volume the blades do on the reverse-moving fluid is -rho*head^r.
    * shock: fluid enters x at its exit edge (R_x) with the tangential velocity w_next R_x +
      q tan(a_in,next); the blade there accepts w_x R_x + q tan(a_x)  =>  V^r_sh,x as above.
    * consistency: with all C_sh = 1, F_Q(0-) (this form) = F_Q(0+) (eq 2.15) =
      1/2 rho sum w_x^2 (R_exit,x^2 - R_inlet,x^2), the centrifugal head; F_Q is continuous at
      Q = 0.  With C_sh != 1 it jumps at Q = 0 (in either form, an artefact of the shock model).
    """
    rho, A = g["rho"], g["A"]
    Rp, Rt, Rs = g["R_p"], g["R_t"], g["R_s"]
    (tp, tt, ts), (tpp, ttt, tss) = _tans(g)
    q = Q / A

    hr_p = w_p * Rs**2 + Rs * tpp * q
    hr_t = w_t * Rp**2 + Rp * ttt * q
    hr_s = w_s * Rt**2 + Rt * tss * q

    F_p = rho * Q * (hr_p - hr_t)  # pump receives from turbine
    F_t = rho * Q * (hr_t - hr_s)  # turbine receives from stator
    F_s = rho * Q * (hr_s - hr_p)  # stator receives from pump

    head_r = w_p * (hr_t - hr_p) + w_t * (hr_s - hr_t) + w_s * (hr_p - hr_s)

    V_sh_p = Rp * (w_t - w_p) + q * (ttt - tp)
    V_sh_t = Rt * (w_s - w_t) + q * (tss - tt)
    V_sh_s = Rs * (w_p - w_s) + q * (tpp - ts)
    V_re2 = q**2 * (1 + tpp**2) + q**2 * (1 + ttt**2) + q**2 * (1 + tss**2)
    loss_r = 0.5 * (g["C_p"] * V_sh_p**2 + g["C_t"] * V_sh_t**2 + g["C_s"] * V_sh_s**2) + 0.5 * g["f"] * V_re2

    F_Q = rho * (head_r - sigma * loss_r)
    return F_p, F_t, F_s, F_Q


def forces(w_p, w_t, w_s, Q, sigma, g, form="reverse"):
    """(F_p, F_t, F_s, F_Q): forward form for sigma = +1, reverse form for sigma = -1.

    form="thesis" instead uses the thesis equations literally for both signs (forward form with
    sgn(Q) = sigma in eq 2.19), for comparison with the physics.md section 8 statement.
    """
    if sigma > 0 or form == "thesis":
        return forces_forward(w_p, w_t, w_s, Q, g, sigma=float(np.sign(sigma)))
    return forces_reverse(w_p, w_t, w_s, Q, g, sigma=-1.0)


def loss_per_volume(w_p, w_t, w_s, Q, sigma, g):
    """rho*loss (Pa, >= 0): the dissipated energy per unit volume of fluid passed.

    Forward: rho/2 sum C Vsh^2 + rho f/2 sum |Vre|^2 (eq 2.19 without the sgn);
    reverse: rho*loss^r.  Obtained as |F_Q(sigma) - F_Q(loss-free)|, computed directly.
    """
    g0 = dict(g, C_p=0.0, C_t=0.0, C_s=0.0, f=0.0)
    return -sigma * (forces(w_p, w_t, w_s, Q, sigma, g)[3] - forces(w_p, w_t, w_s, Q, sigma, g0)[3])


def sgn(Q):
    """sign with sgn(0) = +1 (the forward form is used at Q = 0 unless asked otherwise)."""
    return 1.0 if Q >= 0 else -1.0


# ----------------------------------------------------------------------------------------------
# 3. Absorbed power and the passivity check
# ----------------------------------------------------------------------------------------------
def absorbed_power(w_p, w_t, w_s, Q, sigma, g):
    """P_abs = -(w_p F_p + w_t F_t + w_s F_s + Q F_Q), W.  Must equal rho |Q| loss >= 0."""
    F_p, F_t, F_s, F_Q = forces(w_p, w_t, w_s, Q, sigma, g)
    return -(w_p * F_p + w_t * F_t + w_s * F_s + Q * F_Q)


def check_absorbed_power(g, n=2000, seed=1):
    """Random points of both flow directions: P_abs == rho|Q|loss and >= 0; also
    sum w F + Q rho head == 0.  Returns the largest relative mismatch and the minimum P_abs."""
    rng = np.random.default_rng(seed)
    worst, pmin = 0.0, np.inf
    for _ in range(n):
        w_p, w_t, w_s = rng.uniform(-400, 400, 3)
        Q = rng.uniform(-0.5, 0.5)
        sigma = sgn(Q)
        P = absorbed_power(w_p, w_t, w_s, Q, sigma, g)
        L = abs(Q) * loss_per_volume(w_p, w_t, w_s, Q, sigma, g)
        scale = abs(P) + abs(L) + 1.0
        worst = max(worst, abs(P - L) / scale)
        pmin = min(pmin, P)
    return worst, pmin


# ----------------------------------------------------------------------------------------------
# 4. Steady states by brute-force scanning
# ----------------------------------------------------------------------------------------------
def stator_speed_free(w_p, w_t, Q, g, form="reverse"):
    """Free-wheeling stator: solve F_s(w_s) = 0 for w_s (F_s is affine in w_s for Q != 0).

    Done numerically from two evaluations: F_s(w_s) = F_s(0) + w_s*(F_s(1) - F_s(0)).
    Works on arrays of Q (Q must not be 0).
    """
    sigma = np.sign(Q)
    out = np.empty_like(np.asarray(Q, dtype=float))
    for sg in (1.0, -1.0):
        m = sigma == sg
        if not np.any(m):
            continue
        Qm = np.asarray(Q, dtype=float)[m]
        F0 = forces(w_p, w_t, 0.0, Qm, sg, g, form)[2]
        F1 = forces(w_p, w_t, 1.0, Qm, sg, g, form)[2]
        out[m] = -F0 / (F1 - F0)
    return out


def _FQ_locked(Q, w_p, w_t, g, form="reverse"):
    Q = np.asarray(Q, dtype=float)
    sg = np.where(Q >= 0, 1.0, -1.0)
    res = np.empty_like(Q)
    for s in (1.0, -1.0):
        m = sg == s
        if np.any(m):
            res[m] = forces(w_p, w_t, 0.0, Q[m], s, g, form)[3]
    return res


def _FQ_free(Q, w_p, w_t, g, form="reverse"):
    Q = np.asarray(Q, dtype=float)
    w_s = stator_speed_free(w_p, w_t, Q, g, form)
    res = np.empty_like(Q)
    for s in (1.0, -1.0):
        m = np.sign(Q) == s
        if np.any(m):
            res[m] = forces(w_p, w_t, w_s[m], Q[m], s, g, form)[3]
    return res


def _q_grid(w_p, w_t, g, fq, form="reverse", n_lin=4000, n_log=400):
    """Q grid for one sign (positive values): linear up to Qmax plus a log grid near 0.
    Qmax is doubled until F_Q(+Qmax) < 0 and F_Q(-Qmax) > 0 (losses dominate)."""
    Qmax = 4.0 * g["A"] * max(abs(w_p), abs(w_t), 1.0) * max(g["R_p"], g["R_t"], g["R_s"])
    for _ in range(20):
        if fq(np.array([Qmax]), w_p, w_t, g, form)[0] < 0 and fq(np.array([-Qmax]), w_p, w_t, g, form)[0] > 0:
            break
        Qmax *= 2.0
    lin = np.linspace(0.0, Qmax, n_lin + 1)[1:]
    log = np.geomspace(Qmax * 1e-9, Qmax / n_lin, n_log)
    return np.unique(np.concatenate([log, lin]))


def _scan_roots(fq, w_p, w_t, g, form="reverse"):
    """All roots of F_Q(Q) on each side of 0 (sign changes on the grid, refined by brentq).
    A tangential (double) root without a sign change on the 4400-point grid can be missed."""
    grid = _q_grid(w_p, w_t, g, fq, form)
    roots = []
    for side in (1.0, -1.0):
        Qs = side * grid
        F = fq(Qs, w_p, w_t, g, form)
        for i in range(len(Qs) - 1):
            if F[i] == 0.0:
                roots.append(Qs[i])
            elif F[i] * F[i + 1] < 0:
                roots.append(
                    brentq(
                        lambda x: fq(np.array([x]), w_p, w_t, g, form)[0],
                        Qs[i],
                        Qs[i + 1],
                        xtol=1e-15,
                        rtol=1e-13,
                        maxiter=200,
                    )
                )
    return sorted(roots)


def _state(w_p, w_t, w_s, Q, g, mode, fq, form="reverse"):
    sigma = sgn(Q)
    F_p, F_t, F_s, F_Q = forces(w_p, w_t, w_s, Q, sigma, g, form)
    h = 1e-7 * max(abs(Q), 1e-6)
    dFdQ = (fq(np.array([Q + h]), w_p, w_t, g, form)[0] - fq(np.array([Q - h]), w_p, w_t, g, form)[0]) / (2 * h)
    return {
        "mode": mode,
        "Q": Q,
        "w_s": w_s,
        "T_p": -F_p,
        "T_t": -F_t,
        "T_t_delivered": F_t,
        "T_s": -F_s,
        "F_Q_residual": F_Q,
        "P_abs": -(w_p * F_p + w_t * F_t + w_s * F_s + Q * F_Q),
        "dFQ_dQ": dFdQ,  # < 0: stable for the flow row (speeds held fixed)
        "stable": dFdQ < 0,
    }


def held_check_locked(w_p, w_t, g, form="reverse"):
    """F_Q at Q = 0+ (forward form) and 0- (reverse form), stator locked, and whether Q = 0 is
    held: F_Q(0+) <= 0 <= F_Q(0-)."""
    fp = forces(w_p, w_t, 0.0, 0.0, +1, g, form)[3]
    fm = forces(w_p, w_t, 0.0, 0.0, -1, g, form)[3]
    return {"F_Q_0p": fp, "F_Q_0m": fm, "held": fp <= 0.0 <= fm}


def held_check_free(w_p, w_t, g, form="reverse"):
    """Same for the free stator.  At Q = 0 w_s is undetermined; the limits w_s(0+) and w_s(0-)
    of the F_s = 0 solution are used on each side."""
    eps = 1e-12
    ws_p = stator_speed_free(w_p, w_t, np.array([eps]), g, form)[0]
    ws_m = stator_speed_free(w_p, w_t, np.array([-eps]), g, form)[0]
    fp = forces(w_p, w_t, ws_p, 0.0, +1, g, form)[3]
    fm = forces(w_p, w_t, ws_m, 0.0, -1, g, form)[3]
    return {"F_Q_0p": fp, "F_Q_0m": fm, "w_s_0p": ws_p, "w_s_0m": ws_m, "held": fp <= 0.0 <= fm}


def steady_locked(w_p, w_t, g, form="reverse"):
    """All steady states with the stator locked (w_s = 0), Q != 0, by scanning F_Q(Q).
    Each state: dict with Q, w_s, T_p, T_t, T_t_delivered (= -T_t), T_s, P_abs, stability."""
    return [_state(w_p, w_t, 0.0, Q, g, "locked", _FQ_locked, form) for Q in _scan_roots(_FQ_locked, w_p, w_t, g, form)]


def steady_free(w_p, w_t, g, form="reverse"):
    """All steady states with a free-wheeling stator (T_s = 0 => F_s = 0), Q != 0.
    "stable" here means dF_Q/dQ < 0 along F_s = 0 (stator speed following Q quasi-statically)."""
    out = []
    for Q in _scan_roots(_FQ_free, w_p, w_t, g, form):
        w_s = stator_speed_free(w_p, w_t, np.array([Q]), g, form)[0]
        out.append(_state(w_p, w_t, w_s, Q, g, "free", _FQ_free, form))
    return out


# ----------------------------------------------------------------------------------------------
# 5. One-way clutch rule
# ----------------------------------------------------------------------------------------------
def steady_state(w_p, w_t, g, form="reverse"):
    """Steady state with the one-way clutch.

    Rule: locked if a locked steady state with T_s >= 0 exists; else free-wheeling with
    w_s >= 0; else held (Q = 0, zero torques).  Among several admissible states of the chosen
    mode the first one that is stable for the flow row (dF_Q/dQ < 0) is returned, else the first.
    Second return value: all admissible candidates (of every mode), for inspection.
    """
    locked = [s for s in steady_locked(w_p, w_t, g, form) if s["T_s"] >= 0.0]
    free = [s for s in steady_free(w_p, w_t, g, form) if s["w_s"] >= 0.0]
    candidates = locked + free
    for group in (locked, free):
        if group:
            stable = [s for s in group if s["stable"]]
            return (stable[0] if stable else group[0]), candidates
    hl, hf = held_check_locked(w_p, w_t, g, form), held_check_free(w_p, w_t, g, form)
    # w_s is undetermined at Q = 0 (any w_s gives F_s = 0); reported as NaN
    held = {
        "mode": "held",
        "Q": 0.0,
        "w_s": float("nan"),
        "T_p": 0.0,
        "T_t": 0.0,
        "T_t_delivered": 0.0,
        "T_s": 0.0,
        "P_abs": 0.0,
        "held_if_locked": bool(hl["held"]),
        "held_if_free": bool(hf["held"]),
    }
    return held, candidates
