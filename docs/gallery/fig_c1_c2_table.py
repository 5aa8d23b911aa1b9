"""Gallery: thesis figures C.1 and C.2, the steady-state look-up table of Appendix C (Table C.1) as the
table model uses it: torque ratio and capacity factor against speed ratio.

The points are Table C.1 (bundled converter ``li-sunden-2016``); the line is the table model's steady
state at 2000 rpm between them (tcsim interpolates TR and CF linearly inside the table).

Run it::

    python docs/gallery/fig_c1_c2_table.py [--fast] [--out DIR]

writes ``fig_c_1.png`` (torque ratio), ``fig_c_2.png`` (capacity factor) and their data as CSV;
``--fast`` computes 21 speed ratios instead of 201 (plus the table's own).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from _common import parse_args, save, tidy

from tcsim.models.converter import load_converter
from tcsim.plots.common import plt
from tcsim.plots.styles import model_line
from tcsim.steady import characterise

COLUMNS = ["speed_ratio", "torque_ratio", "capacity_factor_nm_s2"]


def curves(fast: bool) -> dict[str, pd.DataFrame]:
    """The table model's line and Table C.1's points, by legend label."""
    conv = load_converter("li-sunden-2016")
    assert conv.characteristic is not None
    sr, tr, cf = conv.characteristic.arrays()
    grid = np.unique(np.round(np.concatenate([np.linspace(0.0, 1.0, 21 if fast else 201), sr]), 12))
    return {
        "SS table model, 2000 rpm": characterise(conv, "table", 2000.0, grid),
        "Table C.1": pd.DataFrame({"speed_ratio": sr, "torque_ratio": tr, "capacity_factor_nm_s2": cf}),
    }


def plot(data: dict[str, pd.DataFrame], column: str, ylabel: str):
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    line, points = data["SS table model, 2000 rpm"], data["Table C.1"]
    ax.plot(line["speed_ratio"], line[column], **model_line("table", label="SS table model, 2000 rpm"))
    ax.plot(points["speed_ratio"], points[column], "o", color="k", mfc="none", label="Table C.1", zorder=3)
    ax.set_xlabel("Speed ratio [-]")
    ax.set_ylabel(ylabel)
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def main() -> None:
    args = parse_args(__doc__, "gallery_table")
    data = curves(args.fast)
    frame = tidy(data, COLUMNS)
    save(plot(data, "torque_ratio", "Torque ratio [-]"), args.out, "fig_c_1", frame, "Figure C.1: Torque Ratio")
    fig = plot(data, "capacity_factor_nm_s2", "Capacity factor [N·m/(rad/s)²]")
    save(fig, args.out, "fig_c_2", frame, "Figure C.2: Capacity Factor")


if __name__ == "__main__":
    main()
