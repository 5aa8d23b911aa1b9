"""The Hrovat & Tobler steady state as a vectorised NumPy closed form: the peer of the core's batch.

Written from the equations (Li & Sundén 2016, eqs 2.12–2.15 with zero left-hand sides and the
losses of eqs 2.19–2.25; the reverse-flow form and the rules of ``docs/models.md``, "Reverse flow",
"At Q = 0" and "Steady state in every quadrant"), not from the core's code. It is written the way a
NumPy user would write it: the angular momentum leaving each element, ``h_x = ω_x R² + R tan α q``,
the Euler head ``Σ ω_x (h_x − h_src(x))`` and the losses expanded into the coefficients of a
quadratic in the flow, solved with a cancellation-free root formula; each branch is evaluated on
the points that need it only (boolean indexing), the clutch rule with ``np.where``.

Two entry points:

* :func:`steady_state`: every quadrant the core covers, with the same columns and ``stator_mode``
  codes as ``tcsim._core.ht_steady_states(..., strict=False)``: forward flow with the stator locked
  (0) or free-wheeling (1), reverse flow likewise, no flow (2, zero torques; ω_s = ω_t where the
  clutch released, 0 where the flow is held at rest), and −1 (NaN values) where the speeds are not
  finite or the steady state overflows. Every branch of the core is covered.
* :func:`locked_drive`: the locked-stator forward quadratic alone (the "20-line closed form" of
  issue 16), valid only below the coupling point in drive; no clutch, no other quadrant.

Geometry: the core's fifteen parameters (``tcsim._core.ht_parameter_names()``, SI, angles in
radians), one row for every point or one row per point.
"""

from __future__ import annotations

import numpy as np

LOCKED, FREE_WHEELING, NO_FLOW, NO_STEADY_STATE = 0, 1, 2, -1
COLUMNS = ("flow_m3_s", "stator_speed_rad_s", "pump_torque_nm", "turbine_torque_nm", "stator_torque_nm")


def _params(geometry: np.ndarray) -> dict[str, np.ndarray]:
    """Named parameters and tangents; scalars for one row, columns for one row per point."""
    g = np.atleast_2d(np.asarray(geometry, dtype=float))
    col = (lambda k: g[0, k]) if g.shape[0] == 1 else (lambda k: g[:, k])
    names = ("A", "rho", "rp", "rt", "rs", "ap", "at", "as", "app", "att", "ass", "Cp", "Ct", "Cs", "f")
    p = {name: col(k) for k, name in enumerate(names)}
    for k in ("p", "t", "s", "pp", "tt", "ss"):
        p["t" + k] = np.tan(p["a" + k])
    return p


def _sub(p: dict, idx: np.ndarray) -> dict:
    """The parameters of the points ``idx`` (unchanged when they are one row)."""
    return {k: v[idx] if np.ndim(v) else v for k, v in p.items()}


def _largest_root(c0, c1, c2):
    """Largest real root of ``c0 + c1 x + c2 x²`` without cancellation, and whether there is a real
    root (False where the discriminant is negative or the polynomial constant)."""
    with np.errstate(all="ignore"):
        disc = c1 * c1 - 4.0 * c2 * c0
        s = np.sqrt(disc)
        w = np.where(c1 >= 0.0, -0.5 * (c1 + s), 0.5 * (s - c1))
        r1, r2 = w / c2, c0 / w
        root = np.where(w == 0.0, 0.0, np.where(r1 >= r2, r1, r2))
        root = np.where(c2 == 0.0, -c0 / c1, root)
        exists = np.where(c2 == 0.0, c1 != 0.0, ~(disc < 0.0))
        return root, exists


def _poly_square(u, v, c):
    """``c (u + v x)²`` as its three coefficients."""
    return c * u * u, 2.0 * c * u * v, c * v * v


def _forward_coefficients(p, wp, wt, a, b):
    """F_Q/ρ for Q > 0 as a quadratic in q = Q/A with ω_s = a + b q: Euler head minus losses."""
    rp2, rt2, rs2 = p["rp"] ** 2, p["rt"] ** 2, p["rs"] ** 2
    # h_x = h0 + h1 q, leaving across the exit edges
    hp0, hp1 = wp * rp2, p["rp"] * p["tp"]
    ht0, ht1 = wt * rt2, p["rt"] * p["tt"]
    hs0, hs1 = a * rs2, b * rs2 + p["rs"] * p["ts"]
    # head = ω_p (h_p − h_s) + ω_t (h_t − h_p) + ω_s (h_s − h_t), ω_s = a + b q
    dp0, dp1, ds0, ds1 = hp0 - hs0, hp1 - hs1, hs0 - ht0, hs1 - ht1
    c0 = wp * dp0 + wt * (ht0 - hp0) + a * ds0
    c1 = wp * dp1 + wt * (ht1 - hp1) + a * ds1 + b * ds0
    c2 = b * ds1
    # shock velocities (eqs 2.20–2.22) and friction (eqs 2.23–2.25), each halved
    shocks = (
        (p["rs"] * (a - wp), p["rs"] * b + p["ts"] - p["tpp"], p["Cp"]),
        (p["rp"] * (wp - wt), p["tp"] - p["ttt"], p["Ct"]),
        (p["rt"] * (wt - a), p["tt"] - p["tss"] - p["rt"] * b, p["Cs"]),
    )
    for u, v, c in shocks:
        s0, s1, s2 = _poly_square(u, v, 0.5 * c)
        c0, c1, c2 = c0 - s0, c1 - s1, c2 - s2
    c2 = c2 - 0.5 * p["f"] * (3.0 + p["tp"] ** 2 + p["tt"] ** 2 + p["ts"] ** 2)
    return c0, c1, c2


def _reverse_coefficients(p, wp, wt, a, b):
    """F_Q/ρ for Q < 0 as a quadratic in x = −Q/A with ω_s = a + b x: Euler head plus losses."""
    rp2, rt2, rs2 = p["rp"] ** 2, p["rt"] ** 2, p["rs"] ** 2
    # h_x = h0 + h1 x, leaving across the inlet edges (radius of the element before), q = −x
    hp0, hp1 = wp * rs2, -p["rs"] * p["tpp"]
    ht0, ht1 = wt * rp2, -p["rp"] * p["ttt"]
    hs0, hs1 = a * rt2, b * rt2 - p["rt"] * p["tss"]
    # head = ω_p (h_t − h_p) + ω_t (h_s − h_t) + ω_s (h_p − h_s)
    ds0, ds1 = hp0 - hs0, hp1 - hs1
    c0 = wp * (ht0 - hp0) + wt * (hs0 - ht0) + a * ds0
    c1 = wp * (ht1 - hp1) + wt * (hs1 - ht1) + a * ds1 + b * ds0
    c2 = b * ds1
    shocks = (
        (p["rp"] * (wt - wp), p["tp"] - p["ttt"], p["Cp"]),
        (p["rt"] * (a - wt), p["rt"] * b + p["tt"] - p["tss"], p["Ct"]),
        (p["rs"] * (wp - a), p["ts"] - p["tpp"] - p["rs"] * b, p["Cs"]),
    )
    for u, v, c in shocks:
        s0, s1, s2 = _poly_square(u, v, 0.5 * c)
        c0, c1, c2 = c0 + s0, c1 + s1, c2 + s2
    c2 = c2 + 0.5 * p["f"] * (3.0 + p["tpp"] ** 2 + p["ttt"] ** 2 + p["tss"] ** 2)
    return c0, c1, c2


def _free_stator(p, wp, wt, sign):
    """ω_s = a + b x of the free-wheeling stator (T_s = 0): x = q forwards, x = −q backwards."""
    if sign > 0:
        rs2 = p["rs"] ** 2
        return wt * p["rt"] ** 2 / rs2, (p["rt"] * p["tt"] - p["rs"] * p["ts"]) / rs2
    rt2 = p["rt"] ** 2
    return wp * p["rs"] ** 2 / rt2, (p["rt"] * p["tss"] - p["rs"] * p["tpp"]) / rt2


def _solve(p, wp, wt, sign, free):
    """Flow, stator speed and the three torques (pump, delivered turbine, stator) in one direction
    and clutch state, and whether that has a root of the flow's sign."""
    zero = np.zeros_like(wp)
    a, b = _free_stator(p, wp, wt, sign) if free else (zero, 0.0)
    coefficients = _forward_coefficients if sign > 0 else _reverse_coefficients
    x, exists = _largest_root(*coefficients(p, wp, wt, a, b))
    with np.errstate(all="ignore"):
        has = exists & ~(x <= 0.0)  # a NaN root (overflow) counts as found, to be refused
        ws, q = a + b * x, sign * x
        flow, rho = q * p["A"], p["rho"]
        if sign > 0:  # external torques ρQ(h_x − h_src(x)); the turbine's delivered torque is −T_t
            hp = wp * p["rp"] ** 2 + p["rp"] * p["tp"] * q
            ht = wt * p["rt"] ** 2 + p["rt"] * p["tt"] * q
            hs = ws * p["rs"] ** 2 + p["rs"] * p["ts"] * q
            pump, turbine, stator = rho * (hp - hs) * flow, -rho * (ht - hp) * flow, rho * (hs - ht) * flow
        else:  # external torques −ρQ(h_x − h_src(x)) with the inlet-edge h_x; src: p ← t ← s ← p
            hp = wp * p["rs"] ** 2 + p["rs"] * p["tpp"] * q
            ht = wt * p["rp"] ** 2 + p["rp"] * p["ttt"] * q
            hs = ws * p["rt"] ** 2 + p["rt"] * p["tss"] * q
            pump, turbine, stator = -rho * (hp - ht) * flow, rho * (ht - hs) * flow, -rho * (hs - hp) * flow
    return (flow, ws, pump, turbine, zero if free else stator), has


def _empty(n: int) -> dict[str, np.ndarray]:
    out = {c: np.full(n, np.nan) for c in COLUMNS}
    out["stator_mode"] = np.full(n, NO_STEADY_STATE, dtype=np.int8)
    return out


def _put(out: dict, idx: np.ndarray, values, mode) -> None:
    for c, v in zip(COLUMNS, values):
        out[c][idx] = v
    out["stator_mode"][idx] = mode


def _finite(values) -> np.ndarray:
    ok = np.isfinite(values[0])
    for v in values[1:]:
        ok &= np.isfinite(v)
    return ok


def _in_direction(p, wp, wt, sign, first: bool) -> dict[str, np.ndarray]:
    """The clutch rule in one flow direction: locked while T_s ≥ 0, else free-wheeling with
    ω_s ≥ 0, else no flow with ω_s = ω_t; mode −1 where a state overflows. In the direction the flow
    starts in (``first``) a missing locked root is an overflow; in the other direction the
    free-wheeling root alone is tried then."""
    out = _empty(wp.size)
    locked, has = _solve(p, wp, wt, sign, free=False)
    finite = has & _finite(locked)
    holds = finite & (locked[4] >= 0.0)
    _put(out, holds, [v[holds] for v in locked], LOCKED)
    released = np.flatnonzero(finite & ~holds)
    alone = np.flatnonzero(~has) if not first else released[:0]
    for idx, clutch in ((released, True), (alone, False)):
        free, found = _solve(_sub(p, idx), wp[idx], wt[idx], sign, free=True)
        ok = found & _finite(free)
        turning = ok & (free[1] >= 0.0)
        _put(out, idx[turning], [v[turning] for v in free], FREE_WHEELING)
        # the clutch on a locked state: an overflowing free-wheeling state is an error (mode −1)
        rest = idx[~turning & ~(found & ~ok)] if clutch else idx[~turning]
        _put(out, rest, (0.0, wt[rest], 0.0, 0.0, 0.0), NO_FLOW)
    return out


def steady_state(geometry: np.ndarray, pump_speed_rad_s, turbine_speed_rad_s) -> dict[str, np.ndarray]:
    """Steady states in every quadrant, with the core's columns and mode codes (module docstring).

    Parameters
    ----------
    geometry : array, shape (15,) or (n, 15)
        The core's parameter row(s): SI units, angles in radians.
    pump_speed_rad_s, turbine_speed_rad_s : array, shape (n,)
        Speeds, rad/s.

    Returns
    -------
    dict
        ``flow_m3_s`` (m³/s), ``stator_speed_rad_s`` (rad/s), ``pump_torque_nm``,
        ``turbine_torque_nm`` (delivered), ``stator_torque_nm`` (N·m), ``stator_mode`` (int8).
    """
    wp = np.asarray(pump_speed_rad_s, dtype=float).reshape(-1)
    wt = np.asarray(turbine_speed_rad_s, dtype=float).reshape(-1)
    p = _params(geometry)
    out = _empty(wp.size)
    zero = np.zeros_like(wp)
    with np.errstate(all="ignore"):
        forward = _forward_coefficients(p, wp, wt, zero, 0.0)[0] * p["rho"]
        reverse = _reverse_coefficients(p, wp, wt, zero, 0.0)[0] * p["rho"]
    ok = np.isfinite(wp) & np.isfinite(wt) & np.isfinite(forward) & np.isfinite(reverse)
    # the direction the flow starts in from rest with the stator at rest: F_Q(0+) > 0 forwards,
    # F_Q(0−) < 0 backwards, the larger if both (forwards on a tie), held if neither
    fw, bw = ok & (forward > 0.0), ok & (reverse < 0.0)
    direction = np.where(fw & bw, np.where(forward >= -reverse, 1, -1), np.where(fw, 1, np.where(bw, -1, 0)))
    held = ok & (direction == 0)
    _put(out, held, (0.0, 0.0, 0.0, 0.0, 0.0), NO_FLOW)
    for sign in (1, -1):
        idx = np.flatnonzero(ok & (direction == sign))
        first = _in_direction(_sub(p, idx), wp[idx], wt[idx], sign, first=True)
        # where that ends in no flow, the other direction's steady state if it is not no flow too
        stopped = np.flatnonzero(first["stator_mode"] == NO_FLOW)
        at = idx[stopped]
        other = _in_direction(_sub(p, at), wp[at], wt[at], -sign, first=False)
        take = other["stator_mode"] != NO_FLOW
        for c in (*COLUMNS, "stator_mode"):
            first[c][stopped[take]] = other[c][take]
            out[c][idx] = first[c]
    return out


def locked_drive(geometry: np.ndarray, pump_speed_rad_s, turbine_speed_rad_s) -> dict[str, np.ndarray]:
    """The locked-stator forward steady state alone (drive below the coupling point): the quadratic
    of eq 2.15 with ω_s = 0 and its largest root, torques of eqs 2.12–2.14. No clutch, no other
    quadrant; same parameters and units as :func:`steady_state`."""
    wp = np.asarray(pump_speed_rad_s, dtype=float).reshape(-1)
    wt = np.asarray(turbine_speed_rad_s, dtype=float).reshape(-1)
    values, _ = _solve(_params(geometry), wp, wt, 1, free=False)
    return dict(zip(COLUMNS, values))
