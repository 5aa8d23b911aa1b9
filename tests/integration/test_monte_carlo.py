"""Monte Carlo study files and ``tcsim monte-carlo`` (:mod:`tcsim.models.study_file`,
:mod:`tcsim.analysis.monte_carlo`): the draws' statistics, rows bit for bit the same whatever the
chunking or the scheduler, resumable, refusing a bad file before anything runs (exit 2, one line),
and the drawn values reaching the runs."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import signal
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from scipy import stats

import tcsim.analysis.monte_carlo as mc
import tcsim.plots.monte_carlo as plots_mc
from interrupts import ClientStopped, interrupt, stop_after
from tcsim.analysis.launch import SUMMARY_COLUMNS, SUMMARY_LABELS
from tcsim.analysis.monte_carlo import draw_cases, monte_carlo_study, run_monte_carlo
from tcsim.cli.monte_carlo import summary_lines
from tcsim.errors import InputError
from tcsim.io.shards import MANIFEST, SHARDS, read_shards, run_to_shards, shard_name
from tcsim.models.converter import load_converter
from tcsim.models.study_file import Lognormal, Normal, Parameter, TruncatedNormal, Uniform, load_study_file
from tcsim.models.vehicle import load_vehicle
from tcsim.plots.monte_carlo import histogram_bins

#: A study of converter and vehicle parameters, every kind of distribution, the three models.
STUDY = """\
name = "tolerance"
vehicle = "midsize-awd-8at"
runs = {runs}
seed = {seed}
outputs = ["time_0_50_km_h_s", "time_0_100_km_h_s", "effective_torque_ratio_dip_first_0_5_s", "shift_count"]

[distributions]
"vehicle.body.mass_kg" = {{ kind = "truncated-normal", mean = 1930.0, std = 40.0, low = 1850.0, high = 2010.0 }}
vehicle.engine.inertia_kg_m2 = {{ kind = "lognormal", mean = 0.2, std = 0.01 }}
"converter.inertia.turbine_kg_m2" = {{ kind = "uniform", low = 0.053, high = 0.059 }}
"converter.quasi_dynamic.pump_shape_effect_m2" = {{ kind = "normal", mean = 0.4, std = 0.04 }}
"""


def write_study(path: Path, runs: int = 15, seed: int = 7, extra: str = "") -> Path:
    path.write_text(STUDY.format(runs=runs, seed=seed) + extra, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def study_path(tmp_path_factory) -> Path:
    return write_study(tmp_path_factory.mktemp("mc") / "study.toml")


@pytest.fixture(scope="module")
def study(study_path):
    return monte_carlo_study(load_study_file(study_path))


@pytest.fixture(scope="module")
def unchunked(study):
    return run_monte_carlo(study)


def snapshot(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def listed(out: Path) -> dict[str, dict]:
    return json.loads((out / MANIFEST).read_text())["chunks"]


# --------------------------------------------------------------------------------------------
# the draws


def _parameter(dist) -> tuple[Parameter]:
    return (Parameter("p", "vehicle", "body", "mass_kg", dist),)


N = 2000


@pytest.mark.parametrize(
    ("dist", "mean", "std", "bounds"),
    [
        (Normal(kind="normal", mean=3.0, std=0.5), 3.0, 0.5, None),
        (Uniform(kind="uniform", low=-1.0, high=2.0), 0.5, 3.0 / math.sqrt(12), (-1.0, 2.0)),
        (Lognormal(kind="lognormal", mean=0.2, std=0.03), 0.2, 0.03, (0.0, math.inf)),
        (
            TruncatedNormal(kind="truncated-normal", mean=10.0, std=2.0, low=9.0, high=15.0),
            stats.truncnorm(-0.5, 2.5, loc=10.0, scale=2.0).mean(),
            stats.truncnorm(-0.5, 2.5, loc=10.0, scale=2.0).std(),
            (9.0, 15.0),
        ),
        (  # both bounds far in the upper tail: drawn by the mirror image
            TruncatedNormal(kind="truncated-normal", mean=0.0, std=1.0, low=4.0, high=4.5),
            stats.truncnorm(4.0, 4.5).mean(),
            stats.truncnorm(4.0, 4.5).std(),
            (4.0, 4.5),
        ),
    ],
)
def test_draws_have_the_distributions_mean_and_std(dist, mean, std, bounds):
    """N = 2000 draws of a fixed seed: the sample mean within 4 standard errors of the mean, the
    sample std within 4 of its own (≈ std/√(2N), wider for the lognormal's heavier tail), every draw
    inside the support."""
    x = draw_cases(_parameter(dist), 12345, 0, N)[:, 0]
    assert abs(x.mean() - mean) < 4 * std / math.sqrt(N)
    kurtosis = float(stats.kurtosis(x)) + 3.0
    assert abs(x.std(ddof=1) - std) < 4 * std * math.sqrt((kurtosis - 1) / (4 * N))
    if bounds is not None:
        assert bounds[0] <= x.min() and x.max() <= bounds[1]


def test_a_case_draws_the_same_values_whatever_the_range_it_is_drawn_in(study):
    whole = draw_cases(study.parameters, study.seed, 0, 40)
    pieces = np.vstack([draw_cases(study.parameters, study.seed, a, min(a + 7, 40)) for a in range(0, 40, 7)])
    np.testing.assert_array_equal(whole, pieces)
    other_seed = draw_cases(study.parameters, study.seed + 1, 0, 40)
    assert not np.isin(other_seed, whole).any()


# --------------------------------------------------------------------------------------------
# rows


def test_rows_are_one_per_case_and_model_with_the_drawn_parameters(study, unchunked):
    assert list(unchunked.columns) == list(study.columns)
    assert len(unchunked) == 15 * 3 and (unchunked["error"] == "").all()
    assert unchunked["case"].tolist() == [i for i in range(15) for _ in range(3)]
    assert unchunked["model"].tolist() == ["table", "hrovat-tobler", "quasi-dynamic"] * 15
    drawn = draw_cases(study.parameters, study.seed, 0, 15)
    for j, p in enumerate(study.parameters):
        np.testing.assert_array_equal(unchunked[p.key].to_numpy()[::3], drawn[:, j])
    assert np.isfinite(unchunked["time_0_100_km_h_s"]).all()
    table = unchunked[unchunked["model"] == "table"]
    assert (table["effective_torque_ratio_dip_first_0_5_s"] == 0.0).all()  # the reference against itself


def test_a_refused_case_keeps_its_rows_with_the_reason_and_the_others_run(study, unchunked, monkeypatch):
    """A case whose drawn values the vehicle's checks refuse (as a combination of values can be):
    its rows keep the drawn values with NaN outputs and the reason; the other cases are unchanged."""
    real = mc.build_vehicle

    def refusing(data, path, converter):
        if data["body"]["mass_kg"] > 1950.0:
            raise InputError(path, "[body].mass_kg", data["body"]["mass_kg"], "a mass this test accepts")
        return real(data, path, converter)

    monkeypatch.setattr(mc, "build_vehicle", refusing)
    df = dataclasses.replace(study).rows(0, study.n_cases)
    refused = df["vehicle.body.mass_kg"] > 1950.0
    assert 0 < refused.sum() < len(df)
    assert df.loc[refused, "error"].str.contains(r"\[body\].mass_kg = .*: expected a mass this test accepts").all()
    assert df.loc[refused, list(study.outputs)].isna().all().all()
    pd.testing.assert_frame_equal(df[~refused], unchunked[~refused], check_exact=True)
    key = [p.key for p in study.parameters]
    pd.testing.assert_frame_equal(df[key], unchunked[key], check_exact=True)


def test_a_drawn_mass_reaches_the_run_heavier_is_slower(tmp_path):
    """Only the mass drawn: for each model, 0–100 km/h takes longer the heavier the car."""
    path = tmp_path / "m.toml"
    path.write_text(
        'runs = 8\nseed = 3\nmodels = ["table", "hrovat-tobler"]\noutputs = ["time_0_100_km_h_s"]\n'
        '[distributions]\n"vehicle.body.mass_kg" = { kind = "uniform", low = 1500.0, high = 2500.0 }\n',
        encoding="utf-8",
    )
    df = run_monte_carlo(monte_carlo_study(load_study_file(path)))
    for _, rows in df.groupby("model"):
        ordered = rows.sort_values("vehicle.body.mass_kg")
        assert ordered["vehicle.body.mass_kg"].is_unique
        assert ordered["time_0_100_km_h_s"].is_monotonic_increasing


@pytest.mark.parametrize("chunk_size", [1, 7, 15])
def test_shards_of_any_chunk_size_are_the_unchunked_rows_bit_for_bit(tmp_path, study, unchunked, chunk_size):
    run = run_to_shards(study, tmp_path / "s", chunk_size)
    assert run.computed == list(range(-(-15 // chunk_size))) and run.rows == 45
    pd.testing.assert_frame_equal(read_shards(tmp_path / "s"), unchunked, check_exact=True)


def test_the_command_line_table_is_the_python_rows(cli, tmp_path, study_path, unchunked):
    r = cli("monte-carlo", study_path, "--out", tmp_path / "o", "--no-plots")
    assert r.code == 0, r.stderr
    assert "tolerance: 15 cases × 3 models (table, hrovat-tobler, quasi-dynamic), 0 of 45 runs without outputs" in (
        r.stdout
    )
    written = pd.read_csv(tmp_path / "o" / "monte_carlo.csv", dtype={"error": str}, keep_default_na=False)
    pd.testing.assert_frame_equal(written, unchunked, check_dtype=False, check_exact=False, rtol=1e-15)


def test_the_figures_are_one_histogram_per_output(cli, tmp_path):
    path = write_study(tmp_path / "s.toml", runs=3)
    r = cli("monte-carlo", path, "--out", tmp_path / "o")
    assert r.code == 0, r.stderr
    pngs = sorted(p.name for p in (tmp_path / "o").glob("*.png"))
    outputs = ["effective_torque_ratio_dip_first_0_5_s", "shift_count", "time_0_100_km_h_s", "time_0_50_km_h_s"]
    assert pngs == [f"monte_carlo_{o}.png" for o in outputs]


def test_each_summary_metric_has_an_axis_label_with_its_documented_unit(monkeypatch, tmp_path):
    # fresh-eyes trial: the histograms' x axes read raw column names ("time_0_50_km_h_s")
    doc = (Path(__file__).resolve().parents[2] / "docs" / "launch_summary.md").read_text(encoding="utf-8")
    units = dict(re.findall(r"^\| `(\w+)` \| ([^|]+?) \|", doc, flags=re.M))
    brackets = {"s": ("[s]", "[s after release]"), "m/s²": ("[m/s²]",), "–": ("[-]",)}
    assert set(SUMMARY_LABELS) == set(SUMMARY_COLUMNS) - {"model"}
    for column, label in SUMMARY_LABELS.items():
        assert label.endswith(brackets[units[column]]), (column, units[column], label)
    shown = []
    monkeypatch.setattr(plots_mc, "finish_figure", lambda fig, ax, path, title, xlabel: shown.append(xlabel) or path)
    df = pd.DataFrame({"model": ["table"] * 3, "time_0_50_km_h_s": [4.0, 4.1, 4.3], "other_s": [1.0, 2.0, 3.0]})
    plots_mc.plot_histogram(df, "time_0_50_km_h_s", ["table"], tmp_path / "a.png", "t")
    plots_mc.plot_histogram(df, "other_s", ["table"], tmp_path / "b.png", "t")
    assert shown == ["Time 0–50 km/h [s]", "other_s"]


# --------------------------------------------------------------------------------------------
# bad files: exit 2, one line naming the file and the field, nothing written


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (
            '"vehicle.body.drag_area_m2" = { kind = "normal", mean = 0.67, std = 0.01 }\n',
            "distributions.\"vehicle.body.drag_area_m2\" = 'normal(mean=0.67, std=0.01)': expected a distribution "
            "whose support (-inf, inf) lies within the valid range of vehicle.body.drag_area_m2 (a truncated-normal "
            "bounds a normal): at -1.79769e+308, [body].drag_area_m2: expected",
        ),
        (
            '"converter.geometry.pump_exit_angle_deg" = { kind = "uniform", low = -95.0, high = -20.0 }\n',
            "distributions.\"converter.geometry.pump_exit_angle_deg\" = 'uniform(low=-95, high=-20)': expected a "
            "distribution whose support [-95, -20] lies within the valid range of "
            "converter.geometry.pump_exit_angle_deg: at -95, [geometry].pump_exit_angle_deg: expected greater than -90",
        ),
        (
            '"vehicle.body.mass_kgg" = { kind = "uniform", low = 1.0, high = 2.0 }\n',
            "distributions.\"vehicle.body.mass_kgg\" = 'vehicle.body.mass_kgg': expected a real number of the vehicle",
        ),
        (
            '"converter.geometry.pump_radius" = { kind = "uniform", low = 1.0, high = 2.0 }\n',
            "distributions.\"converter.geometry.pump_radius\" = 'converter.geometry.pump_radius': expected a number",
        ),
        (
            '"vehicle.gearbox.ratios" = { kind = "uniform", low = 1.0, high = 2.0 }\n',
            "distributions.\"vehicle.gearbox.ratios\" = 'vehicle.gearbox.ratios': expected a real number",
        ),
        (
            '"vehicle.body.grade_percent" = { kind = "gamma", mean = 1.0 }\n',
            "distributions.\"vehicle.body.grade_percent\".kind = 'gamma': expected one of 'normal', 'uniform'",
        ),
        (
            '"vehicle.body.grade_percent" = { kind = "uniform", low = 1.0, high = 1.0 }\n',
            'distributions."vehicle.body.grade_percent"',
        ),
        (
            '"vehicle.body.grade_percent" = { kind = "truncated-normal", mean = 0.0, std = 1.0, '
            "low = 40.0, high = 41.0 }\n",
            "expected low and high within a few std of mean",
        ),
    ],
)
def test_a_bad_distribution_is_exit_2_one_line_before_anything_runs(cli, tmp_path, extra, expected):
    path = write_study(tmp_path / "s.toml", extra=extra)
    for chunked in ([], ["--chunk-size", "2"]):
        r = cli("monte-carlo", path, "--out", tmp_path / "o", *chunked)
        lines = r.stderr.strip().splitlines()
        assert r.code == 2 and len(lines) == 1, r.stderr
        assert lines[0].startswith(f"error: {path}: ") and expected in lines[0], lines[0]
        assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("runs = 0", "runs = 0: expected greater than or equal to 1"),
        ('outputs = ["time_0_60_mph_s"]', "outputs = 'time_0_60_mph_s': expected a launch summary column"),
        (
            'models = ["hrovat-tobler"]',
            "outputs = 'effective_torque_ratio_dip_first_0_5_s': expected the 'table' model among the models",
        ),
        ("seed = -1", "seed = -1: expected greater than or equal to 0"),
        ("colour = 1", "colour = 1: expected a known key"),
        ('vehicle = "nope"', "vehicle = 'nope'"),
        ('converter = "c.toml"', "converter = 'c.toml': expected a bundled converter (li-sunden-2016, "),
    ],
)
def test_a_bad_top_level_key_is_exit_2_one_line(cli, tmp_path, text, expected):
    key = text.split(" = ")[0]
    base = [line for line in STUDY.format(runs=3, seed=1).splitlines() if not line.startswith(f"{key} = ")]
    path = tmp_path / "s.toml"
    path.write_text("\n".join([text, *base]) + "\n", encoding="utf-8")
    r = cli("monte-carlo", path, "--out", tmp_path / "o")
    assert r.code == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert expected in r.stderr, r.stderr
    assert not (tmp_path / "o").exists()


def test_the_vehicle_and_converter_files_are_relative_to_the_study_file(tmp_path, cli):
    (tmp_path / "files").mkdir()
    conv = Path(load_converter("li-sunden-2016-fitted").path).read_text(encoding="utf-8")
    (tmp_path / "files" / "c.toml").write_text(conv.replace("[inertia]\n", "[inertia]\n# mine\n"), encoding="utf-8")
    vehicle = Path(load_vehicle("midsize-awd-8at").path).read_text(encoding="utf-8")
    (tmp_path / "files" / "v.toml").write_text(vehicle.replace('"li-sunden-2016-fitted"', '"c.toml"'), encoding="utf-8")
    (tmp_path / "files" / "s.toml").write_text(
        'vehicle = "v.toml"\nconverter = "c.toml"\nmodels = ["table"]\noutputs = ["time_0_50_km_h_s"]\n'
        'runs = 2\nseed = 5\n[distributions]\n"converter.inertia.turbine_kg_m2" = '
        '{ kind = "uniform", low = 0.05, high = 0.06 }\n',
        encoding="utf-8",
    )
    study = monte_carlo_study(load_study_file(tmp_path / "files" / "s.toml"))
    assert Path(study.converter_path) == tmp_path / "files" / "c.toml"
    assert Path(study.vehicle_path) == tmp_path / "files" / "v.toml"
    r = cli("monte-carlo", "files/s.toml", "--out", "o", "--no-plots", cwd=tmp_path)
    assert r.code == 0, r.stderr
    assert "2 cases × 1 model (table), 0 of 2 runs without outputs" in r.stdout


def test_more_runs_than_fit_in_memory_need_chunks(cli, tmp_path):
    path = write_study(tmp_path / "s.toml", runs=100_001)
    r = cli("monte-carlo", path, "--out", tmp_path / "o")
    assert r.code == 2 and "runs = 100001: expected at most 100000 without --chunk-size" in r.stderr, r.stderr


# --------------------------------------------------------------------------------------------
# resuming, refusing another study, interrupted


def test_a_study_file_changed_between_runs_is_refused(cli, tmp_path):
    path = write_study(tmp_path / "s.toml", runs=4)
    out = tmp_path / "o"
    assert cli("monte-carlo", path, "--out", out, "--chunk-size", "2").code == 0
    before = snapshot(out)
    write_study(path, runs=4, seed=8)
    r = cli("monte-carlo", path, "--out", out, "--chunk-size", "2")
    assert r.code == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "--out" in r.stderr and "it holds another study" in r.stderr
    assert snapshot(out) == before
    write_study(path, runs=4)  # as it was: the study is complete, nothing computed
    r = cli("monte-carlo", path, "--out", out, "--chunk-size", "2")
    assert r.code == 0 and "(0 computed, 2 kept from an earlier run)" in r.stdout, r.stderr
    assert snapshot(out) == before


def test_a_plain_study_directory_is_named_as_such_when_refused(cli, tmp_path):
    """A trial: a sharded study into a plain study's output said "2 files tcsim did not write as a
    study", of files tcsim had written; the refusal names the command whose output it holds. Files
    of no tcsim run are still named as such."""
    path = write_study(tmp_path / "s.toml", runs=4)
    out = tmp_path / "o"
    assert cli("monte-carlo", path, "--out", out).code == 0
    before = snapshot(out)
    r = cli("monte-carlo", path, "--out", out, "--chunk-size", "2")
    assert r.code == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert f"it holds the output of an unsharded 'tcsim monte-carlo' run: {len(before)} files, e.g. " in r.stderr, (
        r.stderr
    )
    assert snapshot(out) == before
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "a.txt").write_text("x")
    r = cli("monte-carlo", path, "--out", tmp_path / "notes", "--chunk-size", "2")
    assert r.code == 2 and "it holds 1 file tcsim did not write as a sharded study, e.g. 'a.txt'" in r.stderr


def test_a_study_whose_client_stops_resumes_without_recomputing(tmp_path, study, unchunked):
    out = tmp_path / "s"
    written: list[int] = []
    with pytest.raises(ClientStopped):
        run_to_shards(study, out, 4, on_chunk=stop_after(2, written))
    assert sorted(int(i) for i in listed(out)) == written == [0, 1]
    run = run_to_shards(study, out, 4)
    assert run.kept == [0, 1] and run.computed == [2, 3]
    pd.testing.assert_frame_equal(read_shards(out), unchunked, check_exact=True)


@pytest.mark.subprocess
def test_an_interrupted_study_exits_130_and_keeps_its_finished_shards(tmp_path):
    write_study(tmp_path / "s.toml", runs=200)
    args = ["monte-carlo", "s.toml", "--out", "o", "--chunk-size", "2"]
    out = tmp_path / "o"
    r = interrupt(args, signal.SIGINT, lambda p, cwd, o: (out / MANIFEST).is_file() and len(listed(out)) >= 2, tmp_path)
    assert r.returncode == 130, r.stderr
    assert r.stderr.strip().splitlines() == [
        "interrupted (SIGINT): the finished chunks in o are kept; run it again to resume"
    ]
    done = listed(out)
    assert 2 <= len(done) < 100
    assert sorted(q.name for q in (out / SHARDS).iterdir()) == sorted(shard_name(int(i)) for i in done)


# --------------------------------------------------------------------------------------------
# on a dask cluster


@pytest.mark.subprocess
def test_a_local_cluster_gives_the_unchunked_rows_bit_for_bit(tmp_path, cluster, study, unchunked):
    run = run_to_shards(study, tmp_path / "s", 7, scheduler=cluster.scheduler_address)
    assert sorted(run.computed) == [0, 1, 2]
    pd.testing.assert_frame_equal(read_shards(tmp_path / "s"), unchunked, check_exact=True)


@pytest.mark.subprocess
def test_the_command_line_on_a_local_cluster(cli, tmp_path, study_path, unchunked):
    pytest.importorskip("distributed")
    args = ["--chunk-size", "4", "--scheduler", "local", "--workers", "2", "--no-progress"]
    r = cli("monte-carlo", study_path, "--out", tmp_path / "s", *args)
    assert r.code == 0, r.stderr
    assert "45 rows in 4 chunks of 4 cases (4 computed, 0 kept from an earlier run)" in r.stdout
    pd.testing.assert_frame_equal(read_shards(tmp_path / "s"), unchunked, check_exact=True)
    # the shards' statistics are one call away, and the command says which (fresh-eyes trial)
    said = " ".join(r.stdout.split())
    columns = ["model", "error", *study_outputs(study_path)]
    assert f"statistics: tcsim.io.shards.read_shards({str(tmp_path / 's')!r}, {columns!r})" in said, said
    assert list(read_shards(tmp_path / "s", columns).columns) == columns


def study_outputs(path) -> list[str]:
    return list(dict.fromkeys(load_study_file(path).doc.outputs))


def test_the_summary_counts_finished_runs_without_a_value():
    # a run that finished but never reached the speed has no time to it: the summary says how many
    # (the "runs without outputs" line counts failed runs only; trial finding, issue 16)
    df = pd.DataFrame(
        {
            "model": ["table"] * 4 + ["hrovat-tobler"] * 2,
            "error": ["", "", "", "refused"] + [""] * 2,
            "time_0_100_km_h_s": [9.0, 11.0, np.nan, np.nan, np.nan, np.nan],
        }
    )
    study = SimpleNamespace(outputs=("time_0_100_km_h_s",), models=("table", "hrovat-tobler"))
    assert summary_lines(df, study) == [
        "  time_0_100_km_h_s: table 10 ± 1.41 (n = 2; 1 finished without a value), "
        "hrovat-tobler - (n = 0; 2 finished without a value)"
    ]
    df["time_0_100_km_h_s"] = [9.0, 11.0, 10.0, np.nan, 8.0, 8.0]
    assert summary_lines(df, study) == ["  time_0_100_km_h_s: table 10 ± 1 (n = 3), hrovat-tobler 8 ± 0 (n = 2)"]
    # one value has no sample spread: no "± nan" (a trial's runs = 1)
    df["time_0_100_km_h_s"] = [9.0, np.nan, np.nan, np.nan, 8.0, 8.0]
    assert summary_lines(df, study) == [
        "  time_0_100_km_h_s: table 9 (n = 1; 2 finished without a value), hrovat-tobler 8 ± 0 (n = 2)"
    ]


def test_models_far_apart_each_get_bins_of_their_own():
    # trial finding: two models 0.05 s apart, each with a spread of 0.005 s, drew each spread as one bar
    rng = np.random.default_rng(3)
    near = {"table": rng.normal(2.84, 0.02, 100), "quasi-dynamic": rng.normal(2.85, 0.02, 100)}
    bins = histogram_bins(near)
    assert bins["table"] is bins["quasi-dynamic"]  # overlapping: the same bins, comparable bars
    far = {"table": rng.normal(2.84, 0.0005, 100), "quasi-dynamic": rng.normal(2.89, 0.0005, 100), "x": np.empty(0)}
    bins = histogram_bins(far)
    assert set(bins) == {"table", "quasi-dynamic"}
    for m in bins:
        assert bins[m][0] == far[m].min() and bins[m][-1] == far[m].max()
        filled = np.unique(np.digitize(far[m], bins[m][1:-1])).size
        assert filled >= 5, (m, filled)
    assert histogram_bins({"table": np.full(4, 2.0)})["table"].tolist() == np.linspace(2.0, 3.0, 6).tolist()


def test_an_output_no_run_reaches_gets_an_empty_histogram_not_a_crash(tmp_path, cli):
    """A trial's part-pedal study: no run reaches 100 km/h, so ``time_0_100_km_h_s`` has no finite
    value and the histogram took the minimum of an empty array (exit 1, a ValueError)."""
    assert histogram_bins({"table": np.empty(0)}) == {}
    text = STUDY.format(runs=2, seed=7).replace("runs = 2\n", 'runs = 2\nscenario = "part-pedal"\nmodels = ["table"]\n')
    study = tmp_path / "pp.toml"
    study.write_text(text, encoding="utf-8")
    r = cli("monte-carlo", study, "--out", tmp_path / "o")
    assert r.code == 0, r.stderr
    frame = pd.read_csv(tmp_path / "o" / "monte_carlo.csv")
    assert frame["time_0_100_km_h_s"].isna().all() and frame["time_0_50_km_h_s"].notna().all()
    assert (tmp_path / "o" / "monte_carlo_time_0_100_km_h_s.png").stat().st_size > 0
