"""Transient runs of the isolated converter (one, or a batch) and whole-vehicle launch runs with their
scenarios. Imports models and the base layer."""
