"""The public surface survives the layering of issue 9: every name of ``tcsim.__all__``, every dotted
name the README and ``docs/*.md`` document, and each command of the CLI run once in-process on
bundled data."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

import tcsim
from tcsim import transient as tr
from tcsim.cli import main
from tcsim.io import fmu as fmu_io

REPO = Path(__file__).resolve().parents[2]
MEASUREMENT = REPO / "tests" / "golden" / "data" / "takeoff_measurement.csv"

#: Dotted names of README.md and docs/*.md (modules and the names in them).
DOCUMENTED = [
    "tcsim._core.launch_runs",
    "tcsim._core.transient_runs",
    "tcsim._core.transient_batch",
    "tcsim._core.transient_event_kinds",
    "tcsim._core.output_value_rules",
    "tcsim._core.TransientRun",
    "tcsim._core.TransientEvent",
    "tcsim._core.RunError",
    "tcsim.characterise",
    "tcsim.coupling_point",
    "tcsim.dynamic_model",
    "tcsim.hrovat_tobler_steady_state",
    "tcsim.load_converter",
    "tcsim.simulate",
    "tcsim.simulate_batch",
    "tcsim.simulate_columns",
    "tcsim.transient.simulate_columns",
    "tcsim.transient.BatchColumns",
    "tcsim.steady.hrovat_tobler_steady_state",
    "tcsim.steady_state",
    "tcsim.steady.steady_state",
    "tcsim.transient.isolated_takeoff",
    "tcsim.transient.simulate",
    "tcsim.transient.dynamic_model",
    "tcsim.transient.PumpTorqueTurbineSpeed",
    "tcsim.transient.Speeds",
    "tcsim.transient.PumpTorqueLoad",
    "tcsim.transient.DynamicModel",
    "tcsim.transient.TransientResult",
    "tcsim.replay.replay",
    "tcsim.replay.write_replay",
    "tcsim.replay.error_metrics",
    "tcsim.replay.smoothed_rate",
    "tcsim.fmu.export_fmu",
    "tcsim.fmu.model_description_xml",
    "tcsim.fitting.fit_hrovat_tobler",
    "tcsim.shape_fit.fit_shape_effects",
    "tcsim.shape_fit.mass_matrix_bound",
    "tcsim.shape_fit.measured_effective_torques",
    "tcsim.shape_fit.plot_shape_effect_sweep",
    "tcsim.shape_fit.shape_effect_sweep",
    "tcsim.shape_fit.shape_fit_command",
    "tcsim.shape_fit.sweep_minima",
    "tcsim.shape_fit.smoothed_rate",
    "tcsim.models.design.design_geometry",
    "tcsim.models.design.design_table",
    "tcsim.study.run_study",
    "tcsim.study.default_definition",
    "tcsim.measurement.read_measurement",
    "tcsim.measurement.parse_channel_map",
]


def resolve(dotted: str):
    """The object a dotted name names: the longest importable module prefix, then attributes."""
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ModuleNotFoundError:
            continue
        for attr in parts[i:]:
            obj = getattr(obj, attr)
        return obj
    raise ModuleNotFoundError(dotted)


@pytest.mark.parametrize("name", tcsim.__all__)
def test_every_name_of_all_imports(name):
    assert getattr(tcsim, name) is not None
    exec(f"from tcsim import {name}", {})  # noqa: S102 - the import statement itself


def names_in_docs() -> set[str]:
    """Every dotted ``tcsim.…`` name written in README.md and docs/*.md (so that a page added or
    edited cannot name what does not exist)."""
    pattern = re.compile(r"(?<![\w/.-])tcsim(?:\.[A-Za-z_]\w*)+")
    pages = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
    return {m.group(0) for page in pages for m in pattern.finditer(page.read_text(encoding="utf-8"))}


def test_the_docs_name_the_api_they_describe():
    found = names_in_docs()
    assert {"tcsim.operating_point", "tcsim.characterise", "tcsim.transient"} <= found, sorted(found)


@pytest.mark.parametrize("dotted", sorted(set(DOCUMENTED) | names_in_docs()))
def test_documented_names_resolve(dotted):
    assert resolve(dotted) is not None


@pytest.mark.parametrize("module", ["transient", "replay", "fmu", "fitting", "shape_fit", "steady", "study"])
def test_facades_export_what_all_says(module):
    mod = importlib.import_module(f"tcsim.{module}")
    assert all(hasattr(mod, name) for name in mod.__all__)


def test_readme_python_example():
    df = tcsim.characterise("li-sunden-2016", model="hrovat-tobler")
    conv = tcsim.load_converter("li-sunden-2016")
    assert "hrovat-tobler" in conv.models and 0 < tcsim.coupling_point(conv) < 1
    out = tcsim.hrovat_tobler_steady_state(conv.core_geometry(), [209.4] * 3, [0.0, 100.0, 200.0])
    assert len(df) > 100 and len(out["flow_m3_s"]) == 3
    r = tcsim.simulate("li-sunden-2016", tr.isolated_takeoff(), model="hrovat-tobler")
    assert len(r.frame()) > 0 and isinstance(r.events, list)
    m = tcsim.dynamic_model("li-sunden-2016", "quasi-dynamic")
    runs = tcsim.simulate_batch([m.with_shape_effects(s, s) for s in (0, 0.1)], [tr.isolated_takeoff()])
    assert len(runs) == 2
    ss = tcsim.steady_state("li-sunden-2016", "table", [209.4, -100.0], [[0.0], [300.0]])
    assert list(ss.columns) == list(tcsim.characterise("li-sunden-2016", model="table").columns) and len(ss) == 4


def run(*args: object) -> None:
    assert main([str(a) for a in args]) == 0, args


def test_cli_converters(capsys):
    run("converters")
    assert "li-sunden-2016" in capsys.readouterr().out


def test_cli_characterise(tmp_path):
    run("characterise", "li-sunden-2016", "--out", tmp_path)
    assert (tmp_path / "characteristic.csv").is_file()


def test_cli_fit(tmp_path):
    run("fit", "li-sunden-2016", "--target", "li-sunden-2016", "--free", "friction_loss", "--out", tmp_path)
    assert (tmp_path / "fitted.toml").is_file() and (tmp_path / "fit_report.md").is_file()


def test_cli_study(tmp_path):
    run("study", "li-sunden-2016", "--out", tmp_path)
    assert (tmp_path / "study.csv").is_file()


def test_cli_replay(tmp_path):
    run("replay", "li-sunden-2016", MEASUREMENT, "--out", tmp_path)
    assert (tmp_path / "metrics.csv").is_file() and (tmp_path / "events.csv").is_file()


def test_cli_fit_shapes(tmp_path):
    run("fit-shapes", "li-sunden-2016", MEASUREMENT, "--out", tmp_path)
    assert (tmp_path / "shape_fit.json").is_file() and (tmp_path / "shape_sweep.csv").is_file()


def test_cli_launch(tmp_path):
    run("launch", "--model", "table", "--out", tmp_path)
    assert (tmp_path / "summary.csv").is_file() and (tmp_path / "table.csv").is_file()


def test_cli_export_fmu(tmp_path, monkeypatch, fmu_library):
    monkeypatch.setenv(fmu_io.LIBRARY_ENV, str(fmu_library))
    run("export-fmu", "li-sunden-2016", "--model", "table", "--out", tmp_path / "table.fmu")
    assert (tmp_path / "table.fmu").is_file()
