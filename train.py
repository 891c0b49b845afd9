"""Train a TVC policy with stable-baselines3 on the batched lvgym envs: ``python train.py --help``.

The command is :mod:`lvgym.agents.training.train`, installed as ``lvgym train`` (``pip install 'lvgym[train]'``);
this file runs it from a checkout (``python train.py --total-timesteps 2e6 --max-wall-time 3600``) and
keeps its names importable.
"""

from lvgym.agents.training.train import (  # noqa: F401
    DEFAULT_EVAL_SUITES, RECIPES, RESUME_OVERRIDABLE, Args, check_options, create_run, env_kwargs_of, main, make_venv,
    parse_args, prepare, protocol_training, train, training_seed)

if __name__ == "__main__":
    main()
