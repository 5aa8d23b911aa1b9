"""The bad-input catalogue: every case gives exit code 2, one message naming the file, the field
and the value, no traceback, and no output written."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import C1_CF, C1_SR, C1_TR

BUNDLED = (
    Path(__file__).resolve().parents[2] / "python" / "tcsim" / "data" / "converters" / "li-sunden-2016.toml"
).read_text()


def table_csv(header="speed_ratio,torque_ratio,capacity_factor_nm_s2", rows=None) -> str:
    rows = rows or [f"{s},{t},{c!r}" for s, t, c in zip(C1_SR, C1_TR, C1_CF)]
    return header + "\n" + "\n".join(rows) + "\n"


def edit(old: str, new: str) -> str:
    assert old in BUNDLED, old
    return BUNDLED.replace(old, new, 1)


C1_ROWS = [f"{s},{t},{c!r}" for s, t, c in zip(C1_SR, C1_TR, C1_CF)]

# name: (file name, content, extra args, words the message must contain: field and value)
CASES = {
    "toml syntax error": ("bad.toml", BUNDLED.replace("[inertia]", "[inertia", 1), [], ["(syntax)"]),
    "missing field": ("bad.toml", edit("turbine_kg_m2 = 0.056\n", ""), [], ["[inertia].turbine_kg_m2", "missing"]),
    "unknown key": (
        "bad.toml",
        edit("friction_loss = 0.2\n", "friction_loss = 0.2\nfriction_los = 0.3\n"),
        [],
        ["[geometry].friction_los", "0.3", "unknown"],
    ),
    "negative inertia": (
        "bad.toml",
        edit("pump_kg_m2 = 0.109", "pump_kg_m2 = -0.109"),
        ["--model", "table"],
        ["[inertia].pump_kg_m2", "-0.109"],
    ),
    "non-monotonic speed ratio (toml)": (
        "bad.toml",
        edit("0.00, 0.10, 0.20, 0.30", "0.00, 0.10, 0.30, 0.20"),
        [],
        ["[characteristic].speed_ratio[3]", "0.2", "strictly increasing"],
    ),
    "nan in toml table": (
        "bad.toml",
        edit("2.14, 1.99, 1.84", "2.14, nan, 1.84"),
        [],
        ["[characteristic].torque_ratio[1]", "nan"],
    ),
    "array length mismatch": (
        "bad.toml",
        edit("2.14, 1.99, 1.84", "2.14, 1.99"),
        [],
        ["[characteristic].torque_ratio", "12 values"],
    ),
    "angle beyond 90 degrees": (
        "bad.toml",
        edit("stator_exit_angle_deg = 60.0", "stator_exit_angle_deg = 95.0"),
        [],
        ["[geometry].stator_exit_angle_deg", "95"],
    ),
    "string where a number is expected": (
        "bad.toml",
        edit("flow_area_m2 = 0.01", 'flow_area_m2 = "0.01"'),
        [],
        ["[geometry].flow_area_m2", "0.01"],
    ),
    "no losses": (
        "bad.toml",
        edit(
            "pump_shock_loss = 1.0\nturbine_shock_loss = 1.0\nstator_shock_loss = 1.0\nfriction_loss = 0.2",
            "pump_shock_loss = 0.0\nturbine_shock_loss = 0.0\nstator_shock_loss = 0.0\nfriction_loss = 0.0",
        ),
        [],
        ["[geometry].friction_loss", "0"],
    ),
    "unknown source key": (
        "bad.toml",
        edit("[sources]\n", '[sources]\n"geometry.radius" = "made up"\n'),
        [],
        ["[sources]", "geometry.radius"],
    ),
    "non-monotonic speed ratio (csv)": (
        "bad.csv",
        table_csv(rows=C1_ROWS[:3] + [C1_ROWS[5], C1_ROWS[4]] + C1_ROWS[6:]),
        [],
        ["line 6, speed_ratio", "0.4", "strictly increasing"],
    ),
    "nan in csv": (
        "bad.csv",
        table_csv(rows=C1_ROWS[:2] + ["0.2,nan,3.228e-3"] + C1_ROWS[3:]),
        [],
        ["line 4, torque_ratio", "nan"],
    ),
    "text in csv": (
        "bad.csv",
        table_csv(rows=C1_ROWS[:2] + ["0.2,1.84,abc"] + C1_ROWS[3:]),
        [],
        ["line 4, capacity_factor_nm_s2", "abc"],
    ),
    "non-positive capacity in drive": (
        "bad.csv",
        table_csv(rows=C1_ROWS[:4] + ["0.4,1.56,-3.112e-3"] + C1_ROWS[5:]),
        [],
        ["line 6, capacity_factor_nm_s2", "-0.003112", "positive"],
    ),
    "zero torque ratio in drive": (
        "bad.csv",
        table_csv(rows=["0.0,0.0,3.272e-3"] + C1_ROWS[1:]),
        [],
        ["line 2, torque_ratio", "0"],
    ),
    "two capacity columns": (
        "bad.csv",
        table_csv(header="speed_ratio,torque_ratio,capacity_factor_nm_s2,mp1000_nm", rows=[r + ",1" for r in C1_ROWS]),
        [],
        ["line 1 (header)", "exactly one capacity column"],
    ),
    "no capacity column": (
        "bad.csv",
        table_csv(header="speed_ratio,torque_ratio,k_factor", rows=C1_ROWS),
        [],
        ["line 1 (header)", "k_factor"],
    ),
    "wrong column count": (
        "bad.csv",
        table_csv(rows=C1_ROWS[:5] + ["0.5,1.43"] + C1_ROWS[6:]),
        [],
        ["line 7", "0.5,1.43"],
    ),
    "vtcc without its header": (
        "bad.vtcc",
        "ratio,mu,torque\n0,1.8,377\n1,1,0\n",
        [],
        ["line 1 (header)", "ratio,mu,torque"],
    ),
    "missing section for the model": (
        "table.csv",
        table_csv(),
        ["--model", "hrovat-tobler"],
        ["[geometry]", "missing", "hrovat-tobler"],
    ),
    "unknown model": ("table.csv", table_csv(), ["--model", "lookup"], ["--model", "lookup"]),
    "negative pump speed": ("table.csv", table_csv(), ["--pump-speed-rpm", "-100"], ["--pump-speed-rpm", "-100"]),
    "unknown converter": (None, None, [], ["no-such-converter", "bundled converter"]),
    "unsupported file type": ("conv.json", "{}", [], ["file type", ".json"]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_input_gives_exit_2_and_one_clear_message(cli, tmp_path, case):
    name, content, extra, words = CASES[case]
    if name is None:
        target = "no-such-converter"
    else:
        target = tmp_path / name
        target.write_text(content)
    out = tmp_path / "out"
    r = cli("characterise", target, *extra, "--out", out)
    assert r.code == 2, (r.code, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr + r.stdout
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, lines
    msg = lines[0]
    assert msg.startswith("error: ")
    if case in ("unknown model", "negative pump speed"):
        assert "command line" in msg
    else:
        assert str(target) in msg, msg
    for w in words:
        assert w in msg, f"{w!r} not in {msg!r}"
    assert "expected" in msg
    assert not out.exists(), "no output may be written on bad input"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")], "no staging directory left behind"


def test_catalogue_is_large_enough():
    assert len(CASES) >= 10


def test_usage_error_is_exit_2(cli, tmp_path):
    r = cli("characterise", "li-sunden-2016", "--no-such-option", "--out", tmp_path / "o")
    assert r.code == 2
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "o").exists()
