"""tcsim: hydrodynamic torque converter models for vehicle simulation.

Three models (``table``, ``hrovat-tobler``, ``quasi-dynamic``) after Li & Sundén (2016),
"Evaluation of torque converter models for vehicle take-off simulation", Chalmers/Volvo Cars,
and Hrovat & Tobler (1985). Units are SI and carried in every name (``conventions.md``).

Tiers:

* one-liners: :func:`characterise` (a converter name or file and a model → DataFrame),
  :func:`steady_state` (steady states at any pump and turbine speeds → DataFrame),
  :func:`operating_point` (the backward operating point: pump speed and torque from turbine speed
  and torque → DataFrame) and
  :func:`simulate` (a converter, a drive and a model → :class:`~tcsim.transient.TransientResult`);
* objects: :func:`load_converter` → :class:`Converter`, then :mod:`tcsim.steady` per model;
  :func:`dynamic_model` → :class:`~tcsim.transient.DynamicModel` and the drives of
  :mod:`tcsim.transient`; :func:`simulate_batch` for many runs on all cores, :func:`simulate_columns`
  for their results as one array per column;
* raw: :mod:`tcsim._core` (NumPy arrays in, arrays out, GIL released).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .errors import InputError, TcsimWarning

if TYPE_CHECKING:
    from .api import characterise, operating_point, steady_state
    from .models.characteristic import Characteristic
    from .models.converter import Converter, bundled_names, load_converter
    from .models.dynamic import dynamic_model
    from .models.steady import coupling_point, hrovat_tobler_steady_state
    from .simulation.transient import simulate, simulate_batch, simulate_columns

#: Where each public name lives: imported on first use, so that ``import tcsim`` and ``tcsim --help``
#: do not import pandas, SciPy or matplotlib (issue 16).
_LAZY: dict[str, str] = {
    "Characteristic": ".models.characteristic",
    "Converter": ".models.converter",
    "bundled_names": ".models.converter",
    "load_converter": ".models.converter",
    "dynamic_model": ".models.dynamic",
    "coupling_point": ".models.steady",
    "hrovat_tobler_steady_state": ".models.steady",
    "simulate": ".simulation.transient",
    "simulate_batch": ".simulation.transient",
    "simulate_columns": ".simulation.transient",
    "characterise": ".api",
    "steady_state": ".api",
    "operating_point": ".api",
}

__all__ = [
    "Characteristic",
    "Converter",
    "InputError",
    "TcsimWarning",
    "bundled_names",
    "characterise",
    "coupling_point",
    "dynamic_model",
    "hrovat_tobler_steady_state",
    "load_converter",
    "operating_point",
    "simulate",
    "simulate_batch",
    "simulate_columns",
    "steady_state",
]


def __getattr__(name: str) -> Any:
    """A public name of :data:`_LAZY`, imported on first use (PEP 562)."""
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'tcsim' has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})
