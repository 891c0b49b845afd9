"""Attitude arithmetic shared by every layer (imports nothing of lvgym): scalar-first quaternions.

``q_bi`` is the attitude of frame b relative to frame i; ``C_ib = R(q_bi)`` takes b components to i
components (``v_i = C_ib @ v_b``), as in the dynamics core and docs/conventions.md.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True, error_model="numpy", inline="always")
def quat_to_dcm(q0, q1, q2, q3, C):
    """Write ``C = R(q)`` (the matrix taking frame-b components to frame-i components for
    ``q = q_bi``) of the normalised quaternion into the 3x3 array ``C``."""
    n = 1.0 / math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    q0 *= n
    q1 *= n
    q2 *= n
    q3 *= n
    C[0, 0] = 1.0 - 2.0 * (q2 * q2 + q3 * q3)
    C[0, 1] = 2.0 * (q1 * q2 - q0 * q3)
    C[0, 2] = 2.0 * (q1 * q3 + q0 * q2)
    C[1, 0] = 2.0 * (q1 * q2 + q0 * q3)
    C[1, 1] = 1.0 - 2.0 * (q1 * q1 + q3 * q3)
    C[1, 2] = 2.0 * (q2 * q3 - q0 * q1)
    C[2, 0] = 2.0 * (q1 * q3 - q0 * q2)
    C[2, 1] = 2.0 * (q2 * q3 + q0 * q1)
    C[2, 2] = 1.0 - 2.0 * (q1 * q1 + q2 * q2)


@nb.njit(cache=True)
def quat_to_dcm_batch(q, C):
    """:func:`quat_to_dcm` over a batch: ``q`` (B, 4) scalar-first, ``C`` (B, 3, 3) written."""
    for j in range(q.shape[0]):
        quat_to_dcm(q[j, 0], q[j, 1], q[j, 2], q[j, 3], C[j])


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a (x) b`` of scalar-first quaternions (..., 4) (``q_ac = q_ab (x) q_bc``)."""
    a0, a1, a2, a3 = np.moveaxis(np.asarray(a, dtype=float), -1, 0)
    b0, b1, b2, b3 = np.moveaxis(np.asarray(b, dtype=float), -1, 0)
    return np.stack([a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3, a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
                     a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1, a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0], axis=-1)
