"""Slosh filters on the gyro for the rate-fed ESO in the upper stage (reduced.py): margins per filter."""
import sys, itertools, numpy as np, assisted as A, reduced as R
from lvgym.baselines.filters import StructuralFilter
from lvgym.baselines.design.lqg_row import response
t = float(sys.argv[1])
fl = [("none", None)]
for lp in (12.0, 18.0, 25.0):
    for z in (0.4, 0.7):
        fl.append((f"lp {lp} z {z}", StructuralFilter(lowpass_radps=lp, lowpass_damping=z)))
for wn_, zn, d in itertools.product((8.0, 9.0, 10.0, 11.0), (0.3, 0.6), (0.1, 0.3)):
    fl.append((f"notch {wn_} z {zn} d {d}", StructuralFilter(notch_radps=wn_, notch_damping=zn, notch_depth=d)))
for lz, lp_ in ((2.0, 6.0), (3.0, 9.0), (1.5, 4.5)):
    fl.append((f"lead {lz}/{lp_}", StructuralFilter(lead_zero_radps=lz, lead_pole_radps=lp_)))
f = lambda x: f"{x['gain_margin_db']:.1f}/{x['gain_reduction_margin_db']:.1f} {x['phase_margin_deg']:.1f}@{x['gain_crossover_radps']:.2f}"
res = []
for name, sf in fl:
    fr = None if sf is None else response(sf.tf(A.DT), A.W)
    for kappa, zeta, wn, wo in itertools.product((0.0, 1.0), (0.7, 1.0, 1.4), (0.4, 0.54, 0.8, 1.2), (11.0, 16.0, 22.0, 30.0)):
        a = R.evaluate(t, wn, zeta, wo, kappa, fr)
        res.append((A.score(a), name, kappa, zeta, wn, wo, a))
res.sort(key=lambda x: -x[0])
for s, name, kappa, zeta, wn, wo, a in res[:12]:
    print(f"{s:.2f} {name} kappa {kappa} zeta {zeta} wn {wn} wo {wo} | rig {f(a['rigid'])} | non {f(a['nonrigid'])}", flush=True)
