"""Start-up fits the job (issue 16 item 7): ``import tcsim`` and the CLI's import (what
``tcsim --help`` runs) load neither pandas, SciPy nor matplotlib; the public names resolve on first
use. Times are measured in bench/, never asserted here."""

from __future__ import annotations

import subprocess
import sys

import pytest

import tcsim

HEAVY = ("pandas", "scipy", "matplotlib", "numpy")


@pytest.mark.parametrize("module", ["tcsim", "tcsim.cli"])
def test_importing_loads_no_heavy_library(module):
    code = f"import sys, {module}; print(','.join(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert out.stdout.strip() == "", out.stdout


def test_every_public_name_resolves_and_is_listed():
    for name in tcsim.__all__:
        assert getattr(tcsim, name) is not None, name
    assert set(tcsim.__all__) <= set(dir(tcsim))
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        _ = tcsim.no_such_name  # type: ignore[attr-defined]


def test_launch_without_plots_or_mat_loads_neither_matplotlib_nor_scipy(tmp_path):
    """``tcsim launch --no-plots`` writing CSV draws nothing and writes no ``.mat``, so it imports
    neither matplotlib nor SciPy (half a second each on the 2-core machine); the files are all there."""
    out = tmp_path / "out"
    code = (
        "import sys\n"
        "from tcsim.cli.app import main\n"
        f"code = main(['launch', '--no-plots', '--out', {str(out)!r}])\n"
        "print(code, ','.join(m for m in ('matplotlib', 'scipy') if m in sys.modules))\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True)
    assert run.stdout.strip().splitlines()[-1] == "0", run.stdout[-2000:]
    assert (out / "summary.csv").is_file() and not list(out.glob("*.png"))
