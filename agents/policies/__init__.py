"""What flies in the benchmark: the learned policies' batch laws with their one-row faces
(:mod:`lvgym.benchmark.batch`), and the loaders of their saved files.

- :mod:`.sb3`: a trained stable-baselines3 model as a batch law (:class:`~.sb3.SB3Law`) and a benchmark Policy
  (:class:`~.sb3.SB3Policy`), the factories of a saved and of a shipped model (``ppo``, ``ppo-res-lqg``);
- :mod:`.saved`: the files a saved model is made of (``.zip``, ``_vecnormalize.pkl``, ``.json``), loading them
  to fly, and ``lvgym export-policy``; :mod:`.algos`: the algorithms by name; :mod:`.checkpoints`: a training
  run's checkpoints, which a run folder's loader reads;
- :mod:`.mlp`: the compiled forward of a trained multilayer perceptron (each row on its own);
- :mod:`.residual`: a learned policy on a classical baseline (:class:`~.residual.ResidualLaw`), how a residual
  run flies;
- :mod:`.inversion`: ``inversion-id``, the privileged reference's law on a learned disturbance observer
  (:mod:`.observer`, NumPy; :mod:`.observer_net`, its torch network and ``.pt`` files; :mod:`.staging`, the
  next stage's ignition), and :mod:`.inversion_record`, the record ``.json`` a trained observer is saved with
  and the policy it names;
- :mod:`.bc`: a policy cloned by ``lvgym bc``.

Nothing here imports :mod:`lvgym.agents.training` or :mod:`lvgym.agents.wrappers` (tests/test_layers.py): a
worker that flies a learned policy imports this package only.
"""
