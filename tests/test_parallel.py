"""The shared executor (lvgym.parallel): order, callbacks and how a failing task is reported."""

import pytest

from lvgym.parallel import run_map


def _square_or_fail(x: int) -> int:
    if x == 3:
        raise ValueError("three is not allowed")
    return x * x


@pytest.mark.parametrize("executor", ["serial", "local"])
def test_results_in_task_order_with_a_callback_per_task(executor):
    seen = []
    out = run_map(_square_or_fail, [5, 1, 4, 2], executor, workers=2, progress=False,
                  on_result=lambda i, r: seen.append((i, r)))
    assert out == [25, 1, 16, 4]
    assert sorted(seen) == [(0, 25), (1, 1), (2, 16), (3, 4)]


@pytest.mark.parametrize("executor", ["serial", "local"])
def test_a_failing_task_is_named(executor):
    with pytest.raises(RuntimeError, match=r"task failed: x = 3: three is not allowed"):
        run_map(_square_or_fail, [1, 3, 2], executor, workers=2, progress=False, describe=lambda x: f"x = {x}")
    with pytest.raises(ValueError, match="three"):                 # without describe: the task's own error
        run_map(_square_or_fail, [1, 3], executor, workers=2, progress=False)


def test_unknown_executor_is_refused():
    with pytest.raises(ValueError, match="executor"):
        run_map(_square_or_fail, [1], "threads")
