"""Learned TVC policies with stable-baselines3 (PPO, SAC, TD3) and sb3-contrib (RecurrentPPO) on the batched
lvgym envs, in three sub-packages by role:

- :mod:`lvgym.agents.policies`: what flies in the benchmark, batch laws with one-row faces
  (:mod:`lvgym.benchmark.batch`) and the loaders of their files: :mod:`~lvgym.agents.policies.sb3` (a trained SB3
  model, :class:`~lvgym.agents.policies.sb3.SB3Policy`), :mod:`~lvgym.agents.policies.saved` (a saved model's
  files, ``lvgym export-policy``) with :mod:`~lvgym.agents.policies.algos` and
  :mod:`~lvgym.agents.policies.checkpoints`, :mod:`~lvgym.agents.policies.mlp` (the compiled actor),
  :mod:`~lvgym.agents.policies.residual` (a learned policy on a classical baseline),
  :mod:`~lvgym.agents.policies.inversion` (``inversion-id``: the privileged reference's law on a learned
  disturbance observer, :mod:`~lvgym.agents.policies.observer` in NumPy at flight time,
  :mod:`~lvgym.agents.policies.observer_net` its torch network, :mod:`~lvgym.agents.policies.staging`,
  :mod:`~lvgym.agents.policies.inversion_record` its record) and :mod:`~lvgym.agents.policies.bc` (a cloned
  policy);
- :mod:`lvgym.agents.training`: ``lvgym train`` (:mod:`~lvgym.agents.training.train`; ``train.py`` at the
  repository root runs it) with its set-up, hyperparameters (``agents/training/hyperparams/<algo>.yaml``,
  :mod:`~lvgym.agents.training.config`), callbacks, progress and run folder; campaigns
  (``agents/training/campaigns``); Minari datasets and behaviour cloning (``lvgym dataset``, ``lvgym bc``); the
  teacher-student recipe (``lvgym train --recipe teacher-student``,
  :mod:`~lvgym.agents.training.teacher_student`);
- :mod:`lvgym.agents.wrappers`: the reward and loop wrappers of training (residual actions, the command's
  rate, the load's margin, the loop's dispersion).

Training imports the policies and the wrappers; the wrappers import the policies; the policies import neither
(tests/test_layers.py). :mod:`experiments.rigid_vs_nonrigid_training.robustness` is the rigid-trained vs
nonrigid-trained experiment.

Training is ``lvgym train`` (``docs/training.md``). Nothing in ``lvgym`` imports this package (the command
layer names it); importing it does not import stable-baselines3 (the submodules do). Importing it registers
the shipped learned policies with the benchmark (``ppo``, ``ppo-res-lqg``, ``inversion-id``,
``inversion-id-stratos``, ``inversion-id-smile``; their files are in ``agents/trained``) and the loaders of
saved models (``evaluate.py --policies runs/my_run``, ``model.zip``, a cloned ``bc.pt`` or an observer's
record ``.json``); their factories, all in :mod:`lvgym.agents.policies`, are named as strings, imported only
where a policy flies.
"""

from lvgym.benchmark.registry import register_policy, register_policy_loader

# the shipped learned policies (agents/trained, docs/training.md): PPO of SmileAscent-v0 (the ideal state
# observation), and protocol v1's: PPO residual on lqg, flight sensors, a 4-sample history
register_policy("ppo", "lvgym.agents.policies.sb3:shipped_policy")
register_policy("ppo-res-lqg", "lvgym.agents.policies.sb3:shipped_policy", file="ppo_res_lqg_smile_v1",
                name="ppo-res-lqg")
# protocol v2's, for smile-v2-faults: the privileged reference's law on a learned disturbance observer (a
# teacher-student scheme; it flies in NumPy)
register_policy("inversion-id", "lvgym.agents.policies.inversion:shipped_inversion")
# ... for stratos-tvc-v2: the same law on an observer trained on Stratos III, its moment carried 3 steps ahead
register_policy("inversion-id-stratos", "lvgym.agents.policies.inversion:shipped_inversion",
                file="inversion_id_stratos_tvc_v2", name="inversion-id-stratos")
# ... for smile-v2 (no faults): an observer trained on its flights, the moment carried 5 steps ahead
register_policy("inversion-id-smile", "lvgym.agents.policies.inversion:shipped_inversion", file="inversion_id_smile_v2",
                name="inversion-id-smile")
# a saved stable-baselines3 model (flown with the VecNormalize statistics it carries or has beside it as
# <stem>_vecnormalize.pkl; one trained under VecNormalize without them is refused) or a train.py run folder (its
# best model, else its final model, else its newest checkpoint: the command names which)
register_policy_loader("lvgym.agents.policies.sb3:load_policy", suffixes=(".zip",), folders=True,
                       description="a stable-baselines3 .zip model or a train.py run folder",
                       describe="lvgym.agents.policies.saved:describe_saved")
# a learned disturbance observer's record (.json beside its .npz: lvgym train --recipe teacher-student writes one,
# agents/trained holds the shipped ones): evaluate.py --policies results/teacher-student/smile-v2/inversion_id_smile_v2.json
register_policy_loader("lvgym.agents.policies.inversion_record:from_record", suffixes=(".json",),
                       description="a disturbance observer's record .json (lvgym train --recipe teacher-student)")
# a policy cloned by ``lvgym bc`` (its .pt file): evaluate.py --policies runs/student-s0.pt
register_policy_loader("lvgym.agents.policies.bc:policy", suffixes=(".pt",),
                       description="a cloned policy .pt (lvgym bc)")
