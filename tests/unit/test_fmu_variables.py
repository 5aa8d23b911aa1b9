"""The FMU's variable table (``crates/tcsim-fmu/src/variables.rs``, exposed as
``tcsim._core.fmu_variables``) is the one source of ``modelDescription.xml``: the XML written
today is identical, but for the GUID and the generation time, to the one written before the table
moved into Rust (``tests/data/fmu/``), and every variable in it is a row of the table."""

from __future__ import annotations

import re
from pathlib import Path
from xml.etree import ElementTree

import pytest

from tcsim import _core
from tcsim.io import fmu as tfmu
from tcsim.io import fmu3
from tcsim.models.dynamic import dynamic_model

REFERENCE = Path(__file__).resolve().parents[1] / "data" / "fmu"
CONVERTER = "li-sunden-2016"
MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
CAUSALITIES = ("pump-torque", "speeds", "torques")


def _normalised(xml: str) -> str:
    xml = re.sub(r'guid="[^"]*"', 'guid="GUID"', xml)
    return re.sub(r'generationDateAndTime="[^"]*"', 'generationDateAndTime="TIME"', xml)


@pytest.mark.parametrize("causality", CAUSALITIES)
@pytest.mark.parametrize("model", MODELS)
def test_model_description_is_the_reference(model, causality):
    xml = tfmu.model_description_xml(dynamic_model(CONVERTER, model), causality)
    reference = (REFERENCE / f"{model}-{causality}.xml").read_text(encoding="utf-8")
    assert _normalised(xml) == _normalised(reference)


@pytest.mark.parametrize("causality", CAUSALITIES)
@pytest.mark.parametrize("model", MODELS)
def test_the_description_lists_the_inputs_the_fmu_declares(model, causality):
    # fresh-eyes trial: the description left out turbine_accel_rad_s2 (the export line listed it)
    dyn = dynamic_model(CONVERTER, model)
    declared = [v["name"] for v in tfmu.fmu_variables(dyn, causality) if v["causality"] == "input"]
    for xml in (tfmu.model_description_xml(dyn, causality), fmu3.model_description_xml(dyn, causality)):
        description = ElementTree.fromstring(xml).attrib["description"]
        listed = re.search(r"Inputs ([^;.]*)[;.]", description)
        assert listed is not None and listed.group(1).split(", ") == declared, description


@pytest.mark.parametrize("causality", CAUSALITIES)
@pytest.mark.parametrize("model", MODELS)
def test_every_variable_is_a_row_of_the_table(model, causality):
    dyn = dynamic_model(CONVERTER, model)
    table = _core.fmu_variables(dyn.spec, causality)
    root = ElementTree.fromstring(tfmu.model_description_xml(dyn, causality))
    scalars = root.findall("./ModelVariables/ScalarVariable")
    assert len(scalars) == len(table)
    for sv, row in zip(scalars, table, strict=True):
        real = sv.find("Real")
        assert real is not None
        assert (int(sv.get("valueReference", "-1")), sv.get("name"), sv.get("causality")) == (
            row["vr"],
            row["name"],
            row["causality"],
        )
        assert (real.get("unit"), real.get("start")) == (row["unit"], row["start_text"])
    assert root.get("numberOfEventIndicators") == str(_core.fmu_event_indicators(model))
    assert root.find("ModelExchange").get("modelIdentifier") == _core.FMU_MODEL_IDENTIFIER  # type: ignore[union-attr]


def test_the_table_answers_for_the_tunable_parameters():
    dyn = dynamic_model(CONVERTER, "hrovat-tobler")
    params = [v for v in _core.fmu_variables(dyn.spec, "pump-torque") if v["key"] is not None]
    first = _core.FMU_FIRST_PARAMETER_VR
    assert [p["vr"] for p in params] == list(range(first, first + len(params)))
    angles = [p for p in params if p["unit"] == "rad"]
    assert angles and all(p["display_unit"] == "deg" for p in angles)
    assert {p["name"] for p in params} >= set(_core.ht_parameter_names())


def test_bad_model_or_causality_is_an_input_error():
    spec = dynamic_model(CONVERTER, "table").spec
    with pytest.raises(_core.CoreInputError):
        _core.fmu_variables(spec, "turbine-torque")
    with pytest.raises(_core.CoreInputError):
        _core.fmu_variables({**spec, "kind": "lockup"}, "speeds")
