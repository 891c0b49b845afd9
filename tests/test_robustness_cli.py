"""``python -m experiments.rigid_vs_nonrigid_training.robustness``: the commands of the rigid-trained against non-rigid-trained experiment
(no training here: the commands are what the experiment runs, checked by ``--dry-run``'s list)."""

from __future__ import annotations

from argparse import Namespace

from experiments.rigid_vs_nonrigid_training import robustness


def _args(**kw) -> Namespace:
    base = dict(env_id="lvgym/SmileAscent-v1", algo="ppo", tag=None, train_args="", seeds=[0, 1], total_timesteps=None,
                wind="protocol", randomize=["protocol"], suites=["smile-v1"], baselines=["gs-pid-flex", "lqg"],
                episodes=50, runs_dir="/nonexistent-runs", out="results/robustness", dry_run=True)
    return Namespace(**{**base, **kw})


def test_the_default_experiment_is_protocol_v1s():
    cmds = robustness.commands(_args())
    train = [c for c in cmds if c[1].endswith("train.py")]
    assert len(train) == 4                                             # 2 models x 2 seeds, non-rigid first
    assert [c[c.index("--model") + 1] for c in train] == ["nonrigid", "nonrigid", "rigid", "rigid"]
    assert all(c[c.index("--env-id") + 1] == "lvgym/SmileAscent-v1" for c in train)
    assert all(c[c.index("--randomize") + 1] == "protocol" for c in train)
    evaluate = cmds[-1]
    assert evaluate[1].endswith("evaluate.py")
    assert evaluate[evaluate.index("--suites") + 1] == "smile-v1"
    assert "gs-pid-flex" in evaluate and "lqg" in evaluate
    assert evaluate[evaluate.index("--out") + 1] == "results/robustness"


def test_train_args_and_tag_reach_every_run():
    cmds = robustness.commands(_args(tag="res-lqg", train_args="--residual lqg --history 4"))
    train = [c for c in cmds if c[1].endswith("train.py")]
    assert all(c[-4:] == ["--residual", "lqg", "--history", "4"] for c in train)
    assert [c[c.index("--name") + 1] for c in train] == ["robust-res-lqg-nonrigid-s0", "robust-res-lqg-nonrigid-s1",
                                                         "robust-res-lqg-rigid-s0", "robust-res-lqg-rigid-s1"]
    exported = [c for c in cmds if "export" in c]
    assert [c[-1].rsplit("/", 1)[-1] for c in exported] == [
        "robust-res-lqg-nonrigid-s0", "robust-res-lqg-nonrigid-s1", "robust-res-lqg-rigid-s0", "robust-res-lqg-rigid-s1"]
