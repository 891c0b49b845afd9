"""Probe of eso's linear design: margins, mode gains and noise over (w_c, w_o, filter) at SMILE v1 rows."""
import pickle, sys, time
from pathlib import Path
import numpy as np
from lvgym.baselines.design import esodesign as ed
from lvgym.baselines.design.lqg_design import _op
from lvgym.baselines.design.linearize import reused_flights, rigid_terms
from lvgym.baselines.filters import StructuralFilter
from lvgym.baselines.design.flightloop import mode_frequencies
from lvgym.baselines.design.noise import gyro_noise

CACHE = Path(__file__).resolve().parents[2] / "results/eso_ops.pkl"

def plants(times):
    if CACHE.exists():
        import control
        return {t: {k: (control.ss(*v) if isinstance(v, tuple) else v) for k, v in p.items()} for t, p in pickle.loads(CACHE.read_bytes()).items()}
    out = {}
    with reused_flights():
        for t in times:
            opr = _op("smile", t, "rigid", 50.0)
            opn = _op("smile", t, "nonrigid", 50.0)
            terms = rigid_terms(opr)
            b0 = terms["vectored_thrust"] * terms["arm"] / terms["inertia"]
            sig, rl = gyro_noise(opn)
            out[t] = dict(b0=b0, rigid=ed.sampled_plant(opr), nonrigid=ed.sampled_plant(opn), modes=mode_frequencies(opn), sigma=sig, rl=rl)
    return out


def row(p, wc, wo, filt):
    comp = ed.compensator(p["b0"], wc, wo, 0.02, filt)
    a = ed.assess(comp, {"rigid": p["rigid"], "nonrigid": p["nonrigid"]}, p["modes"], p["sigma"], p["rl"])
    f = lambda m: f"{m['gain_margin_db']:5.1f}/{m['gain_reduction_margin_db']:6.1f} {m['phase_margin_deg']:6.1f}@{m['gain_crossover_radps']:5.2f}{'' if m['closed_loop_stable'] else ' UNST'}"
    return a, (f"rig {f(a['rigid'])} | non {f(a['nonrigid'])} | slosh {max(a['slosh_db'], default=-99):5.1f} "
               f"bend {', '.join(f'{x:.1f}' for x in a['bending_db'])} | noise {100*a['noise_rate']:5.1f} %")


if __name__ == "__main__":
    times = (3.0, 10.0, 20.0, 28.8, 36.0, 41.0, 56.0, 62.0, 68.0)
    t0 = time.time()
    P = plants(times)
    if not CACHE.exists():
        CACHE.parent.mkdir(exist_ok=True)
        CACHE.write_bytes(pickle.dumps({t: {k: ((v.A, v.B, v.C, v.D, v.dt) if hasattr(v, 'A') else v) for k, v in p.items()} for t, p in P.items()}))
    print(f"plants in {time.time()-t0:.0f} s; b0", {t: round(P[t]['b0'], 2) for t in times})
    wc, wo = float(sys.argv[1]), float(sys.argv[2])
    lp = float(sys.argv[3]) if len(sys.argv) > 3 else 150.0
    notch = sys.argv[4] if len(sys.argv) > 4 else "off"
    for t in times:
        p = P[t]
        bend = p["modes"]["bending"]
        kw = dict(lowpass_radps=lp, lowpass_damping=0.5)
        if notch != "off" and bend and bend[0] < 150:
            kw.update(notch_radps=bend[0], notch_damping=float(notch), notch_depth=0.05)
        filt = StructuralFilter(**kw)
        print(f"{t:5.1f} bend {bend[0]:6.1f}", row(p, wc, wo, filt)[1])
