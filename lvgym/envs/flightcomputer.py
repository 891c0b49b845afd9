"""The flight computer of ``observation="flight"``: it samples the IMU and integrates its gyros (compiled).

At every control step (period ``dt``) the flight computer reads the outputs of the IMU's filters
(:mod:`lvgym.simulator.imu`: the gyros at the IMU station, which see the bending slope rate, through the
sensor bandwidth and the anti-aliasing low-pass; the accelerometers at the station, with lever arm and
bending, through the anti-aliasing low-pass) and adds what the sensors add at a sample:

- gyro: ``omega_meas = filtered rate + b + n``, with the bias ``b`` a random walk
  (``b_k = b_(k-1) + N(0, sigma_b^2 dt)``, ``sigma_b`` = ``gyro_bias_rw_radps_per_sqrt_s``) started at a
  draw ``N(0, gyro_bias_radps^2)`` per axis, and the angle random walk ``n ~ N(0, ARW^2 / dt)`` (``ARW`` =
  ``gyro_arw_rad_per_sqrt_s``), white from sample to sample;
- accelerometer: ``filtered specific force + N(0, accel_noise_mps2^2)``.

Navigation model (what the attitude entries assume). The attitude is the flight computer's own: a
strapdown quaternion ``q_nav`` (scalar first, the estimate of ``q_bi``), set to the true attitude at
the reset (on the pad: an ideal alignment) and then propagated once per control step with the mean
of the last two gyro samples held over the period, ``q_nav <- q_nav (x) (cos(|theta|/2),
sin(|theta|/2) theta/|theta|)``, ``theta = (omega_meas,k-1 + omega_meas,k) dt / 2``: a first-order
strapdown algorithm without coning correction. So the attitude error carries the integrated bias
(about ``b t``), the angle random walk, the gyro's view of bending, the filters' lag and the algorithm's
error; nothing aids it (no star tracker, no GNSS attitude). The accelerometers do not enter it. The
reference axis, the reference pitch rate, Mach and dynamic pressure are taken exact (as from an
ideal velocity and position navigation and an air-data model). The task's own checks (the attitude
limit, the reward's rate errors) use the true state.

Every draw comes from the row's generator in Python (:meth:`.functional.AscentFuncEnv.transition`), scaled,
into the row's ``draws`` (layout :data:`.layouts.FLIGHT_DRAWS`), before this kernel reads them.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from lvgym.simulator.imu import imu_output_k

from .layouts import FD, G0, NV, OF, T

__all__ = ["flight_sample_k", "integrate_attitude_k"]


@nb.njit(cache=True, nogil=True, inline="always")
def integrate_attitude_k(q, o, w0, w1, w2, dt):
    """The quaternion ``q[o:o + 4]`` (scalar first), in place: ``q (x) exp(theta / 2)`` with ``theta = (w0, w1, w2) dt``
    [rad/s, s] a body-frame rotation vector, then normalised."""
    t0, t1, t2 = w0 * dt, w1 * dt, w2 * dt
    ang = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    c = math.cos(0.5 * ang)
    s = math.sin(0.5 * ang) / ang if ang > 1e-12 else 0.5
    d1, d2, d3 = s * t0, s * t1, s * t2
    a0, a1, a2, a3 = q[o], q[o + 1], q[o + 2], q[o + 3]
    b0 = a0 * c - a1 * d1 - a2 * d2 - a3 * d3
    b1 = a0 * d1 + a1 * c + a2 * d3 - a3 * d2
    b2 = a0 * d2 - a1 * d3 + a2 * c + a3 * d1
    b3 = a0 * d3 + a1 * d2 - a2 * d1 + a3 * c
    n = math.sqrt(b0 * b0 + b1 * b1 + b2 * b2 + b3 * b3)
    q[o], q[o + 1], q[o + 2], q[o + 3] = b0 / n, b1 / n, b2 / n, b3 / n


@nb.njit(cache=True, nogil=True)
def flight_sample_k(task, imu, st, ref_pitch, bias, draws, nav, obs, first):
    """One sample of the flight computer: the rate and accelerometer entries of ``obs`` (layout
    OBS_FLIGHT) and the strapdown attitude in ``nav`` (layout NAV; the caller turns it into the attitude
    entries).

    ``imu`` the IMU's parameters, ``st`` the row's IMU filter states; ``ref_pitch`` [rad/s]; ``bias``
    (3,) [rad/s] the gyro bias, ``draws`` the step's draws (layout FLIGHT_DRAWS), ``nav`` the strapdown
    attitude and the last sample (all in place). ``first``: the sample at a reset (no bias step, no
    integration; ``nav`` already holds the true attitude)."""
    rate = np.empty(3)
    force = np.empty(2)
    imu_output_k(imu, st, rate, force)
    if not first:
        for i in range(3):
            bias[i] += draws[FD.bias_step + i]
    m0 = rate[0] + bias[0] + draws[FD.gyro_noise]
    m1 = rate[1] + bias[1] + draws[FD.gyro_noise + 1]
    m2 = rate[2] + bias[2] + draws[FD.gyro_noise + 2]
    og = NV.gyro
    if not first:
        integrate_attitude_k(nav, NV.q_nav, 0.5 * (nav[og] + m0), 0.5 * (nav[og + 1] + m1), 0.5 * (nav[og + 2] + m2),
                             task[T.dt])
    nav[og], nav[og + 1], nav[og + 2] = m0, m1, m2
    obs[OF.roll_rate] = m0
    obs[OF.pitch_rate_error] = m1 - ref_pitch
    obs[OF.yaw_rate_error] = m2
    obs[OF.accel_y] = (force[0] + draws[FD.accel_noise]) / G0
    obs[OF.accel_z] = (force[1] + draws[FD.accel_noise + 1]) / G0
