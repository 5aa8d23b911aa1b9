"""``tcsim.torus``: fluid-parameter estimates from a circular torus (docs/models.md), kept as a facade
of :mod:`tcsim.models.torus`."""

from __future__ import annotations

from .models.torus import TorusEstimate, torus_estimate

__all__ = ["TorusEstimate", "torus_estimate"]
