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


def test_slosh_block_offsets():
    lay = Layout(2, 3)
    assert lay.slosh_block == 8 + 3 and lay.slosh_param(1, "phi").start == \
        lay.params["slosh"].start + lay.slosh_block + 8


@pytest.mark.parametrize("n, k", [(0, 0), (1, 1), (6, 2), (0, 4)])
def test_compiled_offset_forms_agree_with_the_layout(n, k):
    """The forms the kernels evaluate (``at(X.eta_dot, K, N)``, the pendulum strides, the sizes) give
    the offsets of :class:`Layout`."""
    from lvgym.dynamics.layout import SIZES, SLOSH_BLOCK, X_PER_SLOSH, P, S, U, X
    from lvgym.packing import at_py

    lay = Layout(n, k)
    for table, forms in ((lay.state, X), (lay.params, P), (lay.loads, U)):
        assert {name: at_py(getattr(forms, name), k, n) for name in table} == \
            {name: sl.start for name, sl in table.items()}
    assert (at_py(SIZES.state, k, n), at_py(SIZES.params, k, n), at_py(SIZES.loads, k, n)) == \
        (lay.n_x, lay.n_p, lay.n_u)
    assert at_py(SIZES.speeds, k, n) == 6 + 2 * k and at_py(SLOSH_BLOCK, k, n) == lay.slosh_block
    for j in range(n):
        assert at_py(X.q_si, k, n) + j * X_PER_SLOSH.q_si == lay.state["q_si"].start + 4 * j
        assert at_py(X.omega_si_s, k, n) + j * X_PER_SLOSH.omega_si_s == lay.state["omega_si_s"].start + 2 * j
        for name in Layout.SLOSH_FIELDS:
            start = at_py(P.slosh, k, n) + j * at_py(SLOSH_BLOCK, k, n) + at_py(getattr(S, name), k, n)
            assert start == lay.slosh_param(j, name).start


@pytest.mark.parametrize("n, k", [(0, 0), (3, 2)])
def test_workspace_is_sized_by_the_layouts(n, k):
    from lvgym.dynamics.kernels import term_rows
    from lvgym.dynamics.layout import ATTITUDES, RK4_ROWS, SLOSH_WORK, TERMS_PER_PENDULUM, WORK_ROWS
    from lvgym.dynamics.stepper import make_workspace

    lay = Layout(n, k)
    ws = make_workspace(n, k, lay.n_u)
    nr = 6 + 2 * k
    assert (ws.n_slosh, ws.n_modes) == (n, k) and (ws.deriv.n_slosh, ws.deriv.n_modes) == (n, k)
    assert ws.buf.shape == (RK4_ROWS.size, lay.n_x) and not ws.buf.any()   # zero: padding keeps zero rates
    assert ws.u.shape == (lay.n_u,) and ws.deriv.A.shape == (nr, nr) and ws.deriv.rhs.shape == (nr,)
    assert ws.deriv.slosh.shape == (max(n, 1), SLOSH_WORK.size) and ws.deriv.C.shape == (ATTITUDES.size, 3, 3)
    assert ws.deriv.work.shape == (WORK_ROWS.size(k, n), max(nr, 3))
    # every rank-one term's two rows lie in the field ``terms`` of the work rows
    rows = [r for q in range(TERMS_PER_PENDULUM * n) for r in term_rows(q)]
    terms = WORK_ROWS.resolve(k, n).slice("terms")
    assert len(set(rows)) == len(rows) and all(terms.start <= r < terms.stop for r in rows)


def test_dynamics_kernels_define_no_offsets_of_their_own():
    """The kernels take every offset from a layout: no integer offset constants in their modules."""
    import re

    from lvgym.dynamics import invariants, kernels, stepper

    for module in (kernels, stepper, invariants):
        own = [name for name, value in vars(module).items()
               if isinstance(value, int) and not isinstance(value, bool) and re.fullmatch(r"_?[A-Z][A-Z0-9_]*", name)
               and not name.endswith("_SIZE") and name != "_TERMS"]
        assert not own, f"{module.__name__} defines offsets {own}"
