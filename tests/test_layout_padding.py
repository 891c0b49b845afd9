"""Every offset of the dynamics kernels comes from the layouts: with ``LVGYM_LAYOUT_PADDING=1`` (an unused
entry in front of every field, see :mod:`lvgym.packing`) the derivative and the RK4 steps give the same
numbers, bit for bit, field by field."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

N_SLOSH, N_MODES = 2, 2


def _compute() -> dict[str, np.ndarray]:
    """A 2-slosh 2-mode vehicle built by name: its derivative and its state after 50 RK4 steps (with the
    exact modal propagator and without), each state field by name."""
    from lvgym.dynamics import NonRigidModel

    rng = np.random.default_rng(2024)
    model = NonRigidModel(N_SLOSH, N_MODES)
    lay = model.layout
    slosh = [{"m": 40.0, "length": 0.6, "r_hinge": (-2.0, 0.01, -0.02), "zeta": 0.05, "omega": 4.0,
              "phi": (0.05, -0.03)},
             {"m": 25.0, "length": 0.4, "inertia": 0.8, "r_hinge": (-3.5, 0.0, 0.0), "zeta": 0.02,
              "omega": 6.0, "phi": (0.04, 0.02)}]
    p = model.params(m_b=1500.0, J_b=[[150.0, 1.0, 0.0], [1.0, 6000.0, 2.0], [0.0, 2.0, 6100.0]],
                     r_cg=(-4.0, 0.01, -0.01), r_gimbal=(-9.0, 0.0, 0.0), omega_modes=(60.0, 150.0),
                     zeta_modes=(0.01, 0.02), phi_gimbal=(0.04, -0.03), dphi_gimbal=(0.01, 0.02), slosh=slosh)
    u = model.loads(f_b_i=(10.0, -20.0, 5.0), m_b_b=(3.0, -1.0, 2.0), thrust_b=(40_000.0, 150.0, -90.0),
                    g_i=(-9.81, 0.0, 0.01), f_eta=(1.0, -2.0, 0.5, 0.3))
    x = lay.zeros_state()
    lay.view(x, "state", "r_zw_i")[:] = rng.normal(size=3) * 50
    lay.view(x, "state", "v_zw_i")[:] = rng.normal(size=3) * 10
    q = rng.normal(size=4)
    lay.view(x, "state", "q_bi")[:] = q / np.linalg.norm(q)
    lay.view(x, "state", "omega_bi_b")[:] = rng.normal(size=3) * 0.2
    lay.view(x, "state", "eta")[:] = rng.normal(size=(2, N_MODES)) * 0.01
    lay.view(x, "state", "eta_dot")[:] = rng.normal(size=(2, N_MODES)) * 0.1
    qs = lay.view(x, "state", "q_si")
    qs[:, 1:] = rng.normal(size=(N_SLOSH, 3)) * 0.2
    qs /= np.linalg.norm(qs, axis=-1, keepdims=True)
    lay.view(x, "state", "omega_si_s")[:] = rng.normal(size=(N_SLOSH, 2)) * 0.5

    results = {"deriv": model.derivative(x, p, u),
               "rk4": model.step(x, p, u, 1e-3, 50),
               "rk4-classic": model.step(x, p, u, 1e-3, 50, method="rk4-classic")}
    out = {}
    for what, vector in results.items():
        assert np.all(np.isfinite(vector)), what
        for name in lay.state:
            out[f"{what}/{name}"] = lay.view(vector, "state", name).copy()
    out["n_x"] = np.array(lay.n_x)
    return out


def test_padded_layouts_give_the_same_numbers(tmp_path):
    from lvgym import packing

    assert not packing.PADDING, "run the test suite without LVGYM_LAYOUT_PADDING"
    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, LVGYM_LAYOUT_PADDING="1", NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"),
               PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    result = tmp_path / "padded.npz"
    run = subprocess.run([sys.executable, __file__, str(result)], env=env, cwd=root, capture_output=True,
                         text=True, timeout=900)
    assert run.returncode == 0, run.stdout + run.stderr
    padded = np.load(result)
    plain = _compute()
    assert int(padded["n_x"]) > int(plain["n_x"])          # the padding took effect
    assert set(padded.files) == set(plain)
    differ = [key for key in plain if key != "n_x" and not np.array_equal(plain[key], padded[key])]
    assert not differ, f"fields that differ with padded layouts: {differ}"


if __name__ == "__main__":
    from lvgym import packing

    assert packing.PADDING, "the padded run needs LVGYM_LAYOUT_PADDING=1"
    np.savez(sys.argv[1], **_compute())
