"""Y_bbr bias diagnosis: the EKF on the preprocessed log vs on the noise-free truth channels (all, one, all-but-one).

    PYTHONPATH=. python -m ekf.bias_diagnosis [SEED]   (~3 min; findings in ekf/OUTPUT_ERROR_NOTES.md)
"""
import sys, time, numpy as np
from dataclasses import replace
from ekf.estimate import REPO, data_from_trial, estimate, load_config
from ekf.reproduce import TRIALS
from ekf.filter import DERIVATIVES
cfg = load_config()
seed = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
for name, f in TRIALS.items():
    d = data_from_trial(REPO/"configs/trials"/f, cfg, seed=seed, workdir=f"/tmp/ekf-bias/{name.replace(' ','_')}_{seed}")
    tr = d.truth; m = d.meas
    T = {ch: np.interp(m.t, tr.t, getattr(tr, ch)) for ch in ("u","v","r","delta","n")}
    rows = {}
    def run(label, **over):
        mm = replace(m, **over)
        e = estimate(replace(d, meas=mm), cfg)
        err = e.errors_pct()
        rows[label] = err
    run("log")
    run("truth all", **T)
    for ch in ("u","v","r","delta","n"):
        run(f"truth {ch} only", **{ch: T[ch]})
        others = {k: v for k, v in T.items() if k != ch}
        run(f"truth but {ch}", **others)
    print(f"== {name} seed {seed}")
    print("%-16s" % "" + " ".join(f"{n:>7s}" for n in DERIVATIVES))
    for k, e in rows.items():
        print("%-16s" % k + " ".join(f"{e[n]:7.2f}" for n in DERIVATIVES), flush=True)
