"""The line before the flight model's first compile (:mod:`lvgym.simulator.coldstart`): said when numba's cache of the
function about to compile is cold, on stderr, once per process, and not when the cache holds it. A small function
in a temporary file stands for the flight model (its compile takes a fraction of a second); the real hook is checked
in a fresh process whose cache this process has warmed."""

from __future__ import annotations

import importlib.util
import io
import subprocess
import sys
from pathlib import Path

import pytest

from lvgym.simulator import coldstart
from lvgym.simulator.threads import Kernel

SOURCE = '''import numba as nb
import numpy as np


@nb.njit(cache=True)
def twice(x, out):
    out[0] = 2.0 * x
'''


def _module(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def fresh(monkeypatch):
    """A process that has said nothing yet."""
    monkeypatch.setattr(coldstart, "_announced", False)


def test_cold_then_warm_and_once_per_process(tmp_path, fresh):
    import numpy as np

    path = tmp_path / "kernels_probe.py"
    path.write_text(SOURCE, encoding="utf-8")
    first = _module(path, "kernels_probe_a")
    assert coldstart.cache_is_cold(first.twice) and coldstart.cache_is_cold(first.twice.py_func)
    out = io.StringIO()
    assert coldstart.announce_compile(first.twice, out)
    assert out.getvalue() == coldstart.MESSAGE + "\n" and "\n" not in coldstart.MESSAGE
    assert not coldstart.announce_compile(first.twice, out)                 # once per process
    assert out.getvalue().count("\n") == 1
    y = np.zeros(1)
    first.twice(1.5, y)                                                     # compiles, writes numba's cache
    assert y[0] == 3.0 and not coldstart.cache_is_cold(first.twice)         # compiled in this process
    again = _module(path, "kernels_probe_b")                                # a new dispatcher of the same source
    assert not again.twice.signatures and not coldstart.cache_is_cold(again.twice)
    path.write_text(SOURCE + "\n\n# edited\n", encoding="utf-8")           # an edited source: stale, cold again
    assert coldstart.cache_is_cold(_module(path, "kernels_probe_c").twice)


def test_the_kernel_says_it_on_stderr_before_its_first_call(tmp_path, fresh, capsys):
    import numpy as np

    path = tmp_path / "kernels_probe2.py"
    path.write_text(SOURCE, encoding="utf-8")
    kernel = Kernel(_module(path, "kernels_probe2").twice)
    y = np.zeros(1)
    kernel(2.0, y)
    kernel(3.0, y)
    captured = capsys.readouterr()
    assert captured.err == coldstart.MESSAGE + "\n" and captured.out == "" and y[0] == 6.0


def test_nothing_is_said_when_numba_does_not_compile(tmp_path, fresh, monkeypatch):
    from numba.core import config

    path = tmp_path / "kernels_probe3.py"
    path.write_text(SOURCE, encoding="utf-8")
    twice = _module(path, "kernels_probe3").twice
    assert coldstart.cache_is_cold(twice)
    monkeypatch.setattr(config, "DISABLE_JIT", True)
    assert not coldstart.cache_is_cold(twice) and not coldstart.announce_compile(twice, io.StringIO())


def test_the_flight_model_warm_says_nothing():
    """A fresh process importing the flight model and stepping it, its compiled code in numba's cache (warmed by
    this process first): no line."""
    from lvgym.simulator import Simulator, TimelineSpec

    code = ("from lvgym.simulator import Simulator, TimelineSpec\n"
            "sim = Simulator('stratos3', 'rigid', timeline=TimelineSpec(t_end=2.0))\n"
            "data = sim.reset()\n"
            "sim.step(data, [[0.0, 0.0]], 0.1)\n")
    exec(code, {"Simulator": Simulator, "TimelineSpec": TimelineSpec})   # warms the cache (compiles when cold)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert coldstart.MESSAGE not in proc.stderr
