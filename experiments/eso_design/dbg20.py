import numpy as np, assisted as A
t = 20.0
for kappa in (1.0, 0.0):
    for wn, zeta, wo in ((5.2, 0.7, 8.0), (5.2, 0.5, 11.0), (3.0, 0.7, 6.0), (1.0, 0.7, 4.0)):
        a = A.evaluate(t, wn, zeta, wo / wn, kappa)
        g = A.stable(t, wn, zeta, wo / wn, kappa)
        f = lambda x: f"{x['gain_margin_db']:.1f}/{x['gain_reduction_margin_db']:.1f} {x['phase_margin_deg']:.1f}@{x['gain_crossover_radps']:.2f} {np.round(x['crossovers_radps'],2)}"
        print(kappa, wn, zeta, wo, f"{A.score(a):.2f}", f(a['rigid']), f(a['nonrigid']), g, flush=True)
