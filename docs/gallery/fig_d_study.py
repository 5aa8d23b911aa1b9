"""Gallery: thesis figures D.1–D.15, the parameter study of Appendix D: one Hrovat & Tobler parameter
at a time over its Table D.1 range, the torque ratio, capacity factor and volume flow against speed
ratio at a pump speed of 2000 rpm.

The converter is ``li-sunden-2016`` (Table D.1's reference geometry; the thesis's inertias, fluid
length and shape effects do not enter a steady state). :func:`tcsim.study.run_study` (what
``tcsim study`` runs) computes every point in closed form, where the thesis ran its Simulink model
until it settled; :func:`tcsim.plots.study.plot_parameter` draws each figure, the reference value in
black.

Run it::

    python docs/gallery/fig_d_study.py [--fast] [--out DIR]

writes ``fig_d_1.png`` … ``fig_d_15.png`` (Table D.1's order) and their data as CSV; ``--fast`` runs
3 values per parameter instead of 5 (plus the reference).
"""

from __future__ import annotations

from _common import parse_args

from tcsim.analysis.study import default_definition, run_study
from tcsim.models.converter import load_converter
from tcsim.plots.study import plot_parameter

CONVERTER = "li-sunden-2016"
#: These figures are three panels wide (13.5 in): a lower resolution keeps them near the others' size.
DPI_STUDY = 72


def main() -> None:
    args = parse_args(__doc__, "gallery_study")
    conv = load_converter(CONVERTER)
    assert conv.geometry is not None
    definition = default_definition().replace(values_per_parameter=3 if args.fast else 5)
    study = run_study(conv, definition)
    for number, p in enumerate(definition.parameters, start=1):
        reference = float(getattr(conv.geometry, p.key))
        title = f"{CONVERTER}, 2000 rpm (thesis figure D.{number})"
        png = plot_parameter(study, p, reference, args.out / f"fig_d_{number}.png", title, dpi=DPI_STUDY)
        rows = study[study["parameter"] == p.key].assign(reference_value=reference)
        rows.to_csv(args.out / f"fig_d_{number}.csv", index=False)
        print(f"fig_d_{number}: {png}")


if __name__ == "__main__":
    main()
