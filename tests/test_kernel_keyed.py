"""lvgym.simulator.threads.Kernel.keyed: a compiled function called through its entry point gives what its
dispatcher gives, one overload per key (the observations' dtype of a law)."""

from __future__ import annotations

import numba as nb
import numpy as np

from lvgym.simulator.threads import Kernel


@nb.njit(cache=False)
def _scaled_sum(x, gain, out):
    for i in range(x.shape[0]):
        out[i] = gain * x[i] + 1.0


def test_entry_points_give_the_dispatchers_numbers_per_key():
    kernel = Kernel(_scaled_sum)
    for dtype in (np.float32, np.float64, np.float32):
        x = np.arange(5, dtype=dtype) / 3
        out, want = np.empty(5), np.empty(5)
        kernel.keyed(np.dtype(dtype), x, 0.7, out)            # the first call of a key: the dispatcher
        kernel.keyed(np.dtype(dtype), x, 0.7, out)            # then its entry point
        _scaled_sum(x, 0.7, want)
        np.testing.assert_array_equal(out, want)
        np.testing.assert_allclose(out, 0.7 * np.arange(5) / 3 + 1.0, rtol=1e-6)
    assert set(kernel.entries) == {np.dtype(np.float32), np.dtype(np.float64)}
    assert len(_scaled_sum.signatures) == 2 and all(callable(e) for e in kernel.entries.values())
