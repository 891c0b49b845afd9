"""The console script ``lvgym``: every command of the benchmark, one subcommand each.

    lvgym --help                       # the commands, one line each
    lvgym evaluate --help              # a command's options
    lvgym evaluate --policies zero lqg --suites smile-v1 --episodes 10
    lvgym train --total-timesteps 2e6 --max-wall-time 3600
    lvgym campaign agents/training/campaigns/v2_example.yaml --dry-run
    lvgym design pid --vehicle smile
    lvgym vehicle slender --length 10 > slender10.yaml

``python -m lvgym`` is the same. Each subcommand is the command line of a module (``lvgym evaluate`` is
``evaluate.py``, ``lvgym design pid`` is ``python -m lvgym.baselines.design.tune``, ``lvgym vehicle beam`` is
``python -m lvgym.vehicle.beam``, ...), declared once as a dataclass (:mod:`lvgym.commandline`); the module
is imported only when its command runs, after checking that the extra it needs is installed (``lvgym train``
without stable-baselines3: ``pip install 'lvgym[train]'``).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

from lvgym.commandline import Command, dispatch

__all__ = ["COMMANDS", "main"]

_BENCHMARK = ("tqdm", "matplotlib")
_TRAIN = ("stable_baselines3", "torch", "tqdm")
_CONTROL = ("control", "matplotlib")

#: the subcommands: name, module:function, one line of help, the extra and the modules it installs
COMMANDS: tuple[Command, ...] = (
    Command("evaluate", "lvgym.cli.evaluate:main", "compare policies on the frozen benchmark protocol (evaluate.py)",
            "benchmark", _BENCHMARK),
    Command("train", "lvgym.agents.training.train:main", "train a policy with stable-baselines3 (train.py)", "train",
            _TRAIN),
    Command("curves", "lvgym.agents.training.curves:main", "learning curves of training runs: score_v2 of the "
            "validations and the rollouts' cost against env steps and wall time, the IQM over seeds", "benchmark",
            _BENCHMARK),
    Command("campaign", "lvgym.agents.training.campaign:main", "a training campaign: configurations x seeds (locally "
            "or on Ray), evaluation on the test seeds, comparison over the runs", "train", _TRAIN),
    Command("margins", "lvgym.cli.margins:main", "time-domain gain and delay margins of policies in the nonlinear "
            "simulation", "benchmark", _BENCHMARK),
    Command("headline", None, "the headline that decides: its policies chosen on validation seeds, flown once on "
            "the named test block, its results page", sub=(
        Command("select", "lvgym.cli.headline:select_main", "fly every reported policy of the v2 suites on "
                "validation seeds and write the frozen selection file", "benchmark", _BENCHMARK),
        Command("fly", "lvgym.cli.headline:fly_main", "fly the selected policies on the named test block and the 50 "
                "development seeds, and write the headline's record", "benchmark", _BENCHMARK),
        Command("page", "lvgym.cli.results_page:page_main", "write docs/results.md from the headline's record"),
    )),
    Command("compare-headline", "lvgym.cli.results_page:compare_main", "compare your lvgym evaluate result files "
            "with the headline, suite by suite, with the same statistics"),
    Command("ledger", "lvgym.cli.ledger:main", "how often each policy has flown on test seeds, and on which "
            "blocks (the ledger of test flights)"),
    Command("fingerprint", "lvgym.cli.fingerprint:main", "check (or write) a frozen protocol's fingerprint"),
    Command("verify", "lvgym.verify.__main__:main", "the verification table against the thesis (chapter 4)", sub=(
        Command("rocketpy", "lvgym.verify.rocketpy_case:main", "the rigid simulator against RocketPy (Stratos III)",
                "dev", ("rocketpy", "matplotlib")),
        Command("rocketpy-timing", "lvgym.verify.rocketpy_timing:main", "wall times of lvgym and RocketPy, the "
                "same flight", "dev", ("rocketpy",)),
    )),
    Command("bench", "lvgym.cli.bench:main", "speed of the dynamics core (RK4 steps per second) and of the shipped "
            "control laws (microseconds per row-step at 1 and 1,024 rows)", "benchmark", _BENCHMARK),
    Command("bench-envs", "lvgym.bench_envs:main", "speed of the ascent envs (env steps per second, construction)"),
    Command("bench-train", "lvgym.cli.bench_train:main", "speed of training against the env's: raw batched env steps/s, "
            "ppo-fast end to end, microseconds per sample in the env, inference and update", "train", _TRAIN),
    Command("studies", "lvgym.studies.__main__:main", "the thesis's studies: doe, ld-sweep, tw-sweep", "studies",
            ("pandas", "statsmodels", "matplotlib")),
    Command("render", "lvgym.envs.render:main", "draw the renderer's example frame to a PNG", "benchmark",
            ("matplotlib",)),
    Command("export-policy", "lvgym.agents.policies.saved:export_main", "copy a training run's policy to a stem "
            "(STEM.zip, STEM_vecnormalize.pkl, STEM.json)", "train", ("stable_baselines3", "torch")),
    Command("dataset", "lvgym.agents.training.datasets:main", "record policies' flights as Minari datasets "
            "(offline RL)", "datasets", ("minari", "pyarrow")),
    Command("bc", "lvgym.agents.training.clone:main", "behaviour cloning of a policy from its Minari dataset",
            "datasets", ("minari", "pyarrow", "torch")),
    Command("design", None, "the classical controllers' offline design tools", sub=(
        Command("pid", "lvgym.baselines.design.tune:main", "tune the rigid PID gain schedule (gs-pid)", "control",
                _CONTROL),
        Command("pid-flex", "lvgym.baselines.design.flexdesign:main", "design the PID with structural filters "
                "for the flexible vehicle (gs-pid-flex)", "control", _CONTROL),
        Command("lqg", "lvgym.baselines.design.lqg_design:main", "design the LQG schedule on the non-rigid plant "
                "(lqg)", "control", _CONTROL),
        Command("indi", "lvgym.baselines.design.indi_design:main", "design the INDI schedule: control power, gains "
                "and structural filters per row (indi)", "control", _CONTROL),
        Command("pd-relief", "lvgym.baselines.design.pdrelief:main", "place the soft attitude loop without integral "
                "on the vehicle's control power (gs-pd-relief)", "control", _CONTROL),
        Command("charts", "lvgym.baselines.design.charts:main", "Bode and Nichols charts of a gain schedule's "
                "open loops", "control", _CONTROL),
        Command("auto", "lvgym.baselines.design.auto:main", "design gs-pid, gs-pid-flex and lqg for a vehicle file "
                "in about a minute, cached by its content", "control", _CONTROL),
    )),
    Command("vehicle", None, "the vehicle layer's tools", sub=(
        Command("beam", "lvgym.vehicle.beam:main", "the beam's bending modes against the thesis's (Tables 6.8 and "
                "6.9, Eq. 6.2 and 6.3) as a Markdown table"),
        Command("slender", "lvgym.vehicle.slender:main", "print the YAML vehicle file of the parametric slender "
                "vehicle (thesis 6.1-6.2)"),
    )),
)

_DESCRIPTION = ("lvgym: a Gymnasium benchmark for thrust-vector control of flexible, sloshing launch vehicles. "
                "Its commands:")


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``lvgym <command> ...``; returns the exit status (a command's own int, else 0)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["--version"]:
        from importlib.metadata import PackageNotFoundError, version

        try:
            print(f"lvgym {version('lvgym')}")
        except PackageNotFoundError:
            import lvgym

            print(f"lvgym {lvgym.__version__}")
        return 0
    result = dispatch(COMMANDS, argv, "lvgym", _DESCRIPTION)
    return result if isinstance(result, int) and not isinstance(result, bool) else 0


if __name__ == "__main__":
    sys.exit(main())
