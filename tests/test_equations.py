"""The compiled equations against hand numbers and against the dense null-space oracle."""

import numpy as np
import pytest
from oracle import Oracle

from lvgym.dynamics import NonRigidModel


def _random_vehicle(n, k, rng, inertia=(0.0, 0.3)):
    model = NonRigidModel(n, k)
    slosh = [{"m": rng.uniform(0.5, 20), "length": rng.uniform(0.3, 2), "r_hinge": rng.normal(size=3),
              "inertia": inertia[j % 2], "zeta": 0.1, "omega": 3.0, "phi": rng.normal(size=k) * 0.3}
             for j in range(n)]
    a = rng.normal(size=(3, 3))
    p = model.params(m_b=30.0, J_b=a @ a.T + 3 * np.eye(3), r_cg=[-2, 0.01, 0.02],
                     r_gimbal=[-5, 0, 0], omega_modes=rng.uniform(10, 60, k),
                     zeta_modes=rng.uniform(0, 0.05, k), phi_gimbal=rng.normal(size=k) * 0.3,
                     dphi_gimbal=rng.normal(size=k) * 0.2, slosh=slosh)
    lay = model.layout
    x = lay.zeros_state() + rng.normal(size=lay.n_x) * 0.5
    for o in [lay.state["q_bi"].start] + [lay.state["q_si"].start + 4 * j for j in range(n)]:
        x[o:o + 4] /= np.linalg.norm(x[o:o + 4])
    return model, x, p, rng.normal(size=lay.n_u) * 5


def _accelerations(model, xdot):
    s = model.layout.state
    return np.concatenate([xdot[s["v_zw_i"]], xdot[s["omega_bi_b"]], xdot[s["eta_dot"]],
                           xdot[s["omega_si_s"]]])


@pytest.mark.parametrize("n, k", [(0, 0), (1, 1), (2, 0), (0, 2), (3, 2), (6, 2)])
def test_kernel_matches_dense_null_space_assembly(n, k):
    rng = np.random.default_rng(10 * n + k)
    model, x, p, u = _random_vehicle(n, k, rng)
    got = _accelerations(model, model.derivative(x, p, u))
    ref = Oracle(model.layout).accelerations(x, p, u)
    np.testing.assert_allclose(got, ref, rtol=1e-7, atol=1e-7 * np.abs(ref).max())


def test_batch_equals_single():
    rng = np.random.default_rng(3)
    vehicles = [_random_vehicle(3, 2, rng) for _ in range(5)]
    model = vehicles[0][0]
    x = np.stack([v[1] for v in vehicles])
    p = np.stack([v[2] for v in vehicles])
    u = np.stack([v[3] for v in vehicles])
    batch = model.derivative(x, p, u)
    single = np.stack([model.derivative(x[i], p[i], u[i]) for i in range(5)])
    np.testing.assert_array_equal(batch, single)
    stepped = model.step(x, p, u, 1e-3, 20)
    np.testing.assert_array_equal(stepped[2], model.step(x[2], p[2], u[2], 1e-3, 20))


def test_rigid_body_hand_numbers():
    """No slosh, no modes: Newton and Euler with gyroscopic coupling."""
    model = NonRigidModel()
    J = np.diag([2.0, 5.0, 7.0])
    p = model.params(m_b=4.0, J_b=J)
    x = model.layout.zeros_state()
    w = np.array([0.3, -0.2, 0.5])
    x[model.layout.state["omega_bi_b"]] = w
    u = model.loads(f_b_i=[8.0, 0, -4.0], m_b_b=[1.0, 2.0, 3.0], g_i=[0, 0, -9.81])
    xd = model.derivative(x, p, u)
    np.testing.assert_allclose(xd[3:6], [2.0, 0.0, -1.0 - 9.81])
    wdot = np.linalg.solve(J, [1.0, 2.0, 3.0] - np.cross(w, J @ w))
    np.testing.assert_allclose(xd[10:13], wdot)
    np.testing.assert_allclose(xd[6:10], 0.5 * np.array([0.0, *w]))


def test_thrust_at_gimbal_with_flex_tilt_hand_numbers():
    """Thesis eq. 2.20-2.22: thrust tilted by the slope at the gimbal, applied at the deflected node."""
    model = NonRigidModel(0, 1)
    p = model.params(m_b=100.0, J_b=[10, 400, 400], r_cg=[-4, 0, 0], r_gimbal=[-9, 0, 0],
                     omega_modes=[50.0], phi_gimbal=[0.2], dphi_gimbal=[-0.05])
    x = model.layout.zeros_state()
    x[model.layout.state["eta"]] = [0.1, 0.0]  # y-plane mode deflected
    thrust = 1000.0
    xd = model.derivative(x, p, model.loads(thrust_b=[thrust, 0, 0]))
    slope = -0.05 * 0.1
    f_b = thrust * np.array([np.cos(slope), np.sin(slope), 0.0])
    np.testing.assert_allclose(xd[3:6], f_b / 100.0)
    r_e = np.array([-5.0, 0.2 * 0.1, 0.0])   # gimbal from CG, deflected by phi * eta
    np.testing.assert_allclose(xd[10:13], np.cross(r_e, f_b) / np.array([10, 400, 400]))
    eta_dd = xd[model.layout.state["eta_dot"]]
    np.testing.assert_allclose(eta_dd, [0.2 * f_b[1] - 50.0 ** 2 * 0.1, 0.0])


def test_vanishing_and_empty_slosh_mass_is_regular():
    rng = np.random.default_rng(7)
    model, x, p, u = _random_vehicle(2, 1, rng, inertia=(0.0, 0.0))
    lay = model.layout
    ref_model = NonRigidModel(1, 1)
    # drop pendulum 1 entirely: the same vehicle with one pendulum
    p_ref = np.concatenate([p[:lay.params["slosh"].start], p[lay.slosh_param(0, "m").start:
                                                             lay.slosh_param(0, "phi").stop]])
    x_ref = np.concatenate([x[:lay.state["q_si"].start], x[lay.state["q_si"]][:4],
                            x[lay.state["omega_si_s"]][:2]])
    ref = ref_model.derivative(x_ref, p_ref, u)
    for m in (1e-12, 0.0):
        p[lay.slosh_param(1, "m")] = m
        xd = model.derivative(x, p, u)
        assert np.all(np.isfinite(xd))
        np.testing.assert_allclose(xd[:lay.state["q_si"].start], ref[:lay.state["q_si"].start],
                                   rtol=1e-9, atol=1e-9)
    # an empty tank freezes its pendulum state
    assert np.all(xd[lay.state["q_si"]][4:] == 0) and np.all(xd[lay.state["omega_si_s"]][2:] == 0)
    # a vanishing mass still moves as a massless pendulum
    p[lay.slosh_param(1, "m")] = 1e-12
    assert np.any(model.derivative(x, p, u)[lay.state["omega_si_s"]][2:] != 0)


def test_point_mass_pendulum_at_ninety_degrees_is_regular():
    model = NonRigidModel(1, 0)
    p = model.params(m_b=1.0, J_b=[1, 1, 1], slosh=[{"m": 5.0, "length": 1.0, "r_hinge": [0, 0, 0]}])
    x = model.layout.zeros_state()
    c = np.cos(np.pi / 4)
    for q in ([c, 0, 0, c], [c, 0, c, 0], [0.0, 0.0, 1.0, 0.0]):   # 90 deg about z, y; 180 deg
        x[model.layout.state["q_si"]] = q
        x[model.layout.state["omega_si_s"]] = [1.0, -2.0]
        xd = model.derivative(x, p, model.loads(g_i=[-9.81, 0, 0]))
        assert np.all(np.isfinite(xd))


def test_shift_cg_keeps_the_structure_in_place():
    from scipy.spatial.transform import Rotation
    model = NonRigidModel()
    x = model.layout.zeros_state()
    rot = Rotation.from_euler("zyx", [30, -20, 10], degrees=True)
    q = rot.as_quat()
    x[6:10] = [q[3], q[0], q[1], q[2]]
    x[10:13] = [0.1, -0.4, 0.2]
    d = np.array([-0.5, 0.02, 0.0])
    y = model.shift_cg(x, d)
    C = rot.as_matrix()
    np.testing.assert_allclose(y[0:3], C @ d)
    np.testing.assert_allclose(y[3:6], C @ np.cross(x[10:13], d))
    np.testing.assert_array_equal(y[6:], x[6:])


def test_angular_momentum_is_kept_in_free_space_with_damped_slosh():
    """No external loads: the angular momentum about the origin of B, the slosh bodies (and the
    internal damper torques between them) is constant."""
    from lvgym.verify.cases import case_e_model
    from scipy.spatial.transform import Rotation

    model, x, p, _ = case_e_model(zeta=0.2)
    lay = model.layout
    lay.view(p, "params", "J_b")[:] = [[1.0, 0.1, 0.0], [0.1, 200.0, 0.0], [0.0, 0.0, 200.0]]
    p[lay.slosh_param(1, "inertia")] = 0.05
    x[lay.state["eta"]] *= 0.1
    x[lay.state["eta_dot"]] *= 0.1
    x[lay.state["omega_bi_b"]] = [0.5, 0.1, -0.2]
    x[lay.state["omega_si_s"]] = [0.3, -0.1, 0.0, 0.2]
    x[lay.state["r_zw_i"]] = 0.0   # about a point near the vehicle, not 6,379 km away
    x[lay.state["v_zw_i"]] = [1.0, -2.0, 0.5]

    def h_total(x):
        q = x[lay.state["q_bi"]]
        C = Rotation.from_quat([*q[1:], q[0]]).as_matrix()
        J = lay.view(p, "params", "J_b")
        h = C @ J @ x[lay.state["omega_bi_b"]] + p[0] * np.cross(x[0:3], x[3:6])
        r, v = model.slosh_kinematics(x, p)
        for j in range(2):
            m_j = p[lay.slosh_param(j, "m")][0]
            qs = x[lay.state["q_si"]][4 * j:4 * j + 4]
            Cs = Rotation.from_quat([*qs[1:], qs[0]]).as_matrix()
            w_s = np.array([0.0, *x[lay.state["omega_si_s"]][2 * j:2 * j + 2]])
            h += m_j * np.cross(r[j], v[j]) + Cs @ (p[lay.slosh_param(j, "inertia")][0] * w_s)
        return h

    h0 = h_total(x)
    e0 = model.energy(x, p, [0, 0, 0])["total"]
    errors = []
    for dt in (5e-4, 2.5e-4):
        x1 = model.step(x, p, model.loads(), dt, int(round(2.0 / dt)))
        errors.append(np.linalg.norm(h_total(x1) - h0) / np.linalg.norm(h0))
    assert errors[1] < 1e-8
    assert errors[0] / errors[1] > 12   # what is left is fourth-order truncation error
    assert model.energy(x1, p, [0, 0, 0])["total"] < e0   # the dampers dissipate
