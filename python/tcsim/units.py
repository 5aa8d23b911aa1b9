"""Unit constants shared by every layer (SI inside tcsim; these convert the units people use)."""

from __future__ import annotations

from . import _core

_UNITS = _core.unit_constants()  # the core's tcsim_core::units, the one owner of these numbers
#: rad/s per rpm (π/30).
RAD_S_PER_RPM: float = _UNITS["rad_s_per_rpm"]
#: m/s per km/h.
KM_H: float = _UNITS["m_s_per_km_h"]
#: N·m per lbf·ft.
LBF_FT_IN_NM: float = _UNITS["nm_per_lbf_ft"]
#: The pump speed at which tcsim evaluates steady states and stall figures unless told otherwise, rpm:
#: the core's reference pump speed (also where the default flow time constant τ_Q is evaluated).
DEFAULT_PUMP_SPEED_RPM: float = _core.reference_pump_speed_rpm()
#: :data:`DEFAULT_PUMP_SPEED_RPM` in rad/s, as the core converts it.
DEFAULT_PUMP_SPEED_RAD_S: float = _core.reference_pump_speed_rad_s()
