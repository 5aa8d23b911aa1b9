"""The warnings about finished runs of several models (``tcsim.models.dynamic.warn_about_runs``): the
overrun extension is one line per converter naming every run that reached it (a fresh-eyes trial saw
``tcsim drive`` on the bundled defaults print the same warning twice, once per table model)."""

from __future__ import annotations

import warnings

import numpy as np

from tcsim.errors import TcsimWarning
from tcsim.models.dynamic import dynamic_model, warn_about_runs

CONVERTER = "li-sunden-2016-fitted"  # a table ending at SR 1 with overrun = "mirror"


def columns(top_speed_ratio: float) -> dict[str, np.ndarray]:
    pump = np.full(5, 200.0)
    return {"pump_speed_rad_s": pump, "turbine_speed_rad_s": pump * np.linspace(0.2, top_speed_ratio, 5)}


def caught(runs) -> list[str]:
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        warn_about_runs("drive", runs)
    return [str(x.message) for x in w if issubclass(x.category, TcsimWarning) and "overrun" in str(x.message)]


def test_runs_that_reach_the_extension_share_one_warning_naming_each():
    table, ht, qd = (dynamic_model(CONVERTER, m) for m in ("table", "hrovat-tobler", "quasi-dynamic"))
    runs = [("table", table, columns(1.42)), ("hrovat-tobler", ht, columns(1.6)), ("quasi-dynamic", qd, columns(1.43))]
    [message] = caught(runs)
    assert message.endswith(
        "overrun = \"mirror\": the table ends at SR 1; the drive runs 'table' and 'quasi-dynamic' reached SR "
        "1.42 and 1.43, where tcsim mirrors the characteristic (the turbine drives the pump; see docs/models.md)"
    ), message
    assert message.startswith(str(table.source))


def test_one_run_is_named_alone_and_runs_within_the_table_are_not():
    table, qd = dynamic_model(CONVERTER, "table"), dynamic_model(CONVERTER, "quasi-dynamic")
    [message] = caught([("table", table, columns(0.9)), ("quasi-dynamic", qd, columns(1.2))])
    assert "the drive run 'quasi-dynamic' reached SR 1.2," in message
    assert caught([("table", table, columns(0.95)), ("quasi-dynamic", qd, columns(1.0))]) == []
