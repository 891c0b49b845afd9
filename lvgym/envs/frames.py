"""From an ascent env to a :class:`~.render.RenderFrame`: what the picture shows, read off its flight."""

from __future__ import annotations

from typing import Any

import numpy as np

from lvgym.simulator.core import dcm_batch

from .functional import RENDER_STATIONS
from .render import HumanViewer, Renderer, RenderFrame


def make_frame(env: Any) -> RenderFrame:
    """A render frame of the single ascent env ``env`` (its row 0)."""
    sim, tl = env.flight, env.timeline                     # the rows (a SimView), the tables
    dyn, lay = env.sim.dynamics, env.sim.layout
    t = float(sim.t[0])
    length = float(env.vehicle.length)
    render = slice(1, 1 + RENDER_STATIONS)                  # station 0 is the IMU, its probes follow these
    stations = tl.sensor_stations[render]
    deflection = np.zeros_like(stations)
    if dyn.n_modes:
        phi = tl.left("phi_sensor", sim.t)[0, render]       # (S, K) shapes of the modes in force
        deflection = phi @ sim.state("eta")[0, 1]           # pitch-plane (z) deflection [m]
    C_ib = dcm_batch(sim.state("q_bi")[:1])[0]
    up = -sim.conditions("g_i")[0] / np.linalg.norm(sim.conditions("g_i")[0])
    # the body axis' angle from the local vertical, signed as a rotation about the body pitch axis y_b
    pitch = np.degrees(np.arctan2(np.cross(up, C_ib[:, 0]) @ C_ib[:, 1], up @ C_ib[:, 0]))
    N = dyn.n_slosh
    if N:
        p = sim.p[0]
        hinges = np.array([p[lay.slosh_param(j, "r_hinge")][0] for j in range(N)])
        lengths = np.array([p[lay.slosh_param(j, "length")][0] for j in range(N)])
        masses = np.array([p[lay.slosh_param(j, "m")][0] for j in range(N)])
        angles = np.degrees(sim.slosh_angles()[0, :, 1])
    else:
        hinges = lengths = masses = angles = np.zeros(0)
    rates = np.array(env._rates[-250:]) if env._rates else np.zeros((0, 4))
    axes = tuple(n for n, w in zip(("roll", "pitch", "yaw"), env.task.rate_weights) if w > 0) or ("pitch", "yaw")
    ended = ""
    if env.state is not None and env.state.task.reason[0] != 0:
        from .layouts import REASONS
        ended = REASONS[int(env.state.task.reason[0])]
    elif env.state is not None and env.state.task.truncated[0]:
        ended = "mission time reached"
    wind = sim.conditions("wind_n")[0]
    return RenderFrame(t=t, length=length, diameter=float(env.vehicle.stages[0].outer_diameter),
                       pitch_deg=float(pitch), stations=stations, deflection=deflection, slosh_stations=hinges,
                       slosh_lengths=lengths, slosh_angles_deg=angles, slosh_masses=masses,
                       gimbal_station=float(sim.p[0, lay.params["r_gimbal"].start]),
                       gimbal_deg=float(np.degrees(sim.gimbal[0, 0])),
                       wind_mps=(float(np.hypot(wind[0], wind[1])), float(-wind[2])),
                       rates_t=rates[:, 0] if rates.size else np.zeros(0),
                       rates_degps=np.degrees(rates[:, 1:]) if rates.size else np.zeros((0, 3)),
                       stage=tl.stage_names[int(tl.left("stage", sim.t)[0])],
                       info=f"Mach {sim.conditions('mach')[0]:.2f}  q {sim.conditions('qbar')[0] / 1e3:.1f} kPa",
                       model=env.task.model, termination=ended, bending=dyn.n_modes > 0, rate_axes=axes)


def render_frame(env: Any, mode: str) -> np.ndarray | None:
    """Render ``env`` in ``mode`` (``rgb_array``: an image; ``human``: a window)."""
    frame = make_frame(env)
    if env._renderer is None:
        env._renderer = Renderer() if mode == "rgb_array" else HumanViewer()
    if mode == "rgb_array":
        return env._renderer.render_rgb(frame)
    env._renderer.show(frame)
    return None
