"""Compiled task signals of the ascent envs: reference, errors, reward terms, termination, observation.

One call per control step evaluates, for every row of a batch, what the task needs after the simulator
has advanced: the reference rates (zero, or the gravity-turn pitch program), the reference axis turned
by them, the rate errors and their integral, the reward terms, the q-alpha and attitude checks, and the
noise-free observation. Sensor noise is added afterwards from each row's own generator
(:mod:`.functional`). The functions take a few named blocks: the task parameters ``task`` (layout
:data:`.layouts.TASK`), the simulator's :data:`~lvgym.simulator.advance.StepSetup`, its rows
(:class:`~lvgym.simulator.SimData`), the task's rows (:data:`TaskData`) and the timeline's
:class:`~lvgym.simulator.Tables`; every offset comes from a layout.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba as nb
import numpy as np

from lvgym.borrow import unowned, unowned_all
from lvgym.dynamics.layout import STATE, X
from lvgym.packing import at
from lvgym.rotations import quat_to_dcm
from lvgym.simulator.layouts import RL, A, D
from lvgym.simulator.timeline import locate_k

from .flightcomputer import flight_sample_k
from .layouts import G0, NV, RW, OF, OS, O, T

#: the task's rows (B leading): ``steps`` (B,) int64 control steps flown; ``on`` (B,) bool the controller
#: acts at the next step; ``on_step`` (B,) bool it acted during the last step; ``axis_ref_i`` (B, 3) the
#: reference axis, inertial; ``cum_error`` (B, 3) [rad] integrated |rate errors| (roll, pitch, yaw);
#: ``rate_error`` (B, 3) [rad/s] |rate - reference| after the last step; ``gyro_bias`` (B, 3) [rad/s];
#: ``obs`` (B, n_obs) float32 the observation (with its noise: what the flight computer sampled); ``att``
#: (B, 2) [rad] attitude error; ``terms`` (B, n_terms) the last step's reward terms (layout REWARD);
#: ``reward`` (B,); ``reason`` (B,) int64 termination code (index of REASONS); ``truncated`` (B,) bool;
#: ``qalpha`` (B,) [Pa deg]; ``mass`` (B,) [kg] the whole stack's mass at the row's time; ``stage`` (B,) int64
#: the lowest attached stage at the row's time; ``pending`` (B, D, n_a) the actions sampled but not yet
#: acting (``action_delay_steps`` D; one neutral slot when there is no delay), the oldest first; with
#: ``observation="flight"`` (:mod:`.flightcomputer`; zeros otherwise): ``nav`` (B, n_nav) the strapdown
#: attitude and the last gyro sample (layout NAV), ``draws`` (B, n_draws) the step's sensor draws (layout
#: FLIGHT_DRAWS); ``history`` (B, n_hist) float32 the stacked observation of ``history=k`` (:mod:`.history`;
#: no columns when it is off; the compiled signals do not touch it); ``fault`` (B, n_fault) the episode's
#: in-flight fault (layout :data:`.faults.FAULT`; zeros: none; the compiled signals do not touch it); ``score``
#: (B, n_score) the score reward's running sums (:mod:`.scorereward`; no columns without ``reward_kind="score_v2"``;
#: the compiled signals do not touch it)
TaskData = namedtuple("TaskData", ["steps", "on", "on_step", "axis_ref_i", "cum_error", "rate_error", "gyro_bias",
                                   "obs", "att", "terms", "reward", "reason", "truncated", "qalpha", "mass",
                                   "stage", "pending", "nav", "draws", "history", "fault", "score"])
XF = STATE.fixed


@nb.njit(cache=True, nogil=True, inline="always")
def qalpha_limit_k(task, t, mach):
    """The structural q-alpha limit [Pa deg] at time ``t`` [s] and Mach ``mach``: ``qalpha_limit`` (layout
    TASK), or its table over Mach or time, linear between the rows and held beyond (as ``numpy.interp``)."""
    over = task[T.qalpha_over]
    if over == 0.0:
        return task[T.qalpha_limit]
    x = mach if over == 1.0 else t
    n = int(task[T.qalpha_n])
    ox, oy = T.qalpha_x, T.qalpha_y
    if x <= task[ox]:
        return task[oy]
    for i in range(1, n):
        if x < task[ox + i]:
            x0, y0 = task[ox + i - 1], task[oy + i - 1]
            return y0 + (task[oy + i] - y0) / (task[ox + i] - x0) * (x - x0)
    return task[oy + n - 1]


@nb.njit(cache=True)
def qalpha_limit_rows(task, t, mach, out):
    """:func:`qalpha_limit_k` of every row: ``t``, ``mach`` (B,) into ``out`` (B,) [Pa deg]."""
    for b in range(t.shape[0]):
        out[b] = qalpha_limit_k(task, t[b], mach[b])


@nb.njit(cache=True, nogil=True)
def controller_on_k(task, tl_t, tl_burning, t):
    """Whether the controller acts at time ``t``: after ``on_after`` and while an engine burns."""
    i, w = locate_k(tl_t, t)
    return t >= task[T.on_after] - 1e-9 and tl_burning[i + 1 if w >= 1.0 else i] != 0.0


@nb.njit(cache=True, nogil=True)
def reference_pitch_rate_k(task, omega_e, t, x, cond):
    """Reference pitch rate [rad/s]: zero, or the gravity-turn programme (a kick of ``kick_angle``
    between ``kick_start`` and ``kick_end``, then ``-g sin(theta) / V`` with theta the velocity's angle
    from the local vertical; negative turns the nose downrange). The velocity is the inertial one, or
    with ``earth_velocity`` the one relative to the Earth turning at ``omega_e`` [rad/s] about z_i."""
    if task[T.gravity_turn] == 0.0:
        return 0.0
    if task[T.kick_start] <= t < task[T.kick_end]:
        return -task[T.kick_angle] / (task[T.kick_end] - task[T.kick_start])
    if t < task[T.kick_end]:
        return 0.0
    gx, gy, gz = cond[D.g_i], cond[D.g_i + 1], cond[D.g_i + 2]
    gn = math.sqrt(gx * gx + gy * gy + gz * gz)
    ov, orr = XF.v_zw_i, XF.r_zw_i
    vx, vy, vz = x[ov], x[ov + 1], x[ov + 2]
    if task[T.earth_velocity] != 0.0:                 # v - omega_e x r, omega_e along z_i
        vx, vy = vx + omega_e * x[orr + 1], vy - omega_e * x[orr]
    speed = max(math.sqrt(vx * vx + vy * vy + vz * vz), 1.0)
    cos_th = min(max(-(vx * gx + vy * gy + vz * gz) / (gn * speed), -1.0), 1.0)
    return -gn * math.sqrt(1.0 - cos_th * cos_th) / speed


@nb.njit(cache=True, nogil=True)
def attitude_error_k(C, a, out):
    """Pitch and yaw attitude error [rad] of the body axis ``C[:, 0]`` (``C = C_ib``) against the
    reference axis ``a`` (inertial): ``-(C^T (x_b x a))[1:3]``."""
    x0, x1, x2 = C[0, 0], C[1, 0], C[2, 0]
    e0, e1, e2 = x1 * a[2] - x2 * a[1], x2 * a[0] - x0 * a[2], x0 * a[1] - x1 * a[0]
    out[0] = -(C[0, 1] * e0 + C[1, 1] * e1 + C[2, 1] * e2)
    out[1] = -(C[0, 2] * e0 + C[1, 2] * e1 + C[2, 2] * e2)


@nb.njit(cache=True, nogil=True)
def observe_k(task, setup, sim, ts, b, C, ref_pitch, dphi, mass):
    """Noise-free observation of row ``b`` into ``ts.obs[b]`` (layout OBS_STATE or OBS_SENSORS) and its
    attitude error into ``ts.att[b]``, from the simulator's row ``b`` of ``sim``, the reference axis
    ``ts.axis_ref_i[b]``, the controller flag ``ts.on[b]`` and the gyro bias ``ts.gyro_bias[b]``. ``C``:
    ``C_ib`` of the row; ``ref_pitch`` [rad/s] the reference pitch rate; ``dphi`` (K,): mode slopes at the
    IMU (sensors only); ``mass`` [kg] of the whole stack."""
    t, x, cond, act = sim.t[b], sim.x[b], sim.conditions[b], sim.actuator[b]
    on, bias, obs, att = ts.on[b], ts.gyro_bias[b], ts.obs[b], ts.att[b]
    n_slosh, n_modes = setup.n_slosh, setup.n_modes
    attitude_error_k(C, ts.axis_ref_i[b], att)
    ow = XF.omega_bi_b
    w0, w1, w2 = x[ow], x[ow + 1], x[ow + 2]
    if task[T.sensors] != 0.0:
        K = n_modes
        o_etad = at(X.eta_dot, n_modes, n_slosh)          # y-plane modes, then the K z-plane ones
        for k in range(K):                   # the gyro sees the slope rate of the deflected section
            w1 -= dphi[k] * x[o_etad + K + k]
            w2 += dphi[k] * x[o_etad + k]
        w0 += bias[0]
        w1 += bias[1]
        w2 += bias[2]
        obs[OS.accel_z] = (cond[D.f_aero_b + 2] + cond[D.thrust_b + 2]) / mass / G0
        obs[OS.accel_y] = (cond[D.f_aero_b + 1] + cond[D.thrust_b + 1]) / mass / G0
    else:
        obs[O.alpha] = cond[D.alpha]
        obs[O.beta] = cond[D.beta]
    obs[O.roll_rate] = w0
    obs[O.pitch_rate_error] = w1 - ref_pitch
    obs[O.yaw_rate_error] = w2
    obs[O.pitch_attitude_error] = att[0]
    obs[O.yaw_attitude_error] = att[1]
    obs[O.mach_over_10] = cond[D.mach] / 10.0
    obs[O.qbar_over_1e5] = cond[D.qbar] / 1e5
    obs[O.gimbal_pitch] = act[A.gimbal] / task[T.gimbal_limit]
    obs[O.gimbal_yaw] = act[A.gimbal + 1] / task[T.gimbal_limit]
    obs[O.time_fraction] = t / task[T.mission]
    obs[O.controller_on] = 1.0 if on else 0.0
    obs[O.pitch_rate_reference] = ref_pitch


@nb.njit(cache=True, nogil=True)
def flight_observe_k(task, setup, sim, ts, b, a, ref_pitch, first, C):
    """The flight computer's sample (:mod:`.flightcomputer`) into the entries 0-6 of row ``b``'s
    observation: gyro and accelerometers from the IMU, the attitude error of the strapdown attitude
    against the reference axis ``a`` (``C``: 3x3 scratch, overwritten)."""
    nav = ts.nav[b]
    flight_sample_k(task, setup.imu, sim.imu[b], ref_pitch, ts.gyro_bias[b], ts.draws[b], nav, ts.obs[b], first)
    oq = NV.q_nav
    quat_to_dcm(nav[oq], nav[oq + 1], nav[oq + 2], nav[oq + 3], C)
    # pitch, then yaw: consecutive (asserted in .layouts)
    attitude_error_k(C, a, ts.obs[b, OF.pitch_attitude_error:OF.yaw_attitude_error + 1])


@nb.njit(cache=True, nogil=True, inline="always")
def _imu_and_mass_k(tables, t):
    """Row of the timeline in force at ``t`` (for the mode slopes at the IMU) and the stack's mass [kg]."""
    i, w = locate_k(tables.t, t)
    j = i + 1 if w >= 1.0 else i
    return j, (1.0 - w) * tables.mass[i] + w * tables.mass[i + 1]


@nb.njit(cache=True, nogil=True)
def reset_signals(rows, task, setup, sim, ts, tables):
    """Reference axis (the launch axis), controller flag, mass and observation of freshly reset
    ``rows`` of the task rows ``ts`` (a :data:`TaskData`) over the simulator rows ``sim``."""
    C = np.empty((3, 3))
    oq = XF.q_bi
    for b in rows:
        xb = sim.x[b]
        t = sim.t[b]
        quat_to_dcm(xb[oq], xb[oq + 1], xb[oq + 2], xb[oq + 3], C)
        for i in range(3):
            ts.axis_ref_i[b, i] = C[i, 0]
        ts.on[b] = controller_on_k(task, tables.t, tables.burning, t)
        ts.on_step[b] = ts.on[b]
        j, mass = _imu_and_mass_k(tables, t)
        ts.mass[b] = mass
        ts.stage[b] = int(tables.stage[j])
        ref_pitch = reference_pitch_rate_k(task, setup.rail[RL.omega_e], t, xb, sim.conditions[b])
        observe_k(task, setup, sim, ts, b, C, ref_pitch, tables.dphi_sensor[j, 0], mass)
        if task[T.flight] != 0.0:
            for i in range(4):
                ts.nav[b, NV.q_nav + i] = xb[oq + i]
            flight_observe_k(task, setup, sim, ts, b, ts.axis_ref_i[b], ref_pitch, True, C)


@nb.njit(cache=True, nogil=True)
def step_signals_range(lo, hi, task, setup, sim, ts, tables):
    """Signals of rows ``lo:hi`` after a control step (``ts.steps`` already counts it).

    Turns ``axis_ref_i`` by the reference pitch rate about the body pitch axis; writes the rate errors
    and adds them to ``cum_error`` [rad]; keeps the controller flag of the step flown in ``on_step`` and
    sets ``on`` for the next one; writes the observation without noise, the attitude error, the reward
    terms (layout REWARD) and their sum, the termination code, ``truncated``, q-alpha [Pa deg], the
    mass and the stage."""
    _signals_rows(lo, hi, task, setup, sim, ts, tables, np.empty((3, 3)))


@nb.njit(cache=True, nogil=True)
def _signals_rows(lo, hi, task, setup, sim, ts, tables, C):
    """:func:`step_signals_range` with a 3x3 scratch ``C``. Every array is used through a borrowed view
    (:mod:`lvgym.borrow`; the caller holds them all): the per-row functions it calls take the named
    blocks without an atomic reference count per array."""
    task, C = unowned(task), unowned(C)
    setup, sim, ts, tables = unowned_all(setup), unowned_all(sim), unowned_all(ts), unowned_all(tables)
    dt = task[T.dt]
    omega_e = setup.rail[RL.omega_e]
    oq, ow = XF.q_bi, XF.omega_bi_b
    for b in range(lo, hi):
        xb, cond, a, t = sim.x[b], sim.conditions[b], ts.axis_ref_i[b], sim.t[b]
        quat_to_dcm(xb[oq], xb[oq + 1], xb[oq + 2], xb[oq + 3], C)
        ref_pitch = reference_pitch_rate_k(task, omega_e, t, xb, cond)
        if ref_pitch != 0.0:                  # Rodrigues: turn a about the body pitch axis k
            ang = ref_pitch * dt
            k0, k1, k2 = C[0, 1], C[1, 1], C[2, 1]
            ca, sa = math.cos(ang), math.sin(ang)
            kv = k0 * a[0] + k1 * a[1] + k2 * a[2]
            c0, c1, c2 = k1 * a[2] - k2 * a[1], k2 * a[0] - k0 * a[2], k0 * a[1] - k1 * a[0]
            a[0] = a[0] * ca + c0 * sa + k0 * kv * (1.0 - ca)
            a[1] = a[1] * ca + c1 * sa + k1 * kv * (1.0 - ca)
            a[2] = a[2] * ca + c2 * sa + k2 * kv * (1.0 - ca)
        e0, e1, e2 = 0.0, 0.0, 0.0
        failed = sim.failed[b]
        if not failed:
            e0, e1, e2 = abs(xb[ow]), abs(xb[ow + 1] - ref_pitch), abs(xb[ow + 2])
        ts.rate_error[b, 0], ts.rate_error[b, 1], ts.rate_error[b, 2] = e0, e1, e2
        ts.cum_error[b, 0] += e0 * dt
        ts.cum_error[b, 1] += e1 * dt
        ts.cum_error[b, 2] += e2 * dt
        terms, act = ts.terms[b], sim.actuator[b]
        terms[RW.rate_roll] = -task[T.rate_weights] * e0 * dt
        terms[RW.rate_pitch] = -task[T.rate_weights + 1] * e1 * dt
        terms[RW.rate_yaw] = -task[T.rate_weights + 2] * e2 * dt
        terms[RW.effort] = -task[T.effort_weight] * act[A.effort]
        terms[RW.effort_rate] = -task[T.effort_rate_weight] * act[A.effort_rate]
        ts.on_step[b] = ts.on[b]
        ts.on[b] = controller_on_k(task, tables.t, tables.burning, t)
        j, mass = _imu_and_mass_k(tables, t)
        ts.mass[b] = mass
        ts.stage[b] = int(tables.stage[j])
        observe_k(task, setup, sim, ts, b, C, ref_pitch, tables.dphi_sensor[j, 0], mass)
        if task[T.flight] != 0.0 and not failed:
            flight_observe_k(task, setup, sim, ts, b, a, ref_pitch, False, C)
        qalpha = cond[D.qbar] * math.degrees(cond[D.alpha_total])
        ts.qalpha[b] = qalpha
        code = 0
        if math.degrees(math.sqrt(ts.att[b, 0] ** 2 + ts.att[b, 1] ** 2)) > task[T.attitude_limit]:
            code = 1
        if qalpha > qalpha_limit_k(task, t, cond[D.mach]):
            code = 2
        if failed:
            code = 3
        ts.reason[b] = code
        ts.truncated[b] = code == 0 and ts.steps[b] >= task[T.n_steps]
        terms[RW.failure] = -task[T.failure_penalty] * max(task[T.mission] - t, 0.0) if code != 0 else 0.0
        ts.reward[b] = (terms[RW.rate_roll] + terms[RW.rate_pitch] + terms[RW.rate_yaw] + terms[RW.effort]
                        + terms[RW.effort_rate] + terms[RW.failure])
        if failed:
            for i in range(ts.obs.shape[1]):
                ts.obs[b, i] = 0.0
