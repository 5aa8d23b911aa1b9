"""Grid sweeps in Monte Carlo study files (issue 16: shape-effect sweeps on the sharded path): the
full factorial and its order, the random draws of each grid point, rows bit for bit the same
whatever the chunking, files without a grid drawing as before grids existed, bad grids refused
before anything runs (exit 2, one line naming the file, the field and the value), and a sharded
shape-effect sweep resumed from the command line."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from interrupts import ClientStopped, stop_after
from tcsim.analysis.monte_carlo import case_generator, draw, draw_cases, monte_carlo_study, run_monte_carlo
from tcsim.errors import InputError, TcsimWarning
from tcsim.io.shards import MANIFEST, read_shards, run_to_shards
from tcsim.models.study_file import MAX_RUNS, Grid, Uniform, load_study_file

PUMP = "converter.quasi_dynamic.pump_shape_effect_m2"
TURBINE = "converter.quasi_dynamic.turbine_shape_effect_m2"
MASS = "vehicle.body.mass_kg"

#: Two shape-effect grids (one of each form) × a drawn mass: 3 × 3 grid points × 2 runs = 18 cases.
GRID_STUDY = f"""\
name = "shape-sweep"
models = ["table", "quasi-dynamic"]
outputs = ["time_0_50_km_h_s", "effective_torque_ratio_dip_first_0_5_s"]
runs = 2
seed = 11

[distributions]
"{PUMP}" = {{ kind = "grid", values = [0.0, 0.4, 0.2] }}
"{TURBINE}" = {{ kind = "grid", start = 0.1, stop = 0.3, num = 3 }}
"{MASS}" = {{ kind = "uniform", low = 1800.0, high = 2000.0 }}
"""
PUMP_VALUES = [0.0, 0.4, 0.2]  # the order given, not sorted
TURBINE_VALUES = np.linspace(0.1, 0.3, 3).tolist()
N_CASES = 18


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def grid_path(tmp_path_factory) -> Path:
    return write(tmp_path_factory.mktemp("grid") / "sweep.toml", GRID_STUDY)


@pytest.fixture(scope="module")
def study(grid_path):
    return monte_carlo_study(load_study_file(grid_path))


@pytest.fixture(scope="module")
def unchunked(study):
    return run_monte_carlo(study)


# --------------------------------------------------------------------------------------------
# the factorial


def test_a_two_parameter_grid_times_runs_is_a_full_factorial_the_first_parameter_slowest(study, unchunked):
    assert study.n_cases == N_CASES and study.runs == 2
    assert list(study.columns) == ["case", "model", PUMP, TURBINE, MASS, *study.outputs, "error"]
    assert len(unchunked) == N_CASES * 2 and (unchunked["error"] == "").all()
    cases = unchunked[unchunked["model"] == "table"].reset_index(drop=True)
    assert cases["case"].tolist() == list(range(N_CASES))
    for i, row in cases.iterrows():
        point = int(i) // 2  # each grid point runs `runs` times
        assert row[PUMP] == PUMP_VALUES[point // 3], i
        assert row[TURBINE] == TURBINE_VALUES[point % 3], i
    # every grid point once per run: the factorial, each pair of values `runs` times
    pairs = cases.groupby([PUMP, TURBINE]).size()
    assert len(pairs) == 9 and (pairs == 2).all()
    # the quasi-dynamic runs see the swept shape effects: its outputs differ from point to point
    qd = unchunked[unchunked["model"] == "quasi-dynamic"]
    assert qd["effective_torque_ratio_dip_first_0_5_s"].nunique() == N_CASES


def test_every_grid_point_sees_the_same_draws(study):
    """Common random numbers: the mass of case i is the first draw of (seed, i % runs), so run r of
    every grid point has the same mass (trial finding: with a draw per case, the sampling noise of
    the mass was twice the effect of the swept shape effects); a grid takes nothing from the
    generator."""
    values = draw_cases(study.parameters, study.seed, 0, N_CASES, study.runs)
    mass = Uniform(kind="uniform", low=1800.0, high=2000.0)
    expected = [draw(mass, case_generator(11, i % study.runs)) for i in range(N_CASES)]
    assert values[:, 2].tolist() == expected
    per_point = values[:, 2].reshape(-1, study.runs)
    assert (per_point == per_point[0]).all() and len(set(per_point[0])) == study.runs


def test_a_case_has_the_same_values_whatever_the_range_it_is_drawn_in(study):
    whole = draw_cases(study.parameters, study.seed, 0, N_CASES, study.runs)
    for size in (1, 5, 7):
        pieces = [
            draw_cases(study.parameters, study.seed, a, min(a + size, N_CASES), study.runs)
            for a in range(0, N_CASES, size)
        ]
        np.testing.assert_array_equal(np.vstack(pieces), whole)


@pytest.mark.parametrize(
    ("start", "stop", "num"), [(0.1, 0.3, 3), (0.0, 0.003, 4), (-1.7, 2.9, 11), (5.0, -3.0, 7), (0.3, 9.9, 1)]
)
def test_start_stop_num_are_numpy_linspace_bit_for_bit(start, stop, num):
    grid = Grid(kind="grid", start=start, stop=stop, num=num)
    assert len(grid) == num
    assert grid.points() == np.linspace(start, stop, num).tolist()
    assert grid.points()[0] == start and (num == 1 or grid.points()[-1] == stop)


@pytest.mark.parametrize("chunk_size", [1, 7, N_CASES])
def test_shards_of_a_grid_at_any_chunk_size_are_the_unchunked_rows_bit_for_bit(tmp_path, study, unchunked, chunk_size):
    run = run_to_shards(study, tmp_path / "s", chunk_size)
    assert run.computed == list(range(-(-N_CASES // chunk_size))) and run.rows == N_CASES * 2
    pd.testing.assert_frame_equal(read_shards(tmp_path / "s"), unchunked, check_exact=True)


@pytest.mark.subprocess
def test_a_local_cluster_gives_the_unchunked_rows_of_a_grid_bit_for_bit(tmp_path, cluster, study, unchunked):
    run = run_to_shards(study, tmp_path / "s", 7, scheduler=cluster.scheduler_address)
    assert sorted(run.computed) == [0, 1, 2]
    pd.testing.assert_frame_equal(read_shards(tmp_path / "s"), unchunked, check_exact=True)


def test_a_grid_alone_may_omit_runs_one_case_per_point(cli, tmp_path):
    path = write(
        tmp_path / "g.toml",
        f'seed = 0\nmodels = ["table"]\noutputs = ["time_0_50_km_h_s"]\n[distributions]\n"{PUMP}" = '
        '{ kind = "grid", start = 0.0, stop = 0.003, num = 4 }\n',
    )
    sf = load_study_file(path)
    assert sf.doc.runs is None and sf.doc.n_runs == 1 and sf.doc.n_cases == 4
    study = monte_carlo_study(sf)
    assert study.n_cases == 4
    assert (
        draw_cases(study.parameters, study.seed, 0, 4, study.runs)[:, 0].tolist() == np.linspace(0, 0.003, 4).tolist()
    )
    assert study.definition()["distributions"] == [
        {"parameter": PUMP, "kind": "grid", "start": 0.0, "stop": 0.003, "num": 4}
    ]
    r = cli("monte-carlo", path, "--out", tmp_path / "o", "--no-plots", "--no-progress")
    assert r.code == 0 and "g: 4 cases (4 grid points) × 1 model (table), 0 of 4 runs without outputs" in r.stdout


# --------------------------------------------------------------------------------------------
# files without a grid: as before


#: The test_monte_carlo.py study (seed 7): the values its first three cases drew before grids existed.
NO_GRID_CASES = [
    [1942.1565910416402, 0.20275470124948902, 0.05765411414147116, 0.3643763264497091],
    [1957.97606535079, 0.17772707336504484, 0.05413458639978276, 0.37267644722732557],
    [1907.6390426351568, 0.19471743675667397, 0.05860243043409955, 0.4266754208339684],
]


def test_a_file_without_a_grid_draws_and_defines_the_study_as_before(tmp_path):
    from test_monte_carlo import write_study  # noqa: PLC0415  (the existing study file)

    study = monte_carlo_study(load_study_file(write_study(tmp_path / "s.toml")))
    assert study.n_cases == study.runs == 15
    assert draw_cases(study.parameters, study.seed, 0, 3).tolist() == NO_GRID_CASES
    assert draw_cases(study.parameters, study.seed, 0, 3, runs=5).tolist() == NO_GRID_CASES
    # the manifest's definition (its hash decides whether shards are resumed) has no grid keys
    assert [set(d) for d in study.definition()["distributions"]] == [
        {"parameter", "kind", "mean", "std", "low", "high"},
        {"parameter", "kind", "mean", "std"},
        {"parameter", "kind", "low", "high"},
        {"parameter", "kind", "mean", "std"},
    ]


# --------------------------------------------------------------------------------------------
# bad grids: InputError naming the field and the value; exit 2, one line, nothing written

BASE = 'seed = 1\nmodels = ["table", "quasi-dynamic"]\noutputs = ["time_0_50_km_h_s"]\n'
FIELD = f'distributions."{PUMP}"'
#: A random parameter next to the grid (then runs is required).
DRAWN = f'"{MASS}" = {{ kind = "uniform", low = 1800.0, high = 2000.0 }}\n'
HALF = MAX_RUNS // 2 + 1


@pytest.mark.parametrize(
    ("top", "grid", "field", "value", "expected"),
    [
        ("", "values = []", f"{FIELD}.values", [], "at least one value"),
        ("", "values = [0.1, inf]", f"{FIELD}.values[1]", math.inf, "a finite number"),
        ("", "values = [nan]", f"{FIELD}.values[0]", "nan", "a finite number"),
        ("", "values = [0.1, 0.2, 0.1]", f"{FIELD}.values[2]", 0.1, "distinct values"),
        ("", "values = [0.1], start = 0.0", f"{FIELD}.start", 0.0, "values or start, stop and num, not both"),
        ("", "values = [0.1], num = 2", f"{FIELD}.num", 2, "values or start, stop and num, not both"),
        ("", "start = 0.0, stop = 1.0, num = 0", f"{FIELD}.num", 0, "greater than or equal to 1"),
        ("", "start = 0.0, stop = 1.0, num = 100001", f"{FIELD}.num", 100001, "less than or equal to 100000"),
        ("", "start = 0.0, num = 3", f"{FIELD}.stop", "missing", "start, stop and num together"),
        ("", "start = 0.5, stop = 0.5, num = 2", f"{FIELD}.stop", 0.5, "a stop other than start (0.5) when num > 1"),
        ("", "start = -1e308, stop = 1e308, num = 3", f"{FIELD}.stop", 1e308, "stop − start a finite number"),
        ("", "start = 1.0, stop = 1.000000000000001, num = 9", f"{FIELD}.num", 9, "as many values as distinct numbers"),
        ("", "start = inf, stop = 1.0, num = 2", f"{FIELD}.start", math.inf, "a finite number"),
        ("", "", f"{FIELD}.values", "missing", "values, or start, stop and num"),
        ("", "values = [0.1], step = 0.1", f"{FIELD}.step", 0.1, "a known key"),
        ("runs = 2\n", "values = [0.1, 0.2]", "runs", 2, "1 or no runs when every parameter is a grid"),
        ("", "values = [0.1, 0.2] }\n" + DRAWN, "runs", "missing", f"this key: {MASS} is drawn at random"),
        (
            f"runs = {HALF}\n",
            "values = [0.1, 0.2] }\n" + DRAWN,
            "runs",
            HALF,
            f"at most {MAX_RUNS} cases: 2 grid points × {HALF} runs = {2 * HALF} cases",
        ),
    ],
)
def test_a_bad_grid_is_an_input_error_naming_the_field_and_the_value(cli, tmp_path, top, grid, field, value, expected):
    table = f'"{PUMP}" = {{ kind = "grid"{", " if grid else ""}{grid}'
    table += "" if table.endswith("\n") else " }\n"
    path = write(tmp_path / "s.toml", f"{BASE}{top}[distributions]\n{table}")
    with pytest.raises(InputError) as err:
        load_study_file(path)
    assert err.value.source == str(path) and err.value.field == field, str(err.value)
    assert str(err.value.value) == str(value) and expected in err.value.expected, str(err.value)
    for chunked in ([], ["--chunk-size", "2"]):
        r = cli("monte-carlo", path, "--out", tmp_path / "o", *chunked)
        lines = r.stderr.strip().splitlines()
        assert r.code == 2 and len(lines) == 1, r.stderr
        assert lines[0].startswith(f"error: {path}: {field} = ") and expected in lines[0], lines[0]
        assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("grid", "field", "value", "expected"),
    [
        (  # the values form: the value refused, by its index
            "values = [0.6, 0.7, -1.0]",
            'distributions."vehicle.body.drag_area_m2".values[2]',
            "-1.0",
            "a value within the valid range of vehicle.body.drag_area_m2: [body].drag_area_m2: expected",
        ),
        (  # start, stop, num: every value within the range, accepted
            "start = 0.6, stop = 0.2, num = 3",
            'distributions."vehicle.body.drag_area_m2"',
            "grid(start=0.6, stop=0.2, num=3)",
            None,
        ),
        (
            "start = 0.6, stop = -1.0, num = 3",
            'distributions."vehicle.body.drag_area_m2"',
            "grid(start=0.6, stop=-1, num=3)",
            "a grid whose values lie within the valid range of vehicle.body.drag_area_m2: at value 1 (-0.2), "
            "[body].drag_area_m2: expected",
        ),
    ],
)
def test_every_grid_value_is_checked_against_the_schema(cli, tmp_path, grid, field, value, expected):
    path = write(
        tmp_path / "s.toml",
        f'{BASE}[distributions]\n"vehicle.body.drag_area_m2" = {{ kind = "grid", {grid} }}\n',
    )
    if expected is None:  # every value in range: accepted
        assert len(load_study_file(path).parameters[0].distribution) == 3
        return
    with pytest.raises(InputError) as err:
        load_study_file(path)
    assert err.value.field == field and str(err.value.value) == value and expected in err.value.expected
    r = cli("monte-carlo", path, "--out", tmp_path / "o")
    lines = r.stderr.strip().splitlines()
    assert r.code == 2 and len(lines) == 1 and f"{field} = " in lines[0] and expected in lines[0], r.stderr


def test_more_grid_cases_than_fit_in_memory_need_chunks(cli, tmp_path):
    path = write(
        tmp_path / "s.toml",
        f'{BASE}runs = 50001\n[distributions]\n"{PUMP}" = {{ kind = "grid", values = [0.1, 0.2] }}\n'
        '"vehicle.body.mass_kg" = { kind = "uniform", low = 1800.0, high = 2000.0 }\n',
    )
    r = cli("monte-carlo", path, "--out", tmp_path / "o")
    lines = r.stderr.strip().splitlines()
    assert r.code == 2 and len(lines) == 1, r.stderr
    assert (
        "runs = 50001: expected at most 100000 cases without --chunk-size (2 grid points × 50001 runs = 100002 cases"
        in lines[0]
    )


# --------------------------------------------------------------------------------------------
# the command line: a sharded shape-effect sweep, resumed


def test_a_sharded_shape_effect_sweep_from_the_command_line_resumes(cli, tmp_path, grid_path, study, unchunked):
    out = tmp_path / "s"
    written: list[int] = []
    with pytest.raises(ClientStopped):
        run_to_shards(study, out, 4, on_chunk=stop_after(2, written))
    assert (out / MANIFEST).is_file()
    r = cli("monte-carlo", grid_path, "--out", out, "--chunk-size", "4", "--no-progress")
    assert r.code == 0, r.stderr
    assert (
        "shape-sweep: 18 cases (9 grid points × 2 runs) × 2 models (table, quasi-dynamic), 36 rows in 5 chunks of 4 "
        "cases (3 computed, 2 kept from an earlier run)" in r.stdout
    ), r.stdout
    pd.testing.assert_frame_equal(read_shards(out), unchunked, check_exact=True)
    r = cli("monte-carlo", grid_path, "--out", out, "--chunk-size", "4", "--no-progress")
    assert r.code == 0 and "(0 computed, 5 kept from an earlier run)" in r.stdout, r.stderr


def test_the_unchunked_command_line_table_is_the_python_rows(cli, tmp_path, grid_path, unchunked):
    r = cli("monte-carlo", grid_path, "--out", tmp_path / "o", "--no-plots", "--no-progress")
    assert r.code == 0, r.stderr
    assert "shape-sweep: 18 cases (9 grid points × 2 runs) × 2 models (table, quasi-dynamic), 0 of 36" in r.stdout
    written = pd.read_csv(tmp_path / "o" / "monte_carlo.csv", dtype={"error": str}, keep_default_na=False)
    pd.testing.assert_frame_equal(written, unchunked, check_dtype=False, check_exact=False, rtol=1e-15)


def test_the_docs_shape_effect_sweep_is_a_valid_study_file(tmp_path):
    """docs/study.md "A shape-effect sweep": its file loads, 5 × 4 grid points, one run each."""
    doc = (Path(__file__).resolve().parents[2] / "docs" / "study.md").read_text(encoding="utf-8")
    text = doc.split("**A shape-effect sweep**", 1)[1].split("```toml\n", 1)[1].split("```", 1)[0]
    sf = load_study_file(write(tmp_path / "shape-sweep.toml", text))
    assert [p.key for p in sf.parameters] == [PUMP, TURBINE]
    assert sf.doc.grid_points == sf.doc.n_cases == 20 and sf.doc.n_runs == 1


@pytest.mark.parametrize("bare_first", [False, True])
def test_a_parameter_written_quoted_and_bare_is_given_twice(cli, tmp_path, bare_first):
    """Trial finding: TOML reads ``"a.b.c" = …`` and ``a.b.c = …`` as two keys; flattened to one
    parameter, the later silently replaced the earlier and a 2-point sweep ran as 1 point."""
    quoted = f'"{PUMP}" = {{ kind = "grid", values = [0.1, 0.2] }}\n'
    bare = f'{PUMP} = {{ kind = "grid", values = [0.3] }}\n'
    body = bare + quoted if bare_first else quoted + bare
    path = write(tmp_path / "s.toml", f"{BASE}[distributions]\n{body}")
    with pytest.raises(InputError) as err:
        load_study_file(path)
    assert err.value.field == f'distributions."{PUMP}"' and "given twice" in err.value.expected
    r = cli("monte-carlo", path, "--out", tmp_path / "o")
    assert r.code == 2 and len(r.stderr.strip().splitlines()) == 1 and "given twice" in r.stderr, r.stderr
    assert not (tmp_path / "o").exists()


def test_a_grid_value_a_model_of_the_study_refuses_is_refused_before_anything_runs(cli, tmp_path):
    """Trial finding: a Hrovat & Tobler shape effect beyond the mass matrix's bound passed the
    converter schema, and every run of its grid point failed (the table's and quasi-dynamic's too),
    the reason naming the bundled converter file. A grid's values are fixed: the study's models are
    built at each before anything runs."""
    key = "converter.geometry.pump_shape_effect_m2"
    body = f'"{key}" = {{ kind = "grid", values = [0.01, 0.5] }}\n'
    with_ht = BASE.replace('"quasi-dynamic"]', '"quasi-dynamic", "hrovat-tobler"]')
    path = write(tmp_path / "s.toml", f"{with_ht}[distributions]\n{body}")
    with pytest.raises(InputError) as err:
        load_study_file(path)
    e = err.value
    assert (e.source, e.field, e.value) == (str(path), f'distributions."{key}".values[1]', 0.5), str(e)
    assert "(the hrovat-tobler model): expected |S| < " in e.expected, str(e)
    r = cli("monte-carlo", path, "--out", tmp_path / "o")
    assert r.code == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "o").exists()
    # without the model that uses it, the value runs (the table and quasi-dynamic models ignore it)
    path = write(tmp_path / "t.toml", f"{BASE}[distributions]\n{body}")
    assert load_study_file(path).models == ("table", "quasi-dynamic")


def test_a_study_file_given_where_a_converter_is_expected_says_which_command_runs_it(cli, tmp_path):
    """Trial finding: ``tcsim study STUDY.toml`` said ``source = 'missing'``, no hint of monte-carlo."""
    path = write(tmp_path / "s.toml", f'{BASE}[distributions]\n"{PUMP}" = {{ kind = "grid", values = [0.1] }}\n')
    r = cli("study", path, "--out", tmp_path / "o")
    assert r.code == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "expected a converter file (run a Monte Carlo study file with: tcsim monte-carlo FILE)" in r.stderr
    assert not (tmp_path / "o").exists()


def test_an_implausible_grid_value_is_warned_of_once_naming_the_study_file(tmp_path):
    """Trial finding: 50 kg·m² of pump inertia ran without a word, where ``tcsim launch`` warns."""
    key = "converter.inertia.pump_kg_m2"
    path = write(tmp_path / "s.toml", f'{BASE}[distributions]\n"{key}" = {{ kind = "grid", values = [0.109, 50.0] }}\n')
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        load_study_file(path)
    said = [str(w.message) for w in caught if issubclass(w.category, TcsimWarning)]
    assert said == [
        f'{path}: distributions."{key}".values[1] = 50: [inertia].pump_kg_m2 = 50 is outside the plausible '
        "0.0001 to 10 kg·m² (pump, turbine and stator inertias with their fluid)"
    ], said


@pytest.mark.parametrize(
    ("models", "key", "distribution", "warned"),
    [
        # the H&T geometry's shape effect: no table or quasi-dynamic run sees it (a trial's sweep)
        ('["table", "quasi-dynamic"]', "converter.geometry.pump_shape_effect_m2", "grid", True),
        ('["table", "quasi-dynamic"]', "converter.geometry.pump_shape_effect_m2", "uniform", True),
        ('["table", "hrovat-tobler"]', "converter.geometry.pump_shape_effect_m2", "grid", False),
        ('["table"]', PUMP, "grid", True),
        ('["quasi-dynamic"]', PUMP, "grid", False),
        ('["table"]', "converter.inertia.pump_kg_m2", "uniform", False),
        ('["table"]', MASS, "uniform", False),
    ],
)
def test_a_parameter_no_model_uses_is_warned_of(tmp_path, models, key, distribution, warned):
    """Trial finding: a swept parameter that changes none of the study's models ran every grid point
    the same without a word."""
    low, high = (1800.0, 2000.0) if key == MASS else (0.1, 0.12) if "inertia" in key else (0.0, 0.001)
    dist = (
        f'{{ kind = "grid", values = [{low}, {high}] }}'
        if distribution == "grid"
        else f'{{ kind = "uniform", low = {low}, high = {high} }}'
    )
    runs = "" if distribution == "grid" else "runs = 2\n"
    text = f'seed = 1\n{runs}models = {models}\noutputs = ["time_0_50_km_h_s"]\n[distributions]\n"{key}" = {dist}\n'
    path = write(tmp_path / "s.toml", text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        monte_carlo_study(load_study_file(path))
    said = [str(w.message) for w in caught if issubclass(w.category, TcsimWarning)]
    unused = [m for m in said if "its values change no run" in m]
    if warned:
        names = ", ".join(json_list(models))
        assert unused == [
            f'{path}: distributions."{key}": none of the study\'s models ({names}) uses {key}; its values change no run'
        ], said
    else:
        assert unused == [], said


def json_list(text: str) -> list[str]:
    return [s.strip().strip('"') for s in text.strip("[]").split(",")]


def test_grids_alone_beyond_memory_blame_the_grids_not_the_runs(cli, tmp_path):
    # trial finding: the refusal of a 10⁷-point grid named "runs = 1"
    values = ", ".join(str(0.001 * k) for k in range(400))
    mass = ", ".join(str(1500.0 + k) for k in range(400))
    text = f'{BASE}[distributions]\n"{PUMP}" = {{ kind = "grid", values = [{values}] }}\n'
    text += f'"{MASS}" = {{ kind = "grid", values = [{mass}] }}\n'
    r = cli("monte-carlo", write(tmp_path / "s.toml", text), "--out", tmp_path / "o")
    lines = r.stderr.strip().splitlines()
    assert r.code == 2 and len(lines) == 1, r.stderr
    assert (
        "distributions = '160000 grid points': expected at most 100000 cases without --chunk-size "
        "(400 × 400 grid points × 1 run = 160000 cases; more: --chunk-size streams them to shards)" in lines[0]
    ), lines[0]
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("top", "grid", "field", "shown"),
    [
        ("", '{ kind = "grid", start = 0.1, stop = 0.3, num = 3.0 }', f'distributions."{PUMP}".num', "3.0"),
        ("runs = 2.0\n", '{ kind = "uniform", low = 0.1, high = 0.3 }', "runs", "2.0"),
    ],
)
def test_an_integer_written_as_a_float_is_shown_as_written(tmp_path, top, grid, field, shown):
    # trial finding: `num = 3.0` was refused as "num = 3: expected a valid integer"
    path = write(tmp_path / "s.toml", f'{BASE}{top}[distributions]\n"{PUMP}" = {grid}\n')
    with pytest.raises(InputError) as e:
        load_study_file(path)
    assert str(e.value) == f"{path}: {field} = {shown}: expected an integer, written without a decimal point"
