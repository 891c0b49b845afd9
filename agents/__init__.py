"""Learned TVC policies with stable-baselines3 (PPO, SAC, TD3) and sb3-contrib (RecurrentPPO) on the batched
lvgym envs.

- :mod:`lvgym.agents.config`: per-env hyperparameters (``agents/hyperparams/<algo>.yaml``) as validated dataclasses;
- :mod:`lvgym.agents.train`: the training command (``lvgym train``; ``train.py`` at the repository root runs
  it), with :mod:`lvgym.agents.trainsetup` (recipes, env keywords, seeds, the vectorised env);
- :mod:`lvgym.agents.callbacks`: crash-safe checkpoints (named and listed by :mod:`lvgym.agents.checkpoints`),
  validation on the protocol's validation seeds;
- :mod:`lvgym.agents.progress`: the progress bar and the progress line;
- :mod:`lvgym.agents.policy`: :class:`~lvgym.agents.policy.SB3Policy`, a trained model behind the benchmark Policy interface;
- :mod:`lvgym.agents.residual`: residual policies on a classical baseline (training wrapper and adapter);
- :mod:`lvgym.agents.inversion`: ``inversion-id``, the privileged reference's law on a learned disturbance
  observer (:mod:`lvgym.agents.observer`, NumPy at flight time; fitted with :mod:`lvgym.agents.observer_fit`);
- :mod:`lvgym.agents.teacher_student`: its recipe (``lvgym train --recipe teacher-student``), with
  :mod:`lvgym.agents.teacher` (the teacher's and the student's flights), :mod:`lvgym.agents.dagger` (one training
  seed's rounds), :mod:`lvgym.agents.flight_options` (the choices on validation seeds) and
  :mod:`lvgym.agents.inversion_record` (the record and the policy it names);
- :mod:`experiments.rigid_vs_nonrigid_training.robustness`: the rigid-trained vs nonrigid-trained experiment.

Training is ``lvgym train`` (``docs/training.md``). Nothing in ``lvgym`` imports this package (the command
layer names it); importing it does not import stable-baselines3 (the submodules do). Importing it registers
the shipped learned policies with the benchmark (``ppo``, ``ppo-res-lqg``, ``inversion-id``,
``inversion-id-stratos``, ``inversion-id-smile``) and the loaders of saved models (``evaluate.py --policies
runs/my_run``, ``model.zip``, a cloned ``bc.pt`` or an observer's record ``.json``); their factories are named as strings, imported only where
a policy flies.
"""

from lvgym.benchmark.registry import register_policy, register_policy_loader

# the shipped learned policies (agents/trained, docs/training.md): PPO of SmileAscent-v0 (the ideal state
# observation), and protocol v1's: PPO residual on lqg, flight sensors, a 4-sample history
register_policy("ppo", "lvgym.agents.policy:shipped_policy")
register_policy("ppo-res-lqg", "lvgym.agents.policy:shipped_policy", file="ppo_res_lqg_smile_v1", name="ppo-res-lqg")
# protocol v2's, for smile-v2-faults: the privileged reference's law on a learned disturbance observer (a
# teacher-student scheme; it flies in NumPy)
register_policy("inversion-id", "lvgym.agents.inversion:shipped_inversion")
# ... for stratos-tvc-v2: the same law on an observer trained on Stratos III, its moment carried 3 steps ahead
register_policy("inversion-id-stratos", "lvgym.agents.inversion:shipped_inversion", file="inversion_id_stratos_tvc_v2",
                name="inversion-id-stratos")
# ... for smile-v2 (no faults): an observer trained on its flights, the moment carried 5 steps ahead
register_policy("inversion-id-smile", "lvgym.agents.inversion:shipped_inversion", file="inversion_id_smile_v2",
                name="inversion-id-smile")
# a saved stable-baselines3 model (an optional <stem>_vecnormalize.pkl next to it normalises the
# observations) or a train.py run folder (its best model)
register_policy_loader("lvgym.agents.policy:load_policy", suffixes=(".zip",), folders=True,
                       description="a stable-baselines3 .zip model or a train.py run folder")
# a learned disturbance observer's record (.json beside its .npz: lvgym train --recipe teacher-student writes one,
# agents/trained holds the shipped ones): evaluate.py --policies results/teacher-student/smile-v2/inversion_id_smile_v2.json
register_policy_loader("lvgym.agents.inversion_record:from_record", suffixes=(".json",),
                       description="a disturbance observer's record .json (lvgym train --recipe teacher-student)")
# a policy cloned by ``lvgym bc`` (its .pt file): evaluate.py --policies runs/student-s0.pt
register_policy_loader("lvgym.agents.bc:policy", suffixes=(".pt",), description="a cloned policy .pt (lvgym bc)")
