"""``tcsim.errors.from_core``: a core input error goes to the file of the input the core names in
its ``source`` (data), never to one guessed from the field's text."""

from __future__ import annotations

from tcsim import _core
from tcsim.errors import CORE_SOURCE_NAMES, from_core


def error(field: str, source: str) -> _core.CoreInputError:
    return _core.CoreInputError(f"{field} = -1: expected positive", field, "-1", "positive", source)


def test_every_core_source_has_a_name():
    assert sorted(CORE_SOURCE_NAMES) == sorted(_core.input_sources())


def test_the_source_picks_the_file_not_the_field_name():
    files = {"converter": "c.toml", "vehicle": "v.toml", "scenario": "s.csv"}
    # a field that looks like a vehicle section, about the scenario, goes to the scenario's file
    e = from_core(error("engine.inertia_kg_m2", "scenario"), files)
    assert (e.source, e.field, e.value, e.expected) == ("s.csv", "engine.inertia_kg_m2", -1.0, "positive")
    assert from_core(error("time_s", "vehicle"), files).source == "v.toml"
    assert from_core(error("rtol", "options"), files).source == "solver options"
    assert from_core(error("time_s[2]", "drive"), files).source == "drive"
    assert from_core(error("initial flow_m3_s", "initial"), files).source == "initial state"


def test_one_file_is_the_file_of_the_one_input_passed():
    e = from_core(error("flow_area_m2", "converter"), "c.toml", "[geometry].")
    assert (e.source, e.field) == ("c.toml", "[geometry].flow_area_m2")
    assert str(e) == "c.toml: [geometry].flow_area_m2 = -1: expected positive"


def test_a_value_the_core_wrote_as_text_is_shown_as_written():
    # the core quotes a string the way the file does; the message must not quote it again
    e = from_core(_core.CoreInputError("m", "[body].mass_kg", '"1930"', "a number", "vehicle"), "v.toml")
    assert str(e) == 'v.toml: [body].mass_kg = "1930": expected a number'
    e = from_core(
        _core.CoreInputError("m", "[engine].full_load_torque_nm", "7 values", "8 values", "vehicle"), "v.toml"
    )
    assert str(e) == "v.toml: [engine].full_load_torque_nm = 7 values: expected 8 values"
