"""Training seeds are disjoint from every validation and test seed: ``lvgym train``'s rows and the teacher-student
recipe's flights fly :data:`lvgym.benchmark.suites.TRAINING_SEEDS` only, so model selection (validation seeds) and
reported numbers (test seeds, the named blocks among them) never fly an episode a policy was trained on."""

from __future__ import annotations

import pytest

from lvgym.agents.training.dagger import training_seeds
from lvgym.agents.training.trainsetup import training_seed
from lvgym.benchmark.suites import (N_TEST_SEEDS, N_TRAINING_SEEDS, N_VALIDATION_SEEDS, SEED_BLOCKS, SUITES,
                                    TRAINING_SEED0, TRAINING_SEED_STRIDE, TRAINING_SEEDS, family_validation_suite)


def _held() -> set[int]:
    """Every validation and test seed of every suite (and of the family's validation suites), every named block."""
    held: set[int] = set()
    for suite in SUITES.values():
        for s in (suite, family_validation_suite(suite)):
            held |= set(s.seeds("validation", N_VALIDATION_SEEDS)) | set(s.seeds("test", N_TEST_SEEDS))
    for block in SEED_BLOCKS.values():
        held |= set(block.seeds())
    return held


def test_the_training_range_is_disjoint_from_every_validation_and_test_block():
    held = _held()
    assert len(held) == N_VALIDATION_SEEDS + N_TEST_SEEDS == 20_000            # 0 .. 19,999
    assert min(held) == 0 and max(held) == 19_999
    assert not [s for s in held if s in TRAINING_SEEDS]
    assert TRAINING_SEEDS[0] == TRAINING_SEED0 == 100_000 and len(TRAINING_SEEDS) == N_TRAINING_SEEDS
    assert {b.name for b in SEED_BLOCKS.values()} == {"development-50", "headline-200"}


@pytest.mark.parametrize("n_envs", [1, 8, 1024, TRAINING_SEED_STRIDE])
def test_every_row_of_a_run_is_a_training_seed_at_the_start_and_on_resume(n_envs):
    """Row ``i`` of training seed ``k`` starts at 100,000 + 10,000 k + i (by hand: seed 0 -> 100,000, seed 2 ->
    120,000); the rows of two training seeds never meet; a resumed segment draws its rows among the training
    seeds too (steps as a run's checkpoints give them)."""
    held = _held()
    assert training_seed(0, 0, n_envs) == 100_000 and training_seed(2, 0, n_envs) == 120_000
    top = N_TRAINING_SEEDS // TRAINING_SEED_STRIDE - 1
    firsts = [training_seed(k, 0, n_envs) for k in (0, 1, 2, 3, top)]
    blocks = [set(range(f, f + n_envs)) for f in firsts]
    assert all(not a & b for i, a in enumerate(blocks) for b in blocks[i + 1:])
    firsts += [training_seed(k, step, n_envs) for k in (0, 1, top) for step in (128, 200_000, 10 ** 9, 10 ** 12)]
    for first in firsts:
        assert first in TRAINING_SEEDS and first + n_envs - 1 in TRAINING_SEEDS
        assert first not in held and first + n_envs - 1 not in held
    assert len(set(firsts)) == len(firsts)                                   # each segment its own rows


def test_a_seed_outside_the_range_is_refused_in_one_line():
    top = N_TRAINING_SEEDS // TRAINING_SEED_STRIDE - 1
    with pytest.raises(SystemExit, match=rf"^train.py: --seed -1: an integer in \[0, {top}\] \(rows start at training "
                                         r"seed 100,000 \+ 10,000 seed\)$"):
        training_seed(-1, 0, 8)
    with pytest.raises(SystemExit, match=rf"--seed {top + 1}: an integer in"):
        training_seed(top + 1, 0, 8)
    with pytest.raises(SystemExit, match=r"^train.py: 10001 envs: at most 10,000 rows per run"):
        training_seed(0, 0, TRAINING_SEED_STRIDE + 1)


def test_the_teacher_student_recipes_flights_are_training_seeds():
    held = _held()
    for seed, rnd, count in ((0, 0, 200), (2, 0, 200), (2, 4, 100), (99, 10, 1000)):
        flown = training_seeds(seed, rnd, count)
        assert all(s in TRAINING_SEEDS and s not in held for s in flown)
