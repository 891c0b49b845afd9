"""The margin records of a gs-pid-flex schedule as text: one log line per row (:func:`row_line`) and the
Markdown margin table written beside the schedule (:func:`margin_table`); :mod:`.flexdesign` designs
the schedule."""

from __future__ import annotations

import math
from typing import Any

__all__ = ["margin_table", "row_line"]


def _worst(row: dict[str, Any], model: str) -> dict[str, float]:
    """The worse of the pitch and yaw margins of ``model`` in a row."""
    ms = [row["margins"][f"{model}_{p}"] for p in ("pitch", "yaw")]
    return {"gm": min(m["gain_margin_db"] for m in ms), "gm_down": max(m["gain_reduction_margin_db"] for m in ms),
            "pm": min(abs(m["phase_margin_deg"]) for m in ms), "growth": max(m["max_pole_real_per_s"] for m in ms),
            "noise": max((m["noise_rate_fraction"] for m in ms if "noise_rate_fraction" in m), default=float("nan"))}


def _mode_summary(row: dict[str, Any]) -> tuple[str, str, str]:
    slosh = [m["loop_gain_db"] for m in row["modes"] if m["mode"] == "slosh"]
    bend = [m for m in row["modes"] if m["mode"] == "bending"]
    s = f"{min(slosh):.1f} to {max(slosh):.1f}" if slosh else "-"
    b1 = f"{bend[0]['loop_gain_db']:.1f} ({bend[0]['stabilised']})" if bend else "-"
    hi = f"{max(m['loop_gain_db'] for m in bend[1:]):.1f}" if len(bend) > 1 else "-"
    return s, b1, hi


def _noise(r: dict[str, float], n: dict[str, float]) -> str:
    """The gimbal rate the gyro's noise commands [% of the rate limit, RMS], the worse loop, or '-' where
    not computed."""
    x = max(r["noise"], n["noise"]) if math.isfinite(r["noise"]) and math.isfinite(n["noise"]) else float("nan")
    return f"{100 * x:.1f}" if math.isfinite(x) else "-"


def _meets(row: dict[str, Any]) -> str:
    """'yes', or 'NO' and the requirements missed (where the record lists them)."""
    if row["meets"]:
        return "yes"
    return "NO" + (f" ({', '.join(row['misses'])})" if row.get("misses") else "")


#: the unit of each load objective's measure (:mod:`.loadobjective`)
LOAD_UNITS = {"qalpha": "Pa deg", "accel": "m/s^2"}


def _load(row: dict[str, Any]) -> str:
    """The row's load measure with the objective and the plain design's (``-`` in an end line)."""
    ld = row.get("load")
    return "-" if ld is None else f"{ld['value']:.4g} ({ld['plain']:.4g})"


def row_line(row: dict[str, Any]) -> str:
    r, n = _worst(row, "rigid"), _worst(row, "nonrigid")
    s, b1, hi = _mode_summary(row)
    ld = row.get("load")
    load = "" if ld is None else (f"  {ld['objective']} {ld['value']:.4g} {LOAD_UNITS[ld['objective']]} (plain "
                                  f"{ld['plain']:.4g}), J {ld['J']:.4g} (plain {ld['J_plain']:.4g}), "
                                  f"accel_gain {row.get('accel_gain', 0.0):.3g}")
    return (f"t = {row['time_s']:5.1f} s  m = {row['mass_kg']:8.1f} kg  rigid GM {r['gm']:.1f}/{r['gm_down']:.1f} dB "
            f"PM {r['pm']:.1f} deg  non-rigid GM {n['gm']:.1f}/{n['gm_down']:.1f} dB PM {n['pm']:.1f} deg  "
            f"slosh {s} dB  bending 1 {b1} dB  higher {hi} dB  growth {max(r['growth'], n['growth']):.3f} 1/s  "
            f"noise {_noise(r, n)} %  meets: {_meets(row)}" + load)


def margin_table(doc: dict[str, Any]) -> str:
    """The schedule's margins as a Markdown table (worse of pitch and yaw per row)."""
    def fmt(x: float) -> str:
        return "none" if not math.isfinite(x) or abs(x) >= 99 else f"{x:.1f}"

    obj = (doc.get("design") or {}).get("load_objective")
    lines = [f"# gs-pid-flex margins: {doc['vehicle']} (protocol {doc['protocol']})", "",
             f"Requirements: {doc['requirements']}. Each row's controller flies from the midpoint to the row "
             "before to the midpoint to the row after (its 'end' lines: the same controller on the plants there). "
             "Margins are the worse of pitch and yaw; 'down' is the gain "
             "reduction that destabilises a conditionally stable loop; mode columns are the non-rigid pitch loop's "
             "gain [dB] at the mode ('gain': at least the attenuation below 0 dB; 'phase': inside the loop, held by "
             "the non-rigid margins); noise: the RMS of the gimbal rate the flight gyro's white noise commands "
             "[% of the servo's rate limit], the worse loop (baselines/design/noise.py); 'meets': yes, or NO and the "
             "requirements missed." + ("" if obj is None else
                                       f" Load: the load objective's measure, {obj} [{LOAD_UNITS[obj]} RMS in 1 m/s of "
                                       "lateral Dryden turbulence], of the row's design (and of its plain design, "
                                       "without load relief; baselines/design/loadobjective.py)."), "",
             "| t [s] | mass [kg] | kp | ki | kd | rigid GM up/down [dB] | rigid PM [deg] | non-rigid GM up/down [dB] "
             "| non-rigid PM [deg] | slosh gain [dB] | bending 1 [dB] | higher bending [dB] | noise [%] | meets |"
             + ("" if obj is None else " load (plain) |"),
             "|---:|---:|---:|---:|---:|---|---:|---|---:|---|---|---:|---:|---|" + ("" if obj is None else "---:|")]
    for line in doc["rows"]:
        for kind, row in [("row", line)] + [("end", e) for e in line.get("ends", [])]:
            r, n = _worst(row, "rigid"), _worst(row, "nonrigid")
            s, b1, hi = _mode_summary(row)
            t = f"{row['time_s']:.1f}" + (" (end)" if kind == "end" else "")
            gains = (f"{row['kp']:.4f} | {row['ki']:.4f} | {row['kd']:.5f}" if kind == "row" else "same | | ")
            lines.append(f"| {t} | {row['mass_kg']:.0f} | {gains} | {fmt(r['gm'])} / {fmt(r['gm_down'])} | {fmt(r['pm'])} "
                         f"| {fmt(n['gm'])} / {fmt(n['gm_down'])} | {fmt(n['pm'])} | {s} | {b1} | {hi} | {_noise(r, n)} | "
                         f"{_meets(row)} |" + ("" if obj is None else f" {_load(row)} |"))
    return "\n".join(lines) + "\n"
