"""``tcsim init``: every template is accepted by its command as written, its values are the bundled
data's, ``--from TABLE`` makes a converter whose ``[characteristic]`` is the table (the table model runs
at once, the others name the missing section), and an existing file is never replaced without ``--force``.
"""

from __future__ import annotations

import re
import tomllib

import numpy as np
import pandas as pd
import pytest

from conftest import C1_CF, C1_SR, C1_TR, CONVERTER_DATA
from tcsim import _core
from tcsim.io.scenario import read_scenario
from tcsim.io.templates import KINDS, TEMPLATE_CONVERTER, TEMPLATE_DESIGN, TODO_SECTIONS
from tcsim.models.converter import load_converter
from tcsim.models.design_file import load_design_file
from tcsim.models.vehicle import DEFAULT_VEHICLE, load_vehicle
from tcsim.simulation.scenarios import flip_flop

HMMWV = CONVERTER_DATA / "chrono_hmmwv.csv"

#: Each template, the file it is written to, and the command that must accept it as written (fast options).
ACCEPTED_BY = {
    "converter": ("c.toml", ["characterise", "{file}", "--model", "hrovat-tobler"]),
    "vehicle": ("v.toml", ["launch", "{file}", "--model", "table"]),
    "scenario": ("s.csv", ["launch", "--scenario", "{file}", "--model", "table"]),
    "study": ("st.toml", ["study", "{file}"]),
    "monte-carlo": ("mc.toml", ["monte-carlo", "{file}", "--no-plots"]),
    "design": ("d.toml", ["design", "{file}"]),
}


def one_error_line(run) -> str:
    lines = run.stderr.strip().splitlines()
    assert run.code == 2 and len(lines) == 1 and lines[0].startswith("error: "), run.stderr
    return lines[0]


@pytest.mark.parametrize("kind", KINDS)
def test_each_template_is_accepted_by_its_command_as_written(cli, tmp_path, kind):
    name, command = ACCEPTED_BY[kind]
    r = cli("init", kind, "--out", name, cwd=tmp_path)
    assert r.code == 0, r.stderr
    assert (tmp_path / name).is_file() and f"tcsim {command[0]}" in r.stdout
    r = cli(*[a.format(file=name) for a in command], "--out", "run", cwd=tmp_path)
    assert r.code == 0, r.stderr
    assert (tmp_path / "run" / "tcsim-manifest.json").is_file()


def test_default_file_names(cli, tmp_path):
    for kind in KINDS:
        assert cli("init", kind, cwd=tmp_path).code == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["converter.toml", "vehicle.toml", "scenario.csv", "study.toml", "monte-carlo.toml", "design.toml"]
    )


def test_template_values_are_the_bundled_ones(cli, tmp_path):
    for kind, (name, _) in ACCEPTED_BY.items():
        assert cli("init", kind, "--out", name, cwd=tmp_path).code == 0
    bundled = tomllib.loads(open(load_converter(TEMPLATE_CONVERTER).path, encoding="utf-8").read())
    written = tomllib.loads((tmp_path / "c.toml").read_text(encoding="utf-8"))
    for section in ("characteristic", "inertia", "geometry", "quasi_dynamic", "sources"):
        assert written[section] == bundled[section]
    study = tomllib.loads((tmp_path / "st.toml").read_text(encoding="utf-8"))
    assert study["geometry"] == bundled["geometry"] and "characteristic" not in study
    assert load_vehicle(tmp_path / "v.toml").core_spec() == load_vehicle(DEFAULT_VEHICLE).core_spec()
    design, reference = load_design_file(tmp_path / "d.toml"), load_design_file(TEMPLATE_DESIGN)
    assert (design.design, design.metal_inertia, design.losses) == (
        reference.design,
        reference.metal_inertia,
        reference.losses,
    )
    scenario, builtin = read_scenario(tmp_path / "s.csv"), flip_flop()
    for key in ("time_s", "accelerator_pedal", "brake_pedal"):
        np.testing.assert_array_equal(getattr(scenario, key), getattr(builtin, key))


def test_every_key_has_a_comment_with_its_unit(cli, tmp_path):
    assert cli("init", "converter", "--out", "c.toml", cwd=tmp_path).code == 0
    lines = (tmp_path / "c.toml").read_text(encoding="utf-8").splitlines()
    for i, line in enumerate(lines):
        m = re.match(r"(\w+_(kg_m2|m2|m|deg|kg_m3|nm_s2)) = ", line)
        if m:
            j = i - 1
            while lines[j].startswith("#   "):  # a wrapped comment: its first line gives the unit
                j -= 1
            assert lines[j].split(";")[0] in ("# kg·m²", "# m²", "# m", "# °", "# kg/m³", "# N·m/(rad/s)²"), line


def test_from_table_runs_the_table_model_and_names_what_the_others_need(cli, tmp_path):
    r = cli("init", "converter", "--from", HMMWV, "--out", "c.toml", cwd=tmp_path)
    assert r.code == 0, r.stderr
    assert "TODO in c.toml: [inertia], [geometry], [quasi_dynamic]" in r.stdout
    text = (tmp_path / "c.toml").read_text(encoding="utf-8")
    todo = [line for line in text.splitlines() if line.startswith("# TODO:")]
    assert len(todo) == 1 and all(f"[{s}]" in todo[0] for s in TODO_SECTIONS)
    assert "Project Chrono" in text  # the table's own comments, its source, are kept
    r = cli("characterise", "c.toml", "--model", "table", "--out", "from_toml", cwd=tmp_path)
    assert r.code == 0, r.stderr
    r = cli("characterise", HMMWV, "--model", "table", "--out", "from_csv", cwd=tmp_path)
    assert r.code == 0, r.stderr
    a, b = (pd.read_csv(tmp_path / d / "characteristic.csv") for d in ("from_toml", "from_csv"))
    pd.testing.assert_frame_equal(a, b, rtol=1e-12, atol=0.0)
    line = one_error_line(cli("characterise", "c.toml", "--model", "hrovat-tobler", "--out", "x", cwd=tmp_path))
    assert line == "error: c.toml: [geometry] = 'missing': expected a [geometry] section for the hrovat-tobler model"
    assert not (tmp_path / "x").exists()


def test_from_table_keeps_the_tables_capacity_convention(cli, tmp_path):
    assert cli("init", "converter", "--from", HMMWV, "--out", "c.toml", cwd=tmp_path).code == 0
    written = tomllib.loads((tmp_path / "c.toml").read_text(encoding="utf-8"))["characteristic"]
    table = pd.read_csv(HMMWV, comment="#")
    assert written == {k: table[k].tolist() for k in table.columns}


def test_placeholders_uncommented_give_a_converter_with_every_model(cli, tmp_path):
    assert cli("init", "converter", "--from", HMMWV, "--out", "c.toml", cwd=tmp_path).code == 0
    lines = (tmp_path / "c.toml").read_text(encoding="utf-8").splitlines()
    uncommented = [
        line[2:] if re.match(r"# (\[\w+\]$|\w+ = )", line) else line for line in lines
    ]  # the commented-out sections and keys, not their notes
    (tmp_path / "full.toml").write_text("\n".join(uncommented) + "\n", encoding="utf-8")
    assert load_converter(tmp_path / "full.toml").models == ("table", "hrovat-tobler", "quasi-dynamic")


def test_from_vtcc_and_from_a_converter(cli, tmp_path):
    mp1000 = np.asarray(_core.cf_to_capacity("mp1000_nm", np.array(C1_CF))).tolist()
    vtcc = tmp_path / "c1.vtcc"
    rows = "".join(f"{s},{t},{m!r}\n" for s, t, m in zip(C1_SR, C1_TR, mp1000, strict=True))
    vtcc.write_text("Speed Ratio, Torque Ratio, MP1000\n" + rows)
    for source in (vtcc, "li-sunden-2016"):
        assert cli("init", "converter", "--from", source, "--out", "c.toml", "--force", cwd=tmp_path).code == 0
        conv = load_converter(tmp_path / "c.toml")
        assert conv.models == ("table", "quasi-dynamic")
        np.testing.assert_allclose(conv.characteristic.capacity_factor_nm_s2, C1_CF, rtol=1e-11)
        np.testing.assert_array_equal(conv.characteristic.torque_ratio, C1_TR)


def test_from_a_torque_dependent_table(cli, tmp_path):
    rows = [
        f"{s},{1 + (t - 1) * (1 - k)!r},{c * (1 - k * (1 - s))!r},{torque}"
        for torque, k in ((100.0, 0.0), (300.0, 0.2))
        for s, t, c in zip(C1_SR, C1_TR, C1_CF, strict=True)
    ]
    table = tmp_path / "two.csv"
    table.write_text("speed_ratio,torque_ratio,capacity_factor_nm_s2,input_torque_nm\n" + "\n".join(rows) + "\n")
    assert cli("init", "converter", "--from", table, "--out", "c.toml", cwd=tmp_path).code == 0
    assert (tmp_path / "c.toml").read_text(encoding="utf-8").count("\n[[characteristic]]\n") == 2
    read, written = load_converter(table).characteristic, load_converter(tmp_path / "c.toml").characteristic
    assert len(written.tables()) == 2
    for a, b in zip(read.tables(), written.tables(), strict=True):
        assert a.input_torque_nm == b.input_torque_nm
        np.testing.assert_array_equal(a.torque_ratio, b.torque_ratio)
        np.testing.assert_allclose(a.capacity_factor_nm_s2, b.capacity_factor_nm_s2, rtol=1e-14)


def test_an_existing_file_is_kept_unless_force(cli, tmp_path):
    target = tmp_path / "c.toml"
    target.write_text("# mine\n", encoding="utf-8")
    line = one_error_line(cli("init", "converter", "--out", "c.toml", cwd=tmp_path))
    expected = "expected a file that does not exist yet (--force replaces it)"
    assert line == f"error: command line: --out = 'c.toml': {expected}"
    assert target.read_text(encoding="utf-8") == "# mine\n"
    assert cli("init", "converter", "--out", "c.toml", "--force", cwd=tmp_path).code == 0
    assert "[geometry]" in target.read_text(encoding="utf-8")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.toml"]  # no temporary file left


def test_bad_invocations_are_one_line_and_write_nothing(cli, tmp_path):
    table = tmp_path / "t.csv"
    table.write_bytes(HMMWV.read_bytes())
    cases = {
        ("init", "vehicel"): (
            "KIND = 'vehicel': expected one of converter, vehicle, scenario, study, monte-carlo, design"
        ),
        ("init", "vehicle", "--from", "t.csv"): "--from = 't.csv'",
        ("init", "converter", "--from", "t.csv", "--out", "t.csv", "--force"): "--out = 't.csv'",
        ("init", "converter", "--from", "nope.csv"): "nope.csv",
        ("init", "converter", "--out", ""): "--out = ''",
    }
    for args, expected in cases.items():
        assert expected in one_error_line(cli(*args, cwd=tmp_path)), args
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]
    assert table.read_bytes() == HMMWV.read_bytes()


@pytest.mark.parametrize("kind", ["converter", "vehicle", "design"])
def test_the_suggested_command_names_the_file_as_given(cli, tmp_path, kind):
    """``tcsim init KIND --out 'sub dir/f.toml'`` suggests a command that names that path (quoted for the
    shell), not the bare file name, which is wrong outside the folder; the file's ``name`` is its stem."""
    target = "sub dir/f.toml"
    r = cli("init", kind, "--out", target, cwd=tmp_path)
    assert r.code == 0, r.stderr
    said = " ".join(r.stdout.split())
    assert "run it with: tcsim " in said and "'sub dir/f.toml'" in said, said
    assert tomllib.loads((tmp_path / target).read_text(encoding="utf-8"))["name"] == "f"
