"""A drive's series reach the core as NumPy arrays (issue 16, the Python path of one run).

``Drive.spec()`` gives lists (the raw tier's dicts), the runs pass float64 arrays that the binding
copies in one go (``Drive._core_spec``, ``_output_times``). Nothing may change: a drive of arrays of
any dtype NumPy holds numbers in, strided or not, a 0-d array, a list or a tuple runs as the same
drive given as lists (bit for bit), and the binding gives the same errors for an array as for the
list of its values (non-finite values, times that do not increase, a wrong shape).
"""

from __future__ import annotations

import numpy as np
import pytest

from tcsim import _core
from tcsim import transient as tr
from tcsim.errors import InputError
from tcsim.simulation.transient import _output_times, output_times

TIMES = np.linspace(0.0, 10.0, 201)
T4 = [0.0, 0.1, 0.3, 10.0]
TORQUE = [40.0, 40.0, 120.0, 120.0]  # fits every integer dtype, exact in float16
DTYPES = [
    np.float16,
    np.float32,
    np.float64,
    np.longdouble,
    ">f8",
    np.int8,
    np.int16,
    np.int32,
    np.int64,
    np.uint8,
    np.uint64,
]


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float).view(np.uint64)


def _list_run(model: tr.DynamicModel, drive: tr.Drive, times_s) -> dict:
    """The run as the drive's lists give it (``spec()`` and ``output_times()``, the path before
    arrays): the core's columns of the one run and its events."""
    spec = drive.spec()
    spec["output_time_s"], spec["output_skip"] = output_times(spec["time_s"], times_s)
    raw = _core.transient_batch([model.spec], [spec], None, {}, 1, None)
    assert not raw["failures"]
    return raw


def _same_run(result: tr.TransientResult, raw: dict) -> None:
    assert list(result.columns) == list(raw["columns"])
    for name, col in raw["columns"].items():
        assert np.array_equal(_bits(result[name]), _bits(col)), name
    assert [e.time_s for e in result.events] == raw["event_time_s"].tolist()


@pytest.mark.parametrize("dtype", DTYPES, ids=str)
def test_a_drive_of_arrays_of_any_number_dtype_is_the_run_of_its_lists(dtype):
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    t = np.array([0, 1, 3, 10], dtype=dtype) if np.dtype(dtype).kind in "iu" else np.array(T4, dtype=dtype)
    drive = tr.PumpTorqueLoad(t, np.array(TORQUE, dtype=dtype), 1.2, load_torque_nm=np.array(10, dtype=dtype))
    spec = drive.spec()
    assert isinstance(spec["time_s"], list) and isinstance(spec["load_torque_nm"], float), "spec() keeps lists"
    as_lists = tr.PumpTorqueLoad(spec["time_s"], spec["pump_torque_nm"], 1.2, load_torque_nm=spec["load_torque_nm"])
    times = np.asarray(TIMES, dtype=dtype) if np.dtype(dtype).kind == "f" else TIMES
    result = tr.simulate(m, drive, times_s=times)
    _same_run(result, _list_run(m, as_lists, times))
    assert result.events == tr.simulate(m, as_lists, times_s=times).events


def test_strided_arrays_lists_tuples_and_0d_arrays_run_as_lists():
    m = tr.dynamic_model("li-sunden-2016", "table")
    grid = np.array([[t, -1.0] for t in T4])  # column 0 is a strided view
    wide = np.array([[v, 0.0, 0.0] for v in [200.0, 210.0, 260.0, 250.0]])
    drives = [
        tr.Speeds(grid[:, 0], wide[:, 0], np.array(100.0)),  # strided series, a 0-d constant
        tr.Speeds(tuple(T4), [200.0, 210.0, 260.0, 250.0], 100),  # a tuple, a list, an int
        tr.Speeds(np.array(T4), np.array([200.0, 210.0, 260.0, 250.0]), np.float64(100.0)),
    ]
    assert not grid[:, 0].flags.c_contiguous
    reference = _list_run(m, drives[1], TIMES[::3])
    for d in drives:
        _same_run(tr.simulate(m, d, times_s=TIMES[::3]), reference)  # strided sample times too
    series = tr.Speeds(grid[:, 0], wide[:, 0], np.full(4, 100.0)[::-1])  # a series, not the constant
    _same_run(tr.simulate(m, series, times_s=TIMES[::3]), _list_run(m, series, TIMES[::3]))


def test_the_run_passes_float64_arrays_and_output_times_still_gives_a_list():
    d = tr.PumpTorqueTurbineSpeed(
        [0.0, 1.0, 2.0], np.array([50, 60, 70]), np.array(80.0), lockup_capacity_nm=np.zeros(3, np.float32)
    )
    spec = d._core_spec()
    for key in ("time_s", "pump_torque_nm", "lockup_capacity_nm"):
        assert isinstance(spec[key], np.ndarray) and spec[key].dtype == np.float64 and spec[key].ndim == 1, key
    assert spec["turbine_speed_rad_s"] == 80.0 and type(spec["turbine_speed_rad_s"]) is float
    assert {k: np.asarray(v).tolist() for k, v in spec.items() if k != "kind"} == {
        k: v for k, v in d.spec().items() if k != "kind"
    }
    times, skip = output_times([0.0, 2.0], np.array([0.5, 1.0]))
    assert times == [0.0, 0.5, 1.0] and type(times) is list and skip == 1
    arr, skip = _output_times([0.0, 2.0], np.array([0.5, 1.0]))
    assert isinstance(arr, np.ndarray) and arr.tolist() == times and skip == 1


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("pump_torque_nm", [40.0, np.nan, 250.0, 250.0]),
        ("pump_torque_nm", [40.0, 40.0, np.inf, 250.0]),
        ("time_s", [0.0, 0.3, 0.1, 10.0]),
        ("time_s", [0.0, np.nan, 0.3, 10.0]),
        ("output_time_s", [0.0, np.nan, 10.0]),
        ("output_time_s", [0.0, 5.0, 3.0]),
        ("load_torque_nm", [10.0]),  # a series of one value is not a constant
    ],
)
def test_the_binding_gives_an_array_the_errors_of_its_list(key, value):
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    base = tr.isolated_takeoff().spec()
    outcomes = []
    for given in (value, np.array(value), np.array(value)[::-1][::-1]):
        try:
            raw = _core.transient_batch([m.spec], [{**base, key: given}], None, {}, 1, ["time_s"])
            outcomes.append([(f["kind"], f["field"], f["message"]) for f in raw["failures"]])
        except (_core.CoreInputError, ValueError) as e:
            outcomes.append([(type(e).__name__, *e.args)])
    assert outcomes[0], "the list is refused"
    assert outcomes[1] == outcomes[0] and outcomes[2] == outcomes[0]


@pytest.mark.parametrize("kind", ["load", "speed", "speeds", "clutch"])
def test_each_signal_is_read_against_the_one_reading_of_the_time_stamps(kind):
    """The binding reads a drive's ``time_s`` once for all its signals: a drive without time stamps
    is refused for them even when its signals are constants, a bad ``time_s`` is named before any
    signal, and two drives that differ only in a signal's values run as themselves."""
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    drive = {
        "load": tr.PumpTorqueLoad(T4, TORQUE, 1.2, load_torque_nm=10.0),
        "speed": tr.PumpTorqueTurbineSpeed(T4, TORQUE, 50.0),
        "speeds": tr.Speeds(T4, 200.0, [0.0, 10.0, 60.0, 150.0]),
        "clutch": tr.PumpTorqueTurbineSpeed(T4, TORQUE, 50.0, lockup_capacity_nm=[0.0, 0.0, 50.0, 300.0]),
    }[kind]
    spec = {**drive.spec(), "output_time_s": [0.0, 0.2, 10.0]}  # (else the output times read time_s)
    signals = [k for k in spec if k.endswith(("_nm", "_rad_s")) and k != "load_torque_nm"]
    constants = {**spec, **{k: 100.0 for k in signals}}
    del constants["time_s"]
    with pytest.raises(ValueError, match="time_s"):
        _core.transient_batch([m.spec], [constants], None, {}, 1, ["time_s"])
    with pytest.raises(_core.CoreInputError) as e:  # a bad signal too: the time stamps come first
        _core.transient_batch([m.spec], [{**spec, "time_s": "t", signals[-1]: "x"}], None, {}, 1, None)
    assert e.value.args[1] == "time_s"
    given = signals[0]  # a given input is an output column: the pump's torque or speed
    runs = [spec, {**spec, given: [2.0 * v for v in np.broadcast_to(spec[given], (4,))]}]
    raw = _core.transient_batch([m.spec], runs, None, {}, 2, [given, "turbine_speed_rad_s"])
    assert not raw["failures"] and raw["names"] == [given, "turbine_speed_rad_s"]
    for i, r in enumerate(runs):
        one = _core.transient_batch([m.spec], [r], None, {}, 1, raw["names"])
        rows = slice(raw["offsets"][i], raw["offsets"][i + 1])
        for name in raw["names"]:
            assert np.array_equal(_bits(raw["columns"][name][rows]), _bits(one["columns"][name])), (i, name)
    first, second = np.split(raw["columns"][given], raw["offsets"][1:-1])
    assert np.allclose(second, 2.0 * first, rtol=1e-12, atol=0.0)  # (a torque column is computed: M u̇ − F)


def test_a_drive_series_of_another_shape_is_refused_as_its_nested_list_is():
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    errors = set()
    for torque in (np.array(TORQUE)[:, None], np.array(TORQUE)[:, None].tolist()):
        with pytest.raises(InputError) as e:  # was a bare ValueError naming a TypeError
            tr.simulate(m, tr.PumpTorqueLoad(T4, torque, 1.2), times_s=TIMES)
        errors.add(str(e.value))
    assert errors == {
        "drive: pump_torque_nm = [[40.0], [40.0], [120.0], [120.0]]: expected numbers: a list or a 1-D array of them"
    }


def test_a_0d_array_is_a_constant_and_a_nan_one_is_refused_as_a_nan_number():
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    base = tr.isolated_takeoff().spec()
    runs = [
        _core.transient_batch([m.spec], [{**base, "load_torque_nm": v}], None, {}, 1, ["turbine_speed_rad_s"])
        for v in (10.0, np.array(10.0), np.array(10), np.float32(10.0))
    ]
    for r in runs[1:]:
        assert np.array_equal(
            _bits(r["columns"]["turbine_speed_rad_s"]), _bits(runs[0]["columns"]["turbine_speed_rad_s"])
        )
    for v in (float("nan"), np.array(np.nan)):
        with pytest.raises(_core.CoreInputError) as e:
            _core.transient_batch([m.spec], [{**base, "load_torque_nm": v}], None, {}, 1, None)
        assert e.value.args[1:] == ("load_torque_nm", "NaN", "a finite value", "drive")


@pytest.mark.parametrize(
    ("times", "field"),
    [
        ([0.0, np.nan, 5.0], "times_s[1]"),
        ([0.0, 5.0, 11.0], "times_s[2]"),
        ([-1.0, 5.0], "times_s[0]"),
        ([0.0, np.inf], "times_s[1]"),
    ],
)
def test_sample_times_outside_the_span_or_not_finite_are_the_same_input_errors(times, field):
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    messages = set()
    for given in (times, np.array(times), np.array(times, dtype=np.float32)):
        with pytest.raises(InputError) as e:
            tr.simulate(m, tr.isolated_takeoff(), times_s=given)
        assert e.value.field == field
        messages.add(str(e.value))
    assert len(messages) == 1


def test_decreasing_sample_times_are_one_input_error_whatever_their_type():
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    errors = set()
    for given in ([0.0, 5.0, 3.0], np.array([0.0, 5.0, 3.0])):
        with pytest.raises(InputError) as e:
            tr.simulate(m, tr.isolated_takeoff(), times_s=given)
        errors.add((str(e.value), e.value.core_source))
    assert len(errors) == 1 and "strictly increasing" in errors.pop()[0]  # about the argument times_s[2]


def test_a_drive_whose_start_is_nan_is_refused_by_the_core_as_before():
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    d = tr.PumpTorqueLoad(np.array([np.nan, 1.0, 2.0]), 100.0, 1.2)
    with pytest.raises(InputError) as e:
        tr.simulate(m, d, times_s=[0.5, 1.0])
    assert e.value.core_source == "drive" and "time_s[0]" in e.value.field


@pytest.mark.parametrize("skip", [2, 3])
def test_a_skip_of_every_output_time_is_an_input_error_naming_it(skip):
    # raw tier: it was a plain ValueError (the before/after comparison of the core, issue 16)
    spec = tr.isolated_takeoff().spec()
    spec["output_time_s"], spec["output_skip"] = [0.0, 1.0], skip
    with pytest.raises(_core.CoreInputError) as e:
        _core.transient_batch([tr.dynamic_model("li-sunden-2016", "hrovat-tobler").spec], [spec], None, {}, 1, None)
    assert e.value.args[1:] == ("output_skip", str(skip), e.value.args[3], "drive")
    assert e.value.args[3] == "fewer leading output times to drop than the 2 output times"
