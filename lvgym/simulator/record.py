"""Trajectory recording: what a :class:`~.core.Simulator` flew, as a table, a file and a figure.

:class:`Recorder` takes a snapshot of chosen batch rows whenever asked (after ``reset`` and after
steps, given the rows' :class:`~.data.SimData`); :meth:`Recorder.frame` turns one row's snapshots into a :class:`pandas.DataFrame`,
:meth:`Recorder.save` writes it to CSV or Parquet atomically and :meth:`Recorder.plot` draws it in
one call. :func:`fly` steps a simulator and records it at a fixed interval.

>>> from lvgym.simulator import Simulator, TimelineSpec
>>> from lvgym.simulator.record import fly
>>> sim = Simulator("stratos3", "rigid", timeline=TimelineSpec(t_end=2.0))
>>> data = sim.reset()
>>> rec = fly(sim, data, 1.0, record_dt=0.5)
>>> rec.frame()["t_s"].round(6).tolist()
[0.0, 0.5, 1.0]

Columns (SI; angles in degrees only where the name ends in ``_deg``): ``t_s``; inertial position
``r_x_m, r_y_m, r_z_m`` and velocity ``v_x_mps ..`` of the CG of the rigid body; attitude quaternion
``q0..q3`` (``q_bi``, scalar first); body rates ``p_radps, q_radps, r_radps``; ``altitude_m``,
``mach``, ``qbar_pa``, ``airspeed_mps``, ``alpha_deg``, ``beta_deg``, ``alpha_total_deg``; the wind
``wind_n_mps, wind_e_mps, wind_d_mps`` (NED); the gimbal command held over the last step
``gimbal_pitch_deg, gimbal_yaw_deg``; per slosh pendulum of the model ``slosh_<tank>_y_deg``,
``slosh_<tank>_z_deg``, ``slosh_<tank>_mass_kg``; per bending mode of the model ``eta_y<k>``,
``eta_z<k>`` [sqrt(kg) m]; the slosh masses' lateral CG offset ``cg_offset_y_m, cg_offset_z_m``;
the whole stack's tabulated mass properties ``mass_kg``, ``cg_x_m``, ``Ixx_kgm2, Iyy_kgm2,
Izz_kgm2`` (the timeline at the snapshot time: dispersions given by ``param_scale`` / ``param_offset``
are not in them); ``thrust_n`` (at the snapshot time, see :meth:`Recorder._thrust`); ``stage`` (the lowest attached stage's name); ``events`` (the events
since the previous snapshot, ``"<t> s <text>"`` joined by ``"; "``, or ``""``).
"""

from __future__ import annotations

import math
import os
import re
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import require

if TYPE_CHECKING:                                    # pragma: no cover
    import pandas as pd
    from matplotlib.figure import Figure

    from .core import Simulator
    from .data import SimData
    from .view import SimView

__all__ = ["FORMATS", "PANELS", "Recorder", "fly", "load"]

#: file suffixes :meth:`Recorder.save` writes
FORMATS = (".csv", ".parquet")
#: titles of the panels of :meth:`Recorder.plot`, in order
PANELS = ("altitude", "Mach and dynamic pressure", "angle of attack", "body rates", "gimbal angles",
          "slosh angles", "eta", "lateral CG offset", "mass")
_EVENT_SEP = "; "
_TEXT = ("stage", "events")                # the text columns; all others are numbers


def _tag(name: str) -> str:
    """A column-safe version of a tank name."""
    return re.sub(r"\W+", "_", str(name)).strip("_") or "tank"


class Recorder:
    """Snapshots of the batch rows ``rows`` (default all) of the rows ``data`` (a reset
    :class:`~.data.SimData` of the simulator ``sim``; it gives the batch size).

    Call :meth:`snapshot` with the rows after ``reset`` and after steps; pass it the events that ``sim.step``
    returned (or hand them to :meth:`add_events` after every step when snapshots are rarer than steps).
    The columns are fixed at construction by the simulator's model (slosh columns only for models
    with pendulums, ``eta`` columns only for models with bending modes).
    """

    def __init__(self, sim: Simulator, data: SimData, rows: Sequence[int] | np.ndarray | None = None) -> None:
        self.batch = batch = int(data.t.size)
        if batch == 0:
            raise RuntimeError("reset() the simulator before recording it")
        self.sim = sim
        self.rows = (np.arange(batch) if rows is None
                     else np.atleast_1d(np.asarray(rows, dtype=int)).reshape(-1))
        if self.rows.size == 0 or np.any((self.rows < 0) | (self.rows >= batch)):
            raise ValueError(f"rows = {rows!r}: batch rows in 0..{batch - 1}")
        if np.unique(self.rows).size != self.rows.size:
            raise ValueError(f"rows = {rows!r}: each row once")
        self.n_slosh, self.n_modes = sim.dynamics.n_slosh, sim.dynamics.n_modes
        self.tanks = tuple(_tag(n) for n in sim.timeline.slosh_names[:self.n_slosh])
        self.columns = self._numeric_columns() + ["stage", "events"]
        self._values: list[np.ndarray] = []          # per snapshot (R, n_numeric)
        self._stages: list[list[str]] = []           # per snapshot, per recorded row
        self._texts: list[list[str]] = []            # per snapshot, per recorded row
        self._pending: list[list[tuple[float, str]]] = [[] for _ in self.rows]
        self.events: list[list[tuple[float, str]]] = [[] for _ in self.rows]   # all, per recorded row

    # ------------------------------------------------------------------------------ recording
    def _numeric_columns(self) -> list[str]:
        cols = ["t_s", "r_x_m", "r_y_m", "r_z_m", "v_x_mps", "v_y_mps", "v_z_mps", "q0", "q1", "q2", "q3",
                "p_radps", "q_radps", "r_radps", "altitude_m", "mach", "qbar_pa", "airspeed_mps", "alpha_deg",
                "beta_deg", "alpha_total_deg", "wind_n_mps", "wind_e_mps", "wind_d_mps", "gimbal_pitch_deg",
                "gimbal_yaw_deg"]
        for tank in self.tanks:
            cols += [f"slosh_{tank}_y_deg", f"slosh_{tank}_z_deg", f"slosh_{tank}_mass_kg"]
        cols += [f"eta_y{k}" for k in range(self.n_modes)] + [f"eta_z{k}" for k in range(self.n_modes)]
        cols += ["cg_offset_y_m", "cg_offset_z_m", "mass_kg", "cg_x_m", "Ixx_kgm2", "Iyy_kgm2", "Izz_kgm2",
                 "thrust_n"]
        return cols

    def add_events(self, events: Sequence[Sequence[tuple[float, str]]]) -> None:
        """Accumulate the events ``sim.step`` returned (one list per batch row) for the next snapshot."""
        if len(events) != self.batch:
            raise ValueError(f"{len(events)} event lists for a batch of {self.batch}: pass what "
                             "sim.step returned, one list per batch row")
        for i, b in enumerate(self.rows):
            for t, text in events[b]:
                self._pending[i].append((float(t), str(text)))

    def snapshot(self, data: SimData, events: Sequence[Sequence[tuple[float, str]]] | None = None) -> None:
        """Append the state of the recorded rows of ``data`` (the simulator's rows now); ``events``: what
        the last ``sim.step`` returned (added to those given to :meth:`add_events` since the previous
        snapshot)."""
        if events is not None:
            self.add_events(events)
        rows = self.rows
        sim = self.sim.view(data)
        if sim.batch <= int(rows.max()):
            raise RuntimeError(f"the data has {sim.batch} rows; recorded rows are {rows.tolist()}")
        deg = math.degrees(1.0)
        t = sim.t[rows]

        def cond(name: str) -> np.ndarray:
            return np.asarray(sim.conditions(name))[rows]

        parts = [t[:, None], sim.state("r_zw_i")[rows], sim.state("v_zw_i")[rows], sim.state("q_bi")[rows],
                 sim.state("omega_bi_b")[rows]]
        parts += [cond(n)[:, None] for n in ("altitude", "mach", "qbar", "airspeed")]
        parts += [deg * cond(n)[:, None] for n in ("alpha", "beta", "alpha_total")]
        parts += [cond("wind_n"), deg * sim.gimbal[rows]]
        if self.n_slosh:
            ang = deg * sim.slosh_angles()[rows]                                    # (R, N, 2)
            m_s = self.sim.timeline.interp("slosh_mass", t)[:, :self.n_slosh]           # (R, N)
            parts.append(np.concatenate([ang, m_s[..., None]], axis=2).reshape(rows.size, -1))
        if self.n_modes:
            parts.append(sim.state("eta")[rows].reshape(rows.size, -1))            # y modes, then z
        tl = self.sim.timeline
        J = tl.interp("inertia", t)
        parts += [sim.lateral_cg_offset()[rows], tl.interp("mass", t)[:, None], tl.interp("cg", t)[:, :1],
                  np.diagonal(J, axis1=1, axis2=2), self._thrust(t, cond("pressure"))[:, None]]
        values = np.concatenate([np.asarray(p, dtype=float).reshape(rows.size, -1) for p in parts], axis=1)
        assert values.shape[1] == len(self.columns) - 2, (values.shape, len(self.columns))
        names = tl.stage_names
        stages = [names[int(s)] for s in tl.left("stage", t)]
        texts = []
        for i in range(rows.size):
            texts.append(_EVENT_SEP.join(f"{tt:.3f} s {e}" for tt, e in self._pending[i]))
            self.events[i] += self._pending[i]
            self._pending[i] = []
        self._values.append(values)
        self._stages.append(stages)
        self._texts.append(texts)

    def _thrust(self, t: np.ndarray, p_amb: np.ndarray) -> np.ndarray:
        """Thrust [N] of the recorded rows at their times ``t`` and ambient pressures ``p_amb`` [Pa]:
        ``max(T_0 - A_e p_amb, 0)`` with the timeline's ``T_0`` and ``A_e`` at ``t`` (the formula of
        :mod:`.flight`). Not the condition ``thrust``, which holds ``T_0`` of the middle of the last
        step (and 0 after ``reset``)."""
        tl = self.sim.timeline
        t0, ae = tl.interp("thrust0", t), tl.interp("exit_area", t)
        return np.where(t0 > 0.0, np.maximum(t0 - ae * p_amb, 0.0), 0.0)

    def __len__(self) -> int:
        """Number of snapshots taken."""
        return len(self._values)

    def _index(self, row: int | None) -> int:
        if row is None:
            return 0
        hit = np.flatnonzero(self.rows == int(row))
        if hit.size == 0:
            raise ValueError(f"row = {row!r}: not recorded (recorded rows: {self.rows.tolist()})")
        return int(hit[0])

    # ------------------------------------------------------------------------------ output
    def frame(self, row: int | None = None) -> pd.DataFrame:
        """One line per snapshot of the simulator's batch row ``row`` (default: the first recorded; needs
        pandas, ``pip install 'lvgym[studies]'``)."""
        require("pandas", "studies", "Recorder.frame")
        import pandas as pd

        i = self._index(row)
        numeric = self.columns[:-2]
        if self._values:
            data = np.stack([v[i] for v in self._values])
        else:
            data = np.zeros((0, len(numeric)))
        df = pd.DataFrame(data, columns=numeric)
        df["stage"] = pd.Series([s[i] for s in self._stages], dtype=str)
        df["events"] = pd.Series([e[i] for e in self._texts], dtype=str)
        return df

    def save(self, path: str | os.PathLike[str], row: int | None = None) -> Path:
        """Write :meth:`frame` of ``row`` to ``path`` (``.csv`` or ``.parquet``, by suffix) atomically:
        into a temporary file in the same directory, then renamed over ``path``. Returns the path."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in FORMATS:
            raise ValueError(f"cannot save to {path.name!r}: suffix {path.suffix!r} is not one of {FORMATS}")
        if suffix == ".parquet":
            require("pyarrow", "studies", "Recorder.save to Parquet")
        df = self.frame(row)
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        os.close(fd)
        tmp = Path(tmp_name)
        try:
            if suffix == ".csv":
                df.to_csv(tmp, index=False)
            else:
                df.to_parquet(tmp, index=False)
            with open(tmp, "rb") as fh:
                os.fsync(fh.fileno())
            os.replace(tmp, path)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
        return path

    def plot(self, row: int | None = None, path: str | os.PathLike[str] | None = None) -> Figure:
        """Draw :data:`PANELS` of ``row`` against time on a 3 x 3 grid, events as vertical lines; with
        ``path``, also save it as a PNG (Agg canvas; nothing is shown)."""
        require("matplotlib", "studies", "Recorder.plot")
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        df = self.frame(row)
        events = self.events[self._index(row)]
        t = df["t_s"].to_numpy()
        fig = Figure(figsize=(15.0, 11.0), layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(3, 3, sharex=True).ravel()
        name = getattr(self.sim.vehicle, "name", "vehicle")
        fig.suptitle(f"{name} ({self.sim.model}), batch row {self.rows[self._index(row)]}")

        def lines(ax: Any, cols: Sequence[str], labels: Sequence[str] | None = None, scale: float = 1.0) -> None:
            for c, lab in zip(cols, labels or cols):
                ax.plot(t, scale * df[c].to_numpy(), label=lab)
            if len(ax.get_lines()) > 1:
                ax.legend(fontsize="small", loc="best")
            if not ax.get_lines():
                ax.text(0.5, 0.5, "none in this model", ha="center", va="center", transform=ax.transAxes)

        ax = dict(zip(PANELS, axes))
        lines(ax["altitude"], ["altitude_m"], scale=1e-3)
        ax["altitude"].set_ylabel("altitude [km]")
        a = ax["Mach and dynamic pressure"]
        a.plot(t, df["mach"].to_numpy(), color="C0", label="Mach")
        a.set_ylabel("Mach [-]", color="C0")
        twin = a.twinx()
        twin.plot(t, 1e-3 * df["qbar_pa"].to_numpy(), color="C1", label="qbar")
        twin.set_ylabel("dynamic pressure [kPa]", color="C1")
        lines(ax["angle of attack"], ["alpha_deg", "beta_deg", "alpha_total_deg"], ["alpha", "beta", "total"])
        ax["angle of attack"].set_ylabel("[deg]")
        lines(ax["body rates"], ["p_radps", "q_radps", "r_radps"], ["p", "q", "r"], scale=math.degrees(1.0))
        ax["body rates"].set_ylabel("[deg/s]")
        lines(ax["gimbal angles"], ["gimbal_pitch_deg", "gimbal_yaw_deg"], ["pitch", "yaw"])
        ax["gimbal angles"].set_ylabel("[deg]")
        sl = [c for c in df.columns if c.startswith("slosh_") and c.endswith("_deg")]
        for c in sl:                                   # an empty or separated tank's pendulum is frozen
            empty = df[c.rsplit("_", 2)[0] + "_mass_kg"].to_numpy() <= 0.0
            ax["slosh angles"].plot(t, np.where(empty, np.nan, df[c].to_numpy()), label=c[6:-4])
        lines(ax["slosh angles"], [])
        ax["slosh angles"].set_ylabel("[deg]")
        eta = [c for c in df.columns if re.fullmatch(r"eta_[yz]\d+", c)]
        lines(ax["eta"], eta)
        ax["eta"].set_ylabel("[sqrt(kg) m]")
        lines(ax["lateral CG offset"], ["cg_offset_y_m", "cg_offset_z_m"], ["y", "z"], scale=1e3)
        ax["lateral CG offset"].set_ylabel("[mm]")
        lines(ax["mass"], ["mass_kg"])
        ax["mass"].set_ylabel("[kg]")
        marks: dict[float, list[str]] = {}             # events at one time share a line and a label
        for te, text in events:
            marks.setdefault(round(te, 6), []).append(text)
        for name, a in ax.items():
            a.set_title(name)
            a.grid(True, alpha=0.3)
            for te in marks:
                a.axvline(te, color="0.4", linestyle=":", linewidth=1.0)
        for te, texts in marks.items():
            ax["altitude"].annotate(", ".join(texts), (te, 0.98), xycoords=("data", "axes fraction"), rotation=90,
                                    va="top", ha="right", fontsize="x-small", color="0.3")
        for a in axes[-3:]:
            a.set_xlabel("t [s]")
        if path is not None:
            fig.savefig(Path(path), format="png", dpi=100)
        return fig


def load(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read a file written by :meth:`Recorder.save` back into the frame it was written from."""
    require("pandas", "studies", "lvgym.simulator.load")
    import pandas as pd

    path = Path(path)
    if path.suffix.lower() == ".parquet":
        return pd.read_parquet(path)
    if path.suffix.lower() == ".csv":
        numeric = pd.read_csv(path, nrows=0).columns.difference(_TEXT)
        extra = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}
        return pd.read_csv(path, dtype={c: str for c in _TEXT}, keep_default_na=False,
                           na_values={c: ["", "NaN", "nan"] for c in numeric}, **extra)
    raise ValueError(f"cannot load {path.name!r}: suffix {path.suffix!r} is not one of {FORMATS}")


def fly(sim: Simulator, data: SimData, duration: float, record_dt: float = 0.1, step_dt: float = 0.02,
        gimbal: np.ndarray | Callable[[SimView], Any] | None = None, *,
        rows: Sequence[int] | None = None) -> Recorder:
    """Step the rows ``data`` of ``sim`` (already reset; not reset here; changed in place) for
    ``duration`` [s] from their current time with steps of at most ``step_dt`` [s], snapshotting every
    ``record_dt`` [s] (and at the start and the end).

    ``gimbal``: None (zeros), a (B, 2) array [rad] held throughout, or a callable ``gimbal(view)`` of the
    rows' :class:`~.view.SimView` returning one, evaluated before every step. ``rows``: the batch rows
    recorded (default all)."""
    if not duration > 0.0 or not record_dt > 0.0 or not step_dt > 0.0:
        raise ValueError(f"duration = {duration!r}, record_dt = {record_dt!r} and step_dt = {step_dt!r} "
                         "must be > 0 s")
    rec = Recorder(sim, data, rows)
    rec.snapshot(data)
    marks = [k * record_dt for k in range(1, int(math.floor(duration / record_dt + 1e-9)) + 1)]
    if not marks or duration - marks[-1] > 1e-9 * max(1.0, duration):
        marks.append(duration)                        # a last, shorter interval
    zeros = np.zeros((rec.batch, 2))
    view = sim.view(data)
    done = 0.0
    for mark in marks:
        span = mark - done
        n = max(1, int(math.ceil(span / step_dt - 1e-9)))
        for _ in range(n):
            g = zeros if gimbal is None else (gimbal(view) if callable(gimbal) else gimbal)
            rec.add_events(sim.step(data, g, span / n))
        rec.snapshot(data)
        done = mark
    return rec
