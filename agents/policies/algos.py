"""The stable-baselines3 algorithms lvgym trains and flies, by name: :data:`ALGOS` (the one list of them),
:func:`algo_name` (a name's class name) and :func:`algo_class` (its class, which loads a saved model:
:func:`lvgym.agents.policies.saved.load_model`; ``lvgym train`` builds one, :mod:`lvgym.agents.training.train`).
Importing this module imports neither stable-baselines3 nor sb3-contrib (:func:`algo_class` does).
"""

from __future__ import annotations

__all__ = ["ALGOS", "CONTRIB", "algo_class", "algo_name"]

#: the algorithms train.py trains: name -> stable-baselines3 class (the one list of them); ``ppo-fast``
#: (:mod:`lvgym.agents.training.ppo`) trains its own loop on SB3's PPO networks and saves an SB3 PPO
ALGOS = {"ppo": "PPO", "sac": "SAC", "td3": "TD3", "recurrent-ppo": "RecurrentPPO", "ppo-fast": "PPO"}
#: the algorithms of sb3-contrib (the others are stable-baselines3's)
CONTRIB = ("RecurrentPPO",)


def algo_name(algo: str) -> str:
    """The class name of ``algo`` (a key of :data:`ALGOS` or a class name, any case), e.g. ``RecurrentPPO``;
    an unknown name comes back upper-cased."""
    for key, name in ALGOS.items():
        if algo.lower() in (key, name.lower()):
            return name
    return algo.upper()


def algo_class(algo: str) -> type:
    """The stable-baselines3 (or sb3-contrib) class of ``algo`` (``ValueError`` for an unknown one,
    ``ImportError`` when sb3-contrib is missing)."""
    name = algo_name(algo)
    if name in CONTRIB:
        import sb3_contrib

        return getattr(sb3_contrib, name)
    import stable_baselines3 as sb3

    cls = getattr(sb3, name, None)
    if cls is None:
        raise ValueError(f"algo = {algo!r}: one of {sorted(ALGOS.values())}")
    return cls
