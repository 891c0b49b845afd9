"""Test oracle: the null-space equations assembled literally, with dense matrices (thesis eq. 2.50-2.51).

``A = Y^T M Y``, ``b = Y^T (f - M Ydot u - f_non) - (D u + K q)`` on the modal rows, with ``Ydot u``
taken by a central finite difference of ``Y(q)`` along the motion. It shares nothing with the compiled
kernel but the layout; attitudes come from scipy's Rotation. Slow and only for tests.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from lvgym.dynamics import Layout


def skew(a: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def dcm(q: np.ndarray) -> np.ndarray:
    """C_ib of a scalar-first quaternion q_bi."""
    return Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()


def quat_rate(q: np.ndarray, w: np.ndarray) -> np.ndarray:
    w0, w1, w2 = w
    Om = np.array([[0, -w0, -w1, -w2], [w0, 0, w2, -w1], [w1, -w2, 0, w0], [w2, w1, -w0, 0]])
    return 0.5 * Om @ q


class Oracle:
    def __init__(self, layout: Layout):
        self.lay = layout
        self.N, self.K = layout.n_slosh, layout.n_modes

    def _parts(self, x, p):
        lay, K = self.lay, self.K
        st = {k: x[s] for k, s in lay.state.items()}
        C = dcm(st["q_bi"])
        eta = st["eta"]
        sl = []
        for j in range(self.N):
            g = {k: p[lay.slosh_param(j, k)] for k in Layout.SLOSH_FIELDS}
            Psi = np.zeros((3, 2 * K))
            Psi[1, :K] = g["phi"]
            Psi[2, K:] = g["phi"]
            sl.append((g, Psi, dcm(x[lay.state["q_si"]][4 * j:4 * j + 4])))
        return st, C, eta, sl

    def Y(self, x, p):
        lay, K, N = self.lay, self.K, self.N
        st, C, eta, sl = self._parts(x, p)
        nr = 6 + 2 * K
        Y = np.zeros((nr + 6 * N, nr + 2 * N))
        Y[:nr, :nr] = np.eye(nr)
        E = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        r_cg = p[lay.params["r_cg"]]
        for j, (g, Psi, Cs) in enumerate(sl):
            rho = g["r_hinge"] - r_cg + Psi @ eta
            rows = slice(nr + 6 * j, nr + 6 * j + 3)
            Y[rows, 0:3] = np.eye(3)
            Y[rows, 3:6] = -C @ skew(rho)
            Y[rows, 6:nr] = C @ Psi
            Y[rows, nr + 2 * j:nr + 2 * j + 2] = g["length"] * Cs @ skew([1.0, 0, 0]) @ E
            Y[nr + 6 * j + 3:nr + 6 * j + 6, nr + 2 * j:nr + 2 * j + 2] = E
        return Y

    def kinematic_rate(self, x):
        lay, N = self.lay, self.N
        xd = np.zeros_like(x)
        xd[lay.state["r_zw_i"]] = x[lay.state["v_zw_i"]]
        xd[lay.state["q_bi"]] = quat_rate(x[lay.state["q_bi"]], x[lay.state["omega_bi_b"]])
        xd[lay.state["eta"]] = x[lay.state["eta_dot"]]
        qs = x[lay.state["q_si"]].reshape(N, 4)
        ws = x[lay.state["omega_si_s"]].reshape(N, 2)
        xd[lay.state["q_si"]] = np.concatenate(
            [quat_rate(qs[j], [0.0, ws[j, 0], ws[j, 1]]) for j in range(N)]) if N else []
        return xd

    def speeds(self, x):
        lay = self.lay
        return np.concatenate([x[lay.state["v_zw_i"]], x[lay.state["omega_bi_b"]],
                               x[lay.state["eta_dot"]], x[lay.state["omega_si_s"]]])

    def accelerations(self, x, p, u):
        """Independent accelerations ``[v_dot, omega_dot, eta_ddot, w_dot]`` from dense algebra."""
        lay, K, N = self.lay, self.K, self.N
        nr = 6 + 2 * K
        st, C, eta, sl = self._parts(x, p)
        uu = self.speeds(x)
        Y = self.Y(x, p)
        eps = 1e-6
        xd = self.kinematic_rate(x)
        Ydot = (self.Y(x + eps * xd, p) - self.Y(x - eps * xd, p)) / (2 * eps)
        m_b = p[lay.params["m_b"]][0]
        J = p[lay.params["J_b"]].reshape(3, 3)
        M = np.zeros((nr + 6 * N, nr + 6 * N))
        M[:3, :3] = m_b * np.eye(3)
        M[3:6, 3:6] = J
        M[6:nr, 6:nr] = np.eye(2 * K)
        for j, (g, _, _) in enumerate(sl):
            o = nr + 6 * j
            M[o:o + 3, o:o + 3] = g["m"] * np.eye(3)
            M[o + 4:o + 6, o + 4:o + 6] = g["inertia"] * np.eye(2)
        ld = {k: u[s] for k, s in lay.loads.items()}
        grav = ld["g_i"]
        # thrust: rotate by the slope at the gimbal, apply at the deflected gimbal
        phi_g = p[lay.params["phi_gimbal"]]
        dphi_g = p[lay.params["dphi_gimbal"]]
        s_y, s_z = dphi_g @ eta[:K], dphi_g @ eta[K:]
        f_t = Rotation.from_rotvec([0.0, -s_z, s_y]).apply(ld["thrust_b"])
        Psi_g = np.zeros((3, 2 * K))
        Psi_g[1, :K] = phi_g
        Psi_g[2, K:] = phi_g
        r_cg = p[lay.params["r_cg"]]
        rho_e = p[lay.params["r_gimbal"]] - r_cg + Psi_g @ eta
        w = st["omega_bi_b"]
        f = np.zeros(nr + 6 * N)
        f[:3] = ld["f_b_i"] + m_b * grav + C @ f_t
        f[3:6] = ld["m_b_b"] + np.cross(rho_e, f_t) - np.cross(w, J @ w)
        om = p[lay.params["omega_modes"]]
        ze = p[lay.params["zeta_modes"]]
        om2, ze2 = np.tile(om, 2), np.tile(ze, 2)
        f[6:nr] = ld["f_eta"] + Psi_g.T @ f_t - 2 * ze2 * om2 * st["eta_dot"] - om2 ** 2 * eta
        ws = x[lay.state["omega_si_s"]].reshape(N, 2)
        for j, (g, _, Cs) in enumerate(sl):
            o = nr + 6 * j
            f[o:o + 3] = g["m"] * grav
            w_s = np.array([0.0, *ws[j]])
            w_b_in_s = Cs.T @ C @ w
            rel = w_s - w_b_in_s
            rel[0] = 0.0
            tau = -g["m"] * 2 * g["zeta"] * g["omega"] * g["length"] ** 2 * rel
            f[o + 3:o + 6] = tau
            f[3:6] -= C.T @ Cs @ tau
        A = Y.T @ M @ Y
        b = Y.T @ (f - M @ Ydot @ uu)
        return np.linalg.solve(A, b)
