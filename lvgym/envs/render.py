"""Pictures of an ascent: a side view of the vehicle and a strip chart of its body rates.

The renderer knows nothing about the environments: it draws a plain :class:`RenderFrame` (filled by
``lvgym/envs/frames.py``). Left panel: the vehicle in the pitch plane, tilted by its pitch attitude,
its outline following the bending deflection magnified by ``exaggeration`` (written on the picture,
"bending x50"; not for a model without modes), the engine nozzle turned by the gimbal angle with the
thrust direction, every slosh pendulum as a rod from its hinge with a disc whose area grows with its
mass, a wind arrow and the time, stage, flight model, info text and why the episode ended. Right panel
(bottom panel for a portrait ``size``): the task's body rates against time (roll for a roll-control task).

Picture conventions: x is downrange (to the right), y is up; the vertical dashed line is the local
vertical through the vehicle's mid-length. Every angle is drawn in the sense of a positive pitch
(nose towards downrange, clockwise on the picture): a positive slosh angle swings the pendulum's mass
clockwise about its hinge, a positive gimbal angle turns the nozzle exit clockwise about the gimbal
(the thrust then points towards the +side). A positive deflection is drawn on the +side of the axis
(downrange when vertical). The deflection is exaggerated, the slosh and gimbal angles are true size;
an exaggerated deflection is clipped at a quarter of the length (the label then says "clipped").
Pendulums shorter than a tenth of the length are drawn longer by an integer factor (at most 10, shown
as "slosh rods x2"), so their swing is visible next to a slender body. The wind arrow points where
the air moves (its length grows up to 20 m/s).
Non-finite inputs are skipped or replaced by a neutral value (zero angle, no deflection), never raised.

- :class:`Renderer` (``rgb_array``): a matplotlib ``Figure`` on an Agg canvas, never pyplot, so it runs
  headless and several renderers coexist; the figure and its artists are made once and updated per
  frame (``render_rgb(frame) -> uint8 (H, W, 3)``).
- :class:`HumanViewer` (``human``): the same drawing in a pyplot window (interactive mode). Under a
  non-interactive backend (Agg on a headless machine) it only draws to its canvas, and says so once with a
  warning (use ``render_mode="rgb_array"`` there).
- :func:`render_rgb`: a one-call wrapper over a per-thread cached :class:`Renderer`.

The example picture ``docs/figures/render_example.png`` is made by
``.venv/bin/python -m lvgym.envs.render docs/figures/render_example.png`` (the made-up frame of
:func:`example_frame`).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

from lvgym.errors import require

require("matplotlib", "benchmark", "rendering an ascent env")

import matplotlib  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.collections import LineCollection, PatchCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Circle, Polygon  # noqa: E402

from lvgym.commandline import arg, parse  # noqa: E402
from lvgym.errors import ConfigError  # noqa: E402

_DPI = 100.0
_NONINTERACTIVE = {"agg", "cairo", "pdf", "pgf", "ps", "svg", "template"}


@dataclass(frozen=True)
class RenderFrame:
    """What one picture shows. Stations are along the body axis [m], 0 at the nose tip, negative aft."""

    t: float                       #: time [s]
    length: float                  #: vehicle (current stack) length [m]
    diameter: float                #: [m]
    pitch_deg: float               #: body axis from the vertical in the pitch plane [deg] (+ = nose downrange)
    stations: np.ndarray           #: (n,) stations of the deflection [m]
    deflection: np.ndarray         #: (n,) lateral bending deflection in the pitch plane [m] (true size)
    slosh_stations: np.ndarray     #: (N,) hinge stations [m]
    slosh_lengths: np.ndarray      #: (N,) pendulum lengths [m]
    slosh_angles_deg: np.ndarray   #: (N,) pendulum angle from the body axis in the pitch plane [deg]
    slosh_masses: np.ndarray       #: (N,) [kg] (0 = inactive: a faint hollow marker at the hinge)
    gimbal_station: float          #: [m]
    gimbal_deg: float              #: pitch gimbal angle [deg]
    wind_mps: tuple[float, float]  #: wind in the picture plane (horizontal, vertical) [m/s]
    rates_t: np.ndarray            #: (m,) times of the strip chart [s]
    rates_degps: np.ndarray        #: (m, 3) roll, pitch and yaw body rate [deg/s] (or (m, 2): pitch, yaw)
    stage: str = ""
    info: str = ""                 #: a short text line (e.g. Mach, q)
    model: str = ""                #: the flight model (rigid, slosh, flex, nonrigid)
    termination: str = ""          #: why the episode ended ("" while it flies)
    bending: bool = True           #: the model has bending modes (else no deflection and no "bending x" note)
    rate_axes: tuple[str, ...] = ("pitch", "yaw")   #: the rates the strip chart plots (the task's axes)


def _num(x: object, default: float) -> float:
    """``x`` as a finite float, else ``default``."""
    try:
        v = float(x)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return default
    return v if math.isfinite(v) else default


def _arr(x: object) -> np.ndarray:
    """``x`` as a flat float array (empty if it is not numeric)."""
    try:
        return np.asarray(x, dtype=float).ravel()
    except (TypeError, ValueError):
        return np.zeros(0)


def _nice_ceil(v: float) -> float:
    """The smallest 1, 2, 5 x 10^k not below ``v`` (> 0), so the chart's limits do not jitter."""
    e = 10.0 ** math.floor(math.log10(v))
    return next(m * e for m in (1.0, 2.0, 5.0, 10.0) if m * e >= v * (1 - 1e-12))


class Renderer:
    """Draws :class:`RenderFrame` s on one reused figure.

    Parameters
    ----------
    exaggeration:
        Factor on the bending deflection [-] (finite, >= 0); may be changed between frames.
    size:
        ``(height, width)`` of the image [px], each >= 64. Landscape: chart on the right; portrait: below.
    figure:
        A figure to draw on (the :class:`HumanViewer` passes a pyplot one); by default a new ``Figure``
        on an Agg canvas, outside pyplot.
    """

    def __init__(self, exaggeration: float = 50.0, size: tuple[int, int] = (480, 640),
                 figure: Figure | None = None) -> None:
        try:
            h, w = (int(v) for v in size)
        except (TypeError, ValueError):
            raise ConfigError("size", size, "two ints (height, width) in pixels, each >= 64") from None
        if h < 64 or w < 64:
            raise ConfigError("size", size, "two ints (height, width) in pixels, each >= 64")
        self.size = (h, w)
        self.exaggeration = exaggeration
        if figure is None:
            figure = Figure(figsize=(w / _DPI, h / _DPI), dpi=_DPI)
            FigureCanvasAgg(figure)
        self.fig = figure
        self._build()

    @property
    def exaggeration(self) -> float:
        """Factor on the bending deflection [-]."""
        return self._ex

    @exaggeration.setter
    def exaggeration(self, value: float) -> None:
        v = _num(value, -1.0)
        if v < 0:
            raise ConfigError("exaggeration", value, "a finite number >= 0")
        self._ex = v

    def _build(self) -> None:
        """Make the axes and every artist once; :meth:`draw` only updates their data."""
        h, w = self.size
        fs = max(6.0, 9.0 * min(w, h) / 480.0)
        self._fs = fs
        fig = self.fig
        fig.clear()
        fig.patch.set_facecolor("white")
        if w >= h:
            ax = fig.add_axes((0.01, 0.01, 0.52, 0.98))
            ch = fig.add_axes((0.63, 0.14, 0.35, 0.74))
        else:
            ax = fig.add_axes((0.01, 0.36, 0.98, 0.63))
            ch = fig.add_axes((0.14, 0.07, 0.82, 0.22))
        self.ax, self.chart = ax, ch
        pos = ax.get_position()
        self._xy_ratio = (pos.width * w) / (pos.height * h)  # x span over y span for equal scales
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_facecolor("#eef4fb")
        self._vertical, = ax.plot([], [], ls="--", lw=0.8, color="#9aa8b8", zorder=1)
        self._rigid, = ax.plot([], [], ls=":", lw=0.8, color="#7a7a7a", zorder=2)
        self._body = Polygon(np.zeros((3, 2)), closed=True, facecolor="#d9dde3", edgecolor="#2b2f36",
                             lw=1.2, alpha=0.9, zorder=3)
        ax.add_patch(self._body)
        self._centre, = ax.plot([], [], lw=0.8, color="#c0392b", zorder=4)
        self._nozzle = Polygon(np.zeros((3, 2)), closed=True, facecolor="#555b66", edgecolor="#22252a",
                               lw=0.8, zorder=4)
        ax.add_patch(self._nozzle)
        self._gimbal, = ax.plot([], [], "o", ms=3, color="#22252a", zorder=6)
        self._thrust = ax.annotate("", xy=(0, 0), xytext=(0, 0), zorder=5,
                                   arrowprops=dict(arrowstyle="-|>", color="#e67e22", lw=2.0))
        self._rods = LineCollection([], colors="#1f4e79", linewidths=1.4, zorder=6)
        ax.add_collection(self._rods)
        self._discs = PatchCollection([], facecolor="#2e86c1", edgecolor="#1b4f72", lw=0.8, zorder=7)
        ax.add_collection(self._discs)
        self._idle = PatchCollection([], facecolor="none", edgecolor="#1f4e79", lw=0.6, alpha=0.35, zorder=7)
        ax.add_collection(self._idle)
        self._wind = ax.annotate("", xy=(0.86, 0.84), xytext=(0.86, 0.84), xycoords="axes fraction",
                                 textcoords="axes fraction",
                                 arrowprops=dict(arrowstyle="-|>", color="#16a085", lw=2.0))
        self._wind_txt = ax.text(0.86, 0.79, "", transform=ax.transAxes, ha="center", va="top",
                                 fontsize=fs * 0.9, color="#0e6655")
        self._head = ax.text(0.02, 0.98, "", transform=ax.transAxes, ha="left", va="top", fontsize=fs,
                             family="monospace", linespacing=1.3)
        self._bend = ax.text(0.02, 0.02, "", transform=ax.transAxes, ha="left", va="bottom",
                             fontsize=fs, color="#c0392b")
        self._lines = {n: ch.plot([], [], lw=1.2, color=c, label=n)[0]
                       for c, n in (("#7d3c98", "roll"), ("#c0392b", "pitch"), ("#2874a6", "yaw"))}
        ch.axhline(0.0, color="#999999", lw=0.6)
        ch.set_title("body rates [deg/s]", fontsize=fs)
        ch.set_xlabel("t [s]", fontsize=fs)
        ch.tick_params(labelsize=fs * 0.85)
        ch.grid(True, lw=0.4, alpha=0.5)
        self._fs = fs

    def draw(self, frame: RenderFrame) -> None:
        """Update every artist from ``frame`` (no canvas draw)."""
        self._draw_vehicle(frame)
        self._draw_chart(frame)

    def _draw_vehicle(self, f: RenderFrame) -> None:
        """The side view: outline, centreline, nozzle and thrust, pendulums, wind and text (lengths in m)."""
        L = max(_num(f.length, 1.0), 1e-3)
        D = _num(f.diameter, L / 20.0)
        D = D if D > 0 else L / 20.0
        R = D / 2.0
        pitch = _num(f.pitch_deg, 0.0)
        p = math.radians(pitch)
        a = np.array([math.sin(p), math.cos(p)])       # nose direction
        n = np.array([math.cos(p), -math.sin(p)])      # +side: a turned clockwise by 90 deg
        # deflection on a dense grid, from the finite samples only
        s = np.linspace(0.0, -L, 81)
        st, de = _arr(f.stations), _arr(f.deflection)
        k = min(st.size, de.size)
        ok = np.isfinite(st[:k]) & np.isfinite(de[:k])
        defl = np.zeros_like(s)
        if ok.any():
            order = np.argsort(st[:k][ok])
            defl = np.interp(s, st[:k][ok][order], de[:k][ok][order])
        defl = defl * self._ex
        limit = 0.25 * L
        clipped = bool(np.any(np.abs(defl) > limit))
        defl = np.clip(defl, -limit, limit)
        c = (s[:, None] + 0.5 * L) * a + defl[:, None] * n  # centreline, mid-length at (0, 0)
        tang = np.gradient(c, s, axis=0)
        tang /= np.maximum(np.linalg.norm(tang, axis=1, keepdims=True), 1e-12)
        nrm = np.column_stack([tang[:, 1], -tang[:, 0]])

        def point(st_: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            """Centreline point, tangent (noseward) and +normal at station ``st_`` (extrapolated past the ends)."""
            i = 0 if st_ >= 0 else (-1 if st_ <= -L else None)
            if i is not None:
                t_, n_ = tang[i], nrm[i]
                return c[i] + (st_ - s[i]) * t_, t_, n_
            x = -st_
            xs = -s
            pt = np.array([np.interp(x, xs, c[:, 0]), np.interp(x, xs, c[:, 1])])
            t_ = np.array([np.interp(x, xs, tang[:, 0]), np.interp(x, xs, tang[:, 1])])
            t_ /= max(np.linalg.norm(t_), 1e-12)
            return pt, t_, np.array([t_[1], -t_[0]])

        nose = min(2.5 * D, 0.3 * L)
        x = np.clip(-s / nose, 0.0, 1.0)
        r = R * (1.0 - (1.0 - x) ** 2)
        left, right = c - r[:, None] * nrm, c + r[:, None] * nrm
        self._body.set_xy(np.vstack([right, left[::-1]]))
        self._centre.set_data(c[:, 0], c[:, 1])
        rigid = np.array([0.5 * L * a, -0.5 * L * a])
        self._rigid.set_data(rigid[:, 0], rigid[:, 1])
        span = 0.72 * L
        self._vertical.set_data([0.0, 0.0], [-span, span])
        # engine: nozzle exit turned by the gimbal angle about the gimbal point
        g = math.radians(_num(f.gimbal_deg, 0.0))
        gp, gt, gn = point(_num(f.gimbal_station, -L))
        thrust = math.cos(g) * gt + math.sin(g) * gn
        exit_dir, side = -thrust, np.array([thrust[1], -thrust[0]])
        ln = max(0.6 * D, 0.03 * L)
        ex = gp + ln * exit_dir
        self._nozzle.set_xy(np.array([gp + 0.18 * D * side, ex + 0.4 * D * side,
                                      ex - 0.4 * D * side, gp - 0.18 * D * side]))
        self._gimbal.set_data([gp[0]], [gp[1]])
        self._thrust.xy = tuple(ex + 0.02 * L * exit_dir)
        self._thrust.set_position(tuple(ex + 0.2 * L * exit_dir))
        # slosh pendulums: rod from the hinge, disc area ~ mass; rods shorter than 10 % of L are magnified
        hs, ls, angs, ms = (_arr(v) for v in (f.slosh_stations, f.slosh_lengths, f.slosh_angles_deg,
                                              f.slosh_masses))
        N = min(hs.size, ls.size, angs.size, ms.size)
        mmax = max((v for v in ms[:N] if math.isfinite(v) and v > 0), default=1.0)
        lmax = max((abs(v) for v in ls[:N] if math.isfinite(v)), default=0.0)
        mag = float(min(10, max(1, math.floor(0.1 * L / lmax)))) if lmax > 0 else 1.0
        segs, discs, idle = [], [], []
        for j in range(N):
            if not (math.isfinite(hs[j]) and math.isfinite(ls[j])):
                continue
            hp, ht, hn = point(hs[j])
            m = ms[j] if math.isfinite(ms[j]) else 0.0
            if m <= 0:
                idle.append(Circle(tuple(hp), 0.25 * R))
                continue
            th = math.radians(_num(angs[j], 0.0))
            tip = hp - mag * abs(ls[j]) * (math.cos(th) * ht + math.sin(th) * hn)
            segs.append([tuple(hp), tuple(tip)])
            discs.append(Circle(tuple(tip), max(0.25, 0.85 * math.sqrt(m / mmax)) * R))
        self._rods.set_segments(segs)
        self._discs.set_paths(discs)
        self._idle.set_paths(idle)
        # wind arrow (axes fraction), length grows with speed up to 20 m/s, pointing where the air moves
        wx, wy = (_num(v, 0.0) for v in (tuple(f.wind_mps) + (0.0, 0.0))[:2])
        speed = math.hypot(wx, wy)
        base = np.array([0.86, 0.84])
        if speed > 1e-6:
            tail = base - 0.08 * min(speed / 10.0, 2.0) * np.array([wx, wy]) / speed
            self._wind.xy, self._wind.xyann = tuple(base), tuple(tail)
            self._wind.arrow_patch.set_visible(True)
        else:
            self._wind.arrow_patch.set_visible(False)
        self._wind_txt.set_text(f"wind {speed:.1f} m/s")
        t = _num(f.t, float("nan"))
        model = f"  [{f.model}]" if f.model else ""
        ended = f"\nENDED: {f.termination}" if f.termination else ""
        self._head.set_text(f"t = {t:7.2f} s  {f.stage}{model}\n{f.info}\n"
                            f"pitch {pitch:+6.2f} deg  gimbal {math.degrees(g):+5.2f} deg{ended}")
        bend = (f"bending x{self._ex:g}" + (" (clipped)" if clipped else "")) if f.bending else ""
        slosh = f"slosh rods x{mag:g}" if mag > 1 and N else ""
        self._bend.set_text("\n".join(x for x in (bend, slosh) if x))
        sx, sy = span * max(1.0, self._xy_ratio), span * max(1.0, 1.0 / self._xy_ratio)
        self.ax.set_xlim(-sx, sx)
        self.ax.set_ylim(-sy, sy)

    def _draw_chart(self, f: RenderFrame) -> None:
        """The strip chart: the task's body rates [deg/s] against t [s], symmetric 1-2-5 limits."""
        tt = _arr(f.rates_t)
        cols = ("roll", "pitch", "yaw") if np.ndim(f.rates_degps) == 2 and np.shape(f.rates_degps)[1] == 3 \
            else ("pitch", "yaw")
        rr = _arr(f.rates_degps)
        rr = rr.reshape(-1, len(cols)) if rr.size % len(cols) == 0 else np.zeros((0, len(cols)))
        m = min(tt.size, rr.shape[0])
        tt, rr = tt[:m], rr[:m]
        shown = [n for n in f.rate_axes if n in cols] or list(cols)
        for name, line in self._lines.items():
            on = name in shown
            line.set_visible(on)
            line.set_label(name if on else "_" + name)
            line.set_data(tt, rr[:, cols.index(name)] if on else [])
        rr = rr[:, [cols.index(n) for n in shown]]
        self.chart.legend(loc="upper left", fontsize=self._fs * 0.85, frameon=False)
        ft = tt[np.isfinite(tt)]
        now = _num(f.t, 0.0)
        t0, t1 = (float(ft.min()), float(ft.max())) if ft.size else (now - 1.0, now)
        if t1 - t0 < 1.0:
            t0 = t1 - 1.0
        self.chart.set_xlim(t0, t1)
        fr = np.abs(rr[np.isfinite(rr)])
        lim = _nice_ceil(max(1.0, 1.1 * float(fr.max()) if fr.size else 1.0))
        self.chart.set_ylim(-lim, lim)

    def render_rgb(self, frame: RenderFrame) -> np.ndarray:
        """The picture of ``frame``: uint8 array of shape (height, width, 3)."""
        self.draw(frame)
        canvas = self.fig.canvas
        canvas.draw()
        img = np.asarray(canvas.buffer_rgba())[..., :3]
        h, w = self.size
        if img.shape[:2] != (h, w):  # float rounding of figsize * dpi: pad or crop to the exact size
            out = np.full((h, w, 3), 255, np.uint8)
            hh, ww = min(h, img.shape[0]), min(w, img.shape[1])
            out[:hh, :ww] = img[:hh, :ww]
            return out
        return img.copy()

    def close(self) -> None:
        """Release the figure's artists."""
        self.fig.clear()


class HumanViewer:
    """A pyplot window showing frames (``render_mode="human"``).

    On an interactive backend, :meth:`show` redraws the window and runs its event loop for 1 ms
    (``plt.pause(0.001)``); a window closed by the user is reopened at the next frame. On a
    non-interactive backend (Agg, e.g. a headless machine or ``MPLBACKEND=Agg``) nothing is shown:
    the frame is only drawn to the figure's canvas, without warnings or errors.
    """

    def __init__(self, exaggeration: float = 50.0, size: tuple[int, int] = (480, 640)) -> None:
        self._ex, self._size = exaggeration, size
        self._renderer: Renderer | None = None

    @staticmethod
    def interactive() -> bool:
        """Whether pyplot's backend can show windows."""
        import matplotlib.pyplot as plt
        return str(plt.get_backend()).lower() not in _NONINTERACTIVE

    def show(self, frame: RenderFrame) -> None:
        """Draw ``frame`` and, on an interactive backend, display it."""
        import matplotlib.pyplot as plt
        live = self.interactive()
        r = self._renderer
        if r is None or (live and not plt.fignum_exists(r.fig.number)):
            h, w = self._size
            if live:
                plt.ion()
            fig = plt.figure(figsize=(w / _DPI, h / _DPI), dpi=_DPI)
            if fig.canvas.manager is not None:
                fig.canvas.manager.set_window_title("lvgym")
            r = self._renderer = Renderer(self._ex, self._size, figure=fig)
        r.draw(frame)
        if live:
            r.fig.canvas.draw_idle()
            plt.pause(0.001)
        else:
            if not getattr(self, "_warned", False):
                import warnings
                warnings.warn(f"render_mode='human': matplotlib's backend {plt.get_backend()!r} cannot show a "
                              "window (a headless machine?); nothing is displayed. Use render_mode='rgb_array' "
                              "for images, or set MPLBACKEND to an interactive backend.", stacklevel=3)
                self._warned = True
            r.fig.canvas.draw()

    def close(self) -> None:
        """Close the window (if any)."""
        if self._renderer is not None:
            import matplotlib.pyplot as plt
            plt.close(self._renderer.fig)
            self._renderer = None


_local = threading.local()


def render_rgb(frame: RenderFrame, exaggeration: float = 50.0,
               size: tuple[int, int] = (480, 640)) -> np.ndarray:
    """The picture of ``frame`` (uint8 (H, W, 3)) from a :class:`Renderer` cached per thread and size."""
    cache: dict[tuple[int, int], Renderer] = _local.__dict__.setdefault("renderers", {})
    key = (int(size[0]), int(size[1]))
    r = cache.get(key)
    if r is None:
        r = cache[key] = Renderer(exaggeration, key)
    r.exaggeration = exaggeration
    return r.render_rgb(frame)


def example_frame() -> RenderFrame:
    """A made-up frame: an 8.5 m, 0.3 m vehicle at t = 21 s, first bending mode, two slosh pendulums."""
    L = 8.5
    st = np.linspace(0.0, -L, 41)
    x = -st / L
    defl = 0.008 * (np.cos(np.pi * x) + 0.35 * np.cos(2 * np.pi * x))
    rt = np.linspace(0.0, 21.0, 211)
    rates = np.column_stack([2.5 * np.exp(-rt / 8) * np.sin(2.1 * rt) + 0.3 * np.sin(0.4 * rt),
                             1.2 * np.exp(-rt / 12) * np.sin(1.3 * rt + 1.0)])
    return RenderFrame(t=21.0, length=L, diameter=0.3, pitch_deg=12.0, stations=st, deflection=defl,
                       slosh_stations=np.array([-3.6, -5.8]), slosh_lengths=np.array([0.35, 0.4]),
                       slosh_angles_deg=np.array([18.0, -10.0]), slosh_masses=np.array([14.0, 22.0]),
                       gimbal_station=-8.2, gimbal_deg=3.0, wind_mps=(12.0, 0.0), rates_t=rt,
                       rates_degps=rates, stage="stage 1", info="Mach 1.42  q 38.5 kPa")


@dataclass
class Args:
    """Command-line arguments (``lvgym render --help``)."""

    out: str = arg("render_example.png", positional=True)
    """the PNG file written"""
    exaggeration: float = arg(50.0, lo=0.0, hi=1e6)
    """bending deflection drawn this many times its size"""


def main(argv: list[str] | None = None) -> None:
    """``lvgym render [OUT.png]`` (``python -m lvgym.envs.render``): draw :func:`example_frame` to a PNG."""
    import matplotlib.image

    args = parse(Args, argv, "python -m lvgym.envs.render", "Draw the renderer's example frame (a made-up "
                 "8.5 m vehicle at t = 21 s, bending and two slosh pendulums) to a PNG.")
    matplotlib.image.imsave(args.out, Renderer(args.exaggeration).render_rgb(example_frame()))
    print(f"wrote {args.out} (matplotlib {matplotlib.__version__})")


if __name__ == "__main__":
    main()
