"""Compiled table search shared by the environment kernels (they read packed parameter arrays in place,
without making array views: a view costs two atomic reference-count updates in numba)."""

from __future__ import annotations

import numba as nb


@nb.njit(cache=True, inline="always")
def search_right_k(a, lo, hi, x):
    """``lo + np.searchsorted(a[lo:hi], x, side="right")`` for the sorted ``a[lo:hi]``, without a view
    (the same binary search as numba's and NumPy's; NaN goes to the end)."""
    while lo < hi:
        mid = lo + ((hi - lo) >> 1)
        if a[mid] <= x or x != x:
            lo = mid + 1
        else:
            hi = mid
    return lo
