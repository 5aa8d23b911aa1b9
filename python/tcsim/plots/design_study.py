"""The figure of ``tcsim design-study`` (docs/design.md, "Design studies"): stall torque ratio against
the isolated take-off's effective-TR dip, one point per design, the Pareto front marked."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from .common import finish_figure, mpl_text, plt

#: The file name of the Pareto figure.
PARETO_FILE = "pareto.png"


def plot_design_pareto(study: pd.DataFrame, out_dir: Path, title: str) -> Path:
    """Stall TR (-) against take-off dip (-) of the designs of ``study`` (rows of
    :func:`tcsim.analysis.design_study.design_study`; rows without figures left out), the Pareto
    front joined and marked; written as :data:`PARETO_FILE` in ``out_dir``."""
    fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
    ok = study[study["error"] == ""]
    ax.scatter(ok["takeoff_effective_tr_dip"], ok["stall_torque_ratio"], s=8, c="0.6", label="designs")
    front = ok[ok["pareto_front"]].sort_values("takeoff_effective_tr_dip")
    ax.plot(
        front["takeoff_effective_tr_dip"],
        front["stall_torque_ratio"],
        "o-",
        color="C3",
        ms=4,
        lw=1.2,
        label=mpl_text("Pareto front (higher stall TR, smaller dip)"),
    )
    ax.set_ylabel("Stall torque ratio [-]")
    return finish_figure(fig, ax, Path(out_dir) / PARETO_FILE, title, xlabel="Take-off effective-TR dip [-]")
