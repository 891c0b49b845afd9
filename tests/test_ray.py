"""The Ray executor on a real local cluster (issue 19): ``evaluate.py`` and a study run on it and give the
serial results, and a task that raises reaches the caller with its own message.

The module's fixture starts ``ray start --head --block`` on the loopback address and a free port (2 CPUs,
no dashboard), points ``RAY_ADDRESS`` at it, and stops it afterwards by signalling the process it started
(``--block`` takes its raylet, GCS and workers down with it; nothing else on the machine is touched).
Ray is a test dependency (``pip install -e ".[dev]"``): these tests are not skipped.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from lvgym.errors import ConfigError
from lvgym.parallel import TaskFailed, run_map

ROOT = Path(__file__).resolve().parents[1]


def _evaluate_module():
    spec = importlib.util.spec_from_file_location("lvgym_evaluate_script_ray", ROOT / "evaluate.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def ray_cluster(request, tmp_path_factory):
    """``RAY_ADDRESS`` of a local Ray head started for this module."""
    import ray  # noqa: F401  (a missing Ray is an error here, not a skip)

    port = _free_port()
    log = tmp_path_factory.mktemp("ray") / "ray_start.log"
    # its own temp dir (short: Ray puts sockets in it): the cluster's address file stays out of /tmp/ray,
    # where a later plain ray.init() would look for a cluster to join
    temp_dir = tempfile.mkdtemp(prefix="lvray")
    env = dict(os.environ)
    env["RAY_GRACEFUL_SHUTDOWN_DRAIN_TIMEOUT_S"] = "0"          # stop at once on SIGTERM
    # no token authentication (a ~/.ray/auth_token left by another run switched it on for the head only,
    # and the clients could not connect): the cluster listens on loopback for this test alone
    env["RAY_AUTH_MODE"] = "disabled"
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env.pop("RAY_ADDRESS", None)
    ray_bin = Path(sys.executable).with_name("ray")
    cmd = [str(ray_bin), "start", "--head", "--node-ip-address=127.0.0.1", f"--port={port}", "--num-cpus=2",
           "--include-dashboard=false", "--disable-usage-stats", f"--temp-dir={temp_dir}", "--block"]
    with open(log, "wb") as out:
        proc = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
    old = {k: os.environ.get(k) for k in ("RAY_ADDRESS", "RAY_AUTH_MODE")}
    os.environ["RAY_AUTH_MODE"] = "disabled"

    def stop() -> None:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        if proc.poll() is None:
            proc.send_signal(signal.SIGTERM)                    # `ray start --block` stops what it started
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)             # its own process group (start_new_session)
                proc.wait()
        shutil.rmtree(temp_dir, ignore_errors=True)

    request.addfinalizer(stop)
    deadline = time.monotonic() + 120
    while b"block forever" not in log.read_bytes():
        if proc.poll() is not None or time.monotonic() > deadline:
            raise RuntimeError(f"`{' '.join(cmd)}` did not start (exit {proc.poll()}):\n"
                               + log.read_text(errors="replace")[-3000:])
        time.sleep(0.2)
    os.environ["RAY_ADDRESS"] = f"127.0.0.1:{port}"
    return os.environ["RAY_ADDRESS"]


def test_ray_map_in_order_and_a_raising_task_keeps_its_message(ray_cluster):
    from lvgym.vehicle import load_vehicle

    vehicles = run_map(load_vehicle, ["smile", "stratos3"], "ray", workers=2, progress=False)
    assert [v.name for v in vehicles] == ["smile", "stratos3"]
    with pytest.raises(ConfigError, match=r"^vehicle = 'nope': one of the shipped vehicles \[.*'smile'") as err:
        run_map(load_vehicle, ["smile", "nope"], "ray", workers=2, progress=False)
    assert err.value.key == "vehicle" and err.value.value == "nope"
    with pytest.raises(TaskFailed, match=r"task failed: vehicle nope: vehicle = 'nope': one of the shipped"):
        run_map(load_vehicle, ["nope"], "ray", progress=False, describe=lambda n: f"vehicle {n}")


def test_evaluate_on_ray_gives_the_serial_results_and_worker_errors_reach_the_caller(ray_cluster, tmp_path):
    evaluate = _evaluate_module()
    argv = ["--policies", "zero", "pid", "--suites", "smile-windy", "--episodes", "2", "--mission-time-s", "1.0",
            "--no-plots", "--no-progress"]
    on_ray = evaluate.main([*argv, "--executor", "ray", "--workers", "2", "--out", str(tmp_path / "ray")])
    serial = evaluate.main([*argv, "--executor", "serial", "--out", str(tmp_path / "serial")])
    assert len(on_ray["records"]) == 2 * 2 * 2                     # policies x conditions x episodes
    key = ("policy", "condition", "seed", "failed")
    assert [tuple(r[k] for k in key) for r in on_ray["records"]] == [tuple(r[k] for k in key) for r in serial["records"]]
    # equal to rounding: Ray's workers run BLAS on one thread (OMP_NUM_THREADS=1), this process may not
    assert [r["rate_error_rad"] for r in on_ray["records"]] == [r["rate_error_rad"] for r in serial["records"]]
    assert (tmp_path / "ray" / "episodes.csv").is_file()

    bad = tmp_path / "broken.zip"
    bad.write_bytes(b"not a zip file")
    # a policy that cannot be built: one line naming it and the cause (a PolicyError from the worker)
    with pytest.raises(SystemExit, match=r"^evaluate\.py: task failed: policy 'broken' on 'smile-windy/\w+' seed \d+: "
                                         r"policy = 'broken': its factory \S+ raised ValueError: .*zip") as err:
        evaluate.main(["--policies", str(bad), "--suites", "smile-windy", "--episodes", "1", "--mission-time-s", "0.5",
                       "--executor", "ray", "--workers", "2", "--no-plots", "--no-progress", "--out", str(tmp_path / "b")])
    assert "RayTaskError" not in str(err.value)                    # the task's own error, not Ray's wrapper
    assert len(str(err.value).splitlines()) == 1


def test_a_study_on_ray_gives_the_serial_table(ray_cluster, tmp_path):
    from lvgym.studies import ld_sweep_study
    from lvgym.studies.responses import RunSetup

    setup = RunSetup(t_end=0.5)
    on_ray = ld_sweep_study(tmp_path / "ray", step=0.15, executor="ray", workers=2, progress=False, setup=setup)
    serial = ld_sweep_study(tmp_path / "serial", step=0.15, executor="serial", progress=False, setup=setup)
    assert on_ray.ran == 3 and list(on_ray.table["diameter"]) == [0.2, 0.35, 0.5]
    for col in ("diameter", "ld", "f1_hz", "flex_total", "cg_total"):            # equal to rounding (see above)
        assert list(on_ray.table[col]) == list(serial.table[col]), col    # bit for bit (modes on one BLAS thread)
    assert (tmp_path / "ray" / "runs.csv").is_file()


def test_a_users_policy_file_and_module_reach_the_ray_workers(ray_cluster, tmp_path, monkeypatch):
    """The cluster's workers share neither this process's sys.path nor its working folder: the file is
    loaded by its path, the module from the folder its spec carries."""
    from test_user_policies import POLICY_FILE

    (tmp_path / "my_policy.py").write_text(POLICY_FILE, encoding="utf-8")
    (tmp_path / "ray_user_controllers.py").write_text("from my_policy import make  # noqa: F401\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    evaluate = _evaluate_module()
    argv = ["--policies", "my_policy.py:make", "ray_user_controllers:make", "--suites", "smile-v1", "--episodes", "1",
            "--mission-time-s", "3", "--no-plots", "--no-progress"]
    try:
        on_ray = evaluate.main([*argv, "--executor", "ray", "--workers", "2", "--out", str(tmp_path / "ray")])
        serial = evaluate.main([*argv, "--executor", "serial", "--out", str(tmp_path / "serial")])
    finally:
        for name in [n for n in sys.modules if n in ("my_policy", "ray_user_controllers")
                     or n.startswith("_lvgym_policy_")]:
            del sys.modules[name]
        while str(tmp_path) in sys.path:
            sys.path.remove(str(tmp_path))
    key = ("policy", "condition", "seed", "failed", "rate_error_rad")
    assert [tuple(r[k] for k in key) for r in on_ray["records"]] == [tuple(r[k] for k in key) for r in serial["records"]]
    assert {r["policy"] for r in on_ray["records"]} == {"my_policy", "ray_user_controllers"}
    pids = {int(line.split()[0]) for line in (tmp_path / "loads.log").read_text().splitlines()}
    assert pids - {os.getpid()}, "Ray's workers loaded the user's file"
