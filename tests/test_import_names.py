"""The installed import names: lvgym's code reaches its controllers and agents only as ``lvgym.baselines``
and ``lvgym.agents``, never as the repository folders' own names (``baselines``, ``agents``), which a
checkout's root on ``sys.path`` would make importable as second copies and an installed wheel does not have.
Run where the repository root is not on ``sys.path``."""

import json
import re
import subprocess
import sys
from pathlib import Path

PROBE = """
import json, sys
import lvgym, lvgym.agents, lvgym.baselines
from lvgym.benchmark import build_policy
from lvgym.benchmark.registry import resolve_policy
env = lvgym.make_env("smile-v1", model="nonrigid")
obs, info = env.reset(seed=10000)
actions = {}
for name in ("ppo", "ppo-res-lqg", "gs-pid-flex", "lqg", "aac"):
    if name == "ppo":
        continue                          # v0's policy flies SmileAscent-v0: loaded below on its own env
    policy = build_policy(resolve_policy(name), env)
    policy.reset()
    actions[name] = [float(a) for a in policy.act(obs, info)]
import gymnasium as gym
env0 = gym.make("lvgym/SmileAscent-v0")
p0 = build_policy(resolve_policy("ppo"), env0)
o0, i0 = env0.reset(seed=0)
p0.reset()
actions["ppo"] = [float(a) for a in p0.act(o0, i0)]
print(json.dumps({"actions": actions, "top": sorted(m for m in sys.modules
                                                   if m.split(".")[0] in ("agents", "baselines", "baselines_pid"))}))
"""


def test_shipped_policies_load_without_the_checkout_on_sys_path(tmp_path):
    """Every shipped policy (the learned ones' SB3 files included) builds and acts in a process whose
    ``sys.path`` does not hold the repository root, and no top-level ``agents``/``baselines`` module is
    imported on the way."""
    script = tmp_path / "probe.py"
    script.write_text(PROBE, encoding="utf-8")
    proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["top"] == []
    assert set(out["actions"]) == {"ppo", "ppo-res-lqg", "gs-pid-flex", "lqg", "aac"}
    for name, action in out["actions"].items():
        assert len(action) == 2 and all(-1.0 <= a <= 1.0 for a in action), (name, action)


def test_repository_root_is_not_what_the_tests_import_from():
    """The tests themselves import lvgym's packages under their installed names (a test that imported
    ``agents.policy`` would pass in a checkout and hide a wheel's failure)."""
    root = Path(__file__).resolve().parents[1]
    offenders = []
    for path in sorted((root / "tests").glob("*.py")):
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            s = line.strip()
            if re.match(r"(import|from) (agents|baselines)(\.| |$)", s):
                offenders.append(f"{path.name}:{n}: {s}")
    assert offenders == []
