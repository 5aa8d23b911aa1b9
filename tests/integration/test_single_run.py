"""``simulate`` runs one model under one drive without a batch's bookkeeping (issue 16, the Python
path of a single run: ``transient._single_run``). It must be ``simulate_batch([model], [drive])[0]``
in everything a caller sees: the numbers bit for bit, the column names and their order, the events,
the warnings (their text, count and the place they come from) and each error (its type, text,
blamed input and field), for every model, with and without chosen columns and sample times.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tcsim import transient as tr
from tcsim.errors import InputError
from tcsim.models.dynamic import NearCouplingWarning
from tcsim.simulation.transient import output_times

MODELS = ("table", "hrovat-tobler", "quasi-dynamic", "fragile quasi-dynamic")


def _model(name: str) -> tr.DynamicModel:
    """A bundled model; "fragile quasi-dynamic" has shape effects for which it warns that it may ring
    near coupling (a ``NearCouplingWarning`` at every run)."""
    if name == "fragile quasi-dynamic":
        return tr.dynamic_model("li-sunden-2016", "quasi-dynamic").with_shape_effects(0.015, 0.2)
    return tr.dynamic_model("li-sunden-2016", name)


def _lockup_takeoff() -> tr.PumpTorqueLoad:
    d = tr.isolated_takeoff(tip_out=True)
    capacity = np.where(np.asarray(d.time_s) >= 5.0, 600.0, 0.0)
    return tr.PumpTorqueLoad(
        d.time_s, d.pump_torque_nm, d.load_inertia_kg_m2, d.load_torque_nm, d.load_drag_nm_s2, capacity
    )


def _overrun() -> tr.Speeds:
    """SR 3, beyond the table's SR 1: the table models warn."""
    return tr.Speeds(np.array([0.0, 1.0, 2.0]), np.array([100.0, 120.0, 100.0]), 300.0)


def _both(model, drive, **kw):
    """``simulate`` and ``simulate_batch``'s one run, each with the warnings it gave as
    ``(category, text, filename, lineno)``."""
    out = []
    for call in (tr.simulate, lambda m, d, **k: tr.simulate_batch([m], [d], **k)[0]):
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            result = call(model, drive, **kw)
        out.append((result, [(x.category, str(x.message), x.filename, x.lineno) for x in w]))
    return out


def _assert_same(a: tr.TransientResult, b: tr.TransientResult) -> None:
    assert (a.model, a.chosen_columns, list(a.columns)) == (b.model, b.chosen_columns, list(b.columns))
    for name in a.columns:
        x, y = np.asarray(a[name]), np.asarray(b[name])
        assert x.shape == y.shape and x.dtype == y.dtype, name
        assert np.array_equal(x.view(np.uint64), y.view(np.uint64)), name
    assert a.events == b.events and [type(e) for e in a.events] == [type(e) for e in b.events]
    assert a.frame().equals(b.frame())


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize(
    "kw",
    [
        {},
        {"times_s": np.linspace(0.0, 10.0, 41)},
        {"times_s": np.linspace(0.5, 9.0, 18), "columns": ["turbine_torque_nm", "time_s", "lockup_state"]},
        {"columns": []},
        {"rtol": 1e-8, "columns": ["flow_m3_s"]},
    ],
)
@pytest.mark.parametrize("drive", [tr.isolated_takeoff, _lockup_takeoff, _overrun])
def test_simulate_is_the_batch_of_one_run(name, kw, drive):
    m = _model(name)
    d = drive()
    if drive is _overrun and "times_s" in kw:
        kw = {**kw, "times_s": np.linspace(0.0, 2.0, 5)}
    (one, w_one), (batch, w_batch) = _both(m, d, **kw)
    _assert_same(one, batch)
    assert w_one == w_batch
    if drive is _overrun and name != "hrovat-tobler":
        assert any("reached SR 3" in text for _c, text, _f, _l in w_one), "the table models warn of SR 3"
    if name == "fragile quasi-dynamic":
        assert any(c is NearCouplingWarning for c, _t, _f, _l in w_one)


def test_every_entry_points_warning_comes_from_one_place():
    """Python's default filter shows a warning once per place: the near-coupling warning of a model
    run by ``simulate``, ``simulate_batch`` and ``simulate_columns`` is shown once (it came from two
    places when ``simulate`` left the batch path)."""
    m, d = _model("fragile quasi-dynamic"), tr.isolated_takeoff()
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("default")
        tr.simulate(m, d)
        tr.simulate_batch([m], [d])
        tr.simulate_columns([m, m], [d], columns=["time_s"])
    assert [x.category for x in w] == [NearCouplingWarning]


def _raised(call) -> tuple[type, str, str | None, str | None]:
    with pytest.raises(Exception) as e:
        call()
    err = e.value
    return type(err), str(err), getattr(err, "core_source", None), getattr(err, "field", None)


T3 = np.array([0.0, 1.0, 2.0])
FAILURES = {
    "overflow": ("table", tr.Speeds(T3, np.array([100.0, 100.0, 1e300]), np.zeros(3)), {}),
    "solver": ("hrovat-tobler", tr.PumpTorqueLoad(T3, np.array([100.0, 100.0, 1e300]), load_inertia_kg_m2=1.0), {}),
    "no initial steady state": ("table", tr.Speeds(T3, 1e200, 0.0), {}),
    "a time outside the span": ("hrovat-tobler", tr.Speeds(T3, 100.0, 50.0), {"times_s": [0.0, 1.0, 2.5]}),
    "a time before the start": ("hrovat-tobler", tr.Speeds(T3, 100.0, 50.0), {"times_s": [-1.0, 1.0]}),
    "times not increasing": ("quasi-dynamic", tr.Speeds(T3, 100.0, 50.0), {"times_s": [0.0, 1.5, 1.0]}),
    "a NaN time": ("table", tr.Speeds(T3, 100.0, 50.0), {"times_s": [0.0, np.nan]}),
    "times closer than the resolution": ("table", tr.Speeds(T3, 100.0, 50.0), {"times_s": [0.0, 1.0, 1.0 + 5e-7]}),
    "the same after a later start": ("hrovat-tobler", tr.Speeds(T3, 100.0, 50.0), {"times_s": [0.5, 0.5 + 1e-10]}),
    "an unknown column": ("table", tr.Speeds(T3, 100.0, 50.0), {"columns": ["time_s", "pump_speed"]}),
    "a repeated column": ("hrovat-tobler", tr.Speeds(T3, 100.0, 50.0), {"columns": ["time_s", "time_s"]}),
    "an unknown solver option": ("hrovat-tobler", tr.Speeds(T3, 100.0, 50.0), {"rtoll": 1e-8}),
    "a bad rtol": ("hrovat-tobler", tr.Speeds(T3, 100.0, 50.0), {"rtol": -1.0}),
    "an unknown initial key": ("hrovat-tobler", tr.Speeds(T3, 100.0, 50.0), {"initial": {"pump": 1.0}}),
    "a NaN drive value": ("table", tr.Speeds(T3, np.array([100.0, np.nan, 100.0]), 50.0), {}),
    "no drive": ("table", "not a drive", {}),
    "one time, at the drive's start": ("hrovat-tobler", tr.Speeds(T3, 100.0, 50.0), {"times_s": [0.0]}),
}


@pytest.mark.parametrize("case", sorted(FAILURES))
def test_simulate_fails_as_the_batch_of_one_run(case):
    name, drive, kw = FAILURES[case]
    m = tr.dynamic_model("li-sunden-2016", name)
    one = _raised(lambda: tr.simulate(m, drive, **kw))
    batch = _raised(lambda: tr.simulate_batch([m], [drive], **kw))
    assert one == batch
    assert issubclass(one[0], (InputError, tr.SolverError)), one
    if "times_s" in kw:
        assert one[1].startswith("argument: times_s"), "the caller's times are blamed, not the drive's time_s"


@pytest.mark.parametrize(
    ("times_s", "field", "expected"),
    [
        ([0.0, 1.5, 1.0], "times_s[2]", "strictly increasing times (times_s[1] = 1.5)"),
        ([0.0, 1.0, 1.0 + 5e-7], "times_s[2]", "time stamps at least 1e-6 s apart"),
        ([0.5, 0.5 + 1e-10, 1.0], "times_s[1]", "time stamps at least 1e-6 s apart"),
        ([0.5, 0.2], "times_s[1]", "strictly increasing times (times_s[0] = 0.5)"),
    ],
)
def test_a_batchs_shared_times_are_one_error_about_the_argument(times_s, field, expected):
    """Before: each run of ``simulate_columns`` failed with the core's error about its drive's
    ``time_s[i]`` (the index counting the drive's start put before a later first time)."""
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    drives = [tr.Speeds(T3, 100.0, 50.0), tr.Speeds(T3, 150.0, 50.0)]
    for call in (tr.simulate_columns, tr.simulate_batch):
        with pytest.raises(InputError) as e:
            call([m], drives, times_s=times_s)
        assert (e.value.source, e.value.field) == ("argument", field) and e.value.expected.startswith(expected)


def test_files_name_the_input_the_core_blamed_in_both():
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    drive = tr.Speeds(T3, 1e200, 0.0)
    files = {"drive": "log.csv"}
    one = _raised(lambda: tr.simulate(m, drive, files=files))
    assert one == _raised(lambda: tr.simulate_batch([m], [drive], files=files))
    assert one[1].startswith("log.csv: initial pump_speed_rad_s = 1e+200")


@pytest.mark.parametrize(
    ("times_s", "field"),
    [
        ([0.0, 1.5, 1.0], "times_s[2]"),
        ([0.5, 0.5 + 1e-9], "times_s[1]"),
        ([0.0], "times_s"),
        ([0.0, 3.0], "times_s[1]"),
    ],
)
def test_output_times_checks_what_a_run_would_refuse(times_s, field):
    """``output_times`` (public) refuses what a run refuses about ``times_s``, as its docstring says:
    before, times that do not increase or are too close were returned as they were."""
    with pytest.raises(InputError) as e:
        output_times([0.0, 1.0, 2.0], times_s)
    assert (e.value.source, e.value.field) == ("argument", field)
    assert output_times([0.0, 1.0, 2.0], [0.5, 1.0]) == ([0.0, 0.5, 1.0], 1)


@pytest.mark.parametrize("stamps", [["a", "b"], [], [[0.0, 1.0]], 5.0, [0.0, "x"], [3.0]])
@pytest.mark.parametrize("times_s", [None, [0.0, 0.5]])
def test_a_drive_without_time_stamps_is_an_input_error_about_them(stamps, times_s):
    """Before: with ``times_s``, a ValueError, IndexError or TypeError escaped, and a drive of
    constants with no or one time stamp ran between the output times; the batches failed the same
    way without ``times_s`` (found by a review)."""
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    d = tr.Speeds(stamps, 100.0, 50.0)
    calls = (
        lambda: tr.simulate(m, d, times_s=times_s),
        lambda: tr.simulate_batch([m], [d], times_s=times_s),
        lambda: tr.simulate_columns([m], [d], times_s=times_s).check(),
    )
    for call in calls:
        with pytest.raises(InputError) as e:
            call()
        assert (e.value.core_source, e.value.field) == ("drive", "time_s"), str(e.value)
