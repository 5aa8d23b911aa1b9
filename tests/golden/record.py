"""Record the golden results that the refactor of issue 9 must not move (1e-9 relative).

Run by hand from the repository root, with the tcsim whose numbers are the reference installed:
``python tests/golden/record.py``. It writes ``tests/golden/data/``: the launch summary and a
decimated time series of each model, a replay of a synthetic take-off measurement (which it also
writes, so that later runs replay the same file), two characterisations, the Appendix D study and
a fit of the bundled converter to Table C.1. ``test_golden.py`` repeats the same runs and compares.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
DATA = HERE / "data"
sys.path.insert(0, str(HERE))

from runs import RUNS, make_measurement  # noqa: E402


def main() -> None:
    DATA.mkdir(exist_ok=True)
    make_measurement(DATA / "takeoff_measurement.csv")
    with tempfile.TemporaryDirectory() as tmp:
        for name, run in RUNS.items():
            for rel, frame in run(Path(tmp) / name, DATA).items():
                target = DATA / name / rel
                target.parent.mkdir(parents=True, exist_ok=True)
                frame.to_csv(target, index=False, float_format="%.17g")
                print("wrote", target.relative_to(HERE.parents[1]))
    shutil.rmtree(DATA / "__pycache__", ignore_errors=True)


if __name__ == "__main__":
    main()
