"""numpy's floating-point warnings are not for the user: an overflow on absurd input gives an infinite
bound, which the outward-rounded operations carry soundly (``docs/soundness.md`` §1), so the public
functions of the capabilities run with them silenced (``quiet``), as the command line does.
``numpy.errstate`` is local to the thread (and context), so concurrent calls (a Dask worker's
threads) do not touch each other's settings or the process's warning filters."""
from __future__ import annotations

import functools

import numpy as np


def quiet(function):
    """``function`` with numpy's floating-point warnings (overflow, invalid, division by zero) silenced."""
    @functools.wraps(function)
    def silenced(*args, **kwargs):
        with np.errstate(all="ignore"):
            return function(*args, **kwargs)
    return silenced
