"""lvgym: a Gymnasium benchmark for thrust-vector control of flexible, sloshing launch vehicles.

``import lvgym`` registers the environments with Gymnasium by name (their modules load on
``gymnasium.make``), so the physics layers can be imported without Gymnasium's machinery.
"""

__version__ = "0.1.0"

#: env id -> (entry point, vector entry point)
ENV_IDS = {
    "lvgym/SmileAscent-v0": ("lvgym.envs.ascent:SmileAscentEnv", "lvgym.envs:smile_ascent_vector"),
    "lvgym/SmileAscent-v1": ("lvgym.envs.ascent:SmileAscentV1Env", "lvgym.envs:smile_ascent_v1_vector"),
    "lvgym/StratosIII-v0": ("lvgym.envs.ascent:StratosIIIEnv", "lvgym.envs:stratos3_vector"),
    "lvgym/SlenderAscent-v0": ("lvgym.envs.ascent:SlenderAscentEnv", "lvgym.envs:slender_ascent_vector"),
    "lvgym/StratosIII-v1": ("lvgym.envs.ascent:StratosIIIV1Env", "lvgym.envs:stratos3_v1_vector"),
    "lvgym/SlenderAscent-v1": ("lvgym.envs.ascent:SlenderAscentV1Env", "lvgym.envs:slender_ascent_v1_vector"),
}


def register_envs() -> None:
    """Register the envs with Gymnasium (idempotent; nothing happens without Gymnasium installed)."""
    try:
        import gymnasium as gym
    except ImportError:  # pragma: no cover - gymnasium is a dependency; the physics does not need it
        return
    for env_id, (entry, vector_entry) in ENV_IDS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=entry, vector_entry_point=vector_entry)


register_envs()
