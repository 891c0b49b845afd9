"""Layout of the flat vectors and validation of named parameters."""

import numpy as np
import pytest

from lvgym.dynamics import Layout, NonRigidModel


@pytest.mark.parametrize("n, k", [(0, 0), (1, 1), (6, 2), (3, 0), (0, 4)])
def test_sizes(n, k):
    lay = Layout(n, k)
    assert lay.n_x == 13 + 4 * k + 6 * n
    assert lay.n_p == 16 + 4 * k + n * (8 + k)
    assert lay.n_u == 12 + 2 * k
    # slices tile the vectors without gaps
    for table, total in ((lay.state, lay.n_x), (lay.params, lay.n_p), (lay.loads, lay.n_u)):
        covered = sorted((s.start, s.stop) for s in table.values())
        assert covered[0][0] == 0 and covered[-1][1] == total
        assert all(a[1] == b[0] for a, b in zip(covered[:-1], covered[1:]))


def test_rest_state_has_unit_quaternions():
    lay = Layout(3, 1)
    x = lay.zeros_state(batch=4)
    assert x.shape == (4, lay.n_x)
    np.testing.assert_array_equal(lay.view(x, "state", "q_bi")[:, 0], 1.0)
    np.testing.assert_array_equal(lay.view(x, "state", "q_si")[..., 0], 1.0)
    assert lay.view(x, "state", "q_si").shape == (4, 3, 4)


def test_slosh_param_slices_and_views_write_through():
    model = NonRigidModel(2, 2)
    p = model.params(m_b=10.0, J_b=[1, 2, 2], omega_modes=[10, 20], zeta_modes=[0.01, 0.02],
                     slosh=[{"m": 1.5, "length": 0.4, "r_hinge": [-1, 0, 0], "phi": [0.1, 0.2]},
                            {"m": 2.5, "length": 0.6, "r_hinge": [-2, 0, 0], "zeta": 0.1}])
    lay = model.layout
    assert p[lay.slosh_param(1, "m")][0] == 2.5
    np.testing.assert_array_equal(p[lay.slosh_param(0, "phi")], [0.1, 0.2])
    np.testing.assert_array_equal(p[lay.slosh_param(1, "r_hinge")], [-2, 0, 0])
    lay.view(p, "params", "J_b")[1, 1] = 7.0
    assert p[lay.params["J_b"]][4] == 7.0


@pytest.mark.parametrize("kwargs, match", [
    ({"m_b": -1.0, "J_b": [1, 1, 1]}, "m_b = -1.0"),
    ({"m_b": 1.0, "J_b": [1, -1, 1]}, "J_b"),
    ({"m_b": 1.0, "J_b": [1, 1, 1], "zeta_modes": [-0.1]}, "zeta_modes"),
    ({"m_b": float("nan"), "J_b": [1, 1, 1]}, "finite"),
    ({"m_b": 1.0, "J_b": [1, 1, 1], "omega_modes": [1.0, 2.0]}, "omega_modes has 2 entries"),
])
def test_bad_parameters_name_the_key(kwargs, match):
    model = NonRigidModel(0, 1)
    with pytest.raises(ValueError, match=match):
        model.params(**kwargs)


def test_bad_slosh_entries():
    model = NonRigidModel(1, 0)
    with pytest.raises(KeyError, match="unknown keys"):
        model.params(m_b=1, J_b=[1, 1, 1], slosh=[{"m": 1, "length": 1, "r_hinge": [0, 0, 0], "mas": 2}])
    with pytest.raises(KeyError, match="misses 'length'"):
        model.params(m_b=1, J_b=[1, 1, 1], slosh=[{"m": 1, "r_hinge": [0, 0, 0]}])
    with pytest.raises(ValueError, match="length"):
        model.params(m_b=1, J_b=[1, 1, 1], slosh=[{"m": 1, "length": 0.0, "r_hinge": [0, 0, 0]}])
    with pytest.raises(ValueError, match="expected n_slosh = 1"):
        model.params(m_b=1, J_b=[1, 1, 1])
    with pytest.raises(ValueError, match=r"expected \(29,\) or \(batch, 29\)"):
        NonRigidModel(2, 1).derivative(np.zeros(5), np.zeros(NonRigidModel(2, 1).layout.n_p),
                                       np.zeros(NonRigidModel(2, 1).layout.n_u))


def test_kernel_offsets_agree_with_the_layout():
    from lvgym.dynamics import kernels as k
    lay = Layout(2, 3)
    assert (k.X_R, k.X_V, k.X_Q, k.X_W, k.X_ETA) == tuple(
        lay.state[n].start for n in ("r_zw_i", "v_zw_i", "q_bi", "omega_bi_b", "eta"))
    assert (k.P_M, k.P_CG, k.P_J, k.P_GIM, k.P_MODES) == tuple(
        lay.params[n].start for n in ("m_b", "r_cg", "J_b", "r_gimbal", "omega_modes"))
    assert (k.U_F, k.U_M, k.U_T, k.U_G, k.U_ETA) == tuple(
        lay.loads[n].start for n in ("f_b_i", "m_b_b", "thrust_b", "g_i", "f_eta"))
    assert lay.slosh_block == 8 + 3 and lay.slosh_param(1, "phi").start == \
        lay.params["slosh"].start + lay.slosh_block + 8
