"""Unit constants shared by every layer (SI inside tcsim; these convert the units people use)."""

from __future__ import annotations

import math

from . import _core

#: rad/s per rpm.
RAD_S_PER_RPM = math.pi / 30.0
#: m/s per km/h.
KM_H = 1.0 / 3.6
#: N·m per lbf·ft.
LBF_FT_IN_NM = 1.3558179483314004
#: The pump speed at which tcsim evaluates steady states and stall figures unless told otherwise, rpm:
#: the core's reference pump speed (also where the default flow time constant τ_Q is evaluated).
DEFAULT_PUMP_SPEED_RPM: float = _core.reference_pump_speed_rpm()
#: :data:`DEFAULT_PUMP_SPEED_RPM` in rad/s, as the core converts it.
DEFAULT_PUMP_SPEED_RAD_S: float = _core.reference_pump_speed_rad_s()
