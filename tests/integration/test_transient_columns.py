"""Chosen columns and columnar batches (issue 16, items 1 and 4).

The core computes and stores only the chosen columns, in one pass over a run's samples, and writes
every run of a batch straight into its rows of one array per column (``_core.transient_batch``,
:func:`tcsim.transient.simulate_columns`). Nothing here may change a number: each chosen column is
the full run's column bit for bit (every model, a lock-up run, runs with events), each run of a
columnar batch is :func:`simulate`'s run bit for bit whatever the number of threads, ragged sample
times included; a failing run reports its status and error and leaves the others intact; the
overflow rule lives in the core; the memory estimate counts only the chosen columns.
"""

from __future__ import annotations

import copy
import dataclasses
import pickle

import numpy as np
import pytest

from tcsim import _core
from tcsim import transient as tr
from tcsim.errors import InputError, TcsimWarning
from tcsim.simulation.transient import INFINITE_ALLOWED, NAN_NOT_EXPECTED

MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
CHOSEN = ["effective_torque_ratio", "time_s", "turbine_torque_nm", "stator_mode", "lockup_lock_work_j"]
TIMES = np.linspace(0.05, 10.0, 81)


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float).view(np.uint64)


def _lockup_takeoff() -> tr.PumpTorqueLoad:
    """The take-off with the lock-up clutch engaging from 3 s (it locks, with events)."""
    d = tr.isolated_takeoff(tip_out=True)
    capacity = np.where(np.asarray(d.time_s) >= 5.0, 600.0, 0.0)
    return tr.PumpTorqueLoad(
        d.time_s, d.pump_torque_nm, d.load_inertia_kg_m2, d.load_torque_nm, d.load_drag_nm_s2, capacity
    )


def _drives() -> list[tr.PumpTorqueLoad]:
    return [tr.isolated_takeoff(tip_out=True), _lockup_takeoff()]


@pytest.mark.parametrize("name", MODELS)
def test_chosen_columns_are_the_full_runs_bit_for_bit(name):
    m = tr.dynamic_model("li-sunden-2016", name)
    events = 0
    for drive in _drives():
        full = tr.simulate(m, drive, times_s=TIMES)
        some = tr.simulate(m, drive, times_s=TIMES, columns=CHOSEN)
        assert list(some.columns) == CHOSEN, "the chosen columns, in the caller's order"
        for c in CHOSEN:
            assert np.array_equal(_bits(some[c]), _bits(full[c])), (name, c)
        assert some.events == full.events
        events += len(full.events)
    assert events >= 1, "runs with events (the clutch's lock at least)"
    locked = tr.simulate(m, _lockup_takeoff(), times_s=TIMES, columns=["lockup_state"])["lockup_state"]
    assert (locked == 2.0).any(), "the lock-up run locks"


def test_a_columnar_batch_is_each_runs_simulate_bit_for_bit_whatever_the_threads():
    base = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    models = [base.with_shape_effects(s, s / 2) for s in (0.0, 0.002, 0.004, 0.006, 0.008)]
    drives = [_drives()[i % 2] for i in range(len(models))]
    one = tr.simulate_columns(models, drives, times_s=TIMES, threads=1)
    two = tr.simulate_columns(models, drives, times_s=TIMES, threads=2)
    assert (one.status == tr.RUN_OK).all() and not one.errors
    assert one.time_s is not None and np.array_equal(one.time_s, TIMES)
    assert all(v.shape == (5, len(TIMES)) and v.flags.c_contiguous for v in one.columns.values())
    for name in tr.COLUMNS:
        assert np.array_equal(_bits(one.columns[name]), _bits(two.columns[name])), name
    for k in one.events:
        assert np.array_equal(one.events[k], two.events[k]), k
    for i, (m, d) in enumerate(zip(models, drives)):
        alone = tr.simulate(m, d, times_s=TIMES)
        for name in tr.COLUMNS:
            assert np.array_equal(_bits(one.columns[name][i]), _bits(alone[name])), (i, name)
        assert one.run_events(i) == alone.events and alone.events
        assert one.run(i).events == alone.events
    assert np.all(np.diff(one.events["run"]) >= 0)
    assert {tr.EVENT_KINDS[k] for k in one.events["kind"]} >= {"stator-release", "lockup-lock"}


def test_ragged_sample_times_give_flat_columns_with_offsets():
    m = tr.dynamic_model("li-sunden-2016", "quasi-dynamic")
    short = tr.PumpTorqueLoad(np.linspace(0.0, 2.0, 41), 150.0, load_inertia_kg_m2=1.2, load_torque_nm=10.0)
    long = tr.PumpTorqueLoad(np.linspace(0.0, 3.0, 301), 200.0, load_inertia_kg_m2=1.2, load_torque_nm=10.0)
    b = tr.simulate_columns([m], [short, long, short], columns=["time_s", "pump_speed_rad_s"], threads=2)
    assert b.time_s is None and list(b.offsets) == [0, 41, 342, 383]
    assert b.columns["time_s"].shape == (383,)
    for i, d in enumerate([short, long, short]):
        alone = tr.simulate(m, d)
        for name in ("time_s", "pump_speed_rad_s"):
            assert np.array_equal(_bits(b.rows(name, i)), _bits(alone[name])), (i, name)
    runs = tr.simulate_batch([m], [short, long], columns=["pump_speed_rad_s"])
    assert [len(r["pump_speed_rad_s"]) for r in runs] == [41, 301] and list(runs[0].columns) == ["pump_speed_rad_s"]


def test_a_run_index_counts_from_the_end_when_negative_and_is_refused_out_of_range():
    """``-1`` is the last run, in every accessor and in both layouts (a ragged batch's flat columns
    once sliced ``offsets[-1]:offsets[0]``: empty, silently); an index out of range, not an integer,
    or an unknown column is an InputError naming it (once a bare IndexError or KeyError)."""
    m = tr.dynamic_model("li-sunden-2016", "quasi-dynamic")
    short = tr.PumpTorqueLoad(np.linspace(0.0, 2.0, 41), 150.0, load_inertia_kg_m2=1.2, load_torque_nm=10.0)
    long = tr.PumpTorqueLoad(np.linspace(0.0, 3.0, 301), 200.0, load_inertia_kg_m2=1.2, load_torque_nm=10.0)
    ragged = tr.simulate_columns([m], [short, long], columns=["time_s", "pump_speed_rad_s"])
    even = tr.simulate_columns([m], [short, short], columns=["time_s", "pump_speed_rad_s"], times_s=TIMES[:15])
    for b in (ragged, even):
        for k in (-1, -2):
            i = k + len(b)
            assert np.array_equal(_bits(b.rows("pump_speed_rad_s", k)), _bits(b.rows("pump_speed_rad_s", i)))
            assert b.rows("time_s", k).size == b.rows("time_s", i).size > 0
            assert b.run_events(k) == b.run_events(i)
            assert b.frame(k).equals(b.frame(i))
        assert b.rows("time_s", np.int64(-1)).size == b.rows("time_s", 1).size
        for bad in (2, -3, 99, 1.0, True, "0", None):
            for call in (b.rows, b.run, b.run_events):
                with pytest.raises(InputError) as e:
                    call("time_s", bad) if call == b.rows else call(bad)
                assert (e.value.field, e.value.value) == ("i", bad)
                assert e.value.expected == "an integer run index from -2 to 1 (the batch has 2 runs)"
        with pytest.raises(InputError, match=r"^argument: name = 'foo': expected one of the batch's columns: time_s"):
            b.rows("foo", 0)
    table = tr.dynamic_model("li-sunden-2016", "table")
    failed = tr.simulate_columns([table], [short, tr.Speeds([0.0, 1.0], 1e200, 0.0)])
    with pytest.raises(InputError) as e:
        failed.run(-1)  # the last run's own error (once a bare KeyError: -1)
    assert e.value is failed.errors[1]


def test_a_failing_run_reports_its_status_and_leaves_the_others_intact():
    table, ht = (tr.dynamic_model("li-sunden-2016", name) for name in ("table", "hrovat-tobler"))
    t = np.array([0.0, 1.0, 2.0])
    good = tr.PumpTorqueLoad(t, 120.0, load_inertia_kg_m2=1.2, load_torque_nm=10.0)
    overflowing = tr.Speeds(t, np.array([100.0, 100.0, 1e300]), np.zeros(3))  # a drive beyond the model
    solver_fails = tr.PumpTorqueLoad(t, np.array([100.0, 100.0, 1e300]), load_inertia_kg_m2=1.0)
    refused = tr.Speeds(t, 1e200, 0.0)  # no finite initial steady state
    models = [table, table, table, ht, table]
    drives = [good, overflowing, good, solver_fails, refused]
    b = tr.simulate_columns(models, drives, times_s=t, columns=["time_s", "pump_torque_nm"], threads=2)
    ok, overflow, solver, refused_ = tr.RUN_OK, tr.RUN_OVERFLOW, tr.RUN_SOLVER_ERROR, tr.RUN_INPUT_ERROR
    assert list(b.status) == [ok, overflow, ok, solver, refused_] and sorted(b.errors) == [1, 3, 4]
    assert str(b.errors[1]) == (
        "drive: output pump_torque_nm (run 1) = inf: expected a drive whose run stays finite "
        "(it overflows at t = 2 s: check the drive's values and units)"
    )
    assert b.errors[1].core_source == "drive" and b.errors[4].core_source == "drive"
    assert isinstance(b.errors[3], tr.SolverError) and str(b.errors[3]).startswith(
        "hrovat-tobler (run 3): solver failed"
    )
    assert str(b.errors[4]).startswith("drive: initial pump_speed_rad_s (run 4) = 1e+200: expected")
    assert np.isinf(b.columns["pump_torque_nm"][1]).any(), "an overflowing run keeps its values"
    assert np.isnan(b.columns["pump_torque_nm"][3:]).all(), "a run that failed with an error has NaN rows"
    alone = tr.simulate(table, good, times_s=t)
    for i in (0, 2):
        assert np.array_equal(_bits(b.columns["pump_torque_nm"][i]), _bits(alone["pump_torque_nm"]))
        assert list(b.run(i).columns) == ["time_s", "pump_torque_nm"]
    with pytest.raises(InputError) as e:
        b.run(1)
    assert e.value is b.errors[1]
    # simulate_batch raises the first run's error that is not an overflow, then the first overflow
    with pytest.raises(tr.SolverError, match=r"^hrovat-tobler \(run 3\): solver failed"):
        tr.simulate_batch(models, drives, times_s=t)
    with pytest.raises(InputError, match=r"^drive: output pump_torque_nm \(run 1\) = inf"):
        tr.simulate_batch(models[:3], drives[:3], times_s=t)


def test_the_overflow_rule_is_the_cores():
    assert INFINITE_ALLOWED == frozenset({"k_factor_rpm_per_sqrt_nm"})
    assert NAN_NOT_EXPECTED == ("_rad_s", "_nm", "_m3_s", "_w", "_j")
    assert _core.output_value_rules() == (["k_factor_rpm_per_sqrt_nm"], list(NAN_NOT_EXPECTED))
    # the check covers the chosen columns (and the state, finite here: a given speed of 1e300 rad/s);
    # the pump torque overflows, seen only when chosen
    m = tr.dynamic_model("li-sunden-2016", "table")
    t = np.array([0.0, 1.0, 2.0])
    beyond = [tr.Speeds(t, np.array([100.0, 100.0, 1e300]), np.zeros(3))]
    b = tr.simulate_columns([m], beyond, columns=["time_s"])
    assert list(b.status) == [tr.RUN_OK] and b.columns["time_s"].shape == (1, 3)
    b = tr.simulate_columns([m], beyond, columns=["time_s", "stator_mode", "pump_torque_nm"])
    assert list(b.status) == [tr.RUN_OVERFLOW] and list(b.columns) == ["time_s", "stator_mode", "pump_torque_nm"]
    assert str(b.errors[0]).startswith("drive: output pump_torque_nm = inf: expected a drive whose run stays finite")


@pytest.mark.parametrize(
    ("columns", "field", "value", "expected"),
    [
        (
            ["time_s", "pump_speed"],
            "columns[1]",
            "pump_speed",
            "an output column name, one of time_s, pump_speed_rad_s,",
        ),
        (["flow_m3_s", "flow_m3_s"], "columns[1]", "flow_m3_s", "each column named once"),
    ],
)
def test_an_unknown_or_repeated_column_is_one_input_error(columns, field, value, expected):
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    for call in (
        lambda: tr.simulate(m, tr.isolated_takeoff(), columns=columns),
        lambda: tr.simulate_columns([m], [tr.isolated_takeoff()], columns=columns),
    ):
        with pytest.raises(InputError) as e:
            call()
        assert (e.value.source, e.value.field, str(e.value.value)) == ("argument", field, value)
        assert e.value.expected.startswith(expected) and "\n" not in str(e.value)
    with pytest.raises(InputError, match=r"^argument: columns = 'time_s': expected a list of output column names"):
        tr.simulate(m, tr.isolated_takeoff(), columns="time_s")
    if field == "columns[1]" and value == "pump_speed":
        assert e.value.expected.endswith(", ".join(tr.COLUMNS))


def test_an_empty_choice_gives_status_and_events_only():
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    b = tr.simulate_columns([m], [tr.isolated_takeoff(tip_out=True)], columns=[], times_s=TIMES)
    assert b.columns == {} and list(b.status) == [tr.RUN_OK]
    assert b.run_events(0) == tr.simulate(m, tr.isolated_takeoff(tip_out=True), times_s=TIMES).events
    assert tr.simulate(m, tr.isolated_takeoff(), columns=[]).columns == {}


def test_the_memory_estimate_counts_only_the_chosen_columns():
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    t = np.linspace(0.0, 10.0, 1001)
    # 100 runs × 1001 samples: about (8 bytes × columns + 150 to 300 bytes of state) per sample, so
    # 2 columns need at most 32 MB and all 33 at least 41 MB
    limit = 35e6
    drives = [tr.isolated_takeoff()]
    with pytest.raises(InputError) as e:
        tr.simulate_columns([m] * 100, drives, times_s=t, max_output_bytes=limit)
    assert e.value.field == "output_samples" and "33 columns" in e.value.expected
    b = tr.simulate_columns(
        [m] * 100, drives, times_s=t, columns=["time_s", "pump_speed_rad_s"], max_output_bytes=limit
    )
    assert (b.status == tr.RUN_OK).all() and b.columns["time_s"].shape == (100, 1001)


def test_the_table_models_extension_warning_reads_speeds_not_chosen():
    """The table models warn when a run reaches the overrun rule's extension; the speeds it reads are
    computed for it whatever the choice, and left out of the result."""
    m = tr.dynamic_model("li-sunden-2016", "table")
    t = np.array([0.0, 1.0, 2.0])
    overrun = tr.Speeds(t, 100.0, 300.0)  # SR 3: beyond the table's SR 1
    calm = tr.Speeds(t, 200.0, 100.0)
    with pytest.warns(TcsimWarning, match=r"the run \(run 1\) reached SR 3"):
        b = tr.simulate_columns([m], [calm, overrun], times_s=t, columns=["time_s"])
    assert list(b.columns) == ["time_s"] and (b.status == tr.RUN_OK).all()
    with pytest.warns(TcsimWarning, match=r"the run reached SR 3"):
        r = tr.simulate(m, overrun, columns=["pump_torque_nm"])
    assert list(r.columns) == ["pump_torque_nm"]


def test_a_batch_of_one_run_is_its_columnar_run_with_the_same_warnings_and_errors():
    """simulate and a batch of one run take the core's flat columns as they are (issue 16, the
    Python path): the same numbers, events, warnings (from the same place) and errors."""
    table, ht = (tr.dynamic_model("li-sunden-2016", name) for name in ("table", "hrovat-tobler"))
    t = np.array([0.0, 1.0, 2.0])
    overrun = tr.Speeds(t, np.array([100.0, 120.0, 100.0]), 300.0)  # SR 3: beyond the table's SR 1
    b = tr.simulate_columns([table], [overrun], times_s=t)
    places = set()
    for models, drives in (([table], [overrun]), ([table, table], [overrun])):
        with pytest.warns(TcsimWarning, match=r"reached SR 3") as w:
            runs = tr.simulate_batch(models, drives, times_s=t)
        places |= {(x.filename, x.lineno) for x in w}
        one = runs[0]
        assert list(one.columns) == list(tr.COLUMNS) and one.events == b.run_events(0)
        for name in tr.COLUMNS:
            assert one[name].shape == (3,) and np.array_equal(_bits(one[name]), _bits(b.columns[name][0])), name
    assert len(places) == 1, "the warning comes from one place whatever the batch's size"
    solver_fails = tr.PumpTorqueLoad(t, np.array([100.0, 100.0, 1e300]), load_inertia_kg_m2=1.0)
    expected = tr.simulate_columns([ht], [solver_fails], times_s=t).errors[0]
    for call in (tr.simulate_batch, lambda ms, ds, **kw: [tr.simulate(ms[0], ds[0], **kw)]):
        with pytest.raises(tr.SolverError) as e:
            call([ht], [solver_fails], times_s=t)
        assert str(e.value) == str(expected)


def test_a_single_runs_columns_keep_each_ones_layout():
    """``BatchColumns.runs()`` of one run takes each column as its layout gives it (the whole of a
    flat column, the one row of a (1, S) one), also when a caller mixed the two."""
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    t = np.linspace(0.0, 10.0, 11)
    b = tr.simulate_columns([m], [tr.isolated_takeoff()], times_s=t, columns=["time_s", "pump_speed_rad_s"])
    assert b.columns["time_s"].shape == (1, 11)
    b.columns = {"flat": np.arange(11.0), **b.columns, "also_flat": np.arange(11.0) + 1.0}
    run = b.runs()[0]
    assert {k: v.shape for k, v in run.columns.items()} == {k: (11,) for k in b.columns}
    assert np.array_equal(run["time_s"], t) and np.array_equal(run["also_flat"], np.arange(11.0) + 1.0)


def test_a_batchs_events_are_the_events_event_makes_and_as_frozen():
    # the events are made with their fields set at once (`_event_list`), not through the frozen
    # dataclass's __init__: each must hold its row of the batch's event arrays, and be the
    # Event(...) of its fields, equal, hashed, shown, copied, pickled, replaced and frozen alike
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    drives = [_lockup_takeoff(), tr.isolated_takeoff(tip_out=True), _lockup_takeoff()]
    batch = tr.simulate_columns([m], drives, times_s=TIMES, threads=2)
    ev = batch.events
    runs = batch.runs()
    assert len(runs[0].events) >= 2 and sum(len(r.events) for r in runs) == len(ev["time_s"]) >= 5
    k = 0
    for i, r in enumerate(runs):
        assert r.events == batch.run_events(i)
        for e in r.events:
            assert ev["run"][k] == i
            row = (float(ev["time_s"][k]), tr.EVENT_KINDS[ev["kind"][k]], bool(ev["stator_locked"][k]))
            assert (e.time_s, e.kind, e.stator_locked, e.flow_direction) == (*row, float(ev["flow_direction"][k]))
            k += 1
            made = tr.Event(e.time_s, e.kind, e.stator_locked, e.flow_direction)
            assert (e == made, hash(e) == hash(made), repr(e) == repr(made)) == (True, True, True)
            assert [type(getattr(e, f.name)) for f in dataclasses.fields(e)] == [float, str, bool, float]
            assert pickle.loads(pickle.dumps(e)) == e and copy.deepcopy(e) == e
            assert dataclasses.asdict(e) == dataclasses.asdict(made)
            assert dataclasses.replace(e, kind="flow-zero") == tr.Event(
                e.time_s, "flow-zero", e.stator_locked, e.flow_direction
            )
            with pytest.raises(dataclasses.FrozenInstanceError):
                e.kind = "flow-zero"  # type: ignore[misc]
    empty = tr.simulate_columns([m], [tr.isolated_takeoff()], times_s=np.array([0.0, 0.01]), threads=1)
    assert empty.runs()[0].events == [] and empty.run_events(0) == []
