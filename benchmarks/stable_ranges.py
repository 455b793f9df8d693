"""Largest value of each stiffness/viscosity parameter that the time-step rule still integrates stably.

The time-step rule (1.0.2's, ``particleShear.linkable.builders.time_steps_from_model``) does not
account for ``relative_viscosity``, ``interface_reenforcement_central``/``_tangential`` or
``relative_transversal_link_strength`` beyond a few halvings, and the constitution's step does not
follow ``time_step_factor``: past some value the explicit step diverges whatever the user does.
This script bisects (on a log scale) the largest value of each parameter, the others at their
defaults, for which runs of several seeds end with finite moduli; the validation's ranges
(``particleShear.run.validation``) are set below these values.

Run: ``python benchmarks/stable_ranges.py [--seeds 3] [--N 40]`` (a few minutes on one core).
"""
import argparse
import math
import warnings

from particleShear import doParticleShearSimulation
from particleShear.base.stability import SimulationInstabilityError

START = {"relative_viscosity": (1.0, 1e3), "interface_reenforcement_central": (1.0, 1e3),
         "interface_reenforcement_tangential": (1.0, 1e3), "relative_transversal_link_strength": (1.0, 1e3)}


def runs(name, value, seeds, N):
    for seed in range(1, seeds + 1):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = doParticleShearSimulation(N=N, doDrawing=False, plotStress=False, verbose=False, periods=3,
                                              pre_periods=0.5, seed=seed, return_result=True, **{name: value})
        except SimulationInstabilityError:
            return False
        if not all(math.isfinite(g) for g in list(r.G_surface) + list(r.G_internal)):
            return False
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--N", type=int, default=40)
    ap.add_argument("--steps", type=int, default=6, help="bisection steps on log10 (default 6)")
    a = ap.parse_args()
    for name, (lo, hi) in START.items():
        if not runs(name, lo, a.seeds, a.N):
            print(f"{name}: unstable already at {lo:g}")
            continue
        if runs(name, hi, a.seeds, a.N):
            print(f"{name}: stable up to at least {hi:g}")
            continue
        for _ in range(a.steps):
            mid = math.sqrt(lo * hi)
            lo, hi = (mid, hi) if runs(name, mid, a.seeds, a.N) else (lo, mid)
        print(f"{name}: stable at {lo:.3g}, diverges at {hi:.3g} ({a.seeds} seeds, N = {a.N})", flush=True)


if __name__ == "__main__":
    main()
