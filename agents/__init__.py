"""Learned TVC policies with stable-baselines3 (PPO, SAC, TD3) and sb3-contrib (RecurrentPPO) on the batched
lvgym envs.

- :mod:`lvgym.agents.config`: per-env hyperparameters (``agents/hyperparams/<algo>.yaml``) as validated dataclasses;
- :mod:`lvgym.agents.train`: the training command (``lvgym train``; ``train.py`` at the repository root runs
  it), with :mod:`lvgym.agents.trainsetup` (recipes, env keywords, seeds, the vectorised env);
- :mod:`lvgym.agents.callbacks`: crash-safe checkpoints, validation on the protocol's validation seeds;
- :mod:`lvgym.agents.progress`: the progress bar and the progress line;
- :mod:`lvgym.agents.policy`: :class:`~lvgym.agents.policy.SB3Policy`, a trained model behind the benchmark Policy interface;
- :mod:`lvgym.agents.residual`: residual policies on a classical baseline (training wrapper and adapter);
- :mod:`experiments.rigid_vs_nonrigid_training.robustness`: the rigid-trained vs nonrigid-trained experiment.

Training is ``lvgym train`` (``docs/training.md``). Nothing in ``lvgym`` imports this package (the console
script names its command by a string); importing it does not import stable-baselines3 (the submodules do).
"""
