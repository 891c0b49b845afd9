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


# ------------------------------------------------------------------ errors from workers (issue 19)
class _Unpicklable(Exception):
    def __init__(self, a, b):                       # pickles as args (one message): cannot be rebuilt
        super().__init__(f"{a} and {b}")


def _raise_config_error(x):
    from lvgym.errors import ConfigError

    raise ConfigError("stages[0].tanks[1].fill_ratio", x, "must be in [0, 1]", "v.yaml", 12)


def _raise_unpicklable(x):
    raise _Unpicklable("left", x)


@pytest.mark.parametrize("executor", ["serial", "local"])
def test_a_config_error_in_a_worker_reaches_the_caller_as_itself(executor):
    from lvgym.errors import ConfigError

    with pytest.raises(ConfigError) as err:
        run_map(_raise_config_error, [1.3, 1.4], executor, workers=2, progress=False)
    assert str(err.value) in ("v.yaml, line 12: stages[0].tanks[1].fill_ratio = 1.3: must be in [0, 1]",
                              "v.yaml, line 12: stages[0].tanks[1].fill_ratio = 1.4: must be in [0, 1]")
    assert err.value.key == "stages[0].tanks[1].fill_ratio" and err.value.line == 12
    with pytest.raises(RuntimeError, match=r"task failed: x = 1\.3: v\.yaml, line 12: .*fill_ratio = 1\.3") as err:
        run_map(_raise_config_error, [1.3], executor, workers=2, progress=False, describe=lambda x: f"x = {x}")
    assert isinstance(err.value.__cause__, ConfigError)


def test_an_exception_that_does_not_pickle_arrives_as_a_worker_error():
    from lvgym.parallel import WorkerError

    with pytest.raises(WorkerError, match=r"(?s)_Unpicklable: left and right\n\nworker traceback:\n.*_raise_unpicklable"):
        run_map(_raise_unpicklable, ["right", "right"], "local", workers=2, progress=False)


@pytest.mark.parametrize("workers", [0, -1, 1.5, "2"])
def test_bad_worker_counts_are_refused_before_any_worker_starts(workers):
    from lvgym.errors import ConfigError

    with pytest.raises(ConfigError, match=r"^workers = .*: an integer in \[1, 100000\]$"):
        run_map(_square_or_fail, [1], "local", workers=workers, progress=False)


def _die(x):
    import os

    os._exit(3)


def test_a_dead_worker_breaks_the_pool_with_its_likely_causes():
    from concurrent.futures.process import BrokenProcessPool

    with pytest.raises(BrokenProcessPool, match=r"terminated abruptly.*lvgym: a worker .* died.*__name__ == "
                                                r"\"__main__\".*ran out of memory"):
        run_map(_die, [1, 2], "local", workers=2, progress=False)


def test_a_script_without_a_main_guard_is_told_what_to_do(tmp_path):
    import os
    import subprocess
    import sys
    from pathlib import Path

    script = tmp_path / "unguarded.py"
    script.write_text("from lvgym.parallel import run_map\nprint(run_map(abs, [-1, -2], workers=2, progress=False))\n")
    root = Path(__file__).resolve().parents[1]
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, cwd=root,
                         env={**os.environ, "PYTHONPATH": str(root)})
    assert run.returncode != 0
    last = run.stderr.strip().splitlines()[-1]
    assert last.startswith("concurrent.futures.process.BrokenProcessPool:")
    assert 'needs its top level under `if __name__ == "__main__":`' in last
