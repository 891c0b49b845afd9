"""Side-by-side: assisted.py's closed-form compensator response against esodesign.compensator's."""
import numpy as np, time
import assisted as A
from lvgym.baselines.design.lqg_row import response
t = 20.0; p = A.P[t]; m, c = A.stiffness(p)
for kappa in (0.0, 1.0):
    wn, zeta, wo = 2.0, 0.7, 6.0
    t0 = time.time()
    cr = A.comp_response(p["b0"], kappa * m, kappa * c, wn * wn - kappa * m, 2 * zeta * wn - kappa * c, wo)
    t1 = time.time()
    comp = A.ed.compensator(p["b0"], wn, wo, A.DT, None, A.ed.input_model(A.DT, 1, (15.0, 0.7)), stiffness=kappa * m,
                            damping=kappa * c, kp=wn * wn - kappa * m, kd=2 * zeta * wn - kappa * c)
    r2 = response(comp, A.W)
    print(kappa, np.max(np.abs(cr - r2) / np.abs(r2)), f"{t1-t0:.3f} s, control {time.time()-t1:.3f} s")
