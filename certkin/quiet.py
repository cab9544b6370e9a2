"""numpy's floating-point warnings are not for the user: an overflow on absurd input gives an infinite
bound, which the outward-rounded operations carry soundly (``docs/soundness.md`` §1), so the public
functions of the capabilities run with them silenced (``quiet``), as the command line does."""
from __future__ import annotations

import functools
import warnings

import numpy as np


def quiet(function):
    """``function`` with numpy's floating-point warnings (overflow, invalid, division by zero) silenced."""
    @functools.wraps(function)
    def silenced(*args, **kwargs):
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            return function(*args, **kwargs)
    return silenced
