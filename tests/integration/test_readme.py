"""The README's Python snippet runs verbatim (bundled names only) and returns the full time series."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]


def python_blocks() -> list[str]:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


def test_the_readme_python_snippet_runs_verbatim(tmp_path, monkeypatch):
    blocks = python_blocks()
    assert blocks, "README.md has a ```python block"
    monkeypatch.chdir(tmp_path)  # no file of the checkout is needed: bundled names only
    namespace: dict = {}
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a first run prints no warning
        for i, block in enumerate(blocks):
            exec(compile(block, f"README.md python block {i + 1}", "exec"), namespace)
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # and writes nothing
    times = np.asarray(namespace["times"])
    frame = namespace["r"].frame()
    assert len(times) > 100
    np.testing.assert_array_equal(frame["time_s"].to_numpy(), times)  # every sample, not the breakpoints
    for run in namespace["runs"]:
        np.testing.assert_array_equal(run.frame()["time_s"].to_numpy(), times)
