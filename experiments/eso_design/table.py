"""The margins table of an eso schedule on SMILE v1's nine design rows (probe.py's cached plants), the rules of
the shipped classical designs: rigid and non-rigid GM >= 6 dB, gain reduction <= -6 dB, |PM| >= 30 deg, closed
loop stable, bending gain-stabilised (<= -6 dB). esodesign.assess on its default grid (5,000 frequencies).

    python table.py [schedule.yaml]      (default: baselines/schedules/smile_eso.yaml)
"""
import sys, warnings
import numpy as np
import yaml
warnings.filterwarnings("ignore")
from probe import plants, ed
from lvgym.baselines.eso import load_schedule

P = plants(None)
doc = load_schedule(sys.argv[1] if len(sys.argv) > 1 else "smile_eso")
model = ed.input_model(0.02, 1, (15.0, 0.7))
print("| t [s] | observer | wc, zeta, wo | m, c | rigid GM up/down [dB], PM [deg] at [rad/s] | non-rigid GM up/down, PM at | slosh max [dB] | bending 1 [dB] | noise [%] | meets |")
print("|---:|---|---|---|---|---|---:|---:|---:|---|")
worst = []
for r in doc["rows"]:
    t = float(r["time_s"])
    p = P[t]
    kw = ed.row_design(r)
    filt = ed.RowFilter(r["notch"], 0.02) if r.get("notch") else None
    comp = ed.compensator(p["b0"], float(r["controller_bandwidth_radps"]), float(r["observer_bandwidth_radps"]), 0.02,
                          filt, model, **kw)
    a = ed.assess(comp, {"rigid": p["rigid"], "nonrigid": p["nonrigid"]}, p["modes"], p["sigma"], p["rl"])
    miss = []
    for k in ("rigid", "nonrigid"):
        m = a[k]
        if not m["closed_loop_stable"]:
            miss.append(f"{k} unstable")
        if m["gain_margin_db"] < 6.0 or m["gain_reduction_margin_db"] > -6.0:
            miss.append(f"{k} GM")
        if abs(m["phase_margin_deg"]) < 30.0:
            miss.append(f"{k} PM")
    bend = a["bending_db"][0] if a["bending_db"] else float("nan")
    if bend > -6.0:
        miss.append("bending")
    f = lambda m: (f"{m['gain_margin_db']:.1f} / {m['gain_reduction_margin_db']:.1f}, {m['phase_margin_deg']:.1f} at "
                   f"{m['gain_crossover_radps']:.2f}" + ("" if m["closed_loop_stable"] else " UNSTABLE"))
    print(f"| {t:g} | {kw['observer']}{' + notch' if filt else ''} | {r['controller_bandwidth_radps']:g}, {kw['zeta']:g}, {r['observer_bandwidth_radps']:g} | "
          f"{kw['stiffness']:.2f}, {kw['damping']:.2f} | {f(a['rigid'])} | {f(a['nonrigid'])} | {max(a['slosh_db'], default=-99):.1f} | "
          f"{bend:.1f} | {100 * a['noise_rate']:.1f} | {'yes' if not miss else 'NO: ' + ', '.join(miss)} |", flush=True)
