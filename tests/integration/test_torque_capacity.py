"""Issue 12, item 3: torque-dependent capacity (docs/torque_capacity.md). Several characteristic
tables, each measured at one input torque; the pump torque solves the fixed point T = P(T); a single
table behaves exactly as before; `characterise --input-torque-nm`. The tables are synthetic (no
published torque-dependent table is at hand): Li & Sundén's Table C.1 and variants of it whose CF
drops at low SR as the torque rises (Kietlinski & Fingerman 2007's finding, thesis §4.3.2)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import tomli_w
from hypothesis import given
from hypothesis import strategies as st

from conftest import C1_CF, C1_SR, C1_TR
from tcsim import _core
from tcsim.analysis.fitting import target_table
from tcsim.errors import InputError
from tcsim.models.converter import Converter, load_converter, parse_converter
from tcsim.models.dynamic import dynamic_model
from tcsim.models.steady import characterise, steady_state
from tcsim.transient import isolated_takeoff, simulate

SR = np.array(C1_SR)


def variant(k: float) -> dict:
    """Table C.1 with CF scaled by (1 − k·(1 − SR)) and TR moved towards 1 by k."""
    return {
        "speed_ratio": C1_SR,
        "torque_ratio": [1.0 + (t - 1.0) * (1.0 - k) for t in C1_TR],
        "capacity_factor_nm_s2": [c * (1.0 - k * (1.0 - s)) for s, c in zip(C1_SR, C1_CF, strict=True)],
    }


def document(tables: list[tuple[float, dict]]) -> dict:
    """The bundled li-sunden-2016 with ``[[characteristic]]`` tables (torque, columns)."""
    doc = load_converter("li-sunden-2016").to_toml_dict()
    doc["characteristic"] = [{"input_torque_nm": t, **cols} for t, cols in tables]
    return doc


def write(tmp_path, doc: dict, name: str = "conv.toml"):
    p = tmp_path / name
    p.write_text(tomli_w.dumps(doc))
    return p


TWO = [(100.0, variant(0.0)), (300.0, variant(0.2))]
THREE = [(300.0, variant(0.2)), (100.0, variant(0.0)), (200.0, variant(0.1))]  # any order in the file


@pytest.fixture
def two(tmp_path) -> Converter:
    return load_converter(write(tmp_path, document(TWO)))


@pytest.fixture
def three(tmp_path) -> Converter:
    return load_converter(write(tmp_path, document(THREE)))


# ---------------------------------------------------------------------------------------------
# steady state


@pytest.mark.parametrize("tables", [TWO, THREE])
def test_each_tables_own_input_torque_reproduces_that_table(tmp_path, tables):
    conv = load_converter(write(tmp_path, document(tables)))
    for torque, cols in tables:
        df = characterise(conv, "table", speed_ratio=SR, input_torque_nm=torque)
        np.testing.assert_allclose(df["capacity_factor_nm_s2"], cols["capacity_factor_nm_s2"], rtol=1e-12, atol=0)
        np.testing.assert_allclose(df["torque_ratio"], cols["torque_ratio"], rtol=0, atol=1e-12)
        np.testing.assert_allclose(df["pump_torque_nm"], torque, rtol=1e-12)
        # the forward fixed point at those speeds finds the same torque
        fwd = steady_state(conv, "table", df["pump_speed_rad_s"], df["turbine_speed_rad_s"])
        np.testing.assert_allclose(fwd["pump_torque_nm"], torque, rtol=1e-9)
        np.testing.assert_allclose(fwd["torque_ratio"], cols["torque_ratio"], rtol=0, atol=1e-9)


def test_between_two_tables_cf_and_tr_lie_between_them(two):
    lo, hi = TWO[0][1], TWO[1][1]
    df = characterise(two, "table", speed_ratio=SR, input_torque_nm=200.0)
    cf, tr = df["capacity_factor_nm_s2"].to_numpy(), df["torque_ratio"].to_numpy()
    for got, key in ((cf, "capacity_factor_nm_s2"), (tr, "torque_ratio")):
        a, b = np.array(lo[key]), np.array(hi[key])
        differ = a != b
        assert differ.any()
        assert (np.minimum(a, b)[differ] < got[differ]).all() and (got[differ] < np.maximum(a, b)[differ]).all()
        np.testing.assert_array_equal(got[~differ], a[~differ])
    # CF is linear in T at the same SR: halfway between 100 and 300 N·m, the mean
    np.testing.assert_allclose(
        cf, 0.5 * (np.array(lo["capacity_factor_nm_s2"]) + hi["capacity_factor_nm_s2"]), rtol=1e-12
    )


def test_outside_the_tables_torques_the_nearest_table_is_held(three):
    for torque, table in ((20.0, variant(0.0)), (5000.0, variant(0.2))):
        df = characterise(three, "table", speed_ratio=SR, input_torque_nm=torque)
        np.testing.assert_allclose(df["capacity_factor_nm_s2"], table["capacity_factor_nm_s2"], rtol=1e-12)
        np.testing.assert_allclose(df["torque_ratio"], table["torque_ratio"], rtol=0, atol=1e-12)
    # forward: a slow pump (small torque) is on the first table, a fast one on the last, exactly
    single = parse_converter(document([(100.0, variant(0.0))]) | {"characteristic": variant(0.0)}, "c1")
    heavy = parse_converter(document([(300.0, variant(0.2))]) | {"characteristic": variant(0.2)}, "heavy")
    wp, wt = np.array([50.0, -80.0]), np.array([10.0, -20.0])
    pd.testing.assert_frame_equal(steady_state(three, "table", wp, wt), steady_state(single, "table", wp, wt))
    wp, wt = np.array([600.0, 900.0]), np.array([300.0, 100.0])
    pd.testing.assert_frame_equal(steady_state(three, "table", wp, wt), steady_state(heavy, "table", wp, wt))


def test_the_fixed_point_is_solved_at_any_speeds(two):
    g = np.linspace(-400.0, 400.0, 41)
    wp, wt = (a.ravel() for a in np.meshgrid(g, g))
    df = steady_state(two, "table", wp, wt)
    t = df["pump_torque_nm"].to_numpy()
    tables = two.characteristic.tables()
    p = [
        _core.table_steady_states(*c.arrays(), wp, wt, **c.core_rules())["pump_torque_nm"] for c in tables
    ]  # each table alone at the same speeds
    w = np.clip((t - 100.0) / 200.0, 0.0, 1.0)
    mixed = (1.0 - w) * p[0] + w * p[1]
    np.testing.assert_allclose(mixed, t, rtol=1e-12, atol=1e-9)


speed = st.floats(-500.0, 500.0, allow_nan=False)


@given(points=st.lists(st.tuples(speed, speed), min_size=1, max_size=40))
def test_two_tables_are_passive_at_random_points_of_every_quadrant(points):
    conv = parse_converter(document(TWO), "two")
    wp, wt = (np.array(v) for v in zip(*points, strict=True))
    df = steady_state(conv, "table", wp, wt)
    p = df["pump_torque_nm"] * wp - df["turbine_torque_nm"] * wt
    scale = np.maximum(df["pump_torque_nm"].abs(), df["turbine_torque_nm"].abs()) * np.maximum(np.abs(wp), np.abs(wt))
    assert (p >= -1e-12 * scale).all()


# ---------------------------------------------------------------------------------------------
# one table: exactly as before


def test_a_single_table_and_an_array_of_one_are_the_same_bit_for_bit(tmp_path):
    single = load_converter("li-sunden-2016")
    one = load_converter(write(tmp_path, document([(150.0, variant(0.0))])))
    wp, wt = np.array([200.0, 150.0, -90.0, 0.0]), np.array([20.0, 180.0, 40.0, 100.0])
    for model in ("table", "quasi-dynamic"):
        pd.testing.assert_frame_equal(
            steady_state(one, model, wp, wt), steady_state(single, model, wp, wt), check_exact=True
        )
        a = simulate(single, isolated_takeoff(), model=model).frame()
        b = simulate(one, isolated_takeoff(), model=model).frame()
        pd.testing.assert_frame_equal(a, b, check_exact=True)


def test_a_two_table_transient_run_closes_the_energy_identity(two):
    t = np.linspace(0.0, 4.0, 4001)
    for model in ("table", "quasi-dynamic"):
        f = simulate(two, isolated_takeoff(), model=model, times_s=t).frame()
        assert f["pump_torque_nm"].max() > 150.0  # the run crosses between the tables
        loss = np.trapezoid(f["fluid_loss_power_w"], f["time_s"])
        net = np.trapezoid(f["converter_input_power_w"], f["time_s"]) - loss
        stored = f["stored_energy_j"].iloc[-1] - f["stored_energy_j"].iloc[0]
        through = np.trapezoid((f["pump_torque_nm"] * f["pump_speed_rad_s"]).abs(), f["time_s"])
        assert abs(stored - net) < 1e-6 * through, (model, stored, net, through)


# ---------------------------------------------------------------------------------------------
# characterise --input-torque-nm


@pytest.mark.parametrize("model", ["table", "quasi-dynamic", "hrovat-tobler"])
def test_characterise_at_an_input_torque_finds_pump_speeds_carrying_it(model):
    conv = load_converter("li-sunden-2016")
    df = characterise(conv, model, input_torque_nm=180.0)
    solved = df["pump_speed_rad_s"].notna().to_numpy()
    assert solved.sum() > 90 and (df["pump_speed_rad_s"][solved] > 0).all()
    np.testing.assert_allclose(df["pump_torque_nm"][solved], 180.0, rtol=1e-9)
    # the forward steady state at those speeds gives the torque back
    fwd = steady_state(conv, model, df["pump_speed_rad_s"][solved], df["turbine_speed_rad_s"][solved])
    np.testing.assert_allclose(fwd["pump_torque_nm"], 180.0, rtol=1e-9)
    # where none is found, no positive pump speed carries a positive torque (here: SR 1, H&T)
    sr = df["speed_ratio"][~solved].to_numpy()
    assert (steady_state(conv, model, 200.0, 200.0 * sr)["pump_torque_nm"] <= 0.0).all()


def test_characterise_input_torque_cli(cli, tmp_path, two):
    r = cli("characterise", two.path, "--model", "table", "--input-torque-nm", "200", "--out", tmp_path / "o")
    assert r.code == 0, r.stderr
    df = pd.read_csv(tmp_path / "o" / "characteristic.csv")
    np.testing.assert_allclose(df["pump_torque_nm"], 200.0, rtol=1e-9)
    r = cli("characterise", two.path, "--input-torque-nm", "200", "--pump-speed-rpm", "2000", "--out", tmp_path / "p")
    assert r.code == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "--input-torque-nm = 200" in r.stderr and "not both" in r.stderr
    r = cli("characterise", two.path, "--input-torque-nm", "0", "--out", tmp_path / "q")
    assert r.code == 2 and r.stderr.count("\n") == 1 and "non-zero" in r.stderr, r.stderr
    assert not (tmp_path / "p").exists() and not (tmp_path / "q").exists()


@pytest.mark.filterwarnings("ignore::tcsim.errors.TcsimWarning")  # the table's mirror extension above SR 1
@pytest.mark.parametrize("model", ["table", "hrovat-tobler"])
def test_an_input_torque_no_speed_ratio_carries_is_refused_and_coast_needs_overrun(cli, tmp_path, model):
    """A trial: ``--input-torque-nm -100`` over SR 0-1 wrote 102 rows of NaN with exit 0; a coast
    torque is carried above SR 1; a torque of 1e300 N·m wrote pump speeds of 1.8e151 rad/s."""
    r = cli("characterise", "li-sunden-2016", "-m", model, "--input-torque-nm", "-100", "--out", tmp_path / "n")
    assert r.code == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "--input-torque-nm = -100: expected a torque the converter carries" in r.stderr
    assert "speed ratio of the sweep (0 to 1)" in r.stderr and "speed ratios above 1 (for example 1 to 2)" in r.stderr
    sr = np.linspace(1.1, 2.0, 10)
    coast = characterise(load_converter("li-sunden-2016"), model, speed_ratio=sr, input_torque_nm=-100.0)
    solved = coast["pump_speed_rad_s"].notna().to_numpy()
    assert solved.sum() >= 5 and (coast["pump_speed_rad_s"][solved] > 0).all()
    np.testing.assert_allclose(coast["pump_torque_nm"][solved], -100.0, rtol=1e-9)
    # a drive torque over overrun speed ratios only: the hint points the other way
    r = cli(
        "characterise",
        "li-sunden-2016",
        "-m",
        model,
        "--input-torque-nm",
        "100",
        "--speed-ratio",
        "1.1:2:0.1",
        "--out",
        tmp_path / "p",
    )
    assert r.code == 2 and "(1.1 to 2); a positive (drive) torque needs speed ratios below 1" in r.stderr, r.stderr
    r = cli("characterise", "li-sunden-2016", "-m", model, "--input-torque-nm", "1e300", "--out", tmp_path / "h")
    assert r.code == 2 and "plausible" in r.stderr and "--allow-implausible" in r.stderr, r.stderr
    assert not (tmp_path / "n").exists() and not (tmp_path / "h").exists()


# ---------------------------------------------------------------------------------------------
# files


def test_to_toml_dict_round_trips(two, tmp_path):
    doc = two.to_toml_dict()
    assert [t["input_torque_nm"] for t in doc["characteristic"]] == [100.0, 300.0]
    again = load_converter(write(tmp_path, doc, "again.toml"))
    a, b = two.characteristic.core_table(), again.characteristic.core_table()
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])


def test_a_csv_with_an_input_torque_column_is_the_table_alone_form(tmp_path, two):
    rows = ["input_torque_nm,speed_ratio,torque_ratio,capacity_factor_nm_s2"]
    for torque, cols in TWO:
        rows += [f"{torque},{s!r},{t!r},{c!r}" for s, t, c in zip(*cols.values(), strict=True)]
    p = tmp_path / "two.csv"
    p.write_text("\n".join(rows) + "\n")
    csv = load_converter(p)
    wp, wt = np.array([250.0, 300.0]), np.array([0.0, 200.0])
    pd.testing.assert_frame_equal(steady_state(csv, "table", wp, wt), steady_state(two, "table", wp, wt))


def bad(tmp_path, doc_or_text) -> str:
    p = tmp_path / "bad.toml"
    p.write_text(doc_or_text if isinstance(doc_or_text, str) else tomli_w.dumps(doc_or_text))
    return str(p)


@pytest.mark.parametrize(
    ("edit", "field", "value"),
    [
        (
            lambda d: d["characteristic"][2].update(input_torque_nm=100.0),
            "[characteristic][2].input_torque_nm",
            "100",
        ),
        (lambda d: d["characteristic"][1].pop("input_torque_nm"), "[characteristic][1].input_torque_nm", "'missing'"),
        (
            lambda d: d["characteristic"][0].update(input_torque_nm=-50.0),
            "[characteristic][0].input_torque_nm",
            "-50",
        ),
        (
            lambda d: d["characteristic"][1].update(torque_ratio=[3.0] * 13),
            "[characteristic][1].torque_ratio[4]",
            "3",
        ),
        (
            lambda d: (d["characteristic"][0].update(overrun="mirror"), d["characteristic"][2].update(overrun="table")),
            "[characteristic][2].overrun",
            "'table'",
        ),
    ],
)
def test_bad_torque_tables_exit_2_with_one_line(cli, tmp_path, edit, field, value):
    doc = document(THREE)
    edit(doc)
    path = bad(tmp_path, doc)
    r = cli("characterise", path, "--model", "table", "--out", tmp_path / "out")
    assert r.code == 2, r.stderr
    assert r.stderr.count("\n") == 1, r.stderr
    assert r.stderr.startswith(f"error: {path}: {field} = {value}: expected"), r.stderr
    assert not (tmp_path / "out").exists()


def test_mixing_single_and_array_tables_exits_2(cli, tmp_path):
    text = tomli_w.dumps(document(TWO)) + "\n[characteristic]\nspeed_ratio = [0.0, 1.0]\n"
    path = bad(tmp_path, text)
    r = cli("characterise", path, "--model", "table", "--out", tmp_path / "out")
    assert r.code == 2 and r.stderr.count("\n") == 1 and "(syntax)" in r.stderr, r.stderr


def test_a_fit_target_with_several_tables_is_refused(two):
    with pytest.raises(InputError, match="one characteristic table to fit"):
        target_table(two.path)


def test_the_model_specification_carries_the_tables(two):
    spec = dynamic_model(two, "table").spec
    assert spec["input_torque_nm"] == [100.0, 300.0] and spec["table_rows"] == [13.0, 13.0]
    assert len(spec["speed_ratio"]) == 26
    single = dynamic_model(load_converter("li-sunden-2016"), "table").spec
    assert "input_torque_nm" not in single and "table_rows" not in single
