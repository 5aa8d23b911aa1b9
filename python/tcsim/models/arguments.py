"""Checks of a Python function's arguments: each turns a value of the wrong kind into an
:class:`~tcsim.errors.InputError` about the argument (source ``argument``), not NumPy's or Python's
``TypeError``/``ValueError``/``OverflowError`` from deep inside a call."""

from __future__ import annotations

import numbers

import numpy as np

from ..errors import InputError


def float_array(name: str, value: object, expected: str = "numbers (an array, a list or a number)") -> np.ndarray:
    """``value`` as a float array (any shape; non-finite values kept), else an error about ``name``.
    None is refused (NumPy makes it NaN)."""
    try:
        if value is None:
            raise TypeError
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError.argument(name, value, expected) from None


def real_number(name: str, value: object) -> float:
    """``value`` as a float when it is one real number (a Python or NumPy number, a 0-d array),
    else an error about ``name`` (a string, a list, a bool)."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError.argument(name, value, "a number")
    return float(value)


def worker_count(threads: object) -> int:
    """``threads`` of a batch: a whole number ≥ 0 (0: one worker per core), else an error about it
    (a negative count was an ``OverflowError`` of the binding)."""
    if isinstance(threads, bool) or not isinstance(threads, int | np.integer) or threads < 0:
        raise InputError.argument("threads", threads, "a whole number of workers, 0 for one per core")
    return int(threads)
