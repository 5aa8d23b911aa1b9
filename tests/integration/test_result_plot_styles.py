"""One style map for every figure (tcsim.plots.styles, issue 17 item 3): the drive cycle's figures draw
each model in its style (line style and marker, not colour alone), like the launch, replay and
characterise figures; the fit's and the design's lines, which are not models, take the other styles in
turn, so that two lines never differ in colour only."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from tcsim.analysis.drive import Cycle, drive
from tcsim.models.characteristic import Characteristic
from tcsim.models.vehicle import load_vehicle
from tcsim.plots.design import plot_design_takeoff
from tcsim.plots.drive import plot_drive
from tcsim.plots.fit import fit_figure
from tcsim.plots.styles import MODEL_STYLES, OTHER_STYLES


def captured(monkeypatch) -> list:
    figures: list = []
    monkeypatch.setattr(plt, "close", lambda fig=None: figures.append(fig))
    return figures


def line_style(line) -> tuple:
    return line.get_linestyle(), line.get_marker()


@pytest.fixture(scope="module")
def short_drive():
    """Every model over a 40 s trace: 0 → 10 m/s → 0."""
    t = np.arange(0.0, 40.1, 0.5)
    speed = np.interp(t, [0, 5, 20, 35, 40], [0, 0, 10, 0, 0])
    return drive(load_vehicle(None), Cycle("ramp", "test", t, speed))


@pytest.mark.filterwarnings("ignore:.*overrun:tcsim.errors.TcsimWarning")
def test_the_drive_figures_draw_each_model_in_its_style(short_drive, tmp_path, monkeypatch):
    figures = captured(monkeypatch)
    plot_drive(short_drive, tmp_path)
    monkeypatch.undo()
    assert len(short_drive.runs) == 3
    checked = 0
    try:
        for fig in figures:
            for ax in fig.axes:
                seen: dict[str, set] = {}
                for line in ax.get_lines():
                    model = str(line.get_label()).split(":")[0]
                    if model in MODEL_STYLES:
                        seen.setdefault(model, set()).add(line_style(line))
                for model, styles in seen.items():
                    expected = MODEL_STYLES[model]
                    assert styles == {(expected.linestyle, expected.marker or "None")}, (model, styles)
                if len(seen) > 1:
                    assert len({s for styles in seen.values() for s in styles}) == len(seen)
                    checked += 1
    finally:
        for fig in figures:
            plt.close(fig)
    assert checked == 3  # vehicle speed, speed error, energies


def test_two_lines_that_are_not_models_differ_in_line_style_and_marker(tmp_path, monkeypatch):
    figures = captured(monkeypatch)
    t = np.linspace(0.0, 3.0, 301)
    takeoff = {
        name: pd.DataFrame(dict(time_s=t, effective_torque_ratio=2 - t / 3 + k, turbine_speed_rad_s=10 * t + k))
        for k, name in enumerate(("my-design", "li-sunden-2016"))
    }
    plot_design_takeoff(takeoff, tmp_path, "take-off")
    sr = np.linspace(0.0, 1.0, 11)
    table = Characteristic(sr, 2.0 - sr, np.full_like(sr, 3e-3), source="table.csv")
    curves = {
        label: pd.DataFrame(dict(speed_ratio=sr, torque_ratio=2.0 - sr + k * 0.1))
        for k, label in enumerate(("fitted", "start"))
    }
    figures.append(fit_figure("torque_ratio", curves, "fit", table, 0.9)[0])
    monkeypatch.undo()
    try:
        for fig in figures:
            ax = fig.axes[0]
            lines = [line for line in ax.get_lines() if line.get_label() in {*takeoff, *curves}]
            assert [line.get_marker() for line in lines] == [s.marker for s in OTHER_STYLES[:2]], ax.get_title()
            assert lines[0].get_linestyle() != lines[1].get_linestyle(), ax.get_title()
    finally:
        for fig in figures:
            plt.close(fig)
