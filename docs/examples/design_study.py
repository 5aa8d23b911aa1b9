"""Worked example (e): a design study (Li & Sundén 2016, chapter 4 and Appendix D).

The bundled design ``li-sunden-2016-design`` (the circular torus through Table D.1) with its pump's
exit radius and exit blade angle swept over a 3 × 3 grid: each design's converter is derived from
the hardware (fluid length, shape effects, fluid inertias), its characteristic computed, an isolated
take-off and a vehicle launch run; the script prints the figures and draws stall torque ratio
against the take-off's dip of the effective torque ratio, the Pareto front joined.

Run it::

    python docs/examples/design_study.py [--out DIR] [--fast]

``--fast`` (what CI runs) sweeps a 2 × 2 grid, the corners of the full one.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import numpy as np  # noqa: E402

from tcsim.analysis.design_study import design_study  # noqa: E402
from tcsim.plots.design_study import plot_design_pareto  # noqa: E402


def main() -> Path:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("design_study"), help="folder of the figure")
    parser.add_argument("--fast", action="store_true", help="a 2 x 2 grid (CI)")
    args = parser.parse_args()

    # 1. The grid: pump exit radius R_p in m and pump exit blade angle in degrees (the first varies slowest).
    n = 2 if args.fast else 3
    sweep = {
        "pump_exit_radius_m": np.linspace(0.11, 0.13, n),
        "pump_exit_angle_deg": np.linspace(-30.0, -10.0, n),
    }

    # 2. Every design of the grid around the bundled design (a design .toml of yours works the same).
    study = design_study("li-sunden-2016-design", sweep)

    # 3. The figures, one row per design (docs/design.md, "Design studies", defines every column).
    columns = [
        *sweep,
        "stall_torque_ratio",
        "takeoff_effective_tr_dip",
        "launch_time_0_50_km_h_s",
        "pareto_front",
        "error",
    ]
    print(study[columns].to_string(index=False))

    # 4. The Pareto plot: stall TR against take-off dip.
    args.out.mkdir(parents=True, exist_ok=True)
    figure = plot_design_pareto(study, args.out, "li-sunden-2016-design: pump exit radius × pump exit angle")
    print(f"figure: {figure}")
    return figure


if __name__ == "__main__":
    main()
