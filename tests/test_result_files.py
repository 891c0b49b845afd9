"""Result files of the benchmark (lvgym.benchmark.results, evaluate.py): an interrupted write or a killed
run leaves no half-written file, and the temporaries of dead writers are removed."""

from __future__ import annotations

import csv
import io
import json
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from lvgym.benchmark import Trajectory, degradation, episode_metrics, summarize, write_results
from lvgym.benchmark import results as results_mod
from lvgym.benchmark.results import atomic_write

ROOT = Path(__file__).resolve().parents[1]
SHORT = 3.0   # s: mission time of the short episodes used here


def _rec(cond: str, model: str, value: float, failed: bool = False) -> dict:
    """A record of a four-step hand trajectory with the rate error ``value``."""
    m = episode_metrics(Trajectory(dt_s=0.5, rate_error_radps=np.zeros((4, 3)), gimbal_rad=np.zeros((4, 2)),
                                   alpha_total_rad=np.zeros(4), qalpha_pa_deg=np.zeros(4), reward=np.zeros(4),
                                   time_s=0.5 * np.arange(1, 5), qbar_pa=np.zeros(4), termination=""))
    m.update(rate_error_rad=value, failed=failed, failure_reason="x" if failed else "")
    return {"suite": "s", "condition": cond, "group": "s", "model": model, "wind": "none", "policy": "p", **m}


def _complete(folder: Path) -> None:
    """Every file in ``folder`` is a finished result file and no temporary is left."""
    names = sorted(p.name for p in folder.iterdir())
    assert not [n for n in names if n.startswith(".")], names
    for p in folder.iterdir():
        if p.suffix == ".json":
            json.loads(p.read_text())
        elif p.suffix == ".csv":
            rows = list(csv.reader(io.StringIO(p.read_text())))
            assert all(len(r) == len(rows[0]) for r in rows)
        elif p.suffix == ".png":
            data = p.read_bytes()
            assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[-8:-4] == b"IEND"


def test_an_interrupted_write_leaves_no_partial_file(tmp_path, monkeypatch):
    recs = [_rec("s/rigid", "rigid", v) for v in (1.0, 2.0)] + [_rec("s/nonrigid", "nonrigid", 3.0)]
    s = summarize(recs)
    first = write_results(tmp_path, recs, s, degradation(s), {"run": 1})
    before = {n: p.read_bytes() for n, p in first.items()}

    def broken_plot(records, f, *args):             # writes half a PNG, then fails
        f.write(b"\x89PNG\r\n\x1a\n" + b"\0" * 100)
        raise KeyboardInterrupt("killed while writing")

    monkeypatch.setattr(results_mod, "plot_rate_error", broken_plot)
    with pytest.raises(KeyboardInterrupt):
        write_results(tmp_path, recs[:2], s[:1], [], {"run": 2})
    _complete(tmp_path)
    assert (tmp_path / "rate_error.png").read_bytes() == before["rate_error.png"]
    assert (tmp_path / "results.json").read_bytes() == before["results.json"]   # written last: never reached

    with pytest.raises(RuntimeError):
        atomic_write(tmp_path / "new.csv", lambda f: (f.write("a,b\n1,"), (_ for _ in ()).throw(RuntimeError())))
    assert not (tmp_path / "new.csv").exists()
    _complete(tmp_path)


def test_temporaries_of_dead_writers_are_removed(tmp_path):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / f".episodes.csv.{dead.pid}.tmp"
    stale.write_text("half")
    recs = [_rec("s/rigid", "rigid", 1.0)]
    write_results(tmp_path, recs, summarize(recs), [], {}, plots=False)
    assert not stale.exists()
    _complete(tmp_path)


def _evaluate_cmd(out: Path, *extra: str) -> list[str]:
    return [sys.executable, str(ROOT / "evaluate.py"), "--out", str(out), "--mission-time-s", str(SHORT), *extra]


def _children(pid: int) -> list[int]:
    """Processes whose parent is ``pid`` (Linux /proc)."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.parametrize("sig, executor", [(signal.SIGKILL, "local"), (signal.SIGTERM, "serial")])
def test_a_killed_evaluation_leaves_no_result_file(tmp_path, sig, executor):
    out = tmp_path / "results"
    proc = subprocess.Popen(_evaluate_cmd(out, "--policies", "zero", "--only", "--episodes", "2000", "--executor",
                                          executor, "--workers", "2"),
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    seen = b""
    deadline = time.time() + 60
    while not re.search(rb" [1-9]\d*/\d+ \[", seen) and time.time() < deadline:   # blocks of episodes are finishing
        seen += proc.stderr.read1(1024)
    assert proc.poll() is None, seen.decode(errors="replace")
    workers = _children(proc.pid) if Path("/proc").is_dir() else []
    proc.send_signal(sig)
    proc.communicate(timeout=30)
    assert proc.returncode != 0
    assert not out.exists() or not any(out.iterdir())
    deadline = time.time() + 10                      # pool workers follow their killed parent
    while any(_alive(w) for w in workers) and time.time() < deadline:
        time.sleep(0.2)
    assert not [w for w in workers if _alive(w)]
