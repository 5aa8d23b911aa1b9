"""Property-based tests of the batch API (hypothesis; profiles in tests/conftest.py).

``tcsim._core.transient_runs`` and ``launch_runs`` with random models, drives, scenarios, initial
states, solver options, output steps and thread counts either return one result per run, each
its columns or its :class:`~tcsim._core.RunError`, or raise :class:`~tcsim._core.CoreInputError`:
never another exception, never a panic, never an abort. The Python facades (``tcsim.transient``,
``tcsim.replay``) raise only :class:`~tcsim.errors.InputError` (one line) or ``SolverError``.

Runs are kept short (end times of a few seconds at most, output steps of 1 ms or more) so that an
example costs milliseconds. Output sizes beyond 20 000 samples are left out with ``assume``: a
huge output is defect 2 of issue 10 (the core aborts on the allocation), fixed on another branch.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from tcsim import _core, replay, transient
from tcsim.errors import InputError
from tcsim.models.vehicle import load_vehicle

REPO = Path(__file__).resolve().parents[2]
MEASUREMENT = REPO / "tests" / "golden" / "data" / "takeoff_measurement.csv"
MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
SPECS = {m: transient.dynamic_model("li-sunden-2016", m).spec for m in MODELS}
#: Columns that are finite in every successful run (the others may be NaN where a model lacks the coordinate).
ALWAYS_FINITE = ("time_s", "pump_speed_rad_s", "turbine_speed_rad_s", "pump_torque_nm", "turbine_torque_nm")
MAX_OUTPUT_SAMPLES = 20_000

weird = st.sampled_from([math.nan, math.inf, -math.inf, 0.0, -1.0, 1e-300, 1e300, 5e-324])
#: Tolerances the core must refuse (a finite, tiny tolerance is legal but makes a run arbitrarily slow).
refused = st.sampled_from([math.nan, math.inf, -math.inf, 0.0, -1.0])
reasonable = st.floats(-300.0, 300.0, allow_nan=False)
number = st.one_of(reasonable, reasonable, reasonable, weird)


# --------------------------------------------------------------------------------------------
# strategies


@st.composite
def model_specs(draw: st.DrawFn) -> dict[str, Any]:
    """A bundled model's specification with up to two numbers replaced by odd ones."""
    spec = {k: (list(v) if isinstance(v, list) else v) for k, v in SPECS[draw(st.sampled_from(MODELS))].items()}
    keys = [k for k, v in spec.items() if k != "kind"]
    for _ in range(draw(st.integers(0, 2))):
        key = draw(st.sampled_from(keys))
        value = draw(st.one_of(weird, st.floats(-1.0, 1.0)))
        if isinstance(spec[key], list):
            spec[key][draw(st.integers(0, len(spec[key]) - 1))] = value
        else:
            spec[key] = value
    return spec


@st.composite
def times(draw: st.DrawFn, max_size: int = 5) -> list[float]:
    """Time stamps: increasing over at most a few seconds, or anything."""
    n = draw(st.integers(0, max_size))
    if draw(st.integers(0, 3)):
        step = draw(st.sampled_from([1e-3, 0.01, 0.1, 0.5]))
        return (draw(st.sampled_from([0.0, 0.5])) + step * np.arange(n)).tolist()
    return draw(st.lists(st.one_of(st.floats(-1.0, 3.0), weird), min_size=n, max_size=n))


@st.composite
def signals(draw: st.DrawFn, n: int) -> float | list[float]:
    if draw(st.booleans()):
        return draw(number)
    return draw(st.lists(number, min_size=n, max_size=n + draw(st.sampled_from([0, 0, 0, 1]))))


@st.composite
def drive_specs(draw: st.DrawFn) -> dict[str, Any]:
    t = draw(times())
    kind = draw(st.sampled_from(["pump-torque-turbine-speed", "speeds", "pump-torque-load"]))
    spec: dict[str, Any] = {"kind": kind, "time_s": t}
    if kind == "pump-torque-turbine-speed":
        spec |= {"pump_torque_nm": draw(signals(len(t))), "turbine_speed_rad_s": draw(signals(len(t)))}
    elif kind == "speeds":
        spec |= {"pump_speed_rad_s": draw(signals(len(t))), "turbine_speed_rad_s": draw(signals(len(t)))}
    else:
        spec |= {
            "pump_torque_nm": draw(signals(len(t))),
            "load_torque_nm": draw(signals(len(t))),
            "load_inertia_kg_m2": draw(st.one_of(st.floats(0.0, 5.0), weird)),
            "load_drag_nm_s2": draw(st.one_of(st.floats(0.0, 0.01), weird)),
        }
    if kind != "pump-torque-load" and draw(st.booleans()):
        spec["derivative_window_s"] = draw(st.one_of(st.sampled_from([0.0, 0.01, 0.04, 1.0]), weird))
    if draw(st.booleans()):
        spec["output_time_s"] = draw(times(max_size=4))
    return spec


INITIAL_KEYS = ("pump_speed_rad_s", "turbine_speed_rad_s", "stator_speed_rad_s", "flow_m3_s")
initials = st.one_of(st.none(), st.dictionaries(st.sampled_from(INITIAL_KEYS), number, max_size=2))
options = st.one_of(
    st.none(),
    st.fixed_dictionaries(
        {},
        optional={
            "rtol": st.one_of(st.sampled_from([1e-8, 1e-6, 1e-3]), refused),
            "speed_atol_rad_s": st.one_of(st.sampled_from([1e-6, 1e-3]), refused),
            "first_step_s": st.one_of(st.sampled_from([1e-6, 1e-3]), refused),
        },
    ),
)
threads = st.integers(0, 3)


# --------------------------------------------------------------------------------------------
# the contract of the raw batch calls


def check_runs(runs: list, n: int) -> None:
    assert len(runs) == n
    for run in runs:
        if run.ok:
            assert run.error is None
            for name in ALWAYS_FINITE:
                values = np.asarray(run.columns[name])
                assert np.all(np.isfinite(values)), f"{name}: non-finite values in a successful run"
        else:
            assert run.error.kind in ("input", "solver"), run.error.kind
            if run.error.kind == "input":
                assert run.error.source in _core.input_sources()


def output_samples(drive: dict[str, Any]) -> int:
    return len(drive.get("output_time_s", drive["time_s"]))


@given(
    models=st.lists(model_specs(), min_size=1, max_size=2),
    drives=st.lists(drive_specs(), min_size=1, max_size=2),
    init=initials,
    opts=options,
    workers=threads,
)
def test_transient_runs_return_results_or_refuse_the_input(models, drives, init, opts, workers):
    assume(len(models) == len(drives) or 1 in (len(models), len(drives)))  # else a ValueError, by design
    # defect 6 (issue 10): drive values beyond 1e6 give non-finite results (the xfail test below)
    signals = [v for d in drives for k, v in d.items() if k not in ("kind", "time_s", "output_time_s")]
    assume(not any(np.any(np.abs(np.asarray(v, dtype=float)) > 1e6) for v in [*signals, *(init or {}).values()]))
    try:
        runs = _core.transient_runs(models, drives, init, opts, workers)
    except _core.CoreInputError as e:
        assert len(e.args) == 5 and e.args[4] in _core.input_sources(), e.args
        return
    check_runs(runs, max(len(models), len(drives)))


@given(
    models=st.lists(model_specs(), min_size=1, max_size=2),
    drives=st.lists(drive_specs(), min_size=1, max_size=2),
    init=initials,
    opts=options,
    workers=threads,
    chosen=st.one_of(st.none(), st.lists(st.sampled_from(transient.COLUMNS), unique=True, max_size=6)),
)
def test_a_columnar_batch_is_the_per_run_batch_or_refuses_the_input(models, drives, init, opts, workers, chosen):
    """Issue 16: ``transient_batch`` refuses what ``transient_runs`` refuses, and otherwise gives each
    run's chosen columns bit for bit, its events, and a status that says whether it failed and how."""
    assume(len(models) == len(drives) or 1 in (len(models), len(drives)))
    signals = [v for d in drives for k, v in d.items() if k not in ("kind", "time_s", "output_time_s")]
    assume(not any(np.any(np.abs(np.asarray(v, dtype=float)) > 1e6) for v in [*signals, *(init or {}).values()]))
    try:
        runs = _core.transient_runs(models, drives, init, opts, workers)
    except _core.CoreInputError as e:
        with pytest.raises(_core.CoreInputError) as again:
            _core.transient_batch(models, drives, init, opts, workers, chosen)
        assert again.value.args == e.args
        return
    batch = _core.transient_batch(models, drives, init, opts, workers, chosen)
    names = list(transient.COLUMNS) if chosen is None else chosen
    assert batch["names"] == names and len(batch["status"]) == len(runs)
    failures = {f["run"]: f for f in batch["failures"]}
    kinds = _core.transient_event_kinds()
    for i, run in enumerate(runs):
        rows = slice(batch["offsets"][i], batch["offsets"][i + 1])
        if not run.ok:
            assert failures[i]["kind"] == run.error.kind and failures[i]["message"] == run.error.message
            assert batch["status"][i] == (1 if run.error.kind == "input" else 2)
            continue
        assert batch["status"][i] in (0, 3) and (batch["status"][i] == 3) == (i in failures)
        for name in names:
            got, want = batch["columns"][name][rows], np.asarray(run.columns[name])
            assert np.array_equal(got.view(np.uint64), want.view(np.uint64)), name
        mine = batch["event_run"] == i
        assert [kinds[k] for k in batch["event_kind"][mine]] == [e.kind for e in run.events]
        assert batch["event_time_s"][mine].tolist() == [e.time_s for e in run.events]


VEHICLE = load_vehicle()


@st.composite
def scenario_specs(draw: st.DrawFn) -> dict[str, Any]:
    t = draw(times(max_size=4))
    spec = {
        "time_s": t,
        "accelerator_pedal": draw(st.lists(st.one_of(st.floats(0.0, 1.0), weird), min_size=len(t), max_size=len(t))),
        "brake_pedal": draw(st.lists(st.one_of(st.floats(0.0, 1.0), weird), min_size=len(t), max_size=len(t))),
        "end_time_s": draw(st.one_of(st.floats(-1.0, 2.0), weird)),
    }
    if draw(st.booleans()):
        spec["stop_speed_m_s"] = draw(st.one_of(st.floats(0.0, 30.0), weird))
    if draw(st.booleans()):
        spec["engine_torque_nm"] = draw(st.lists(number, min_size=len(t), max_size=len(t)))
    return spec


@given(
    models=st.lists(model_specs(), min_size=1, max_size=2),
    scenario=scenario_specs(),
    opts=options,
    step=st.one_of(st.none(), st.sampled_from([1e-3, 0.01, 0.1]), weird),
    workers=threads,
)
def test_launch_runs_return_results_or_refuse_the_input(models, scenario, opts, step, workers):
    end = scenario["end_time_s"]
    if step is not None:
        opts = {**(opts or {}), "output_step_s": step}
    # defect 2 (issue 10): an output beyond memory aborts the core; left out until it is fixed
    if math.isfinite(end) and end > 0 and step is not None and math.isfinite(step):
        assume(step <= 0 or end / step <= MAX_OUTPUT_SAMPLES)
    else:
        assume(not (end == math.inf and step is not None and math.isfinite(step) and step > 0))
    try:
        runs = _core.launch_runs(models, VEHICLE.core, scenario, opts, workers)
    except _core.CoreInputError as e:
        assert len(e.args) == 5 and e.args[4] in _core.input_sources(), e.args
        return
    check_runs(runs, len(models))


# --------------------------------------------------------------------------------------------
# the facades


def one_line(e: InputError) -> None:
    text = str(e)
    assert "\n" not in text and "\r" not in text, text


def finite(*values: Any) -> bool:
    return all(np.all(np.isfinite(np.asarray(v, dtype=float))) for v in values)


def simulate_outcome(model: str, drive, initial, rtol) -> str:
    """ "ok", "input" or "solver": what ``tcsim.transient.simulate`` did."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            run = transient.simulate("li-sunden-2016", drive, model, initial=initial, rtol=rtol)
        except InputError as e:
            one_line(e)
            return "input"
        except transient.SolverError:
            return "solver"
    assert finite(*(run.columns[c] for c in ALWAYS_FINITE))
    return "ok"


T4 = [0.0, 0.1, 0.2, 0.3]
signal4 = st.one_of(number, st.lists(number, min_size=4, max_size=4))
speed4 = st.one_of(number, st.lists(st.floats(0.0, 50.0), min_size=4, max_size=4))
drives_api = st.one_of(
    st.builds(transient.PumpTorqueTurbineSpeed, time_s=st.just(T4), pump_torque_nm=signal4, turbine_speed_rad_s=speed4),
    st.builds(transient.Speeds, time_s=st.just(T4), pump_speed_rad_s=signal4, turbine_speed_rad_s=speed4),
    st.builds(
        transient.PumpTorqueLoad,
        time_s=st.just(T4),
        pump_torque_nm=signal4,
        load_inertia_kg_m2=st.one_of(st.floats(0.0, 5.0), weird),
        load_torque_nm=signal4,
        load_drag_nm_s2=st.one_of(st.floats(0.0, 0.01), weird),
    ),
)


def _non_finite_input(drive, initial, rtol) -> bool:
    spec = drive.spec()
    values = [v for k, v in spec.items() if k not in ("kind", "time_s")] + [list((initial or {}).values())]
    return not finite(*values) or (rtol is not None and not math.isfinite(rtol))


@given(
    model=st.sampled_from(MODELS),
    drive=drives_api,
    initial=initials,
    rtol=st.one_of(st.none(), st.sampled_from([1e-6, 1e-4]), refused),
)
def test_simulate_raises_only_input_or_solver_errors(model, drive, initial, rtol):
    # non-finite drive or initial values and values beyond 1e6 (refused as input errors, or finite
    # results, since issue 10) have their own tests below
    assume(not _non_finite_input(drive, initial, rtol) and not _huge_input(drive, initial))
    simulate_outcome(model, drive, initial, rtol)


def _huge_input(drive, initial) -> bool:
    spec = drive.spec()
    values = [v for k, v in spec.items() if k not in ("kind", "time_s")] + [list((initial or {}).values())]
    return any(np.any(np.abs(np.asarray(v, dtype=float)) > 1e6) for v in values)


@settings(suppress_health_check=[HealthCheck.filter_too_much])  # it looks at huge inputs only
@given(model=st.sampled_from(MODELS), drive=drives_api, initial=initials, rtol=st.none())
@example(model="table", drive=transient.Speeds(T4, 1e300, 0.0), initial=None, rtol=None)
def test_simulate_refuses_huge_inputs_or_gives_finite_results(model, drive, initial, rtol):
    assume(_huge_input(drive, initial) and not _non_finite_input(drive, initial, rtol))
    simulate_outcome(model, drive, initial, rtol)


@given(model=st.sampled_from(MODELS), drive=drives_api, initial=initials, rtol=st.none())
@example(
    model="table",
    drive=transient.PumpTorqueLoad(T4, 40.0, 1.0, load_torque_nm=math.nan),
    initial=None,
    rtol=None,
)
def test_simulate_refuses_non_finite_inputs_as_input_errors(model, drive, initial, rtol):
    assume(_non_finite_input(drive, initial, rtol))
    assert simulate_outcome(model, drive, initial, rtol) == "input"


@pytest.fixture(scope="module")
def short_measurement(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("replay") / "m.csv"
    lines = MEASUREMENT.read_text().splitlines()[:201]  # 0.2 s at 1 kHz
    path.write_text("\n".join(lines) + "\n")
    return path


@given(
    models=st.lists(st.sampled_from(MODELS), max_size=2, unique=True),
    drive=st.sampled_from(["pump-torque", "speeds"]),
    initial=initials,
    window=st.one_of(st.none(), st.sampled_from([0.0, 1e-4, 0.04, 0.5, 1e3]), weird),
    metrics_window=st.one_of(st.none(), st.sampled_from([1e-3, 0.05, 1.0, 1e6]), weird),
)
def test_replay_raises_only_input_or_solver_errors(short_measurement, models, drive, initial, window, metrics_window):
    # defect 3 (issue 10): metric windows far shorter than the sampling hang; left out until fixed
    assume(metrics_window is None or not (0 < metrics_window < 1e-3))
    # defect 6/8 (issue 10): a non-finite or huge --initial can end as a SolverError or non-finite output
    assume(finite(list((initial or {}).values())) and all(abs(v) <= 300 for v in (initial or {}).values()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            result = replay.replay(
                "li-sunden-2016", short_measurement, models, drive, None, initial, window, metrics_window
            )
        except InputError as e:
            one_line(e)
            return
        except transient.SolverError:
            return
    for run in result.results.values():
        assert finite(*(run.columns[c] for c in ALWAYS_FINITE))
