"""An independent xNES in numpy/scipy, transcribed from the pseudo-code of Glasmachers et al.
(GECCO 2010), to cross-check trm-optim's xNES: median evaluations to 1e-8 over 11 runs in 10-D
from the same starts (1,...,1; Rosenbrock 0,...,0) and sigma0 = 0.5 as `cargo xtask optimise`.
Uses scipy.linalg.expm. Run: /tmp/cmaenv/bin/pip install scipy; /tmp/cmaenv/bin/python benches/pycma/xnes_reference.py
"""
import numpy as np, scipy.linalg, statistics, sys
def xnes(f, x0, sigma0, target=1e-8, maxevals=100000, seed=0):
    rng = np.random.default_rng(seed)
    d = len(x0); lam = 4 + int(3*np.log(d))
    u = np.array([max(0, np.log(lam/2+1) - np.log(k)) for k in range(1, lam+1)]); u = u/u.sum() - 1/lam
    eta = 3*(3+np.log(d))/(5*d*np.sqrt(d))
    mu = np.array(x0, float); sigma = sigma0; B = np.eye(d); evals = 0; best = np.inf
    while evals < maxevals:
        Z = rng.standard_normal((lam, d)); X = mu + sigma * Z @ B.T
        fit = np.array([f(x) for x in X]); evals += lam; best = min(best, fit.min())
        if best <= target: return evals
        order = np.argsort(fit); Zs = Z[order]
        Gd = u @ Zs; GM = (Zs.T * u) @ Zs; Gs = np.trace(GM)/d; GB = GM - Gs*np.eye(d)
        mu = mu + sigma * B @ Gd; sigma *= np.exp(eta/2*Gs); B = B @ scipy.linalg.expm(eta/2*GB)
    return None
def ell(x):
    d=len(x); return sum(10**(6*i/(d-1))*x[i]**2 for i in range(d))
fs = {"sphere": (lambda x: float(np.sum(x*x)), 1.0), "ellipsoid": (ell, 1.0),
      "rosenbrock": (lambda x: sum(100*(x[i+1]-x[i]**2)**2+(1-x[i])**2 for i in range(len(x)-1)), 0.0)}
for name,(f,x0) in fs.items():
    ev = [xnes(f, [x0]*10, 0.5, seed=s) for s in range(11)]
    ok = sorted(e for e in ev if e)
    print(name, len(ok), statistics.median(ok))
