"""Per-row search of (w_c, w_o) for eso on SMILE v1 (probe.py's plants; the servo in the observer's input model):
the pair of the largest worst-case ratio to the rules (GM / 6 dB, |PM| / 30 deg, rigid and non-rigid, both stable)."""
import sys, warnings
import numpy as np
warnings.filterwarnings("ignore")
from probe import plants, ed

P = plants(None)
model = ed.input_model(0.02, 1, (15.0, 0.7))
w = np.logspace(-4, np.log10(157), 2500)
times = [float(x) for x in sys.argv[1].split(",")]
for t in times:
    p = P[t]
    best = None
    for wc in (0.6, 0.8, 1.0, 1.3, 1.6, 2.0, 2.5):
        for r in (2.5, 3.0, 4.0, 5.0, 6.5, 8.0):
            comp = ed.compensator(p["b0"], wc, wc * r, 0.02, None, model)
            a = ed.assess(comp, {"rigid": p["rigid"], "nonrigid": p["nonrigid"]}, p["modes"], p["sigma"], p["rl"], w=w)
            ok = a["rigid"]["closed_loop_stable"] and a["nonrigid"]["closed_loop_stable"]
            score = min(min(a[k]["gain_margin_db"] / 6.0, abs(a[k]["phase_margin_deg"]) / 30.0) for k in ("rigid", "nonrigid")) if ok else -1
            if best is None or score > best[0]:
                best = (score, wc, wc * r, a)
    s, wc, wo, a = best
    f = lambda m: f"{m['gain_margin_db']:.1f}/{m['gain_reduction_margin_db']:.1f} dB {m['phase_margin_deg']:.1f} deg @{m['gain_crossover_radps']:.2f}"
    print(f"{t:5.1f} wc {wc:.2f} wo {wo:.2f} score {s:.2f} | rigid {f(a['rigid'])} | nonrigid {f(a['nonrigid'])} | slosh {max(a['slosh_db']):.1f} bend {max(a['bending_db']):.1f} | noise {100*a['noise_rate']:.2f} %", flush=True)
