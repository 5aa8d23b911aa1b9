"""Regenerate the bundled ``li-sunden-2016-fitted`` converter through ``tcsim fit``.

Run from the repository root with this checkout's tcsim installed::

    python tools/regenerate_fitted_converter.py

It runs ``tcsim fit li-sunden-2016 --target tests/data/converters/li_sunden_2016_table_c1.csv`` into a
temporary directory and writes its ``fitted.toml`` as ``python/tcsim/data/converters/li-sunden-2016-fitted.toml``,
renamed, with the fit's provenance and warnings in the header. Nothing else is changed: every
derived value (fluid length, shape effects) is the fit's own, recomputed from the fitted radii and
angles (docs/fitting.md), so ``tests/integration/test_fit_derived.py`` finds them again.
"""

from __future__ import annotations

import sys
import tempfile
import tomllib
import warnings
from pathlib import Path

import tomli_w

from tcsim.cli.fit import fit_command

ROOT = Path(__file__).resolve().parents[1]
TARGET = "tests/data/converters/li_sunden_2016_table_c1.csv"
OUT = ROOT / "python" / "tcsim" / "data" / "converters" / "li-sunden-2016-fitted.toml"
TABLE_SOURCE = f"Li & Sundén (2016) Table C.1 (tcsim repository: {TARGET})"
NAME = "li-sunden-2016-fitted"
#: The quasi-dynamic model's shape effects that matched the thesis's take-off measurements best
#: (calibration constants, not geometry: m² by eqs 2.16-2.17), set over what the fit takes from
#: the start converter, so that the bundled launch compares the models as the thesis did.
THESIS_QUASI_DYNAMIC = {"pump_shape_effect_m2": 0.4, "turbine_shape_effect_m2": 0.3}
THESIS_QUASI_DYNAMIC_SOURCE = (
    "Li & Sundén (2016), §4.1 (p. 43) and figures 4.1, 4.3: {name} = {value}, the best match of the Drenth "
    "(quasi-dynamic) model to the take-off measurements (set by tools/regenerate_fitted_converter.py)"
)
#: The flow time constant that goes with them (the thesis gives none): calibrated so that the
#: effective TR recovers to the table's within about a second (physics notes §5, property 4); the
#: bundled launch meets the issue-14 criteria for 0.23-0.44 s (docs/models.md, "Shape effects:
#: the thesis's best match").
FLOW_TIME_CONSTANT_S = 0.35
FLOW_TIME_CONSTANT_SOURCE = (
    "assumed, calibrated: with the thesis's shape effects the effective TR dips at least 0.15 below the table's in "
    "the first 0.5 s of the bundled launch and rejoins it within 0.05 from 1.2 s for 0.23-0.44 s (docs/models.md; "
    "set by tools/regenerate_fitted_converter.py); the torus estimate at stall and 2000 rpm is 2.9 ms"
)


def _replace(value, old: str, new: str):
    if isinstance(value, str):
        return value.replace(old, new)
    if isinstance(value, dict):
        return {k: _replace(v, old, new) for k, v in value.items()}
    return value


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = fit_command("li-sunden-2016", TARGET, Path(tmp) / "fit", None, [], None)
        text = (Path(tmp) / "fit" / "fitted.toml").read_text(encoding="utf-8")
    provenance = [ln for ln in text.splitlines() if ln.startswith("# - ")]
    doc = _replace(tomllib.loads(text), TARGET, TABLE_SOURCE)
    doc["name"] = NAME
    doc["quasi_dynamic"].update(THESIS_QUASI_DYNAMIC)
    for key, value in THESIS_QUASI_DYNAMIC.items():
        name = {"pump_shape_effect_m2": "Sp", "turbine_shape_effect_m2": "St"}[key]
        doc["sources"][f"quasi_dynamic.{key}"] = THESIS_QUASI_DYNAMIC_SOURCE.format(name=name, value=value)
    doc["quasi_dynamic"]["flow_time_constant_s"] = FLOW_TIME_CONSTANT_S
    doc["sources"]["quasi_dynamic.flow_time_constant_s"] = FLOW_TIME_CONSTANT_SOURCE
    provenance = [
        "# - [quasi_dynamic]: the thesis's best-match shape effects Sp = 0.4, St = 0.3 m² (§4.1, p. 43, figs 4.1 "
        "and 4.3) and a calibrated flow time constant of 0.35 s, set by this tool over the start converter's"
        if ln.startswith("# - [quasi_dynamic]")
        else ln
        for ln in provenance
    ]
    header = [
        "# The li-sunden-2016 converter with its Hrovat & Tobler [geometry] angles and losses fitted to its",
        f"# own characteristic (Table C.1) by `tcsim fit li-sunden-2016 --target {TARGET}`,",
        "# as the thesis matched its model to the manufacturer's data (section 3.2.1). All three models then",
        "# share one steady characteristic, so a launch compares their dynamics. The bundled vehicle uses it.",
        "# Regenerate with `python tools/regenerate_fitted_converter.py` (never edit the numbers by hand).",
        "# Where the values come from (tcsim fit):",
        *provenance,
        "# Warnings of the fit:",
        *([f"# - {w.message}" for w in caught] or ["# - none"]),
    ]
    OUT.write_text("\n".join(header) + "\n\n" + tomli_w.dumps(doc), encoding="utf-8")
    print(line.splitlines()[0], f"\nwrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
