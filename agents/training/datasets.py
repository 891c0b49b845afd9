"""Rollouts of the benchmark's policies as Minari datasets, for offline RL and imitation (the ``datasets``
extra: ``pip install "lvgym[datasets]"``).

    lvgym dataset --policies lqg-front gs-pid-flex-quiet --suites smile-v2 --episodes 50

For each policy, suite and flight model it flies ``--episodes`` episodes of the suite's condition on its
**validation** seeds (the seeds training and tuning may use; the test seeds stay unseen) with Minari's
the env, and writes one dataset, ``lvgym/<suite>-<model>/<policy>-v0``, into
Minari's local folder (``MINARI_DATASETS_PATH``, default ``~/.minari/datasets``): the observations the
policy saw, its actions, the rewards and the ends of the episodes, loadable with ``minari.load_dataset``.
Its provenance is in the dataset's own fields: ``algorithm_name`` (the policy), ``author`` (lvgym and its
version), ``code_permalink`` and a ``description`` that names the suite, the model, the protocol, the seed
set and the seeds. A policy that needs the privileged info (the reference) is refused: its observations do
not hold what it acted on.

The episodes are recorded as Minari's episode buffers (Minari's ``DataCollector`` needs JAX for its tree
utilities; the buffers do not) and written in Minari's Arrow format. The env's registration carries a
callable ``vector_entry_point`` (its native ``VectorEnv``), which Minari cannot serialise into the dataset's
environment spec; the dataset gets the spec without it (it names the env id and its options, and
``recover_environment`` rebuilds the env).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

import lvgym.baselines  # noqa: F401  (registers the controllers by name; lvgym.agents, the learned policies)
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.runner import build_policy, policy_options
from lvgym.benchmark.suites import SEED_SETS, condition, get_suite
from lvgym.commandline import arg, parse
from lvgym.errors import ConfigError

__all__ = ["NOISE_STREAM", "collect", "dataset_id", "suite_policies"]

PROG = "lvgym dataset"
PERMALINK = "https://github.com/lvgym/lvgym"


#: the stream of an episode's action-noise generator, ``numpy.random.default_rng([seed, NOISE_STREAM])``
#: (apart from every draw of the env, which its own seeded generator makes)
NOISE_STREAM = 7


def dataset_id(policy: str, suite: str, model: str, action_noise: float = 0.0) -> str:
    """The Minari id of ``policy``'s rollouts on ``suite``'s ``model`` condition (``-noise0p05`` after the
    policy for rollouts with ``action_noise`` 0.05)."""
    noise = f"-noise{action_noise:g}".replace(".", "p") if action_noise else ""
    return f"lvgym/{suite}-{model}/{policy}{noise}-v0"


def _writable_spec(env: Any) -> Any:
    """The env's spec as Minari can write it: no callable ``vector_entry_point`` (module docstring)."""
    return None if env.spec is None else dataclasses.replace(env.spec, vector_entry_point=None)


def collect(policy: str, suite: str = "smile-v2", model: str = "nonrigid", episodes: int = 20,
            seed_set: str = "validation", action_noise: float = 0.0, **overrides: Any) -> Any:
    """Fly ``episodes`` episodes of ``policy`` (a registered name, or a factory reference) on ``suite``'s
    ``model`` condition (``overrides``: env options, e.g. a shorter ``mission_time_s`` for a test) on the
    ``seed_set`` seeds and return the Minari dataset written (module docstring). ``action_noise`` > 0: the
    env flies the policy's action plus Gaussian noise of that standard deviation (in the action's units,
    clipped to the action space; drawn from :data:`NOISE_STREAM`), the dataset's ``actions`` are what the
    env flew, and ``infos["expert_action"]`` what the policy asked for (zeros at the reset), so a clone
    learns how the policy corrects the drift of a perturbed flight (DART: Laskey et al., 2017)."""
    import minari
    from minari.data_collector.episode_buffer import EpisodeBuffer

    if seed_set != "validation":
        raise ConfigError("seed_set", seed_set, "validation: a dataset is training data, and the test seeds stay "
                          f"unseen (the seed sets: {list(SEED_SETS)})")
    spec = resolve_policy(policy, PROG)
    factory = spec.resolve()
    if getattr(factory, "privileged", False):
        raise ConfigError("policies", policy, "a causal policy or a teacher: the privileged reference acts on "
                          "what its observations do not hold")
    # a teacher (a saved policy trained on privileged observations, e.g. fault_info) flies with them, and its
    # rollouts keep only the flight computer's part of the observation: the data of a blind student
    teacher = policy_options(spec)
    if not 0.0 <= float(action_noise) <= 1.0:
        raise ConfigError("action_noise", action_noise, "a standard deviation in [0, 1] (the action's units)")
    suite_obj = get_suite(suite)
    seeds = suite_obj.seeds(seed_set, episodes)
    blind = condition(suite, model, **overrides).make_env()
    env = condition(suite, model, **overrides, **teacher).make_env() if teacher else blind
    n_obs = int(blind.observation_space.shape[0])
    pol = build_policy(spec, env)
    buffers = []
    for i, seed in enumerate(seeds):
        obs, info = env.reset(seed=int(seed))
        pol.reset()
        steps: dict[str, list[Any]] = {"observations": [obs[:n_obs]], "actions": [], "rewards": [], "terminations": [],
                                       "truncations": []}
        noise = np.random.default_rng([int(seed), NOISE_STREAM]) if action_noise else None
        expert: list[np.ndarray] = [np.zeros(env.action_space.shape, env.action_space.dtype)]
        while True:
            action = np.asarray(pol.act(obs, info), dtype=env.action_space.dtype)
            if noise is not None:
                expert.append(action)
                action = np.clip(action + noise.normal(0.0, action_noise, action.shape), env.action_space.low,
                                 env.action_space.high).astype(env.action_space.dtype)
            obs, reward, terminated, truncated, info = env.step(action)
            for key, value in zip(("observations", "actions", "rewards", "terminations", "truncations"),
                                  (obs[:n_obs], action, float(reward), bool(terminated), bool(truncated))):
                steps[key].append(value)
            if terminated or truncated:
                break
        infos = {"expert_action": np.array(expert)} if noise is not None else None
        buffers.append(EpisodeBuffer(id=i, seed=int(seed), infos=infos, **steps))
    description = (f"{spec.name} flying lvgym's {suite} ({suite_obj.description}; protocol {suite_obj.version}), "
                   f"{model} model, {len(seeds)} episodes on the {seed_set} seeds {seeds[0]}-{seeds[-1]}"
                   + (f", env options {overrides}" if overrides else "")
                   + (f", a teacher flying with the privileged options {teacher} (the observations recorded are "
                      "the flight computer's only, without the privileged entries)" if teacher else "")
                   + (f", its actions flown with Gaussian noise of standard deviation {action_noise:g} "
                      "(infos['expert_action']: the policy's own)" if action_noise else ""))
    from lvgym import __version__

    env_spec = _writable_spec(blind)
    return minari.create_dataset_from_buffers(
        dataset_id=dataset_id(spec.name, suite, model, action_noise), buffer=buffers, env=env_spec, eval_env=env_spec,
        algorithm_name=spec.name, author=f"lvgym {__version__}", author_email="lvgym@users.noreply.github.com",
        code_permalink=PERMALINK, description=description, data_format="arrow")


@dataclass
class Args:
    """Command-line arguments (``lvgym dataset --help``)."""

    policies: list[str] = arg(default_factory=lambda: ["lqg-front"], metavar="POLICY")
    """the policies whose rollouts to record (registered names, factory references or saved policies; a
    teacher trained on privileged observations is recorded as its student sees the flight); ``classical``:
    every classical baseline a suite lists, ``learned``: every shipped learned policy it lists"""
    suites: list[str] = arg(default_factory=lambda: ["smile-v2"], metavar="SUITE")
    """the suites to fly"""
    models: list[str] = arg(default_factory=lambda: ["rigid", "nonrigid"], metavar="MODEL")
    """the flight models"""
    episodes: int = arg(20, lo=1, hi=10_000)
    """episodes per policy, suite and model (the first validation seeds)"""
    action_noise: float = arg(0.0, lo=0.0, hi=1.0)
    """fly the policy's actions with Gaussian noise of this standard deviation and record its own actions
    in infos['expert_action'] (DART; 0: none)"""


#: the keywords of ``--policies`` that stand for a suite's listed policies of one kind
KIND_KEYWORDS = ("classical", "learned")


def suite_policies(names: Sequence[str], suite: str) -> list[str]:
    """``names`` with ``classical`` replaced by ``suite``'s causal classical baselines and ``learned`` by its
    shipped learned policies (its protocol list's policies of that kind:
    :func:`lvgym.benchmark.headline.policy_kind`), in the suite's order; duplicates dropped."""
    from lvgym.benchmark.headline import policy_kind

    out: list[str] = []
    for name in names:
        if name in KIND_KEYWORDS:
            listed = get_suite(suite).policies
            if not listed:
                raise ConfigError("policies", name, f"a suite that lists its policies (protocol v2 on); {suite!r} "
                                  "lists none: name the policies")
            out += [p for p in listed if policy_kind(resolve_policy(p, PROG)) == name]
        else:
            out.append(name)
    return list(dict.fromkeys(out))


def main(argv: Sequence[str] | None = None) -> None:
    args = parse(Args, argv, PROG, __doc__)
    for suite in args.suites:
        policies = suite_policies(args.policies, suite)
        if not policies:
            print(f"{suite}: lists no policy of {args.policies}; nothing to record")
        for policy in policies:
            for model in args.models:
                ds = collect(policy, suite, model, args.episodes, action_noise=args.action_noise)
                print(f"{ds.spec.dataset_id}: {ds.total_episodes} episodes, {ds.total_steps} steps")


if __name__ == "__main__":
    main()
