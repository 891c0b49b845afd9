"""Write baselines/schedules/smile_eso.yaml from the per-row choices of the searches (assisted.py, fine20.py,
reduced.py, fine_rate.py, filt56.py): per row the observer, (wc, zeta, wo), kappa (the share of the rigid pair's
stiffness and damping put into the observer's model) and the slosh notch. The rigid pair (m, c) of each row is
read from the row's rigid design plant (assisted.stiffness)."""
import sys
from pathlib import Path
import yaml
import assisted as A
from lvgym.baselines.design.esodesign import schedule_document

NOTCH = {"frequency_radps": 9.0, "damping": 0.3, "depth": 0.3}
#        t:   observer,  wc,   zeta, wo,   kappa, notch
CHOICE = {3.0: ("attitude", 1.5, 0.5, 8.0, 0.5, None),     # perf2.py: the largest |L(1 rad/s)| of score >= 1.05
          10.0: ("attitude", 3.07, 0.3, 8.0, 1.0, None),   # whose rigid closed-loop poles (0.3-30 rad/s) are damped
          20.0: ("attitude", 3.9, 0.5, 6.0, 1.0, None),    # at zeta >= 0.3 (10 s: zeta 0.3, its 0.5 has 5.4 dB non-rigid)
          28.8: ("attitude", 3.07, 0.5, 6.0, 1.0, None),
          36.0: ("attitude", 1.91, 0.7, 8.0, 1.0, None),
          41.0: ("attitude", 1.91, 0.5, 16.0, 1.0, None),
          56.0: ("rate", 0.4, 1.4, 30.0, 1.0, NOTCH),        # filt56.py: the rate-fed ESO with the slosh notch
          62.0: ("rate", 0.4, 0.7, 22.0, 1.0, NOTCH),
          68.0: ("rate", 0.4, 0.7, 11.0, 1.0, NOTCH)}


def rows(choice):
    out = []
    for t, (obs, wc, zeta, wo, kappa, notch) in choice.items():
        m, c = A.stiffness(A.P[t])
        r = {"time_s": t, "observer": obs, "controller_bandwidth_radps": wc, "controller_damping": zeta,
             "observer_bandwidth_radps": wo, "stiffness_per_s2": round(float(kappa * m), 4), "damping_per_s": round(float(kappa * c), 4)}
        if notch:
            r["notch"] = dict(notch)
        out.append(r)
    return out


if __name__ == "__main__":
    path = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "baselines/schedules/smile_eso.yaml"
    doc = schedule_document(rows(CHOICE))
    head = ("# eso schedule of smile, written by experiments/eso_design/make_schedule.py (esodesign.schedule_document);\n"
            "# bandwidths [rad/s], stiffness and control power [1/s^2], damping [1/s]; margins: docs/eso.md.\n")
    path.write_text(head + yaml.safe_dump(doc, sort_keys=False, width=120, default_flow_style=None))
    print(path)
