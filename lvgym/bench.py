"""Speed of the dynamics core: RK4 steps per second (``lvgym bench``, ``python -m lvgym.bench``).

For three vehicle sizes (rigid; 1 slosh + 1 mode per plane; 6 slosh + 2 modes per plane) and for one
vehicle and a batch of 256, on one core. ``steps/s`` counts vehicle-steps (one RK4 step of one vehicle,
four evaluations of the equations). Two ways of calling are timed for one vehicle: many steps per
call (the simulator's substeps inside one compiled call) and one step per Python call (the overhead a
caller pays when it returns to Python after every step).
"""

from __future__ import annotations

import os
import platform
import time
from dataclasses import dataclass

import numpy as np

from .commandline import arg, parse
from .dynamics import NonRigidModel, step_batch, zoh_loads

CONFIGS = (("rigid", 0, 0), ("1 slosh + 1 mode/plane", 1, 1), ("6 slosh + 2 modes/plane", 6, 2))


def vehicle(n_slosh: int, n_modes: int, batch: int, seed: int = 0):
    """A flying vehicle with excited slosh and bending, under thrust and gravity (batch copies with
    small random differences)."""
    rng = np.random.default_rng(seed)
    model = NonRigidModel(n_slosh, n_modes)
    slosh = [{"m": 50.0 + 10 * j, "length": 0.5 + 0.1 * j, "r_hinge": (-2.0 - j, 0.0, 0.0),
              "zeta": 0.01, "omega": 5.0, "phi": 0.05 * np.ones(n_modes)} for j in range(n_slosh)]
    p = model.params(m_b=2000.0, J_b=(200.0, 8000.0, 8000.0), r_cg=(-5.0, 0, 0),
                     r_gimbal=(-10.0, 0, 0), omega_modes=2 * np.pi * (10.0 + 15 * np.arange(n_modes)),
                     zeta_modes=0.01 * np.ones(n_modes), phi_gimbal=0.04 * np.ones(n_modes),
                     dphi_gimbal=0.01 * np.ones(n_modes), slosh=slosh)
    lay = model.layout
    x = lay.zeros_state(batch)
    x[:, lay.state["eta"]] = 0.01 * rng.normal(size=(batch, 2 * n_modes))
    qs = lay.view(x, "state", "q_si")
    qs[..., 1:] = 0.02 * rng.normal(size=(batch, n_slosh, 3))
    qs /= np.linalg.norm(qs, axis=-1, keepdims=True)
    u = model.loads(thrust_b=(60_000.0, 300.0, -200.0), g_i=(-9.81, 0, 0), m_b_b=(5.0, 0, 0))
    return model, x, np.repeat(p[None], batch, 0), np.repeat(u[None], batch, 0)


def _rate(fn, steps: int, min_time: float) -> float:
    fn()  # compile / warm up
    n, start = 0, time.perf_counter()
    while True:
        fn()
        n += 1
        elapsed = time.perf_counter() - start
        if elapsed >= min_time:
            return steps * n / elapsed


def run(min_time: float = 1.0, dt: float = 1e-3) -> list[dict]:
    rows = []
    for name, n_slosh, n_modes in CONFIGS:
        for batch, label in ((1, "1 vehicle"), (256, "batch of 256")):
            model, x, p, u = vehicle(n_slosh, n_modes, batch)
            lay = model.layout
            n_steps = 1000 if batch == 1 else 20

            def many(x=x, p=p, u=u, n_steps=n_steps):
                step_batch(zoh_loads, x, p, u, 0.0, dt, n_steps, n_slosh, n_modes, True, lay.n_u)

            row = {"model": name, "vehicles": label,
                   "steps_per_s": _rate(many, batch * n_steps, min_time)}
            if batch == 1:
                x1, p1, u1 = x[0].copy(), p[0], u[0]
                row["python_call_steps_per_s"] = _rate(
                    lambda: model.step(x1, p1, u1, dt), 1, min_time)
            rows.append(row)
            assert np.all(np.isfinite(x)), f"{name}: the benchmark vehicle diverged"
    return rows


@dataclass
class Args:
    """Command-line arguments (``lvgym bench --help``)."""

    min_time: float = arg(1.0, lo=0.0, lo_open=True, hi=3600.0)
    """seconds per measurement"""


def print_table(rows: list[dict]) -> None:
    """Print :func:`run`'s rows as a Markdown table."""
    print(f"# RK4 steps per second, one core ({platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} cores, numba)\n")
    print("| model | vehicles | vehicle-steps/s | one step per Python call |")
    print("|---|---|---|---|")
    for r in rows:
        extra = f"{r['python_call_steps_per_s']:,.0f}" if "python_call_steps_per_s" in r else ""
        print(f"| {r['model']} | {r['vehicles']} | {r['steps_per_s']:,.0f} | {extra} |")


def main(argv: list[str] | None = None) -> None:
    """``python -m lvgym.bench``: print the table of the dynamics core (``lvgym bench`` prints it and the control
    laws')."""
    args = parse(Args, argv, "python -m lvgym.bench", __doc__)
    print_table(run(args.min_time))


if __name__ == "__main__":
    main()
