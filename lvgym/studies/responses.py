"""One run of the sensitivity study (thesis 6.1-6.2) and its responses.

A run is a :func:`~lvgym.vehicle.slender.slender_vehicle` built from five parameters (length [m],
diameter [m], fill [-], mass flow [kg/s], slosh damping [-]), flown uncontrolled (gimbal held at zero)
for 12 s with the non-rigid model, and reduced to a flat record of numbers (:func:`run_case`).

Set-up (:class:`RunSetup`; the thesis names only "the same launch vehicle model", its Stratos III of
chapter 5, so the set-up is Stratos III's): El Arenosillo, rail at 85 deg elevation, 10 m rail, the
``profile`` wind of the env tier of that name (5 m/s at the ground, 12 m/s at 1 km, 20 m/s from 10 km,
from the west; the launch azimuth of 225 deg puts it across both body planes). The disturbance is the
rail exit into that cross-wind plus the gravity turn off the 85 deg rail: the thesis's Stratos III run
had "wind hitting the vehicle just after leaving the tower" (5.2.2). Gimbal at zero: no controller
appears before thesis 6.3.

Aerodynamics (``aero``): the thesis "assumed constant" aerodynamic coefficients (6.2), the Stratos III
ones of chapter 5, for every vehicle. ``reference`` (default) does the same: every run flies the
Barrowman tables of the reference vehicle (``slender_vehicle()`` defaults, L/D 28.3, close to Stratos
III's 29.3) frozen at Mach ``aero_mach`` (default 2): the same force and moment per dynamic pressure and
angle of attack, centre of pressure at the same station from the nose. ``own``: each vehicle's own
Barrowman tables frozen at ``aero_mach``. ``tables``: each vehicle's full Mach-dependent tables (the CP
of the default vehicle moves ahead of its CG above Mach 3.85, docs/vehicles.md, and it departs at 7 s).

Responses (thesis 6.1, eq. 6.1), from samples every ``sample_dt`` [s] integrated by the trapezoidal rule:

``flex_total``   int_0^T (|eta_y| + |eta_z|) dt [sqrt(kg) m s], |eta_y| = sum over modes k of |eta_y,k|
``flex_max``     max_t (|eta_y| + |eta_z|) [sqrt(kg) m]
``cg_total``     int_0^T (|c_y| + |c_z|) dt [m s], c the lateral CG offset of the whole vehicle caused by
                 the slosh masses (:meth:`~lvgym.simulator.Simulator.lateral_cg_offset`)
``cg_max``       max_t (|c_y| + |c_z|) [m]
``defl_total``   int_0^T max_x (|w_y(x)| + |w_z(x)|) dt [m s], w(x) = sum_k phi_k(x) eta_k the lateral
                 bending deflection at station x (beam mode shapes times eta): flex in metres, comparable
                 between vehicles of different mass (eta is mass-normalised, phi ~ 1/sqrt(mass))
``defl_max``     max_t max_x (|w_y(x)| + |w_z(x)|) [m]

The first four are the thesis's; the two deflections are added because the mass-normalised eta of two
vehicles of different mass are not the same deflection.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

G0 = 9.80665                  # [m/s^2] standard gravity (thrust-to-weight)
RESPONSES = ("flex_total", "flex_max", "cg_total", "cg_max", "defl_total", "defl_max")
FACTORS = ("length", "diameter", "fill", "mass_flow", "slosh_damping")
#: the keys of a :func:`run_case` record, in order
RECORD = (*FACTORS, "ld", "mass0", "tw0", "f1_hz", "f2_hz", "phi1_max", "slosh_mass0", "t_burnout", "alpha_max_deg",
          "departed", *RESPONSES, "wall_s")
#: the env tier ``profile`` (lvgym/envs/spec.py), repeated so the study does not depend on the envs layer
PROFILE_WIND: dict[str, Any] = {"model": "profile", "altitude_m": [0.0, 1000.0, 10000.0, 100000.0],
                                "speed": [5.0, 12.0, 20.0, 20.0], "direction_deg": [270.0, 270.0, 270.0, 270.0]}
DEPARTED_DEG = 20.0           # a run whose total angle of attack exceeds this [deg] ...
QBAR_MIN = 5000.0             # ... while the dynamic pressure is above this [Pa] departed
AERO_MODES = ("reference", "own", "tables")
MACH_MAX = 25.0               # the highest Mach number the aerodynamic tables may be frozen at

__all__ = ["AERO_MODES", "DEPARTED_DEG", "MACH_MAX", "QBAR_MIN", "FACTORS", "G0", "PROFILE_WIND", "RECORD", "RESPONSES",
           "RunSetup", "deflection",
           "responses", "run_case"]


@dataclass(frozen=True)
class RunSetup:
    """How every run of a study is flown (hashed into the cache key with the parameters).

    t_end [s]: run length (thesis: 12 s); physics_dt [s]: RK4 step; sample_dt [s]: response sampling
    (a multiple of physics_dt); site, elevation_deg [deg], rail_length [m]: launch; wind: a wind
    mapping or name; aero_mach: Mach number at which the aerodynamic tables are frozen (None: full
    tables); model: simulator model; n_stations: stations from nose to base where deflection is read.
    """

    t_end: float = 12.0
    physics_dt: float = 0.005
    sample_dt: float = 0.005
    site: str = "el_arenosillo"
    elevation_deg: float = 85.0
    rail_length: float = 10.0
    wind: Any = None
    aero: str = "reference"
    aero_mach: float = 2.0
    model: str = "nonrigid"
    n_stations: int = 41

    def __post_init__(self) -> None:
        """Every value checked here, in the parent process, before a run starts in a worker."""
        from lvgym.errors import ConfigError, check_choice, check_number

        check_number("t_end", self.t_end, 0.0, 3600.0, lo_open=True)
        check_number("physics_dt", self.physics_dt, 0.0, 0.05, lo_open=True)
        check_number("sample_dt", self.sample_dt, self.physics_dt, self.t_end)
        k = self.sample_dt / self.physics_dt
        if abs(k - round(k)) > 1e-6:
            raise ConfigError("sample_dt", self.sample_dt, f"a whole multiple of physics_dt = {self.physics_dt}")
        check_number("elevation_deg", self.elevation_deg, 1.0, 90.0)
        check_number("rail_length", self.rail_length, 0.0, 1000.0)
        check_choice("aero", self.aero, AERO_MODES)
        check_number("aero_mach", self.aero_mach, 0.0, MACH_MAX)
        check_number("n_stations", self.n_stations, 2, 10_000, integer=True)
        from lvgym.simulator import MODELS, SITES

        check_choice("model", self.model, tuple(MODELS))
        if not isinstance(self.site, str) or self.site not in SITES:
            raise ConfigError("site", self.site, f"one of {sorted(SITES)}")

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["wind"] = PROFILE_WIND if self.wind is None else self.wind
        return d


def deflection(phi: np.ndarray, eta: np.ndarray) -> np.ndarray:
    """Largest lateral deflection over the stations, ``max_x (|w_y(x)| + |w_z(x)|)`` [m].

    phi (n, S, K) [1/sqrt(kg)]: mode shapes at S stations for K modes, per sample (or (S, K) for all);
    eta (n, 2, K) [sqrt(kg) m]: modal coordinates, planes (y, z). Returns (n,)."""
    eta = np.asarray(eta, float)
    phi = np.broadcast_to(np.asarray(phi, float), (eta.shape[0],) + np.shape(phi)[-2:])
    w = np.einsum("nsk,npk->nsp", phi, eta)                  # (n, S, 2)
    return np.abs(w).sum(axis=2).max(axis=1)


def _trapz(y: np.ndarray, t: np.ndarray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t))) if len(t) > 1 else 0.0


def responses(t: np.ndarray, eta: np.ndarray, cg: np.ndarray, defl: np.ndarray | None = None) -> dict[str, float]:
    """The responses of one trajectory (module docstring).

    t (n,) [s]; eta (n, 2, K) [sqrt(kg) m] (planes y, z; or (n, 2) for one mode); cg (n, 2) [m] (y, z);
    defl (n,) [m] the deflection of :func:`deflection` (omitted: the deflection responses are NaN)."""
    t = np.asarray(t, float)
    eta = np.asarray(eta, float).reshape(len(t), 2, -1)
    flex = np.abs(eta).sum(axis=(1, 2))
    cgs = np.abs(np.nan_to_num(np.asarray(cg, float))).sum(axis=1)
    out = {"flex_total": _trapz(flex, t), "flex_max": float(flex.max()),
           "cg_total": _trapz(cgs, t), "cg_max": float(cgs.max())}
    if defl is None:
        out |= {"defl_total": math.nan, "defl_max": math.nan}
    else:
        d = np.asarray(defl, float)
        out |= {"defl_total": _trapz(d, t), "defl_max": float(d.max())}
    return out


def run_case(params: dict[str, Any]) -> dict[str, Any]:
    """Fly one run and return its record: the five factors, the vehicle's descriptors, the responses.

    ``params``: the five factors of :data:`FACTORS` (length [m], diameter [m], fill [-], mass_flow
    [kg/s], slosh_damping [-]) and ``setup``, a :meth:`RunSetup.as_dict` mapping. A function of its
    argument only (runs in worker processes).

    Descriptors: ``ld`` [-]; ``mass0`` [kg] and ``tw0`` [-] at lift-off; ``f1_hz``, ``f2_hz`` the beam
    analysis's first two bending frequencies of the loaded vehicle at lift-off; ``phi1_max`` [1/sqrt(kg)]
    the largest |mode shape| of mode 1 over the length; ``slosh_mass0`` [kg]; ``t_burnout`` [s] (NaN if
    after ``t_end``); ``alpha_max_deg`` the largest total angle of attack above :data:`QBAR_MIN`; ``departed``;
    ``wall_s`` [s] the run's wall time."""
    import time

    from lvgym.simulator import EnvironmentSpec, LaunchSpec, PhysicsSpec, Simulator, TimelineSpec
    from lvgym.vehicle.slender import slender_vehicle

    start = time.perf_counter()
    setup = RunSetup(**params["setup"])
    factors = {k: float(params[k]) for k in FACTORS}
    vehicle = slender_vehicle(**factors)
    L = vehicle.length
    if setup.aero not in AERO_MODES:
        raise ValueError(f"aero = {setup.aero!r}: one of {AERO_MODES}")
    aero: Any = "vehicle"
    if setup.aero == "own":
        aero = dict(vehicle.aerodynamics) | {"mach": [float(setup.aero_mach)]}
    elif setup.aero == "reference":
        aero = dict(slender_vehicle().aerodynamics) | {"mach": [float(setup.aero_mach)]}
    stations = np.linspace(0.0, -L, int(setup.n_stations))
    sim = Simulator(vehicle, setup.model, launch=LaunchSpec(setup.site, setup.elevation_deg, setup.rail_length),
                    environment=EnvironmentSpec(wind=setup.wind, aerodynamics=aero,
                                                aeroelastic=False),  # the thesis's study flew no aeroelastic loads
                    timeline=TimelineSpec(t_end=setup.t_end, sensor_stations=stations),
                    physics=PhysicsSpec(setup.physics_dt, threads=1))
    data = sim.reset(batch=1, rng=np.random.default_rng(0))
    v = sim.view(data)
    n = int(round(setup.t_end / setup.sample_dt))
    ts, etas, cgs, alphas = [0.0], [v.state("eta")[0].copy()], [v.lateral_cg_offset()[0]], [0.0]
    events: list[tuple[float, str]] = []
    for _ in range(n):
        events += sim.step(data, np.zeros((1, 2)), setup.sample_dt)[0]
        ts.append(float(v.t[0]))
        etas.append(v.state("eta")[0].copy())
        cgs.append(v.lateral_cg_offset()[0])
        fast = not v.on_rail[0] and v.conditions("qbar")[0] > QBAR_MIN
        alphas.append(float(v.conditions("alpha_total")[0]) if fast else 0.0)
    t = np.array(ts)
    eta = np.array(etas)
    tl = sim.timeline
    K = eta.shape[-1]
    phi = tl.left("phi_sensor", t) if K else np.zeros((len(t), stations.size, 0))
    rec = responses(t, eta, np.array(cgs), deflection(phi, eta) if K else np.zeros(len(t)))
    omega = tl.params[0][sim.layout.params["omega_modes"]] if K else np.zeros(0)
    burn = [tt for tt, e in events if "burnout" in e]
    alpha_max = math.degrees(max(alphas))
    return {**factors, "ld": L / factors["diameter"], "mass0": float(tl.mass[0]),
            "tw0": float(tl.thrust0[0] / (tl.mass[0] * G0)),
            "f1_hz": float(omega[0] / (2 * math.pi)) if K else math.nan,
            "f2_hz": float(omega[1] / (2 * math.pi)) if K > 1 else math.nan,
            "phi1_max": float(np.abs(tl.phi_sensor[0, :, 0]).max()) if K else math.nan,
            "slosh_mass0": float(tl.slosh_mass[0].sum()), "t_burnout": burn[0] if burn else math.nan,
            "alpha_max_deg": alpha_max, "departed": bool(alpha_max > DEPARTED_DEG), **rec,
            "wall_s": time.perf_counter() - start}
