"""Borrowed views (lvgym.borrow): the same numbers compiled and in Python (a cfunc's pure-Python path, as the
linearisation calls the flight loads), and writes through them reach the owner."""

from collections import namedtuple

import numba as nb
import numpy as np

from lvgym.borrow import unowned, unowned_all, unowned_matrix

Pair = namedtuple("Pair", ["a", "b"])


def _fill(v, pair):
    w = unowned(v)
    m = unowned_matrix(w, 2, 2, 3)             # v[2:8] as a 2 x 3 matrix
    for i in range(2):
        for j in range(3):
            m[i, j] = 10 * i + j
    p = unowned_all(pair)
    p.a[0] = p.b[1] + w[0]
    return m[1, 2] + p.a[0]


_fill_compiled = nb.njit(_fill)


def test_views_are_the_same_compiled_and_in_python():
    out = []
    for fn in (_fill, _fill_compiled):
        v = np.arange(10.0)
        pair = Pair(np.zeros(2), np.array([3.0, 4.0]))
        r = fn(v, pair)
        out.append((r, v.copy(), pair.a.copy()))
    for r, v, a in out:
        assert r == 12.0 + 4.0
        assert v.tolist() == [0.0, 1.0, 0.0, 1.0, 2.0, 10.0, 11.0, 12.0, 8.0, 9.0]
        assert a.tolist() == [4.0, 0.0]
