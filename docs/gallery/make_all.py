"""Regenerate the gallery's images: run every gallery script (full runs, or ``--fast``) and copy the PNG
files it makes into ``docs/gallery/img/`` (the CSV data and synthetic measurements stay in a
temporary folder, or in ``--keep DIR``).

Run it from anywhere::

    python docs/gallery/make_all.py [--fast] [--keep DIR]

:data:`SCRIPTS` is the one list of which script makes which thesis figure (the gallery page and
``tests/integration/test_gallery.py`` check against it). A script that fails, or that makes other
PNG files than its own, stops the run with exit code 1 and leaves ``img/`` as it was.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
IMG = HERE / "img"


def _numbers(prefix: str, numbers) -> tuple[str, ...]:
    return tuple(f"fig_{prefix}{n}" for n in numbers)


#: Each gallery script and the figures (PNG names without ``.png``) it makes.
SCRIPTS: dict[str, tuple[str, ...]] = {
    "fig_3_3_3_4_steady.py": _numbers("3_", (3, 4)),
    "fig_3_5_3_6_launch.py": _numbers("3_", (5, 6)),
    "fig_3_13_3_17_replay.py": _numbers("3_", range(13, 18)),
    "fig_4_1_4_6_shape_effects.py": _numbers("4_", range(1, 7)),
    "fig_c1_c2_table.py": _numbers("c_", (1, 2)),
    "fig_d_study.py": _numbers("d_", range(1, 16)),
}


def run(script: str, out: Path, fast: bool) -> list[Path]:
    """Run one script into ``out``; its PNG files (they must be exactly its figures)."""
    command = [sys.executable, str(HERE / script), "--out", str(out)] + (["--fast"] if fast else [])
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{script} failed (exit {done.returncode}):\n{done.stderr[-3000:]}")
    made = sorted(out.glob("*.png"))
    if {p.stem for p in made} != set(SCRIPTS[script]):
        sys.exit(f"{script} made {[p.name for p in made]}, expected {list(SCRIPTS[script])}")
    return made


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fast", action="store_true", help="the scripts' short runs (a check, not for committing)")
    parser.add_argument("--keep", type=Path, help="keep each script's output (PNG, CSV) in DIR/<script>/")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        root = args.keep or Path(tmp)
        made = []
        for script in SCRIPTS:
            out = root / Path(script).stem
            out.mkdir(parents=True, exist_ok=True)
            made += run(script, out, args.fast)
            print(f"{script}: {len(SCRIPTS[script])} figures")
        IMG.mkdir(exist_ok=True)
        for png in made:
            shutil.copyfile(png, IMG / png.name)
    print(f"{len(made)} images in {IMG}")


if __name__ == "__main__":
    main()
