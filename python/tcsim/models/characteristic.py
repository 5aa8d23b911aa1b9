"""The characteristic table (TR and capacity against SR), validated, in any capacity convention."""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any, TypedDict

import numpy as np

from .. import _core
from ..errors import InputError, TcsimWarning, core_value, from_core
from ..units import DEFAULT_PUMP_SPEED_RPM, RAD_S_PER_RPM
from .plausibility import RANGES, warn_implausible


class CoreRules(TypedDict, total=False):
    """The ``[characteristic]`` rules the core's table functions take (absent: the core's default)."""

    overrun: str
    interpolation: str


CAPACITY_KEYS = tuple(_core.capacity_conventions())

#: Stall torque at 2000 rpm outside this range (N·m) suggests a capacity read in the wrong
#: convention (docs/physics.md §1).
PLAUSIBLE_STALL_TORQUE_NM = (20.0, 2000.0)


# --------------------------------------------------------------------------------------------
# the characteristic table


@dataclass(frozen=True)
class Characteristic:
    """TR and CF (N·m/(rad/s)²) against SR, validated; ``convention`` is the capacity key read.

    ``overrun`` and ``interpolation`` are the file's ``[characteristic]`` keys, None where not
    given; the core owns their values and defaults (``"mirror"`` or ``"table"``, the latter the
    default for a table with rows above SR 1; ``"capacity_factor"`` or ``"k_factor"``;
    docs/models.md).

    Torque-dependent capacity (docs/torque_capacity.md): ``input_torque_nm`` is the input (pump)
    torque a table was measured at, N·m (None: not given). A converter with several tables is the
    first (lowest-torque) table with ``by_torque``, all its tables by increasing input torque; its
    own arrays (``speed_ratio``, ...) are then those of the first table, and the core functions take
    :meth:`core_table`, which holds them all.
    """

    speed_ratio: np.ndarray
    torque_ratio: np.ndarray
    capacity_factor_nm_s2: np.ndarray
    convention: str = "capacity_factor_nm_s2"
    source: str = ""
    overrun: str | None = None
    interpolation: str | None = None
    input_torque_nm: float | None = None
    by_torque: tuple[Characteristic, ...] = ()

    @classmethod
    def torque_dependent(cls, tables: Sequence[Characteristic], source: str, prefixes: Sequence[str]) -> Characteristic:
        """The converter's characteristic from several ``tables``, each with its ``input_torque_nm``
        (in any order; sorted here), checked by the core as a whole. ``prefixes[i]`` names table i in
        messages (``"[characteristic][2]."``). Two tables at the same input torque are an error about
        the later one's ``input_torque_nm``."""
        order = sorted(range(len(tables)), key=lambda i: (float(tables[i].input_torque_nm or 0.0), i))
        for a, b in zip(order, order[1:], strict=False):
            if tables[a].input_torque_nm == tables[b].input_torque_nm:
                later, first = max(a, b), min(a, b)
                raise InputError(
                    source,
                    f"{prefixes[later]}input_torque_nm",
                    tables[later].input_torque_nm,
                    f"an input torque of its own ({prefixes[first].rstrip('. ,')} has it too; one table per torque)",
                )
        ordered = tuple(tables[i] for i in order)
        top = replace(ordered[0], by_torque=ordered)
        try:
            _core.table_check(**top.core_table())
        except _core.CoreInputError as e:
            m = re.fullmatch(r"characteristic\[(\d+)\]\.(.+)", e.args[1])
            if m is None:
                raise from_core(e, source) from None
            raise InputError(source, f"{prefixes[order[int(m[1])]]}{m[2]}", core_value(e.args[2]), e.args[3]) from None
        return top

    def __post_init__(self) -> None:
        """A table made directly (``Characteristic(sr, tr, cf)``, not read from a file) is checked as
        a file's is: 1-D arrays of numbers, a known ``convention``, TR and CF positive in drive, and
        the core's rules (finite, as many values in each column, at least 2 points, SR strictly
        increasing, passive); an :class:`InputError` about ``source`` (else ``Characteristic``)."""
        where = self.source or "Characteristic"
        arrays = []
        for key in ("speed_ratio", "torque_ratio", "capacity_factor_nm_s2"):
            value = getattr(self, key)
            try:
                a = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                raise InputError(where, key, value, "an array of numbers") from None
            if a.ndim != 1:
                raise InputError(where, key, f"{a.ndim}-D array", "a 1-D array of numbers")
            object.__setattr__(self, key, a)
            arrays.append(a)
        if self.convention not in CAPACITY_KEYS:
            raise InputError(where, "convention", self.convention, f"one of {', '.join(CAPACITY_KEYS)}")
        if self.by_torque:
            return  # checked as a whole by torque_dependent
        sr, tr, cf = arrays
        try:
            _core.table_check(**self.core_table())
        except _core.CoreInputError as e:
            raise from_core(e, where) from None
        _positive_in_drive(sr, (("torque_ratio", tr), ("capacity_factor_nm_s2", cf)), lambda c, i: f"{c}[{i}]", where)

    def tables(self) -> tuple[Characteristic, ...]:
        """The converter's tables by increasing input torque (this one alone for a single table)."""
        return self.by_torque or (self,)

    def core_table(self) -> dict[str, Any]:
        """Keyword arguments of the core's table functions (``tcsim._core.table_steady_states``, ...)
        and the table keys of the model specification: ``speed_ratio``, ``torque_ratio``,
        ``capacity_factor_nm_s2``, the :meth:`core_rules`, and for several tables their columns one
        after the other with ``input_torque_nm`` and ``table_rows`` (rows per table)."""
        tables = self.tables()
        out: dict[str, Any] = {
            k: np.ascontiguousarray(np.concatenate([getattr(t, k) for t in tables]), dtype=float)
            for k in ("speed_ratio", "torque_ratio", "capacity_factor_nm_s2")
        }
        out.update(self.core_rules())
        if self.by_torque:
            out["input_torque_nm"] = [float(t.input_torque_nm or 0.0) for t in tables]
            out["table_rows"] = [float(len(t.speed_ratio)) for t in tables]
        return out

    @classmethod
    def from_columns(
        cls,
        speed_ratio,
        torque_ratio,
        capacity,
        convention: str,
        source: str,
        where: str = "",
        rows: list[int] | None = None,
        overrun: str | None = None,
        interpolation: str | None = None,
        input_torque_nm: float | None = None,
    ) -> Characteristic:
        """Validate and convert a table read in capacity ``convention`` (measured at input torque
        ``input_torque_nm``, N·m, where the converter's capacity depends on it).

        ``where`` prefixes field names (``"[characteristic]."`` for TOML); ``rows`` maps each
        point to its line number in a text file, so that messages name the line. ``overrun`` and
        ``interpolation`` are checked by the core, with the table's passivity (every row and
        every segment between rows: SR·TR at most 1 where CF > 0, at least 1 where CF < 0).
        """
        if convention not in CAPACITY_KEYS:
            raise InputError(source, f"{where}capacity", convention, f"one of {', '.join(CAPACITY_KEYS)}")
        sr = np.asarray(speed_ratio, dtype=float)
        tr = np.asarray(torque_ratio, dtype=float)
        cap = np.asarray(capacity, dtype=float)

        def name(col: str, i: int) -> str:
            return f"line {rows[i]}, {col}" if rows is not None else f"{where}{col}[{i}]"

        for col, v in (("speed_ratio", sr), ("torque_ratio", tr), (convention, cap)):
            bad = np.flatnonzero(~np.isfinite(v))
            if bad.size:
                raise InputError(source, name(col, int(bad[0])), float(v[bad[0]]), "a finite number")
        if not (len(sr) == len(tr) == len(cap)):
            raise InputError(
                source,
                f"{where}torque_ratio",
                f"{len(tr)} values",
                f"as many values as speed_ratio ({len(sr)}) and {convention} ({len(cap)})",
            )
        if len(sr) < 2:
            raise InputError(source, f"{where}speed_ratio", f"{len(sr)} points", "at least 2 points")
        dec = np.flatnonzero(np.diff(sr) <= 0)
        if dec.size:
            i = int(dec[0]) + 1
            raise InputError(
                source,
                name("speed_ratio", i),
                float(sr[i]),
                f"strictly increasing speed ratio (previous value {sr[i - 1]:g})",
            )
        drive = sr < 1.0
        _positive_in_drive(sr, (("torque_ratio", tr), (convention, cap)), name, source)
        cf = np.asarray(_core.capacity_to_cf(convention, np.ascontiguousarray(cap)))
        bad = np.flatnonzero(~np.isfinite(cf) | (drive & (cf <= 0)))
        if bad.size:  # the file's value overflows (or underflows) on conversion: name it as written
            i = int(bad[0])
            raise InputError(
                source,
                name(convention, i),
                float(cap[i]),
                f"a {convention} whose capacity factor is a finite positive number (it converts to {cf[i]:g} N·m·s²)",
            )
        _check_torques_finite(cf, cap, lambda i: name(convention, i), source, convention)
        warn_implausible("torque_ratio", tr, source, lambda i: name("torque_ratio", i))
        try:  # the core's rules, checked once by __post_init__: the error named as the file writes it
            return cls(sr, tr, cf, convention, source, overrun, interpolation, input_torque_nm)
        except InputError as e:
            row = re.fullmatch(r"torque_ratio\[(\d+)\]", e.field)
            if row is not None and rows is not None:
                raise e.replace(field=name("torque_ratio", int(row[1])), value=float(tr[int(row[1])])) from None
            raise e.replace(field=f"{where}{e.field}") from None

    def core_rules(self) -> CoreRules:
        """The ``overrun`` and ``interpolation`` keys the file gave, for the core's table functions
        and model specification (absent keys: the core's defaults)."""
        rules = CoreRules()
        if self.overrun is not None:
            rules["overrun"] = self.overrun
        if self.interpolation is not None:
            rules["interpolation"] = self.interpolation
        return rules

    def warn_if_extended(self, pump_speed_rad_s, turbine_speed_rad_s, what: str = "the run") -> None:
        """:func:`warn_if_extended` for this table."""
        warn_if_extended(self.source, self.core_table(), pump_speed_rad_s, turbine_speed_rad_s, what)

    def stall_torque_nm(self, pump_speed_rpm: float = DEFAULT_PUMP_SPEED_RPM) -> float:
        """Pump torque at SR = 0 (or the table's first SR ≥ 0) and the given pump speed."""
        i = int(np.searchsorted(self.speed_ratio, 0.0))
        i = min(i, len(self.speed_ratio) - 1)
        return float(self.capacity_factor_nm_s2[i]) * (pump_speed_rpm * RAD_S_PER_RPM) ** 2

    def warn_if_implausible(self) -> None:
        t = self.stall_torque_nm()
        lo, hi = PLAUSIBLE_STALL_TORQUE_NM
        if not lo <= t <= hi:
            warnings.warn(
                f"{self.source}: stall torque at {DEFAULT_PUMP_SPEED_RPM:g} rpm is {t:.4g} N·m with the capacity "
                f"read as {self.convention}; a passenger-car converter gives {lo:g}–{hi:g} N·m. "
                "Check the capacity convention.",
                TcsimWarning,
                stacklevel=3,
            )

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.speed_ratio, self.torque_ratio, self.capacity_factor_nm_s2


def _positive_in_drive(
    sr: np.ndarray, columns: Sequence[tuple[str, np.ndarray]], name: Callable[[str, int], str], source: str
) -> None:
    """TR and the capacity are positive in drive (SR below 1), else an :class:`InputError` naming
    the first row that is not (``name(column, i)``)."""
    drive = sr < 1.0
    for col, v in columns:
        bad = np.flatnonzero(drive & (v <= 0))
        if bad.size:
            i = int(bad[0])
            raise InputError(source, name(col, i), float(v[i]), "a positive value in drive (speed ratio below 1)")


def _check_torques_finite(
    cf: np.ndarray, cap: np.ndarray, name: Callable[[int], str], source: str, convention: str
) -> None:
    """A capacity whose torque CF·ω² overflows at a plausible pump speed is an :class:`InputError`
    naming its row as written (1e308 N·m·s² was run, and its overflow blamed on ``--pump-speed-rpm``)."""
    w = RANGES["speed_rad_s"].high
    with np.errstate(over="ignore"):
        bad = np.flatnonzero(~np.isfinite(np.abs(cf) * (w * w)))
    if bad.size:
        i = int(bad[0])
        raise InputError(
            source,
            name(i),
            float(cap[i]),
            f"a {convention} whose torques are finite at pump speeds up to {w:g} rad/s (CF·ω² overflows)",
        )


def extension_reached(table: dict[str, Any], pump_speed_rad_s, turbine_speed_rad_s) -> float | None:
    """The largest |SR| at which the core's overrun rule extended the table ``table``
    (:meth:`Characteristic.core_table`) beyond its rows at the points (rad/s; the core says where, by
    the ``extension`` flag of ``tcsim._core.table_steady_states``), or None where it extended it at
    none of them."""
    wp = np.asarray(pump_speed_rad_s, dtype=float).reshape(-1)
    wt = np.asarray(turbine_speed_rad_s, dtype=float).reshape(-1)
    ok = np.isfinite(wp) & np.isfinite(wt)
    if not ok.any():
        return None
    wp, wt = np.ascontiguousarray(wp[ok]), np.ascontiguousarray(wt[ok])
    try:
        ext = np.asarray(_core.table_steady_states(**table, pump_speed_rad_s=wp, turbine_speed_rad_s=wt)["extension"])
    except _core.CoreInputError:  # speeds whose torques overflow: the run itself says so
        return None
    if not ext.any():
        return None
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.max(np.abs(wt[ext] / wp[ext])))


def extension_message(source: str, table: dict[str, Any], what: str, reached: str) -> str:
    """The warning that ``what`` (one run, or several) reached SR ``reached`` (as written) beyond the
    rows of the table ``table`` of ``source``, where the overrun rule mirrors the characteristic."""
    end = float(np.asarray(table["speed_ratio"], dtype=float)[-1])
    return (
        f'{source}: overrun = "mirror": the table ends at SR {end:g}; {what} reached SR {reached}, '
        "where tcsim mirrors the characteristic (the turbine drives the pump; see docs/models.md)"
    )


def warn_if_extended(
    source: str,
    table: dict[str, Any],
    pump_speed_rad_s,
    turbine_speed_rad_s,
    what: str = "the run",
) -> None:
    """One :class:`~tcsim.errors.TcsimWarning` when the core's overrun rule extended the table
    ``table`` beyond its rows at any of the points (:func:`extension_reached`): the results there
    rest on the extension rule, not on data (docs/models.md)."""
    reached = extension_reached(table, pump_speed_rad_s, turbine_speed_rad_s)
    if reached is not None:
        warnings.warn(extension_message(source, table, what, f"{reached:.3g}"), TcsimWarning, stacklevel=3)
