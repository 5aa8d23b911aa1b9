"""The plausibility ranges come from the core and act as documented: refuse, or warn with the override."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import pytest

from tcsim import _core
from tcsim.errors import InputError, TcsimWarning
from tcsim.models.plausibility import RANGES, check_plausible, warn_implausible


def test_ranges_are_the_cores():
    assert [(r.quantity, r.unit, r.low, r.high, r.why) for r in RANGES.values()] == _core.plausibility_ranges()


def test_values_inside_pass_and_nan_is_left_to_the_readers():
    rng = RANGES["speed_rad_s"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_plausible("speed_rad_s", [rng.low, 0.0, rng.high, math.nan], "m.csv", "pump_speed_rad_s")
        warn_implausible("radius_m", 0.12, "c.toml", "[geometry].pump_exit_radius_m")


@pytest.mark.parametrize("value", [-1100.5, 1100.5, 6000.0, 1e300])
def test_outside_is_refused_naming_the_range_and_the_override(value):
    with pytest.raises(InputError) as e:
        check_plausible("speed_rad_s", [10.0, value, 2e4], "m.csv", "pump_speed_rad_s")
    msg = str(e.value)
    assert msg.startswith(f"m.csv: pump_speed_rad_s = {value:.6g}: expected a plausible value, -1100 to 1100 rad/s")
    assert msg.endswith("; allow_implausible=True runs it anyway") and "\n" not in msg
    # the command line names its option instead
    assert str(e.value.on_command_line()).endswith("; --allow-implausible runs it anyway")


def test_the_override_turns_the_refusal_into_one_warning():
    with pytest.warns(TcsimWarning, match=r"m.csv: pump_speed_rad_s = 6000 is outside the plausible -1100 to 1100"):
        check_plausible("speed_rad_s", [6000.0], "m.csv", "pump_speed_rad_s", allow=True)


def test_design_values_only_warn():
    with pytest.warns(TcsimWarning, match=r"fluid_density_kg_m3 = 8.4e-292 is outside the plausible 600 to 1200"):
        warn_implausible("fluid_density_kg_m3", 8.4e-292, "c.toml", "[geometry].fluid_density_kg_m3")


def test_the_guarantees_page_lists_every_range():
    page = (Path(__file__).resolve().parents[2] / "docs" / "guarantees.md").read_text(encoding="utf-8")
    for r in RANGES.values():
        unit = f" {r.unit}" if r.unit else ""
        assert f"| `{r.quantity}` | {r.low:g} to {r.high:g}{unit} | {r.why} |" in page, r.quantity
