"""Design studies on the sharded path (``tcsim design-study --chunk-size``,
:class:`tcsim.analysis.chunked.DesignSweepStudy`): the shards are the unchunked study's rows bit for
bit (``pareto_front`` aside, recomputed from them), whatever the chunk size or scheduler, failing
designs included; resumable; the command line."""

from __future__ import annotations

from dataclasses import replace

import pandas as pd
import pytest

from tcsim.analysis.chunked import design_sweep_study
from tcsim.analysis.design_study import design_study, pareto_front
from tcsim.io.shards import read_shards, run_to_shards
from tcsim.models.design_file import load_design_file

#: 4 × 3 designs, the angle 95° refused: four rows with an error, in different chunks.
SWEEP = {"squash_ratio": [0.0, 0.1, 0.2, 0.3], "pump_exit_angle_deg": [-30.0, 95.0, -10.0]}


@pytest.fixture(scope="module")
def elliptic():
    base = load_design_file("li-sunden-2016-design")
    return replace(base, design=replace(base.design, profile="elliptic", squash_ratio=0.0))


@pytest.fixture(scope="module")
def unchunked(elliptic):
    df = design_study(elliptic, SWEEP)
    assert (df["error"] != "").sum() == 4
    return df


@pytest.fixture(scope="module")
def study(elliptic):
    return design_sweep_study(elliptic, SWEEP)


def check(shards: pd.DataFrame, unchunked: pd.DataFrame) -> None:
    pd.testing.assert_frame_equal(shards, unchunked.drop(columns="pareto_front"), check_exact=True)
    front = pareto_front(shards["stall_torque_ratio"].to_numpy(), shards["takeoff_effective_tr_dip"].to_numpy())
    assert front.tolist() == unchunked["pareto_front"].tolist()


@pytest.mark.parametrize("chunk_size", [1, 7, 12])
def test_shards_are_the_unchunked_rows_bit_for_bit(tmp_path, study, unchunked, chunk_size):
    run = run_to_shards(study, tmp_path / "s", chunk_size)
    assert run.rows == 12 and run.computed == list(range(-(-12 // chunk_size)))
    check(read_shards(tmp_path / "s"), unchunked)


def test_a_stopped_study_resumes_without_recomputing(tmp_path, study, unchunked):
    out = tmp_path / "s"

    def stop(index: int) -> None:
        if index == 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_to_shards(study, out, 3, on_chunk=stop)
    run = run_to_shards(study, out, 3)
    assert run.kept == [0, 1] and run.computed == [2, 3]
    check(read_shards(out), unchunked)


@pytest.mark.subprocess
def test_a_local_cluster_gives_the_same_rows(tmp_path, cluster, study, unchunked):
    run_to_shards(study, tmp_path / "s", 5, scheduler=cluster.scheduler_address)
    check(read_shards(tmp_path / "s"), unchunked)


def test_the_command_line(cli, tmp_path):
    args = ["design-study", "li-sunden-2016-design", "--sweep", "pump_exit_radius_m=0.11:0.13:3"]
    r = cli(*args, "--out", tmp_path / "whole", "--no-plots")
    assert r.code == 0, r.stderr
    r = cli(*args, "--out", tmp_path / "s", "--chunk-size", "2", "--no-progress")
    assert r.code == 0, r.stderr
    assert "3 designs of pump_exit_radius_m, 3 rows in 2 chunks of 2 cases (2 computed, 0 kept" in r.stdout
    whole = pd.read_csv(tmp_path / "whole" / "study.csv", dtype={"error": str}, keep_default_na=False)
    shards = read_shards(tmp_path / "s")
    pd.testing.assert_frame_equal(shards, whole.drop(columns="pareto_front"), check_dtype=False, rtol=1e-15)
    r = cli(*args, "--out", tmp_path / "t", "--scheduler", "local")
    assert r.code == 2 and "--scheduler = 'local': expected to be given with --chunk-size" in r.stderr
    assert not (tmp_path / "t").exists()
