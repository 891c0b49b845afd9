"""The timeline's tables against reference arrays kept from the code that built them one row at a time.

``tests/data/timeline_reference.npz`` holds, for each case of :data:`CASES`, every array of the timeline at
every 20th row and at the rows around each event (both sides of an event share its time), the full arrays
of the changes of mode basis, and the events. It was written by the per-row ``build_timeline`` of commit
2a7bc86 (``python tests/test_timeline_reference.py`` with that commit on the path); the array-wise build
reproduced it to the last bit, so the tolerance (1e-12 of each array's largest entry) only allows for a
BLAS or LAPACK that rounds differently. Rewrite the file only when a change of the tables is meant.

The arrays that carry bending modes (:data:`MODAL`) get 1e-9 of their largest entry instead: the modes are
now found by Lanczos on banded factors and their frequencies by Rayleigh quotients
(:mod:`lvgym.vehicle.modesolve`), not by the dense ``eigh`` that wrote the file. Against eigenpairs of the
same matrices refined in 40-digit arithmetic (``tests/test_beam.py``), the old frequencies were off by up
to 2e-9 relative and the new ones by less than 2e-11; the shapes of either solver by 1e-11 ... 5e-10 of
their largest entry, the float64 floor of this mesh. Measured differences from the file: 4e-10 of the
largest entry (``mode_transfer`` of smile_v1), 2.4e-12 for ``params``, whose largest entries are not modal.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

from lvgym.simulator import aeroelastic_strips, build_timeline
from lvgym.vehicle import MassModel, load_vehicle

REFERENCE = Path(__file__).parent / "data" / "timeline_reference.npz"

#: (vehicle, build_timeline arguments): the thrust table, hybrid grain and brent-root burnout of Stratos III
#: (rigid, 240 s); SMILE's three stages with pendulums, modes held (v0's); smile_v1's modes every 2 s,
#: projected across the changes, at the aeroelastic strips of each stage
CASES = {
    "stratos3_rigid": ("stratos3", dict(model="rigid", t_end=240.0)),
    "smile_nonrigid": ("smile", dict(model="nonrigid", t_end=60.0, sensor_stations=[-2.0, -9.0], mode_cutoff_hz=50.0)),
    "smile_v1_projected": ("smile_v1", dict(model="nonrigid", t_end=72.0, sensor_stations=[-2.0], mode_cutoff_hz=50.0,
                                            mode_interval=2.0, mode_basis="projected", strips=True)),
}
_WHOLE = ("mode_change_t", "mode_transfer", "hold", "sensor_stations", "strip_stations")
#: arrays the timeline gained after the file was written, with the value the file's vehicles have in every row
#: (each of their engines gimballed: the whole thrust is vectored)
ADDED = {"vectored_share": 1.0}
#: arrays with frequencies, shapes or slopes of the bending modes in them (see the module docstring)
MODAL = ("params", "phi_sensor", "dphi_sensor", "phi_strip", "dphi_strip", "mode_transfer")


def build(name: str):
    vehicle_name, kw = CASES[name]
    kw = dict(kw)
    vehicle = load_vehicle(vehicle_name)
    strips = aeroelastic_strips(vehicle, aeroelastic=True) if kw.pop("strips", False) else None
    return build_timeline(MassModel(vehicle), cache=False, strip_stations=strips, **kw)


def rows(tl) -> np.ndarray:
    """Every 20th row and the two rows either side of each event time."""
    keep = set(range(0, tl.t.size, 20)) | {tl.t.size - 1}
    for t in tl.event_times:
        i = int(np.searchsorted(tl.t, t))
        keep |= {j for j in range(i - 1, i + 3) if 0 <= j < tl.t.size}
    return np.array(sorted(keep))


def arrays(tl) -> dict[str, np.ndarray]:
    """The arrays of ``tl`` the file keeps (rows picked by :func:`rows`)."""
    pick = rows(tl)
    out = {"rows": pick, "events": np.array([f"{t!r}|{e}" for t, e in tl.events])}
    for f in dataclasses.fields(tl):
        v = getattr(tl, f.name)
        if isinstance(v, np.ndarray):
            out[f.name] = v if f.name in _WHOLE else v[pick]
    return out


@pytest.mark.parametrize("name", sorted(CASES))
def test_tables_equal_the_reference(name):
    with np.load(REFERENCE) as f:
        ref = {k.split("/", 1)[1]: f[k] for k in f.files if k.startswith(name + "/")}
    got = arrays(build(name))
    assert set(got) == set(ref) | set(ADDED)
    for key, value in ADDED.items():
        assert np.all(got[key] == value), key
    assert got["events"].tolist() == ref["events"].tolist()
    assert np.array_equal(got["rows"], ref["rows"])
    worst = {}
    for key, want in ref.items():
        if key in ("events", "rows"):
            continue
        have = got[key]
        assert have.shape == want.shape and have.dtype == want.dtype, key
        if want.dtype.kind in "biu":
            assert np.array_equal(have, want), key
            continue
        scale = float(np.abs(want).max()) if want.size else 0.0
        worst[key] = float(np.abs(have - want).max() / scale) if scale > 0 else 0.0
    assert max(v for k, v in worst.items() if k not in MODAL) <= 1e-12, worst
    assert max(v for k, v in worst.items() if k in MODAL) <= 1e-9, worst


def write(path: Path = REFERENCE) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    data = {f"{name}/{k}": v for name in CASES for k, v in arrays(build(name)).items()}
    np.savez_compressed(path, **data)
    print(f"{path}: {path.stat().st_size / 1024:.0f} KiB")


if __name__ == "__main__":
    write(Path(sys.argv[1]) if len(sys.argv) > 1 else REFERENCE)
