"""Training the learned policies: ``lvgym train`` and its recipes, campaigns, datasets and behaviour cloning.

- :mod:`.train`: the training command (``lvgym train``; ``train.py`` at the repository root runs it), with
  :mod:`.trainsetup` (recipes, env keywords, seeds, the vectorised env), :mod:`.config` (per-env
  hyperparameters, ``hyperparams/<algo>.yaml`` beside it, as validated dataclasses), :mod:`.runfolder` (the run's
  folder and provenance), :mod:`.familytrain` (a vehicle family's rows);
- :mod:`.ppo`: PPO at the batched env's speed on the native VectorEnv (``lvgym train --algo ppo-fast``), with
  :mod:`.fastrun` (its run folder: the same checkpoints, validations and models as an SB3 run);
  :mod:`.curves`: the learning curves of run folders (``lvgym curves``);
- :mod:`.callbacks`: crash-safe checkpoints (named and listed by :mod:`lvgym.agents.policies.checkpoints`),
  validation on the protocol's validation seeds; :mod:`.progress`: the progress bar and line; :mod:`.timing`:
  where a run's wall time goes;
- :mod:`.campaign`: configurations x seeds (``lvgym campaign``; ``campaigns/*.yaml`` beside it), checked by
  :mod:`.campaign_schema`, compared by :mod:`.campaign_compare`;
- :mod:`.datasets`: policies' flights as Minari datasets (``lvgym dataset``); :mod:`.clone`: behaviour
  cloning from one (``lvgym bc``);
- :mod:`.teacher_student`: the teacher-student recipe (``lvgym train --recipe teacher-student``), with
  :mod:`.teacher` (the teacher's and the student's flights), :mod:`.dagger` (one training seed's rounds),
  :mod:`.observer_fit` (the observer's fit) and :mod:`.flight_options` (the choices on validation seeds).

It flies the policies of :mod:`lvgym.agents.policies` and trains in the wrappers of
:mod:`lvgym.agents.wrappers`.
"""
