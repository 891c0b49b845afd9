"""Start-up work (issue 19): the compiled beam assembly against the array formulation it replaced, and the
caches of built models (a hit gives the same objects or arrays, another input misses)."""

from __future__ import annotations

import numpy as np
import pytest

from lvgym.vehicle.beam import _assemble_band, _hermite

_UPPER_I, _UPPER_J = np.triu_indices(4)
_BAND_ROW = 3 + _UPPER_I - _UPPER_J


def _hermite_arrays(xi, h):
    """The former array formulation of the Hermite shape functions."""
    xi2, xi3 = xi * xi, xi * xi * xi
    N = np.stack([1.0 - 3.0 * xi2 + 2.0 * xi3, h * (xi - 2.0 * xi2 + xi3), 3.0 * xi2 - 2.0 * xi3,
                  h * (xi3 - xi2)], axis=-1)
    dN = np.stack([(6.0 * xi2 - 6.0 * xi) / h, 1.0 - 4.0 * xi + 3.0 * xi2, (6.0 * xi - 6.0 * xi2) / h,
                   3.0 * xi2 - 2.0 * xi], axis=-1)
    return N, dN


def _assemble_arrays(x, ei, mpl, pm):
    """The former array formulation of :func:`lvgym.vehicle.beam._assemble_band`."""
    n_dof = 2 * x.size
    h = np.diff(x)
    o = np.ones_like(h)
    hh = (4 * h * h, 2 * h * h, -3 * h * h)
    ke = np.stack([12 * o, 6 * h, -12 * o, 6 * h, hh[0], -6 * h, hh[1], 12 * o, -6 * h, hh[0]], axis=-1)
    me = np.stack([156 * o, 22 * h, 54 * o, -13 * h, hh[0], 13 * h, hh[2], 156 * o, -22 * h, hh[0]], axis=-1)
    ke = ke * (ei / h**3)[:, None]
    me = me * (mpl * h / 420.0)[:, None]
    K = np.zeros((4, n_dof))
    M = np.zeros((4, n_dof))
    for first in (0, 1):
        e = np.arange(first, h.size, 2)
        col = 2 * e[:, None] + _UPPER_J
        K[_BAND_ROW, col] += ke[e]
        M[_BAND_ROW, col] += me[e]
    if pm.size:
        e = np.minimum(np.searchsorted(x, pm[:, 0], side="right") - 1, h.size - 1)
        N, dN = _hermite_arrays((pm[:, 0] - x[e]) / h[e], h[e])
        add = (pm[:, 1, None] * (N[:, _UPPER_I] * N[:, _UPPER_J])
               + pm[:, 2, None] * (dN[:, _UPPER_I] * dN[:, _UPPER_J]))
        np.add.at(M, (np.broadcast_to(_BAND_ROW, add.shape), 2 * e[:, None] + _UPPER_J), add)
    return K, M


@pytest.mark.parametrize("seed", range(40))
def test_assembly_is_the_array_formulation_to_the_bit(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 120))
    x = np.sort(-rng.uniform(0.0, 30.0, n))
    x = np.unique(x)
    if x.size < 2:
        x = np.array([-1.0, 0.0])
    ei = rng.uniform(1e3, 1e9, x.size - 1)
    mpl = rng.uniform(0.1, 500.0, x.size - 1)
    P = int(rng.integers(0, 9))
    stations = np.concatenate([rng.uniform(x[0], x[-1], P), rng.choice(x, min(3, x.size)),  # on nodes too
                               np.repeat(rng.uniform(x[0], x[-1], 1), 2)])                   # two in one place
    pm = np.column_stack([stations, rng.uniform(0.0, 300.0, stations.size),
                          np.where(rng.random(stations.size) < 0.3, 0.0, rng.uniform(0.0, 5.0, stations.size))])
    K, M = _assemble_band(x, ei, mpl, pm)
    K0, M0 = _assemble_arrays(x, ei, mpl, pm)
    assert K.tobytes() == K0.tobytes() and M.tobytes() == M0.tobytes()
    K, M = _assemble_band(x, ei, mpl, np.zeros((0, 3)))
    K0, M0 = _assemble_arrays(x, ei, mpl, np.zeros((0, 3)))
    assert K.tobytes() == K0.tobytes() and M.tobytes() == M0.tobytes()


def test_hermite_is_the_array_formulation_to_the_bit():
    rng = np.random.default_rng(1)
    xi = np.concatenate([rng.random(500), [0.0, 1.0, 0.5]])
    h = rng.uniform(1e-3, 3.0, xi.size)
    for got, want in zip(_hermite(xi, h), _hermite_arrays(xi, h)):
        assert got.tobytes() == want.tobytes()


def _band_matmul_arrays(ab, X):
    """The former array formulation of :func:`lvgym.vehicle.modesolve.band_matmul`."""
    w = ab[:, :, None] if X.ndim == 2 else ab
    out = w[3] * X
    for d in range(1, 4):
        out[:-d] += w[3 - d, d:] * X[d:]
        out[d:] += w[3 - d, d:] * X[:-d]
    return out


@pytest.mark.parametrize("seed", range(20))
def test_band_matmul_is_the_array_formulation_to_the_bit(seed):
    from lvgym.vehicle.modesolve import band_matmul

    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 300))
    ab = rng.normal(size=(4, n)) * 10.0 ** rng.integers(-3, 6)
    for X in (rng.normal(size=n), rng.normal(size=(n, int(rng.integers(1, 5)))), rng.normal(size=(2, n)).T):
        got, want = band_matmul(ab, X), _band_matmul_arrays(ab, X)
        assert got.shape == want.shape and got.tobytes() == np.ascontiguousarray(want).tobytes()


def _subdivide_arrays(kept, h):
    """The former array formulation of :func:`lvgym.vehicle.sections._subdivide`."""
    a, b = kept[:-1], kept[1:]
    n = np.ceil((a - b) / h - 1e-9).astype(np.int64)
    span = np.repeat(np.arange(a.size), n)
    i = np.arange(span.size) - np.repeat(np.cumsum(n) - n, n) + 1
    x = i * ((b - a) / n)[span] + a[span]
    x[(np.cumsum(n) - 1)[n > 0]] = b[n > 0]
    return np.concatenate([kept[:1], x])


@pytest.mark.parametrize("seed", range(30))
def test_subdivide_is_the_array_formulation_to_the_bit(seed):
    from lvgym.vehicle.sections import _subdivide

    rng = np.random.default_rng(seed)
    length = rng.uniform(0.5, 60.0)
    kept = np.unique(np.concatenate([[0.0, -length], -rng.uniform(0.0, length, int(rng.integers(0, 30)))]))[::-1]
    h = length / rng.integers(5, 200)
    got, want = _subdivide(kept, h), _subdivide_arrays(kept, h)
    assert got.tobytes() == want.tobytes()


def test_mass_property_rows_are_the_generic_rows():
    """``MassProperties.row`` and ``TankProperties.row`` name their fields once; every field is taken, and
    each row equals the field-by-field one."""
    from dataclasses import fields

    from lvgym.vehicle import MassModel, load_vehicle
    from lvgym.vehicle.massmodel import _PROPS_ARRAYS, _PROPS_FLOATS, MassProperties
    from lvgym.vehicle.tanks import _TANK_FLOATS, TankProperties

    assert [f.name for f in fields(TankProperties)] == [*_TANK_FLOATS, "fixed_inertia"]
    assert {f.name for f in fields(MassProperties)} == {*_PROPS_FLOATS, *_PROPS_ARRAYS, "slosh_names", "stages",
                                                         "tanks"}
    mm = MassModel(load_vehicle("smile"))
    stretches, _ = mm.history(np.linspace(0.0, 20.0, 9))
    props = mm.properties(stretches[0])
    for i in (0, 3, -1):
        row = props.row(i)
        for f in fields(MassProperties):
            got, batch = getattr(row, f.name), getattr(props, f.name)
            if f.name in _PROPS_FLOATS:
                assert type(got) is float and got == float(batch[i])
            elif f.name in _PROPS_ARRAYS:
                assert got.tobytes() == batch[i].tobytes()
        for tp_row, tp in zip(row.tanks, props.tanks):
            if tp is not None:
                for f in fields(TankProperties):
                    assert np.array_equal(getattr(tp_row, f.name), getattr(tp, f.name)[i])


def test_stage_aerodynamics_built_once_per_vehicle_object():
    """A hit gives the same models (the timeline's strips and the simulator share one Barrowman build);
    another vehicle object, even of equal content, builds its own, with equal tables; a model given by name
    is built at each call; the entry goes with the vehicle object."""
    import gc

    from lvgym.simulator import vehicleaero
    from lvgym.simulator.vehicleaero import aeroelastic_strips, stage_aerodynamics, vehicle_strips
    from lvgym.vehicle.slender import slender_vehicle

    v = slender_vehicle(wall_thickness=0.0045, diameter=0.2833, aero_mach=2.0)
    first = stage_aerodynamics(v)
    assert all(a is b for a, b in zip(first, stage_aerodynamics(v)))
    strips = vehicle_strips(v, first)
    assert all(a is b for a, b in zip(strips, vehicle_strips(v, stage_aerodynamics(v))))
    stations = aeroelastic_strips(v, aeroelastic=True)
    assert np.array_equal(stations, np.array([m.x_strip for m in strips]))
    twin = slender_vehicle(wall_thickness=0.0045, diameter=0.2833, aero_mach=2.0)
    other = stage_aerodynamics(twin)
    assert other[0] is not first[0]
    for name in ("grid", "table", "params"):
        assert getattr(other[0], name).tobytes() == getattr(first[0], name).tobytes()
    by_name = stage_aerodynamics(v, v.aerodynamics)           # a mapping: built at each call
    assert by_name[0] is not first[0] and by_name[0].table.tobytes() == first[0].table.tobytes()
    assert vehicle_strips(v, by_name)[0] is not strips[0]   # not the vehicle's own models: not kept
    key = id(twin)
    del twin, other
    gc.collect()
    assert key not in vehicleaero._BUILT


def test_process_constants_are_copies_of_one_computation():
    """The EGM2008 factors, the IMU filters' discretisation and a site's frames are computed once per
    process and input; each caller gets its own arrays, equal to a new computation; another input misses."""
    from lvgym.environment.earth import C_ne, LaunchSite, geodetic_to_ecef
    from lvgym.environment.gravity import _harmonic_factors, harmonic_factors
    from lvgym.simulator.imu import Imu

    a = harmonic_factors(4)
    a[:] = 0.0                                               # the caller's own array
    b = harmonic_factors(4)
    assert b.tobytes() == _harmonic_factors.__wrapped__(4).tobytes() and b.any()
    assert harmonic_factors(3).size != b.size

    imu = Imu(-1.0, gyro_bandwidth_hz=80.0, gyro_damping=0.7, antialias_hz=20.0)
    d1 = imu.discrete(0.01)
    d1["gyro"][0][:] = 0.0
    d2 = Imu(-2.0, 0, 80.0, 0.7, 20.0).discrete(0.01)         # another station: the same filters
    assert d2["gyro"][0].any()
    from scipy.linalg import expm
    for name, (a_c, b_c, c_c) in imu.continuous().items():
        n = a_c.shape[0]
        em = np.zeros((n + 1, n + 1))
        em[:n, :n], em[:n, n:] = a_c, b_c
        ms = expm(0.01 * em)[:n, :]
        assert d2[name][0].tobytes() == ms[:, :n].tobytes() and d2[name][1].tobytes() == ms[:, n].tobytes()
    assert not np.array_equal(Imu(-1.0, 0, 60.0, 0.7, 20.0).discrete(0.01)["gyro"][0], d2["gyro"][0])

    site = LaunchSite(latitude_deg=69.2943, longitude_deg=16.0205, altitude_m=10.0, azimuth_deg=0.0)
    r = site.r_pad_e
    r[:] = 0.0
    assert site.r_pad_e.tobytes() == geodetic_to_ecef(site.latitude, site.longitude, 10.0).tobytes()
    assert site.C_ne.tobytes() == C_ne(site.latitude, site.longitude).tobytes()
    assert site.C_le is not site.C_le and np.array_equal(site.C_le, site.C_le)


def test_nested_one_blas_thread_limits_once():
    from lvgym.vehicle.beam import _blas, one_blas_thread

    blas = [lc for lc in _blas().lib_controllers if lc.user_api == "blas"]
    before = [lc.get_num_threads() for lc in blas]
    with one_blas_thread():
        with one_blas_thread():
            assert all(lc.get_num_threads() == 1 for lc in blas)
        assert all(lc.get_num_threads() == 1 for lc in blas)
    assert [lc.get_num_threads() for lc in blas] == before


@pytest.mark.parametrize("seed", range(20))
def test_combine_rows_is_combine_to_the_bit(seed):
    from lvgym.vehicle.massmodel import combine, combine_rows

    rng = np.random.default_rng(seed)
    B = int(rng.integers(1, 40))
    parts = []
    for _ in range(int(rng.integers(1, 7))):
        batched = rng.random() < 0.5
        m = rng.uniform(0.0, 500.0, B) if batched else float(rng.uniform(0.0, 500.0))
        if batched and rng.random() < 0.3:
            m[rng.random(B) < 0.3] = 0.0                         # emptied tanks
        c = -rng.uniform(0.0, 20.0, (B, 3) if batched else 3) * np.array([1.0, 0.01, 0.01])
        J = rng.normal(size=(B, 3, 3) if batched else (3, 3))
        parts.append((m, c, J))
    parts.append((np.zeros(B), np.zeros((B, 3)), np.zeros((3, 3))))
    want = [np.broadcast_to(a, s) for a, s in zip(combine(parts), ((B,), (B, 3), (B, 3, 3)))]
    got = combine_rows(parts, B)
    for g, w in zip(got, want):
        assert g.shape == w.shape and g.tobytes() == np.ascontiguousarray(w).tobytes()
    zero = [(np.zeros(B), np.zeros((B, 3)), np.zeros((B, 3, 3)))] * 2          # no mass at all: zeros
    for g, w in zip(combine_rows(zero, B), combine(zero)):
        assert g.tobytes() == w.tobytes()


@pytest.mark.parametrize("short", [None, 0, 5, 64, 100, 10**9])
def test_timeline_entry_written_whole_after_a_short_gathered_write(tmp_path, monkeypatch, short):
    """The entry's buffers go out in one gathered write; a short one (or none) is completed in order."""
    import os

    from lvgym.simulator import cache

    rng = np.random.default_rng(3)
    parts = [b"head" * 5, memoryview(rng.normal(size=13)).cast("B"), bytes(7),
             memoryview(np.arange(6, dtype=np.int64)).cast("B"), b"tail"]
    want = b"".join(bytes(p) for p in parts)
    if short is None:
        monkeypatch.delattr(os, "writev", raising=False)
    else:
        def writev(fd, bufs):
            data = b"".join(bytes(b) for b in bufs)[:short]
            return os.write(fd, data)
        monkeypatch.setattr(os, "writev", writev)
    path = tmp_path / "entry"
    with open(path, "wb") as f:
        cache._write_all(f, parts)
    assert path.read_bytes() == want
