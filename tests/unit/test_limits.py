"""The core's limits (issue 10, defects 2, 8, 10, 11): output size, time resolution, finite inputs,
short numbers in messages. Each limit is an input error (exit 2), never an abort or a solver error."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from tcsim import _core
from tcsim import transient as tr
from tcsim.errors import InputError
from tcsim.models.vehicle import load_vehicle
from tcsim.simulation.launch import run_launch, select_models
from tcsim.simulation.scenarios import flip_flop

T = np.linspace(0.0, 0.5, 51)


def test_the_output_size_is_estimated_and_refused_before_running():
    # small limits, so that a regression runs an ordinary launch instead of filling the memory
    v = load_vehicle()
    models = select_models(v, ["table"])
    with pytest.raises(InputError) as e:
        run_launch(v, flip_flop(), models, options={"output_step_s": 1e-3, "max_output_bytes": 1e7})
    assert (e.value.core_source, e.value.field) == ("options", "output_samples")
    assert "max_output_bytes = 1e7 bytes" in e.value.expected and "lower the sampling" in e.value.expected
    with pytest.raises(InputError) as e:
        run_launch(v, flip_flop(), models, options={"max_output_bytes": 1e5})
    assert (e.value.core_source, e.value.field) == ("scenario", "output_samples")  # the default step: its length
    with pytest.raises(InputError) as e:
        tr.simulate("li-sunden-2016", tr.isolated_takeoff(), model="table", times_s=T, max_output_bytes=100.0)
    assert (e.value.core_source, e.value.field, e.value.value) == ("drive", "output_samples", 51.0)
    with pytest.raises(InputError, match="max_output_bytes"):
        tr.simulate("li-sunden-2016", tr.isolated_takeoff(), model="table", times_s=T, max_output_bytes=-1.0)


ABORTED = {
    "launch_runs with output_step_s=1e-9": """
        from tcsim import _core
        from tcsim.models.vehicle import load_vehicle
        from tcsim.simulation.launch import select_models
        from tcsim.simulation.scenarios import flip_flop
        v = load_vehicle()
        m = select_models(v, ["table"])[0]
        _core.launch_runs([m.spec], v.core, flip_flop().core_spec(), {"output_step_s": 1e-9})
    """,
    "a two-row scenario of 1e5 s": """
        import numpy as np
        from tcsim.models.vehicle import load_vehicle
        from tcsim.simulation.launch import run_launch, select_models
        from tcsim.simulation.scenarios import Scenario
        t, pedal = np.array([0.0, 1e5]), np.array([0.0, 1.0])
        sc = Scenario("long", t, pedal, 1.0 - pedal, 1e5, None, 0.0, "long.csv")
        v = load_vehicle()
        run_launch(v, sc, select_models(v, ["table"]))
    """,
    # 6e6 output times (48 MB here) need 2.2 GB of output: refused before the run starts (within the
    # drive's 10 s: output times outside a drive's span are refused since issue 11)
    "transient_runs at 6e6 output times": """
        import numpy as np
        from tcsim import transient as tr
        t = np.linspace(0.0, 10.0, 6_000_001)
        tr.simulate("li-sunden-2016", tr.isolated_takeoff(), model="table", times_s=t)
    """,
}


#: The field each call's error names: the raw call refuses the step (finer than the time resolution),
#: the others the output's size.
FIELDS = {
    "launch_runs with output_step_s=1e-9": "options output_step_s",
    "a two-row scenario of 1e5 s": "scenario output_samples",
    "transient_runs at 6e6 output times": "drive output_samples",
}


@pytest.mark.parametrize("case", list(ABORTED))
def test_calls_that_aborted_raise_an_input_error(case):
    """Each of these aborted the interpreter (SIGABRT, "memory allocation failed") before."""
    # 3 GB of address space: a regression fails at once instead of taking the machine's memory
    code = "import resource\nresource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))\n"
    code += "from tcsim import _core\nfrom tcsim.errors import InputError\ntry:\n"
    code += textwrap.indent(textwrap.dedent(ABORTED[case]), "    ")
    code += "\nexcept InputError as e:\n    print('error', e.core_source, e.field)\n    raise SystemExit(2)\n"
    code += "except _core.CoreInputError as e:\n    print('error', e.args[4], e.args[1])\n    raise SystemExit(2)\n"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    assert r.stdout.strip() == f"error {FIELDS[case]}"
    assert "panicked" not in r.stderr and "memory allocation" not in r.stderr


@pytest.mark.parametrize(
    ("times", "index"), [(1e5 + np.arange(50) * 1e-9, 1), (np.arange(50) * 1e-12, 1), (np.r_[0.0, 0.5, 0.5 + 1e-7], 2)]
)
def test_time_stamps_finer_than_the_resolution_are_input_errors(times, index):
    drive = tr.PumpTorqueTurbineSpeed(times, np.full(len(times), 40.0), np.full(len(times), 50.0))
    with pytest.raises(InputError) as e:
        tr.simulate("li-sunden-2016", drive, model="hrovat-tobler")
    assert e.value.core_source == "drive"
    assert e.value.field == f"pump_torque_nm.time_s[{index}]"
    assert "at least 1e-6 s apart" in e.value.expected and f"sample {index} is" in e.value.expected
    # output times that close are the caller's argument, not the drive's (this pinned "drive: time_s[1]")
    with pytest.raises(InputError, match=r"^argument: times_s\[1\] = 1e-09: expected time stamps at least 1e-6 s"):
        tr.simulate("li-sunden-2016", tr.isolated_takeoff(), model="table", times_s=[0.0, 1e-9, 1.0])


def test_nan_constant_drive_signals_are_input_errors():
    spec = tr.isolated_takeoff().spec()
    spec["pump_torque_nm"] = float("nan")
    m = tr.dynamic_model("li-sunden-2016", "table")
    with pytest.raises(_core.CoreInputError) as e:
        _core.transient_runs([m.spec], [spec])
    assert e.value.args[1:] == ("pump_torque_nm", "NaN", "a finite value", "drive")


@pytest.mark.parametrize(
    ("initial", "field"),
    [
        ({"pump_speed_rad_s": 1e300}, "initial pump_speed_rad_s"),
        ({"pump_speed_rad_s": 200.0, "stator_speed_rad_s": 1e200, "flow_m3_s": 0.01}, "initial stator_speed_rad_s"),
        ({"pump_speed_rad_s": 200.0, "stator_speed_rad_s": 0.0, "flow_m3_s": 1e200}, "initial flow_m3_s"),
    ],
)
def test_initial_states_with_non_finite_torques_are_input_errors(initial, field):
    with pytest.raises(InputError) as e:
        tr.simulate("li-sunden-2016", tr.isolated_takeoff(), model="hrovat-tobler", times_s=T, initial=initial)
    assert (e.value.core_source, e.value.field) == ("initial", field)


def test_solver_messages_print_short_numbers():
    # more events than allowed: the message lists the state with six significant digits (the core's
    # unit test shows a state of 1e300 printed as 1e300, not with 301 digits)
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    with pytest.raises(tr.SolverError) as e:
        tr.simulate(m, tr.isolated_takeoff(), max_events=0)
    assert "more than 0 events" in str(e.value)
    numbers = [w for w in str(e.value).replace(",", " ").replace(")", " ").split() if w[:1].isdigit()]
    assert numbers and max(len(w) for w in numbers) <= 13, str(e.value)


def test_the_shape_effect_bound_says_at_or_above():
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    spec = m.spec
    shape = list(spec["shape_effect_m2"])
    geometry = np.array([spec["geometry"]], dtype=float)
    bound = _core.mass_matrix_bound(geometry, spec["fluid_length_m"], list(spec["inertia_kg_m2"]), shape)[
        "shape_effect_bounds_m2"
    ][0]
    with pytest.raises(InputError) as e:
        tr.simulate(m.with_shape_effects(bound * (1 + 1e-12), shape[1], shape[2]), tr.isolated_takeoff(), times_s=T)
    assert "is at or above it" in e.value.expected, e.value.expected
