"""Grid of (w_c, w_o) for eso on SMILE v1's rows: the worst margins over the rows (probe.py's plants)."""
import sys, warnings
import numpy as np
warnings.filterwarnings("ignore")
from probe import plants, ed, StructuralFilter

P = plants(None)
lp = 150.0
mode = sys.argv[1]
model = None if mode == "measured" else ed.input_model(0.02, 1, None if mode == "command" else (15.0, 0.7))
WC = [float(x) for x in sys.argv[2].split(",")]
R = [float(x) for x in sys.argv[3].split(",")]
for wc in WC:
    for r in R:
        wo = wc * r
        worst = []
        for t, p in P.items():
            comp = ed.compensator(p["b0"], wc, wo, 0.02, StructuralFilter(lowpass_radps=lp, lowpass_damping=0.5), model)
            a = ed.assess(comp, {"rigid": p["rigid"], "nonrigid": p["nonrigid"]}, p["modes"], p["sigma"], p["rl"],
                          w=np.logspace(-4, np.log10(157), 2500))
            worst.append((t, a["rigid"]["gain_margin_db"], abs(a["rigid"]["phase_margin_deg"]), a["rigid"]["closed_loop_stable"],
                          a["nonrigid"]["gain_margin_db"], abs(a["nonrigid"]["phase_margin_deg"]), a["nonrigid"]["closed_loop_stable"],
                          max(a["bending_db"]), a["noise_rate"]))
        w = np.array([x[1:] for x in worst], float)
        print(f"wc {wc:4.1f} wo {wo:5.1f}: rigid GM {w[:,0].min():5.1f} PM {w[:,1].min():5.1f} stable {int(w[:,2].sum())}/9 | "
              f"non GM {w[:,3].min():5.1f} PM {w[:,4].min():5.1f} stable {int(w[:,5].sum())}/9 | bend {w[:,6].max():5.1f} | noise {100*w[:,7].max():4.1f} %"
              + "  unstable non-rigid at " + ",".join(f"{x[0]:g}" for x in worst if not x[6]), flush=True)
