"""The spread over seeds of the quantities the verdicts bound (docs/analysis.md, "Verdicts").

For each scene it runs ``--seeds`` seeds and prints, per quantity, the smallest and largest value
and how many runs the current threshold passes:

* I₃/I₁ of the internal stress (``linear_response``, ≤ LINEAR_I3_I1),
* the estimators' spread max|ΔG|/max|G*| (``estimators_agree``, ≤ AGREEMENT_TOLERANCE),
* |G*|·γ₀ / baseline noise (``excitation_resolved``, ≥ SIGNAL_TO_NOISE_MIN).

Scenes: the default run at γ₀ = 0.01, 0.2 (default) and 1; N = 50 at f·τ = 0.1, γ₀ = 0.01 (the
estimators disagree); γ₀ = 1e-9 with half a baseline period (the excitation drowns in the noise).

Usage::

    python benchmarks/verdict_thresholds.py [--seeds 12]     # about 3 min per 12 seeds and scene on one core
"""
import argparse
import math
import warnings

from particleShear import doParticleShearSimulation
from particleShear.analysis import verdicts as vd

SCENES = {
    "default, A = 0.01": dict(theAmplitude=0.01),
    "default (A = 0.2)": dict(),
    "default, A = 1": dict(theAmplitude=1.0),
    "N = 50, f·τ = 0.1, A = 0.01": dict(N=50, relative_frequency=0.1, theAmplitude=0.01),
    "N = 50, A = 1e-9, pre_periods = 0.5": dict(N=50, theAmplitude=1e-9, pre_periods=0.5, post_periods=0),
}


def quantities(res):
    """(I3/I1 internal, agreement spread, signal to noise) of one result."""
    p = res.parameters
    moduli = {"surface": res.G_surface, "internal": res.G_internal}
    noise = {est: vd.baseline_noise(res.series["t"], res.series["stress_" + est], res.f, p["pre_periods"])
             for est in ("surface", "internal")}
    return (res.measures["I3_I1_internal"], vd.agreement_spread(moduli),
            vd.signal_to_noise(moduli, p["theAmplitude"], noise))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=12, help="seeds per scene (default 12)")
    args = ap.parse_args()
    rules = (("I3/I1 internal", lambda v: v <= vd.LINEAR_I3_I1, f"<= {vd.LINEAR_I3_I1}"),
             ("estimator spread", lambda v: v <= vd.AGREEMENT_TOLERANCE, f"<= {vd.AGREEMENT_TOLERANCE}"),
             ("signal/noise", lambda v: v >= vd.SIGNAL_TO_NOISE_MIN, f">= {vd.SIGNAL_TO_NOISE_MIN:g}"))
    print(f"{'scene':<38} {'quantity':<17} {'min':>9} {'max':>9}  passes")
    for name, kw in SCENES.items():
        values = []
        for seed in range(1, args.seeds + 1):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    res = doParticleShearSimulation(seed=seed, return_result=True, verbose=False, doDrawing=False,
                                                    plotStress=False, **kw)
                except Exception as exc:  # noqa: BLE001 - a scene that fails to run is reported, not fatal
                    print(f"{name:<38} seed {seed}: {type(exc).__name__}: {exc}")
                    continue
            values.append(quantities(res))
        for k, (q, ok, rule) in enumerate(rules):
            v = [x[k] for x in values if math.isfinite(x[k])]
            if not v:
                continue
            print(f"{name:<38} {q:<17} {min(v):9.3g} {max(v):9.3g}  {sum(map(ok, v))}/{len(v)} ({rule})")


if __name__ == "__main__":
    main()
