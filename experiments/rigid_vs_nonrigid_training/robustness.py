"""The robustness experiment: policies trained on the rigid model against policies trained on the
non-rigid model (slosh and bending), both evaluated on the rigid and the non-rigid conditions of the
benchmark suites. The protocol's degradation table (per policy: the failure rates rigid and non-rigid
beside the non-rigid over rigid ratio and paired difference of the score and of the rate error) then shows
what a rigid-trained policy loses on the flexible, sloshing vehicle, and what non-rigid training buys. The
score charges a failed episode for the mission it did not fly, so its degradation counts failures (a run
that fails every episode no longer looks robust); the rate error stops at a failure. The runs are labelled
``<agent>-s<seed>``, so ``evaluate.py`` also gives each agent's IQM over its training runs.

    python -m experiments.rigid_vs_nonrigid_training.robustness --dry-run                 # print the commands
    python -m experiments.rigid_vs_nonrigid_training.robustness                           # train 2 models x 3 seeds, then evaluate
    python -m experiments.rigid_vs_nonrigid_training.robustness --seeds 0 --total-timesteps 2e6 --episodes 10   # a smaller version
    python -m experiments.rigid_vs_nonrigid_training.robustness --tag res-lqg --train-args "--residual lqg"    # residual on the LQG

By default the experiment is protocol v1's: ``lvgym/SmileAscent-v1`` trained with its flight sensors,
delay and every v1 dispersion (``train.py``'s ``--randomize protocol``), evaluated on ``smile-v1`` beside
the flex-designed ``gs-pid-flex`` and ``lqg``. v0's experiment (2026-11) was ``--env-id
lvgym/SmileAscent-v0 --randomize wind thrust_misalignment mass --suites smile-calm smile-windy
smile-dispersed --baselines pid gs-pid``. ``--train-args`` passes further ``train.py`` options to every
run (``--residual``, ``--history``, ``--hp``, ...); ``--tag`` names the configuration in the run names
(``robust-<tag>-<model>-s<seed>``, default the algorithm).

Every step is restartable: a run with ``final_model.json`` is done and skipped, a run folder without it
is continued with ``train.py --resume``, so the command can simply be run again after an interruption.
Each run's policy (best by validation) is exported as ``<runs-dir>/robustness-policies/<run>.zip`` (so
that ``evaluate.py`` labels it by run), then ``evaluate.py`` runs on the test seeds.

Campaigns now do this in general (``lvgym campaign FILE``, :mod:`lvgym.agents.training.campaign`, docs/training.md
"Campaigns"): any configurations x seeds from one checked YAML file, on this machine or on a Ray cluster,
then the evaluation on the test seeds and the comparison over the runs; this command is kept as the
experiment ran.
"""

from __future__ import annotations

import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from lvgym.commandline import arg, parse

ROOT = Path(__file__).resolve().parents[2]
MODELS = ("nonrigid", "rigid")   # non-rigid first: the policy to ship, if time runs short


def run_name(tag: str, model: str, seed: int) -> str:
    return f"robust-{tag}-{model}-s{seed}"


def train_command(args: Args, model: str, seed: int) -> list[str]:
    """The train.py command of one run (``--resume`` if its folder exists)."""
    folder = Path(args.runs_dir) / run_name(args.tag or args.algo, model, seed)
    if (folder / "config.yaml").is_file():
        return [sys.executable, str(ROOT / "train.py"), "--resume", str(folder)]
    cmd = [sys.executable, str(ROOT / "train.py"), "--env-id", args.env_id, "--algo", args.algo, "--model", model,
           "--seed", str(seed), "--wind", args.wind, "--randomize", *args.randomize, "--name", folder.name,
           "--runs-dir", args.runs_dir, *shlex.split(args.train_args)]
    if args.total_timesteps:
        cmd += ["--total-timesteps", str(int(float(args.total_timesteps)))]
    return cmd


def commands(args: Args) -> list[list[str]]:
    """Every command of the experiment, in order (training runs already finished are left out)."""
    out: list[list[str]] = []
    exported: list[str] = []
    for model in MODELS:
        for seed in args.seeds:
            name = run_name(args.tag or args.algo, model, seed)
            folder = Path(args.runs_dir) / name
            if not (folder / "final_model.json").is_file():
                out.append(train_command(args, model, seed))
            stem = Path(args.runs_dir) / "robustness-policies" / name
            out.append([sys.executable, "-m", "lvgym.agents.policies.saved", "export", str(folder), str(stem)])
            exported.append(str(stem) + ".zip")
    out.append([sys.executable, str(ROOT / "evaluate.py"), "--policies", *args.baselines, *exported,
                "--suites", *args.suites, "--episodes", str(args.episodes), "--out", args.out])
    return out


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.rigid_vs_nonrigid_training.robustness --help``)."""

    env_id: str = "lvgym/SmileAscent-v1"
    """training env"""
    algo: str = arg("ppo", choices=("ppo", "sac", "td3", "recurrent-ppo"))
    """the algorithm"""
    tag: str | None = None
    """configuration name in the run names (default: the algorithm)"""
    train_args: str = ""
    """further train.py options for every run, one string, e.g. '--residual lqg'"""
    seeds: list[int] = arg(default_factory=lambda: [0, 1, 2], lo=0, hi=10**6)
    """training seeds, one run of each model each"""
    total_timesteps: int | None = arg(None, lo=1, hi=10**12)
    """per run (default: the hyperparameter file's)"""
    wind: str = "protocol"
    """training wind tier (protocol: the env's own, the suite's for v1)"""
    randomize: list[str] = arg(default_factory=lambda: ["protocol"])
    """training randomisation (protocol: the env's own, every dispersion for v1)"""
    suites: list[str] = arg(default_factory=lambda: ["smile-v1"], metavar="SUITE")
    """suites of the evaluation"""
    baselines: list[str] = arg(default_factory=lambda: ["gs-pid-flex", "lqg"], nargs="*", metavar="POLICY")
    """evaluate.py policy names beside the agents"""
    episodes: int = arg(50, lo=1, hi=10**6)
    """test seeds per condition and policy"""
    runs_dir: str = "runs"
    """folder of the run folders"""
    out: str = "results/robustness"
    """results folder of the evaluation"""
    dry_run: bool = False
    """print the commands only"""


def main(argv: list[str] | None = None) -> None:
    """Print and run (unless --dry-run) the experiment's commands."""
    args = parse(Args, argv, "python -m experiments.rigid_vs_nonrigid_training.robustness", __doc__)
    for cmd in commands(args):
        print("+ " + shlex.join(cmd), flush=True)
        if not args.dry_run:
            subprocess.run(cmd, cwd=ROOT, check=True)


if __name__ == "__main__":
    main()
