"""Converter and vehicle definitions (TOML schemas, bundled parameter sets), steady state per model,
dynamic models and drives, the design geometry. Imports only :mod:`tcsim._core` and the base layer."""
