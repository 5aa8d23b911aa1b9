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
