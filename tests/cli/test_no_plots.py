"""``--no-plots`` (issue 16 item 7): the commands whose figures are an aid write their tables and
files but no figure, say so, and the tables equal those of a run with plots."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from torque_steps import load_response

ROOT = Path(__file__).resolve().parents[2]
TABLE_C1 = ROOT / "tests" / "data" / "converters" / "li_sunden_2016_table_c1.csv"
TAKEOFF = ROOT / "tests" / "golden" / "data" / "takeoff_measurement.csv"


def _inputs(tmp: Path) -> dict[str, list[str]]:
    """Each command's arguments (short runs), by command."""
    t = np.arange(0.0, 8.0, 0.01)
    pd.DataFrame({"time_s": t, "engine_torque_nm": load_response(t - 0.05)}).to_csv(tmp / "ecm.csv", index=False)
    pd.DataFrame({"time_s": t, "engine_torque_nm": load_response(t)}).to_csv(tmp / "dyno.csv", index=False)
    pd.DataFrame({"time_s": [0.0, 10.0, 20.0], "vehicle_speed_m_s": [0.0, 8.0, 0.0]}).to_csv(
        tmp / "cycle.csv", index=False
    )
    scenario = "time_s,accelerator_pedal,brake_pedal\n0,0,1\n1,0,1\n1.05,1,0\n3,1,0\n"
    (tmp / "scenario.csv").write_text(scenario, encoding="utf-8")
    return {
        "characterise": ["characterise", "li-sunden-2016", "--model", "table"],
        "replay": ["replay", "li-sunden-2016", str(TAKEOFF), "--model", "table"],
        "launch": ["launch", "--scenario", str(tmp / "scenario.csv"), "--model", "table"],
        "drive": ["drive", "--cycle", str(tmp / "cycle.csv"), "--model", "table"],
        "fit": ["fit", "li-sunden-2016", "--target", str(TABLE_C1), "--free", "friction_loss"],
        "torque-estimate": ["torque-estimate", str(tmp / "ecm.csv"), str(tmp / "dyno.csv")],
        "design": ["design", "li-sunden-2016-design"],
        "design-study": ["design-study", "li-sunden-2016-design", "--sweep", "squash_ratio=0:0.2:2"],
    }


@pytest.mark.parametrize(
    "command", ["characterise", "replay", "launch", "drive", "fit", "torque-estimate", "design", "design-study"]
)
def test_no_plots_writes_every_file_but_the_figures(cli, tmp_path, command):
    args = _inputs(tmp_path)[command]
    with_plots = cli(*args, "--out", tmp_path / "with")
    without = cli(*args, "--no-plots", "--out", tmp_path / "without")
    assert with_plots.code == 0 and without.code == 0, (with_plots.stderr, without.stderr)
    drawn = {p.name for p in (tmp_path / "with").iterdir()}
    written = {p.name for p in (tmp_path / "without").iterdir()}
    figures = {n for n in drawn if n.endswith(".png")}
    assert figures, drawn  # the command draws figures by default
    assert written == drawn - figures
    if command == "design":  # its one-page report links only the figures that exist
        assert "![" not in (tmp_path / "without" / "report.md").read_text(encoding="utf-8")
    assert "and plots" not in without.stdout and ".png" not in without.stdout
    for name in written:
        if name.endswith(".csv"):
            a, b = pd.read_csv(tmp_path / "with" / name), pd.read_csv(tmp_path / "without" / name)
            pd.testing.assert_frame_equal(a, b, check_exact=True, obj=name)
