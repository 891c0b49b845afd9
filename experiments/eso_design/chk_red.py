import numpy as np, reduced as R, assisted as A
from lvgym.baselines.design.lqg_row import response
t = 56.0; p = A.P[t]; m, c = A.stiffness(p)
for lp in (0, 40.0):
    filt = None if not lp else response(R.StructuralFilter(lowpass_radps=lp, lowpass_damping=0.7).tf(A.DT), A.W)
    cr = R.comp_response(p["b0"], m, c, 3 - m, 2.0, 6.0, filt)
    r2 = response(R.comp_ss(p["b0"], m, c, 3 - m, 2.0, 6.0, lp), A.W)
    print(lp, np.max(np.abs(cr - r2) / np.abs(r2)))
