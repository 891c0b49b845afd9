"""The speed benchmark of the envs runs its rows (a smoke test: speed itself is never a test)."""

import math

from lvgym.bench_envs import ENV_IDS, floor


def test_floor_flies_the_env_rows():
    rate, cpu = floor(ENV_IDS["v1"], "rigid", 3, 1e-3)
    assert math.isfinite(rate) and rate > 0.0
    assert math.isfinite(cpu) and cpu >= 0.0
