"""Frequency responses of the design tools' linear systems, evaluated fast and stably.

A discrete loop of the flight computer has 20-40 states and is read on a grid of 20,000 frequencies
(:func:`.linearize.margin_grid`), and a design evaluates thousands of them. python-control evaluates a
state-space system one frequency at a time (a linear solve per point). Here the state matrix is brought
once to its complex Schur form ``A = Z T Z^H`` (``Z`` unitary, ``T`` upper triangular: stable for the
defective matrices of the hold and the delays, where an eigenvector basis does not exist), and
``(s I - T) x = Z^H B`` is solved by back-substitution for every frequency at once:

    G(s) = C Z (s I - T)^-1 Z^H B + D,   s = exp(j w dt) (discrete) or j w (continuous).

It gives python-control's numbers to 1e-10 relative at most frequencies, 1e-8 near an integrator's pole at
z = 1, whose conditioning costs both methods digits (tests/test_design_auto.py), 50-80 times faster on the
flight loops.
"""

from __future__ import annotations

from typing import Any

import control
import numpy as np
import scipy.linalg as sla

__all__ = ["frequency_response", "ss_response"]


def ss_response(sys_: control.StateSpace, s: np.ndarray) -> np.ndarray:
    """Complex response of the SISO state-space ``sys_`` at the complex points ``s`` (the Laplace or z
    variable, not a frequency), by the Schur form of its state matrix (module docstring)."""
    s = np.asarray(s, complex).ravel()
    A, B, C, D = (np.asarray(m, float) for m in (sys_.A, sys_.B, sys_.C, sys_.D))
    if B.shape[1] != 1 or C.shape[0] != 1:
        raise ValueError(f"a SISO system: it has {B.shape[1]} inputs and {C.shape[0]} outputs")
    n = A.shape[0]
    if n == 0:
        return np.full(s.size, D[0, 0], complex)
    T, Z = sla.schur(A.astype(complex), output="complex")
    b = Z.conj().T @ B[:, 0]
    x = np.empty((n, s.size), complex)
    for i in range(n - 1, -1, -1):           # (s - T_ii) x_i - sum_{j > i} T_ij x_j = b_i
        x[i] = (b[i] + T[i, i + 1:] @ x[i + 1:]) / (s - T[i, i])
    return (C[0] @ Z) @ x + D[0, 0]


def frequency_response(sys_: Any, w: np.ndarray) -> np.ndarray:
    """Complex response of ``sys_`` (SISO, continuous or discrete; a state-space system by
    :func:`ss_response`) at the angular frequencies ``w`` [rad/s]."""
    w = np.asarray(w, float)
    s = np.exp(1j * w * sys_.dt) if sys_.dt else 1j * w
    if isinstance(sys_, control.StateSpace):
        return ss_response(sys_, s)
    return np.asarray(sys_(s), complex).ravel()
