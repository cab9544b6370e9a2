"""Placeholder: elementary functions (being written)."""
from .interval import Interval
import numpy as np
pi = Interval(np.float64(3.141592653589793), np.nextafter(3.141592653589793, 4))
def sqrt(x): raise NotImplementedError
abs = min = max = sin = cos = tan = atan = atan2 = exp = log = sqrt
