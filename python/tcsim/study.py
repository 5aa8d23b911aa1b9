"""``tcsim.study``: the parameter study of Li & Sundén (2016), Appendix D, kept as a facade of
:mod:`tcsim.analysis.study` (figures: :mod:`tcsim.plots.study`)."""

from __future__ import annotations

from .analysis.study import COLUMNS, TABLE_D1, ParameterRange, StudyDefinition, default_definition, run_study

__all__ = ["COLUMNS", "TABLE_D1", "ParameterRange", "StudyDefinition", "default_definition", "run_study"]
