"""Errors of the Python API name the function's own arguments; the command line shows the same
errors with its options (a trial: ``tcsim.characterise(..., pump_speed_rpm=0)`` said
``command line: --pump-speed-rpm``, and its refusal of an implausible speed named an override,
``--allow-implausible``, that the function did not have)."""

from __future__ import annotations

import numpy as np
import pytest

import tcsim
from tcsim.errors import ARGUMENT, InputError, on_command_line, option_name
from tcsim.io.tables import write_table


@pytest.mark.parametrize(
    ("kwargs", "field", "value"),
    [
        (dict(model="table", pump_speed_rpm=0.0), "pump_speed_rpm", 0.0),
        (dict(model="no-such-model"), "model", "no-such-model"),
        (dict(model="table", input_torque_nm=0.0), "input_torque_nm", 0.0),
    ],
)
def test_characterise_names_its_arguments(kwargs, field, value):
    with pytest.raises(InputError) as e:
        tcsim.characterise("li-sunden-2016", **kwargs)
    assert (e.value.source, e.value.field, e.value.value) == (ARGUMENT, field, value)
    assert str(e.value).startswith(f"argument: {field} = ")
    cli = e.value.on_command_line()
    assert (cli.source, cli.field, cli.value) == ("command line", "--" + field.replace("_", "-"), value)


def test_the_override_named_is_the_functions_own_and_it_works():
    with pytest.raises(InputError) as e:
        tcsim.characterise("li-sunden-2016", "table", pump_speed_rpm=12000.0)
    assert str(e.value).endswith("; allow_implausible=True runs it anyway")
    assert str(e.value.on_command_line()).endswith("; --allow-implausible runs it anyway")
    with pytest.warns(tcsim.TcsimWarning, match="^argument: pump_speed_rpm = 12000 is outside the plausible"):
        frame = tcsim.characterise("li-sunden-2016", "table", pump_speed_rpm=12000.0, allow_implausible=True)
    assert len(frame) > 0


def test_a_copy_keeps_the_override_and_the_core_source():
    e = InputError("m.csv", "pump_speed_rad_s", 9000.0, "a plausible value", core_source="drive", override="x_y")
    moved = e.replace(source="n.csv")
    assert (moved.source, moved.field, moved.core_source, moved.override) == (
        "n.csv",
        "pump_speed_rad_s",
        "drive",
        "x_y",
    )
    assert (
        str(moved.on_command_line())
        == "n.csv: pump_speed_rad_s = 9000: expected a plausible value; --x-y runs it anyway"
    )
    assert e.on_command_line() is not e and InputError("f", "k", 1, "x").on_command_line().source == "f"


def test_warnings_and_options_as_the_command_line_words_them():
    assert (
        on_command_line("argument: pump_speed_rpm = 12000 is outside")
        == "command line: --pump-speed-rpm = 12000 is outside"
    )
    assert on_command_line("m.csv: argument: x = 1") == "m.csv: argument: x = 1"  # only at the start
    assert option_name("out_path") == "--out" and option_name("bounds") == "--bound"
    assert option_name("speed_ratio_max") == "--speed-ratio-max"


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        (dict(speed_ratio="0:1"), "speed_ratio"),
        (dict(speed_ratio=np.zeros((2, 2))), "speed_ratio"),
        (dict(speed_ratio=[0.3, np.nan]), "speed_ratio[1]"),
        (dict(pump_speed_rpm="2000"), "pump_speed_rpm"),
        (dict(pump_speed_rpm=[2000.0]), "pump_speed_rpm"),
        (dict(input_torque_nm="100"), "input_torque_nm"),
    ],
)
def test_characterise_refuses_arguments_of_the_wrong_kind(kwargs, field):
    """A trial: these were a TypeError or ValueError from NumPy, or (NaN) an error about the
    converter file's turbine speed."""
    with pytest.raises(InputError) as e:
        tcsim.characterise("li-sunden-2016", "table", **kwargs)
    assert (e.value.source, e.value.field) == (ARGUMENT, field), str(e.value)


def test_characterise_takes_one_speed_ratio_as_a_number():
    one = tcsim.characterise("li-sunden-2016", "table", speed_ratio=0.5)
    assert list(one["speed_ratio"]) == [0.5]
    assert one.equals(tcsim.characterise("li-sunden-2016", "table", speed_ratio=np.array(0.5)))


@pytest.mark.parametrize("converter", [None, 5, ["li-sunden-2016"]])
def test_the_one_liners_refuse_what_is_not_a_converter(converter):
    for call in (
        lambda: tcsim.characterise(converter),
        lambda: tcsim.steady_state(converter, "table", 100.0, 50.0),
        lambda: tcsim.operating_point(converter, [100.0], [50.0]),
    ):
        with pytest.raises(InputError) as e:
            call()
        assert (e.value.source, e.value.field) == (ARGUMENT, "converter")


def test_small_edges_of_the_api(tmp_path):
    """A trial: ``steady_state(C, "table", None, 100)`` said ``pump_speed_rad_s = nan``;
    ``write_table`` into a missing folder was pandas' OSError."""
    with pytest.raises(InputError) as e:
        tcsim.steady_state("li-sunden-2016", "table", None, 100.0)
    assert (e.value.field, e.value.value) == ("pump_speed_rad_s", None)
    frame = tcsim.characterise("li-sunden-2016", "table", speed_ratio=[0.0, 0.5])
    with pytest.raises(InputError) as e:
        write_table(frame, tmp_path / "missing", "characteristic.csv")
    assert (e.value.source, e.value.field) == (ARGUMENT, "out_dir") and not (tmp_path / "missing").exists()
    assert write_table(frame, tmp_path, "characteristic.csv").is_file()
