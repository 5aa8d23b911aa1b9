"""Design studies (issue 15 item 3; docs/design.md, "Design studies"): the batched figures equal
``tcsim design``'s one design at a time, a failing design keeps its row with the reason, sweeps are
checked, and the Pareto front is the non-dominated set."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import tcsim.analysis.design_study as ds
from tcsim.analysis.design_report import design_report
from tcsim.analysis.design_study import FIGURE_COLUMNS, check_sweep, design_study, pareto_front, parse_sweep
from tcsim.errors import InputError
from tcsim.models.design_file import load_design_file


@pytest.fixture(scope="module")
def elliptic():
    base = load_design_file("li-sunden-2016-design")
    return replace(base, design=replace(base.design, profile="elliptic", squash_ratio=0.0))


def test_batched_figures_equal_tcsim_design_one_at_a_time(elliptic):
    sweep = {"squash_ratio": [0.0, 0.3], "turbine_exit_angle_deg": [-60.0, -40.0]}
    study = design_study(elliptic, sweep)
    assert len(study) == 4 and (study["error"] == "").all()
    assert study[["squash_ratio", "turbine_exit_angle_deg"]].to_numpy().tolist() == [
        [0.0, -60.0],
        [0.0, -40.0],
        [0.3, -60.0],
        [0.3, -40.0],
    ]
    for _, row in study.iterrows():
        d = replace(
            elliptic.design, squash_ratio=row["squash_ratio"], turbine_exit_angle_deg=row["turbine_exit_angle_deg"]
        )
        one = design_report(replace(elliptic, design=d)).summary.iloc[0]
        for c in FIGURE_COLUMNS:
            assert row[c] == pytest.approx(one[c], rel=1e-9, abs=0.0), c
    # the sweep moves the figures (not one design repeated); the squash ratio only acts through
    # the shape effects and L_f, which the steady state does not see
    assert study["turbine_shape_effect_m2"].nunique() == 4
    assert study["takeoff_effective_tr_dip"].nunique() == 4
    assert study["stall_torque_ratio"].nunique() == 2


def test_a_failing_design_keeps_its_row_and_the_others_survive(elliptic):
    bad = design_study(elliptic, {"pump_exit_angle_deg": [-30.0, 95.0, -10.0]})
    good = design_study(elliptic, {"pump_exit_angle_deg": [-30.0, -10.0]})
    assert bad["error"].iloc[0] == bad["error"].iloc[2] == ""
    msg = bad["error"].iloc[1]
    assert "--sweep: pump_exit_angle_deg = 95: expected" in msg and "\n" not in msg
    assert bad.loc[1, list(FIGURE_COLUMNS)].isna().all()
    assert not bool(bad["pareto_front"].iloc[1])
    for c in FIGURE_COLUMNS:
        assert bad[c].iloc[[0, 2]].tolist() == good[c].tolist(), c


def test_a_squash_ratio_out_of_range_is_a_row_error_not_a_failed_study(elliptic):
    study = design_study(elliptic, {"squash_ratio": [0.1, 1.0]})
    assert study["error"].iloc[0] == ""
    # the value is the sweep's, not the design file's (a trial finding: the row blamed the file)
    assert study["error"].iloc[1].startswith("--sweep: squash_ratio = 1: expected a squash ratio in [0, 1)")


def test_an_axial_width_refused_through_its_squash_ratio_blames_the_sweep(elliptic):
    study = design_study(elliptic, {"axial_width_m": [0.01, 0.5]})
    assert study["error"].iloc[0] == ""
    assert study["error"].iloc[1].startswith("--sweep: axial_width_m (as squash_ratio) = -")


def test_a_squash_sweep_of_a_circular_design_is_elliptic_and_squash_0_is_the_circle():
    circular = load_design_file("li-sunden-2016-design")
    assert circular.design.profile == "circular"
    study = design_study(circular, {"squash_ratio": [0.0, 0.3]})
    assert (study["error"] == "").all()
    one = design_report(circular).summary.iloc[0]
    for c in FIGURE_COLUMNS:
        assert study[c].iloc[0] == pytest.approx(one[c], rel=1e-9, abs=1e-15), c
    assert study["turbine_shape_effect_m2"].iloc[1] != study["turbine_shape_effect_m2"].iloc[0]


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ("axial_length_m=0.1:0.2:3", "NAME"),  # not a [design] field
        ("squash_ratio", "NAME"),  # no '='
        ("squash_ratio=0:0.3", "squash_ratio"),  # no count
        ("squash_ratio=a:0.3:4", "squash_ratio bounds"),
        ("squash_ratio=0.3:0.3:4", "squash_ratio bounds"),  # MIN = MAX
        ("squash_ratio=0.3:0.1:4", "squash_ratio bounds"),  # MIN > MAX
        ("squash_ratio=0:inf:4", "squash_ratio bounds"),
        ("squash_ratio=0:0.3:1", "squash_ratio count"),  # N < 2
        ("squash_ratio=0:0.3:1001", "squash_ratio count"),  # N > 1000
        ("squash_ratio=0:0.3:2.5", "squash_ratio count"),
        ("squash_ratio=0:0.3:-3", "squash_ratio count"),
    ],
)
def test_bad_sweeps_are_input_errors(text, field):
    with pytest.raises(InputError) as e:
        parse_sweep(text)
    assert e.value.source == "--sweep" and e.value.field == field


def test_a_sweep_parses_to_evenly_spaced_values_with_both_ends():
    name, values = parse_sweep("pump_exit_radius_m=0.11:0.14:4")
    assert name == "pump_exit_radius_m"
    assert values.tolist() == pytest.approx([0.11, 0.12, 0.13, 0.14], rel=1e-15)
    assert values[0] == 0.11 and values[-1] == 0.14


def test_check_sweep_limits_parameters_and_designs():
    with pytest.raises(InputError, match="one or two"):
        check_sweep({})
    with pytest.raises(InputError, match="one or two"):
        check_sweep({"squash_ratio": [0.0], "pump_exit_radius_m": [0.1], "stator_exit_radius_m": [0.05]})
    with pytest.raises(InputError, match="at most 20000 designs"):
        check_sweep({"squash_ratio": np.zeros(1000), "pump_exit_radius_m": np.zeros(21)})
    with pytest.raises(InputError, match="finite"):
        check_sweep({"squash_ratio": [0.0, float("nan")]})
    check_sweep({"squash_ratio": np.zeros(1000), "pump_exit_radius_m": np.zeros(20)})  # 20000: the limit
    # kept as shards (nothing in memory), only the counts per parameter bound it: 1000 × 1000
    check_sweep({"squash_ratio": np.zeros(1000), "pump_exit_radius_m": np.zeros(1000)}, chunked=True)


def test_pareto_front_is_the_non_dominated_set():
    tr = np.array([2.0, 2.2, 2.1, 2.2, np.nan, 1.9])
    dip = np.array([0.01, 0.02, 0.03, 0.02, 0.0, 0.005])
    # 2 is beaten by 1 (higher TR, smaller dip); 1 and 3 tie (neither beats the other); NaN never
    assert pareto_front(tr, dip).tolist() == [True, True, False, True, False, True]


def test_take_offs_in_chunks_give_the_same_figures(elliptic, monkeypatch):
    sweep = {"squash_ratio": [0.0, 0.2, 0.4], "pump_exit_angle_deg": [-30.0, 95.0, -10.0]}  # 3 bad rows
    whole = design_study(elliptic, sweep)
    monkeypatch.setattr(ds, "TAKEOFF_CHUNK", 2)
    chunked = design_study(elliptic, sweep)
    assert (chunked["error"] != "").sum() == 3
    assert chunked.equals(whole)


def test_an_axial_width_sweep_is_the_squash_sweep_at_each_designs_radii():
    """``axial_width_m`` w sweeps the squash ratio 1 − w/(R_p − R_s) (issue 15's "axial length"): the
    same figures as the squash sweep, thinner tori smaller shape effects and dips; wider than the
    circle is a row error naming the squash ratio."""
    circular = load_design_file("li-sunden-2016-design")
    height = circular.design.pump_exit_radius_m - circular.design.stator_exit_radius_m  # 0.06 m
    squash = [0.0, 0.25, 0.5]
    by_width = design_study(circular, {"axial_width_m": [(1.0 - q) * height for q in squash] + [1.2 * height]})
    by_squash = design_study(circular, {"squash_ratio": squash})
    for c in FIGURE_COLUMNS:
        np.testing.assert_allclose(by_width[c][:3], by_squash[c], rtol=1e-12, err_msg=c)
    assert (np.diff(by_width["turbine_shape_effect_m2"][:3]) < 0).all()
    assert (np.diff(by_width["takeoff_effective_tr_dip"][:3]) < 0).all()
    refused = "--sweep: axial_width_m (as squash_ratio) = -0.2: expected a squash ratio in [0, 1)"
    assert refused in by_width["error"].iloc[3]
    # the width of the radii swept with it: R_p 0.13 m at width 0.06 m is squash 1 − 0.06/0.07
    both = design_study(circular, {"pump_exit_radius_m": [0.13], "axial_width_m": [0.06]})
    alone = design_study(circular, {"pump_exit_radius_m": [0.13], "squash_ratio": [1.0 - 0.06 / 0.07]})
    for c in FIGURE_COLUMNS:
        assert both[c][0] == pytest.approx(alone[c][0], rel=1e-12), c


def test_an_axial_width_sweep_of_a_polyline_design_is_refused():
    base = load_design_file("li-sunden-2016-design")
    d = base.design
    rs, rt, rp, w = d.stator_exit_radius_m, d.turbine_exit_radius_m, d.pump_exit_radius_m, 0.02
    polyline = replace(
        d,
        profile="polyline",
        pump_path_m=((rs, 0.0), (rs, w), (rp, w), (rp, 0.0)),
        turbine_path_m=((rp, 0.0), (rp, -w), (rt, -w), (rt, 0.0)),
        stator_path_m=((rt, 0.0), (rs, 0.0)),
    )
    with pytest.raises(InputError, match="axial_width_m.*expected a circular or elliptic design"):
        design_study(replace(base, design=polyline), {"axial_width_m": [0.03, 0.04]})
