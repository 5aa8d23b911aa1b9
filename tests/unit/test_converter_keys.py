"""A converter file's keys: a misspelt required key names what was typed (fresh-eyes trial)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tcsim.errors import InputError
from tcsim.models.converter import load_converter

BUNDLED = Path(load_converter("li-sunden-2016").path).read_text(encoding="utf-8")


def _refusal(tmp_path: Path, text: str) -> str:
    path = tmp_path / "c.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as e:
        load_converter(path)
    return str(e.value).removeprefix(f"{path}: ")


def test_a_misspelt_required_key_names_the_key_typed(tmp_path):
    assert "\nfluid_density_kg_m3 = " in BUNDLED
    said = _refusal(tmp_path, BUNDLED.replace("\nfluid_density_kg_m3 = ", "\nfluid_density_kgm3 = ", 1))
    assert said == (
        "[geometry].fluid_density_kg_m3 = 'missing': expected this required key "
        "(the section has the unknown key 'fluid_density_kgm3': misspelt?)"
    )


def test_a_missing_key_alone_and_an_unknown_key_alone(tmp_path):
    said = _refusal(tmp_path, BUNDLED.replace("\nfluid_density_kg_m3 = ", "\n# fluid_density_kg_m3 = ", 1))
    assert said == "[geometry].fluid_density_kg_m3 = 'missing': expected this required key"
    said = _refusal(tmp_path, BUNDLED.replace("\nfluid_density_kg_m3 = ", "\nswirl = 1.0\nfluid_density_kg_m3 = ", 1))
    assert said.startswith("[geometry].swirl = 1: expected a known key of [geometry] (this key is unknown")
