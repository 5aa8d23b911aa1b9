"""Computations on runs and measurements: effective torques, error metrics, the replay, launch
summaries, fitting of Hrovat & Tobler parameters and of shape effects, the parameter study."""
