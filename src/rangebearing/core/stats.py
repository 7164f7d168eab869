"""Order statistics of small arrays by a partial sort: ``np.median``'s values without its generic path.

``np.median`` goes through ``_ureduce``, a full ``np.mean`` of the middle pair and
a NaN check: tens of microseconds a call, and the pipeline takes medians of tiny
arrays per band and per landmark. Its first call in a process also imports
``numpy.ma`` (15–20 ms, on the daemon's start-up path). These give the same values:
the middle order statistic, or the mean of the middle two (their sum halved in the
input's float type, or in float64 for integers, as ``np.mean`` computes it), NaN when a float input holds a NaN.
"""

from __future__ import annotations

from typing import Optional

import numpy as np


def median(values: np.ndarray) -> float:
    """``float(np.median(values))`` of any non-empty array (flattened), by a partial sort."""
    part = np.array(values).ravel()  # a copy to partition in place: np.partition's own steps, minus its wrapper
    n = part.size
    half = n // 2
    nan_check = part.dtype.kind in "fc"
    if n % 2:
        part.partition((half, n - 1) if nan_check else half)
        mid = float(part[half])
    else:
        part.partition((half - 1, half, n - 1) if nan_check else (half - 1, half))
        # np.mean's arithmetic: in the float type itself, in float64 for integers
        lo, hi = part[half - 1], part[half]
        mid = float((lo + hi) / 2) if nan_check else (float(lo) + float(hi)) / 2.0
    if nan_check and part[n - 1] != part[n - 1]:  # np.partition puts NaNs last
        return float("nan")
    return mid


def median_rows(values: np.ndarray) -> np.ndarray:
    """``np.median(values, axis=0)`` of a non-empty 2-D array of integers (float64 out) or floats (their type)."""
    a = np.asarray(values)
    n = a.shape[0]
    half = n // 2
    nan_check = a.dtype.kind in "fc"
    if n % 2:
        part = a.copy()
        part.partition((half, n - 1) if nan_check else half, axis=0)
        out = part[half].astype(a.dtype if nan_check else np.float64)
    else:
        part = a.copy()
        part.partition((half - 1, half, n - 1) if nan_check else (half - 1, half), axis=0)
        lo, hi = part[half - 1], part[half]
        out = (lo + hi) / 2 if nan_check else (lo.astype(np.float64) + hi.astype(np.float64)) / 2
    if nan_check:
        out[np.isnan(part[n - 1])] = np.nan
    return out


def percentile(values: np.ndarray, pct: float, table: Optional[np.ndarray] = None) -> float:
    """``np.percentile(values, pct)`` (its default, linear method) by a partial sort.

    Two order statistics and their linear interpolation: the same value as numpy's,
    without its generic path (tens of microseconds a call: verify takes four per candidate,
    the daemon two per status line).
    ``table``: a non-decreasing lookup table; the percentile is then that of
    ``table[values]``, for which only the two order statistics need looking up
    (a non-decreasing map keeps every order statistic).
    """
    part = values.flatten()  # a copy to partition in place: np.partition's own steps, minus its wrapper
    pos = pct / 100.0 * (part.size - 1)
    lo = int(pos)
    hi = min(lo + 1, part.size - 1)
    part.partition((lo, hi))
    low, high = (part[lo], part[hi]) if table is None else (table[part[lo]], table[part[hi]])
    low, high = float(low), float(high)
    t = pos - lo
    return high - (high - low) * (1.0 - t) if t >= 0.5 else low + (high - low) * t
