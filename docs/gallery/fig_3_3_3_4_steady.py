"""Gallery: thesis figures 3.3 and 3.4, the steady-state torque ratio and capacity factor of the models
against the manufacturer's data (Li & Sundén 2016, §3.2.1).

The models run at a fixed pump speed of 2000 rpm over speed ratios 0 to 1 (tcsim's closed-form steady
state; the thesis ran its Simulink models until they settled). The "manufacturer data" are the points
of the thesis's Table C.1. The quasi-dynamic (Drenth) model's steady state is its table by
construction, so one line is both. Hrovat & Tobler runs with the geometry tcsim fitted to Table C.1
(``li-sunden-2016-fitted``) and with Table D.1's reference geometry (``li-sunden-2016``).

Run it::

    python docs/gallery/fig_3_3_3_4_steady.py [--fast] [--out DIR]

writes ``fig_3_3.png`` (torque ratio), ``fig_3_4.png`` (capacity factor) and their data as CSV;
``--fast`` computes 21 speed ratios instead of 101 (plus Table C.1's own).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from _common import parse_args, save, tidy

from tcsim.models.converter import load_converter
from tcsim.plots.common import plt
from tcsim.plots.styles import model_line
from tcsim.steady import characterise, coupling_point

PUMP_SPEED_RPM = 2000.0
COLUMNS = ["speed_ratio", "torque_ratio", "capacity_factor_nm_s2"]


def curves(fast: bool) -> tuple[dict[str, pd.DataFrame], float | None]:
    """The plotted curves by legend label, and the fitted converter's coupling point."""
    fitted, table_d1 = load_converter("li-sunden-2016-fitted"), load_converter("li-sunden-2016")
    assert fitted.characteristic is not None
    table_sr, table_tr, table_cf = fitted.characteristic.arrays()
    sr = np.unique(np.round(np.concatenate([np.linspace(0.0, 1.0, 21 if fast else 101), table_sr]), 12))
    out = {
        "Drenth (quasi-dynamic) = SS table model": characterise(fitted, "table", PUMP_SPEED_RPM, sr),
        "H&T model, geometry fitted to Table C.1": characterise(fitted, "hrovat-tobler", PUMP_SPEED_RPM, sr),
        "H&T model, Table D.1 geometry": characterise(table_d1, "hrovat-tobler", PUMP_SPEED_RPM, sr),
        "Manufacturer data (Table C.1)": pd.DataFrame(
            {"speed_ratio": table_sr, "torque_ratio": table_tr, "capacity_factor_nm_s2": table_cf}
        ),
    }
    return out, coupling_point(fitted)


def plot(out_dir, data: dict[str, pd.DataFrame], column: str, ylabel: str, cp: float | None):
    """One quantity against SR: the model lines, the table's points as circles."""
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    styles = {"Drenth": "table", "H&T model, geometry": "hrovat-tobler"}
    for i, (label, df) in enumerate(data.items()):
        if label.startswith("Manufacturer"):
            ax.plot(df["speed_ratio"], df[column], "o", color="k", mfc="none", label=label, zorder=3)
            continue
        key = next((model for prefix, model in styles.items() if label.startswith(prefix)), label)
        ax.plot(df["speed_ratio"], df[column], **model_line(key, i, label=label, y=df[column]))
    if cp is not None:
        ax.axvline(cp, color="0.6", ls=":", lw=1, label=f"H&T coupling point, SR {cp:.3f}")
    ax.set_xlabel("Speed ratio [-]")
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def main() -> None:
    args = parse_args(__doc__, "gallery_steady")
    data, cp = curves(args.fast)
    frame = tidy(data, COLUMNS)
    fig = plot(args.out, data, "torque_ratio", "Torque ratio [-]", cp)
    save(fig, args.out, "fig_3_3", frame, "Figure 3.3: Comparison of Torque Ratio (2000 rpm)")
    fig = plot(args.out, data, "capacity_factor_nm_s2", "Capacity factor [N·m/(rad/s)²]", cp)
    save(fig, args.out, "fig_3_4", frame, "Figure 3.4: Comparison of Capacity Factor (2000 rpm)")


if __name__ == "__main__":
    main()
