"""The reward and loop wrappers of training: stable-baselines3 wrappers of the batched lvgym env, each switched on
by an option of ``lvgym train``.

- :mod:`.residual`: the env flies a classical baseline plus the learned correction (``--residual``);
- :mod:`.commandrate`: the commanded gimbal rate charged (``--command-rate-charge``);
- :mod:`.loadmargin`: the structural load's margin charged (``--load-margin``);
- :mod:`.loop_dispersion`: the loop's gain and delay drawn per episode (``--loop-gain-db``,
  ``--loop-delay-periods``).

Nothing here imports :mod:`lvgym.agents.training` (tests/test_layers.py).
"""
