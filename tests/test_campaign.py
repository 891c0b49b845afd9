"""Training campaigns (issue 35): ``lvgym campaign FILE`` checks the whole file before any run starts (a bad
value names its key and leaves no folder), lists its runs with ``--dry-run``, runs a tiny campaign here
(2 configurations x 2 seeds, one run resumed from a folder a kill left behind), evaluates it and writes the
comparison, and run again skips everything. On a real loopback Ray cluster (a head of 0 CPUs and two
worker nodes of 1 CPU each, ``ray start`` processes as in test_ray.py) one worker node is killed while it
trains a run: the campaign still finishes every run (Ray retries the task on the other node, where it
resumes) and writes the comparison.

Runs are tiny (512 env steps of 2 s episodes with 8-unit networks, no validation), the evaluation one or
two test seeds of 2 s. Ray is a test dependency: these tests are not skipped without it.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
import yaml
from lvgym.agents.training import campaign as camp
from lvgym.agents.training.campaign_schema import load_campaign
from lvgym.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]

TRAIN = {"env_id": "lvgym/SmileAscent-v0", "total_timesteps": 512, "n_envs": 4, "eval_freq": 0,
         "checkpoint_freq": 256, "hp": ["algo.n_steps=64", "algo.batch_size=128", "algo.n_epochs=2",
                                       "policy.net_arch=[8,8]"],
         "env_kwargs": {"mission_time_s": 2, "controller_on_after_s": 0.2}}
CONFIGURATIONS = {"a": {}, "b": {"hp": {"algo.learning_rate": 1e-3, "algo.n_steps": 64, "algo.batch_size": 128,
                                        "algo.n_epochs": 2, "policy.net_arch": [8, 8]}}}


def _file(tmp: Path, name: str = "tiny", **over) -> Path:
    data = {"name": name, "runs_dir": str(tmp / "runs"), "seeds": [0, 1], "train": dict(TRAIN),
            "configurations": CONFIGURATIONS,
            "evaluation": {"suites": ["smile-windy"], "episodes": 1, "baselines": ["pid"], "mission_time_s": 2.0},
            "executor": "local", "workers": 2}
    for key, value in over.items():
        head, _, tail = key.partition("__")
        if tail:
            data[head] = {**data[head], tail: value}
        else:
            data[head] = value
    path = tmp / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


# ------------------------------------------------------------------------------------------ the file
@pytest.mark.parametrize("over, message", [
    ({"configurations": {"a": {}, "b": {"hp": ["algo.gama=0.99"]}}},
     r"configurations\.b\.hp = \['algo\.gama=0\.99'\]: .*algo\.gama = 0\.99: unknown key.*did you mean 'gamma'"),
    ({"train__total_timesteps": -5}, r"train\.total_timesteps = -5: an integer in \[1, "),
    ({"configurations": {"a": {"residual": "lqgg"}}}, r"configurations\.a\.residual = 'lqgg': one of \["),
    ({"configurations": {"a": {"seed": 3}}}, r"configurations\.a\.seed = 3: set by the campaign"),
    ({"configurations": {"a": {"histroy": 4}}}, r"configurations\.a\.histroy = 4: unknown train\.py option.*"
                                                  r"did you mean 'history'"),
    ({"train__env_kwargs": {"mission_time_s": -3}}, r"train\.env_kwargs = \['mission_time_s=-3'\]: "
                                                     r"lvgym/SmileAscent-v0 option mission_time_s = -3"),
    ({"evaluation__suites": ["smile-v9"]}, r"evaluation\.suites\[0\] = 'smile-v9': a suite of the protocol"),
    ({"evaluation__baselines": ["zero"]}, r"evaluation\.baselines\[0\] = 'zero': a classical baseline"),
    ({"evaluation__episodes": 0}, r"evaluation\.episodes = 0: an integer in \[1, "),
    ({"seeds": [0, 100000]}, r"seeds\[1\] = 100000: .*--seed = 100000: an integer in \[0, 99999\]"),
    ({"executor": "slurm"}, r"executor = 'slurm': one of \('local', 'ray'\)"),
    ({"epochs": 3}, r"epochs = 3: unknown key; one of \["),
])
def test_a_bad_value_is_refused_naming_its_key_before_any_run_starts(tmp_path, over, message):
    import re

    path = _file(tmp_path, **over)
    with pytest.raises(SystemExit) as exit_:
        camp.main([str(path), "--no-progress"])
    text = str(exit_.value.code)
    assert text.startswith(f"lvgym campaign: {path}: ") and len(text.splitlines()) == 1, text
    assert re.search(message, text), text
    assert not (tmp_path / "runs").exists(), "a refused campaign made a folder"


@pytest.mark.parametrize("name", sorted(p.stem for p in (Path(__file__).resolve().parents[1] / "agents" / "training"
                                                         / "campaigns").glob("*.yaml")))
def test_the_shipped_campaigns_validate(name):
    c = load_campaign(ROOT / "agents" / "training" / "campaigns" / f"{name}.yaml")
    assert len(c.runs()) == len(c.configurations) * len(c.seeds) >= 4 and len(c.seeds) >= 3
    assert c.evaluation.seed_set == "test" and c.evaluation.baselines


def test_a_dry_run_lists_the_tasks_and_runs_nothing(tmp_path, capsys):
    out = camp.main([_file(tmp_path).as_posix(), "--dry-run"])
    text = capsys.readouterr().out
    assert out["states"] == {"a-s0": "new", "a-s1": "new", "b-s0": "new", "b-s1": "new"}
    lines = [x for x in text.splitlines() if x.startswith("  ")]
    assert [x.split(":")[0].strip() for x in lines] == ["a-s0", "a-s1", "b-s0", "b-s1"]
    assert "--seed 1 --name b-s1 --runs-dir" in lines[3] and "--hp algo.learning_rate=0.001" in lines[3]
    assert "--total-timesteps 512" in lines[0] and "--env-kwargs mission_time_s=2 controller_on_after_s=0.2" in lines[0]
    assert "1 test seeds of smile-windy beside pid" in text
    assert not (tmp_path / "runs").exists()


# ------------------------------------------------------------------------------------------ a tiny campaign
def _attempts(log: Path) -> int:
    return sum(x.startswith("== ") for x in log.read_text(errors="replace").splitlines())


def _check_finished(folder: Path, runs: list[str], baselines: list[str]) -> dict:
    for r in runs:
        assert (folder / r / "final_model.json").is_file(), r
    assert sorted(p.stem for p in (folder / "evaluation").glob("*.json")) == sorted(runs + baselines)
    comparison = json.loads((folder / "comparison.json").read_text())
    configs = sorted({r.rsplit("-s", 1)[0] for r in runs})
    rows = comparison["rows"]
    assert sorted({r["configuration"] for r in rows}) == configs
    for r in rows:
        assert r["baseline"] in baselines and 0.0 <= r["p_improvement"] <= 1.0
        assert r["iqm_ci_low"] <= r["iqm"] <= r["iqm_ci_high"]
    assert "P(improvement)" in (folder / "comparison.md").read_text()
    return comparison


def test_a_tiny_campaign_runs_resumes_a_killed_run_and_then_skips_everything(tmp_path, capsys):
    from lvgym.agents.training import train

    path = _file(tmp_path)
    folder = tmp_path / "runs" / "tiny"
    # a-s0 as a kill before its first checkpoint leaves it: config.yaml only
    run = {r.name: r for r in load_campaign(path).runs()}["a-s0"]
    args, given = train.parse_args(list(run.argv))
    _, config, run_dir, _ = train.prepare(args, given)
    train.create_run(config, run_dir)

    t0 = time.perf_counter()
    out = camp.main([str(path), "--no-progress"])
    first = time.perf_counter() - t0
    assert sorted((r["run"], r["status"]) for r in out["results"]) == [
        ("a-s0", "finished"), ("a-s1", "finished"), ("b-s0", "finished"), ("b-s1", "finished")]
    assert [r["resumed"] for r in sorted(out["results"], key=lambda r: r["run"])] == [True, False, False, False]
    assert "has no complete checkpoint to resume from" in (folder / "logs" / "a-s0.log").read_text()
    comparison = _check_finished(folder, ["a-s0", "a-s1", "b-s0", "b-s1"], ["pid"])
    assert {(r["condition"], r["configuration"]) for r in comparison["rows"]} == {
        (c, k) for c in ("smile-windy/rigid", "smile-windy/nonrigid", "all") for k in ("a", "b")}
    assert all(r["runs"] == 2 and r["episodes"] == (2 if r["condition"] == "all" else 1) for r in comparison["rows"])
    written = {p.name: p.stat().st_mtime_ns for p in (folder / "evaluation").iterdir()}

    t0 = time.perf_counter()
    again = camp.main([str(path), "--no-progress"])                 # everything done: skipped
    second = time.perf_counter() - t0
    assert again["results"] == []
    assert {p.name: p.stat().st_mtime_ns for p in (folder / "evaluation").iterdir()} == written
    assert "evaluation: 5 of 5 already written; flying 0" in capsys.readouterr().err
    for name in ("a-s1", "b-s0"):                                  # one attempt each
        assert _attempts(folder / "logs" / f"{name}.log") == 1
    assert [r["iqm"] for r in again["rows"]] == [r["iqm"] for r in comparison["rows"]]
    print(f"tiny campaign: {first:.1f} s; again, all skipped: {second:.1f} s")

    # a changed configuration of a run already started is refused (it would continue with its own options)
    changed = _file(tmp_path, train__total_timesteps=1024)
    with pytest.raises(SystemExit, match=r"configurations\.a = '--total-timesteps 1024': run a-s0 was started with "
                                         r"--total-timesteps 512, and continues with its own options"):
        camp.main([str(changed), "--dry-run"])


# ------------------------------------------------------------------------------------------ on Ray
def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _ray_env() -> dict[str, str]:
    env = dict(os.environ)
    env.update(RAY_GRACEFUL_SHUTDOWN_DRAIN_TIMEOUT_S="0", RAY_AUTH_MODE="disabled",
               # a dead node is noticed within seconds (the defaults take tens)
               RAY_health_check_period_ms="1000", RAY_health_check_timeout_ms="3000",
               RAY_health_check_failure_threshold="5",
               RAY_raylet_start_wait_time_s="120")                # a busy machine starts nodes slowly
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env.pop("RAY_ADDRESS", None)
    return env


@pytest.fixture
def ray_nodes(tmp_path):
    """A loopback Ray cluster: a head of 0 CPUs and two worker nodes of 1 CPU each, every node a
    ``ray start --block`` process in its own session (killing one's process group kills that node)."""
    import ray  # noqa: F401  (a missing Ray is an error here, not a skip)

    port = _free_port()
    temp_dir = tempfile.mkdtemp(prefix="lvcamp")                   # short: Ray puts sockets in it
    # this interpreter's Ray (a venv whose packages come through a .pth file has no `ray` script of its own)
    ray_cmd = [sys.executable, "-m", "ray.scripts.scripts"]
    env = _ray_env()
    common = ["--node-ip-address=127.0.0.1", "--disable-usage-stats", "--block"]
    procs: list[tuple[subprocess.Popen, Path]] = []

    def start(args: list[str], name: str) -> subprocess.Popen:
        log = tmp_path / f"ray_{name}.log"
        # each node its own agent port (the default, 52365, is one per machine: two nodes here, and any other
        # Ray on this machine, would contend for it)
        ports = [f"--dashboard-agent-listen-port={_free_port()}"]
        with open(log, "wb") as out:
            proc = subprocess.Popen([*ray_cmd, "start", *args, *ports, *common], cwd=ROOT, env=env, stdout=out,
                                    stderr=subprocess.STDOUT, start_new_session=True)
        procs.append((proc, log))
        return proc

    def wait_started(proc: subprocess.Popen, log: Path) -> None:
        deadline = time.monotonic() + 120
        while b"block forever" not in log.read_bytes():
            if proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"ray start did not start (exit {proc.poll()}):\n{log.read_text()[-3000:]}")
            time.sleep(0.2)

    try:
        head = start(["--head", f"--port={port}", "--num-cpus=0", "--include-dashboard=false",
                      f"--temp-dir={temp_dir}"], "head")
        wait_started(head, procs[0][1])
        workers = []
        for i in (1, 2):                                            # one after the other: a busy GCS registers both
            workers.append(start([f"--address=127.0.0.1:{port}", "--num-cpus=1"], f"worker{i}"))
            wait_started(*procs[-1])
        yield {"address": f"127.0.0.1:{port}", "workers": workers, "env": env}
    finally:
        for proc, _ in reversed(procs):
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)                    # `ray start --block` stops what it started
        for proc, _ in reversed(procs):
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)                 # its own process group (start_new_session)
                proc.wait()
        shutil.rmtree(temp_dir, ignore_errors=True)


def _worker_of(log: Path) -> int | None:
    """The pid of the worker process of a run's latest attempt (its log's last header)."""
    heads = [x for x in log.read_text(errors="replace").splitlines() if x.startswith("== ")] if log.is_file() else []
    return int(heads[-1].split("(worker ")[1].split(")")[0]) if heads else None


def test_on_a_ray_cluster_a_killed_worker_node_does_not_stop_the_campaign(ray_nodes, tmp_path):
    path = _file(tmp_path, name="onray", configurations={"a": {}}, seeds=[0, 1, 2], executor="ray",
                 train__total_timesteps=4096, train__checkpoint_interval_s=0.5)
    folder = tmp_path / "runs" / "onray"
    env = {**ray_nodes["env"], "RAY_ADDRESS": ray_nodes["address"]}
    cmd = [sys.executable, "-m", "lvgym.cli.main", "campaign", str(path), "--no-progress"]
    log = tmp_path / "campaign.log"
    t0 = time.perf_counter()
    with open(log, "wb") as out:
        proc = subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=out, stderr=subprocess.STDOUT,
                                start_new_session=True)
    killed_node, victim = ray_nodes["workers"][0], None
    try:
        deadline = time.monotonic() + 150
        while victim is None:                                     # a run of the first worker node under way
            if proc.poll() is not None or time.monotonic() > deadline:
                raise AssertionError(f"no run started on the first worker node (exit {proc.poll()}):\n"
                                     f"{log.read_text()[-3000:]}")
            for run in ("a-s0", "a-s1", "a-s2"):
                pid = _worker_of(folder / "logs" / f"{run}.log")
                started = any((folder / run / "checkpoints").glob("step_*.json"))    # mid-run: a checkpoint
                with_node = pid is not None and _sid(pid) == killed_node.pid
                if started and with_node and not (folder / run / "final_model.json").exists():
                    victim = run
            time.sleep(0.1)
        _kill_node(killed_node.pid)                               # the node, its raylet and workers, its train.py
        killed_node.wait()
        kill_at = time.perf_counter() - t0
        proc.wait(timeout=180)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    text = log.read_text()
    reran = False
    if proc.returncode != 0:                                      # the issue allows a rerun that resumes
        reran = True
        rerun = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=180)
        text += rerun.stdout + rerun.stderr
        assert rerun.returncode == 0, text[-3000:]
    wall = time.perf_counter() - t0
    _check_finished(folder, ["a-s0", "a-s1", "a-s2"], ["pid"])
    attempts = (folder / "logs" / f"{victim}.log").read_text()
    assert _attempts(folder / "logs" / f"{victim}.log") == 2 and f"--resume {folder / victim}" in attempts, attempts[-3000:]
    assert f"resuming {folder / victim} from checkpoint step_" in attempts, attempts[-3000:]
    print(f"on Ray: {victim} killed at {kill_at:.1f} s, campaign done in {wall:.1f} s"
          f"{' (after a rerun)' if reran else ' (retried by Ray)'}")
    assert not reran, f"Ray did not retry the killed run:\n{text[-3000:]}"


def _sid(pid: int) -> int | None:
    try:
        return os.getsid(pid)
    except ProcessLookupError:
        return None


def _kill_node(sid: int) -> None:
    """SIGKILL a worker node as a crash would: the process group of its ``ray start`` (raylet and the node's
    daemons) and every other process of its session (Ray puts each worker in a process group of its own;
    the worker's train.py is in the worker's)."""
    os.killpg(sid, signal.SIGKILL)
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit() and _sid(int(entry.name)) == sid:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(int(entry.name), signal.SIGKILL)


def test_on_a_v2_suite_an_unflyable_flight_counts_as_failed_in_the_comparison():
    """score_v2 charges an unflyable flight like a failed one, so the comparison's failure rate counts both."""
    from lvgym.agents.training.campaign_compare import comparison_rows

    def rec(policy, seed, score, failed=False, flyable=True):
        return {"suite": "smile-v2", "condition": "smile-v2/rigid", "policy": policy, "seed": seed,
                "score_v2": score, "failed": failed, "flyable": flyable, "score": score}

    records = [rec("a-s0", 0, 1.0, flyable=False), rec("a-s0", 1, 0.5), rec("a-s0", 2, 2.0, failed=True),
               rec("a-s0", 3, 0.4), rec("lqg", 0, 0.6), rec("lqg", 1, 0.6), rec("lqg", 2, 0.6), rec("lqg", 3, 0.6)]
    rows = comparison_rows(records, {"a": ["a-s0"]}, ["lqg"], reps=50)
    row = next(r for r in rows if r["condition"] == "smile-v2/rigid")
    assert row["metric"] == "score_v2" and row["failure_rate"] == 0.5 and row["baseline"] == "lqg"


# ------------------------------------------------------------------------------------------ the family's tracks
def _family_file(tmp: Path, suites: list[str], configurations: dict) -> Path:
    return _file(tmp, "fam", configurations=configurations,
                 evaluation={"suites": suites, "episodes": 1, "baselines": ["auto-lqg"], "mission_time_s": 2.0})


def test_a_family_campaign_flies_each_track_on_the_suite_that_gives_its_observation(tmp_path):
    """The blind track's runs (and a run trained on one vehicle) fly family-v2, the informed track's runs
    family-v2-informed: the observation the run was trained on."""
    path = _family_file(tmp_path, ["family-v2", "family-v2-informed", "smile-v2"],
                        {"blind": {"suite": "family-v2"}, "informed": {"suite": "family-v2-informed"},
                         "smile": {"suite": "smile-v2"}, "told": {"env_kwargs": {"vehicle_info": True}}})
    c = load_campaign(path, check_train=False)
    assert c.suites_of("blind") == ("family-v2", "smile-v2")
    assert c.suites_of("smile") == ("family-v2", "smile-v2")
    assert c.suites_of("informed") == ("family-v2-informed",)
    assert c.suites_of("told") == ("family-v2-informed",)
    lines = camp._listing(c, "local", 2)
    assert "  informed flies family-v2-informed" in lines and "  blind flies family-v2, smile-v2" in lines


def test_a_configuration_whose_observation_no_evaluation_suite_gives_is_refused(tmp_path):
    path = _family_file(tmp_path, ["family-v2-informed"], {"blind": {"suite": "family-v2"}})
    with pytest.raises(ConfigError, match=r"configurations\.blind = 'family-v2': a configuration whose observation "
                                          r"one of evaluation\.suites \['family-v2-informed'\] gives: it trains "
                                          r"without the vehicle's design parameters"):
        load_campaign(path, check_train=False)


def test_the_evaluation_flies_each_run_on_its_own_suites_and_the_baselines_on_all(tmp_path, monkeypatch):
    import lvgym.benchmark as bench

    path = _family_file(tmp_path, ["family-v2", "family-v2-informed"],
                        {"blind": {"suite": "family-v2"}, "informed": {"suite": "family-v2-informed"}})
    c = load_campaign(path, check_train=False)
    for r in c.runs():
        Path(r.folder).mkdir(parents=True)
        (Path(r.folder) / "final_model.json").write_text("{}")
    monkeypatch.setattr("lvgym.benchmark.registry.resolve_policy", lambda ref, prog: ref.split("=")[0])
    calls = []

    def fake(per_suite, suites, episodes, seed_set, executor, workers, progress):
        calls.append({s.name: list(v) for s, v in zip(suites, per_suite.values())})
        assert [s.name for s in suites] == list(per_suite) and all(s.version.endswith("+override") for s in suites)
        return [{"policy": p, "suite": s} for s, ps in per_suite.items() for p in ps]

    monkeypatch.setattr(bench, "evaluate", fake)
    records = camp._evaluate_all(c, "local", 2, False)
    assert calls == [{"family-v2": ["blind-s0", "blind-s1", "auto-lqg"],
                      "family-v2-informed": ["informed-s0", "informed-s1", "auto-lqg"]}]
    assert {(r["policy"], r["suite"]) for r in records} == {
        ("blind-s0", "family-v2"), ("blind-s1", "family-v2"), ("informed-s0", "family-v2-informed"),
        ("informed-s1", "family-v2-informed"), ("auto-lqg", "family-v2"), ("auto-lqg", "family-v2-informed")}
    assert camp._evaluate_all(c, "local", 2, False) == records and len(calls) == 1     # written: not flown again


def test_a_family_suite_is_compared_per_flight_model_over_its_vehicles():
    """Two vehicles, two seeds, one run and one baseline: the rows are each model over both vehicles, then
    all; the mean and the failure share by hand."""
    from lvgym.agents.training.campaign_compare import comparison_rows

    def rec(policy, vehicle, model, seed, score, failed=False):
        return {"suite": "family-v2", "condition": f"family-v2/{vehicle}/{model}", "policy": policy, "seed": seed,
                "score_v2": score, "failed": failed, "flyable": True, "score": score}

    records = [rec(p, v, m, s, x + (0.5 if m == "nonrigid" else 0.0) + 0.1 * s, failed=(p == "auto-lqg" and v == 20001
                                                                                       and m == "nonrigid" and s == 1))
               for p, x in (("a-s0", 1.0), ("auto-lqg", 2.0)) for v in (20000, 20001)
               for m in ("rigid", "nonrigid") for s in (0, 1)]
    rows = comparison_rows(records, {"a": ["a-s0"]}, ["auto-lqg"], reps=50)
    assert [r["condition"] for r in rows] == ["rigid, 2 vehicles", "nonrigid, 2 vehicles", "all"]
    by = {r["condition"]: r for r in rows}
    assert by["rigid, 2 vehicles"]["mean"] == pytest.approx(1.05) and by["rigid, 2 vehicles"]["episodes"] == 4
    assert by["nonrigid, 2 vehicles"]["baseline_mean"] == pytest.approx(2.55)
    assert by["all"]["mean"] == pytest.approx(1.30) and by["all"]["episodes"] == 8
    assert by["all"]["failure_rate"] == 0.0 and by["nonrigid, 2 vehicles"]["p_improvement"] == 1.0
