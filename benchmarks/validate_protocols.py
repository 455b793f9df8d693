"""Validation of the rheometer's protocols over seeds (docs/protocols.md, issue 23 item 6).

(a) crosslinked solid, small strain: relaxation plateau G, σ₀/γ(∞) of a creep well below yield and
    the low-amplitude, low-frequency G′ agree (paired over seeds: same seed = same packing);
(b) uncrosslinked (yield-stress) packing: a creep above the flow curve's yield stress flows at the
    rate the flow curve (log-log interpolation of the seed means) gives for σ₀;
(d) the steady stress at the oscillation's peak rate γ₀ω against the oscillatory amplitude |G*|γ₀
    (measured: |G*|γ₀ ≥ σ_steady(γ₀ω) at γ₀ = 0.3 — the steady stress is a lower, not an upper bound).

Every protocol runs as one run_batch of all seeds. Prints mean ± standard error over seeds, paired
differences in units of their standard error and PASS/FAIL (|z| ≤ 3, one-sided z ≥ −3 for orders), and wall time per run.

    python benchmarks/validate_protocols.py --quick          # N=40, 4 seeds, short holds
    python benchmarks/validate_protocols.py --N 150 --seeds 6
"""
import argparse
import time
import warnings

import numpy as np

from particleShear.run.batch import run_batch


def mse(x):
    x = np.asarray(x, float)
    return x.mean(), x.std(ddof=1) / np.sqrt(len(x))


def paired(a, b):
    d = np.asarray(a, float) - np.asarray(b, float)
    m, se = mse(d)
    return m, se, m / se if se > 0 else np.inf


def timed(label, kws, times):
    t = time.perf_counter()
    out = run_batch(kws)
    times[label] = (time.perf_counter() - t) / len(kws)
    return out


def line(name, x):
    m, se = mse(x)
    print(f"  {name:38s} {m:10.4g} ± {se:.2g}   (seeds: {', '.join(f'{v:.4g}' for v in x)})")


def verdict(name, a, b, zmax=3.0):
    m, se, z = paired(a, b)
    ok = abs(z) <= zmax
    print(f"  {name:38s} diff {m:+.4g} ± {se:.2g}  z = {z:+.2f}  {'PASS' if ok else 'FAIL'}")
    return ok


def part_a(base, seeds, gamma0, f, hold, times):
    """Crosslinked solid at small strain: three moduli of one packing per seed."""
    b = dict(base, do_permanent_links=True, relative_frequency=f)
    osc = timed("oscillatory (a)", [dict(b, seed=s, theAmplitude=gamma0) for s in seeds], times)
    rel = timed("relaxation (a)", [dict(b, seed=s, protocol="relaxation", theAmplitude=gamma0, ramp_time=1.0,
                                        hold_time=hold) for s in seeds], times)
    gp = np.array([r.G_surface[0] for r in osc])
    gpl = np.array([r.summary["G_plateau_surface"] for r in rel])
    s0 = float(gamma0 * np.mean(gp))       # a stress that strains the solid by about γ₀
    cr = timed("creep (a)", [dict(b, seed=s, protocol="creep", creep_stress=s0, hold_time=hold) for s in seeds],
               times)
    # the solid creeps from its residual plate stress σ_res (step 0 at rest) to σ₀
    gc = np.array([(s0 - r.summary["residual_stress"]) / r.summary["strain_plateau"] for r in cr])
    print(f"(a) crosslinked, γ₀ = {gamma0}, f·τ = {f}, hold {hold} τ, creep σ₀ = {s0:.4g} Pa")
    line("G' oscillatory (Pa)", gp)
    line("G_plateau relaxation (Pa)", gpl)
    line("(σ₀ − σ_res)/strain_plateau creep (Pa)", gc)
    verdict("G_plateau - G' (equality)", gpl, gp)
    ok = [verdict("σ₀/γ(∞) - G' (equality)", gc, gp)]
    # linear viscoelasticity: G(t) ≤ 1/J(t) and both ≤ G'(ω): one-sided within 3 paired errors
    for name, hi, lo in (("σ₀/γ(∞) ≥ G_plateau", gc, gpl), ("G' ≥ σ₀/γ(∞)", gp, gc), ("G' ≥ G_plateau", gp, gpl)):
        m, se, z = paired(hi, lo)
        ok.append(z >= -3.0)
        print(f"  {name:38s} diff {m:+.4g} ± {se:.2g}  z = {z:+.2f}  {'PASS' if z >= -3.0 else 'FAIL'} (order)")
    return all(ok), dict(gp=gp, gpl=gpl, gc=gc)


def part_b_d(base, seeds, rates, strain, hold, gamma0, f, times):
    b = dict(base, do_permanent_links=False, relative_frequency=f)
    peak = gamma0 * 2 * np.pi * f           # γ₀ω·τ
    all_rates = sorted(set(rates) | {peak})
    st = timed("steady (b,d)", [dict(b, seed=s, protocol="steady", relative_rate=r, total_strain=strain)
                                for s in seeds for r in all_rates], times)
    sig = np.array([r.summary["stress_surface"] for r in st]).reshape(len(seeds), len(all_rates))
    mean = sig.mean(axis=0)
    print(f"(b) uncrosslinked flow curve, strain {strain}: relative_rate -> σ (Pa)")
    for j, r in enumerate(all_rates):
        line(f"γ̇τ = {r:.4g}", sig[:, j])
    # σ₀ between the two highest measured rates' mean stresses: above the lowest-rate stress (≥ σ_y)
    lr, ls = np.log(all_rates), np.log(mean)
    order = np.argsort(ls)
    s0 = float(np.exp(0.5 * (ls[order][-1] + ls[order][-2])))
    target = float(np.exp(np.interp(np.log(s0), ls[order], lr[order])))
    cr = timed("creep (b)", [dict(b, seed=s, protocol="creep", creep_stress=s0, hold_time=hold) for s in seeds],
               times)
    tau = cr[0].tau
    crate = np.array([r.summary["creep_rate"] for r in cr]) * tau
    # per seed: that seed's own flow curve interpolated at σ₀ (paired)
    seed_rate = []
    for i in range(len(seeds)):
        o = np.argsort(sig[i])
        seed_rate.append(float(np.exp(np.interp(np.log(s0), np.log(sig[i][o]), lr[o]))))
    print(f"    creep σ₀ = {s0:.4g} Pa; flow-curve rate (seed-mean curve) γ̇τ = {target:.4g}")
    line("creep_rate·τ", crate)
    line("flow-curve rate·τ at σ₀ (per seed)", seed_rate)
    ok_b = verdict("log creep rate - log flow rate", np.log(np.abs(crate) + 1e-300), np.log(seed_rate))

    osc = timed("oscillatory (d)", [dict(b, seed=s, theAmplitude=gamma0) for s in seeds], times)
    gstar = np.array([np.hypot(*r.G_surface) * gamma0 for r in osc])
    speak = sig[:, all_rates.index(peak)]
    print(f"(d) γ₀ = {gamma0}, f·τ = {f}: peak rate γ₀ω·τ = {peak:.4g}")
    line("|G*|·γ₀ oscillatory (Pa)", gstar)
    line("steady σ at γ₀ω (Pa)", speak)
    m, se, z = paired(gstar, speak)
    ok_d = z >= -3.0
    print(f"  {'|G*|γ₀ - σ_steady(γ₀ω)':38s} diff {m:+.4g} ± {se:.2g}  z = {z:+.2f}  "
          f"{'PASS' if ok_d else 'FAIL'} (measured relation: |G*|γ₀ ≥ σ_steady(γ₀ω))")
    line("ratio |G*|γ₀ / σ_steady(γ₀ω)", gstar / speak)
    return ok_b, ok_d, dict(sig=sig, rates=all_rates, s0=s0, crate=crate, seed_rate=np.array(seed_rate),
                            gstar=gstar, speak=speak)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=6)
    p.add_argument("--N", type=int, default=150)
    p.add_argument("--quick", action="store_true", help="N=40, 4 seeds, short holds")
    a = p.parse_args(argv)
    if a.quick:
        a.N, a.seeds = 40, 4
    seeds = list(range(1, a.seeds + 1))
    hold = 50.0 if a.quick else 200.0
    base = dict(N=a.N, cut_lines=0 if a.quick else 5, pre_periods=0.2, periods=3, post_periods=0,
                doDrawing=False, verbose=False)
    times = {}
    warnings.simplefilter("ignore")
    t0 = time.perf_counter()
    ok_a, _ = part_a(base, seeds, gamma0=0.02, f=0.05, hold=hold, times=times)
    # dense rates near the creep stress (the top of the curve): a log-log interpolation of a convex
    # curve between distant rates underestimates the rate at a given stress
    rates = (0.003, 0.01, 0.03) if a.quick else (0.003, 0.01, 0.03, 0.05, 0.07)
    ok_b, ok_d, _ = part_b_d(base, seeds, rates=rates, strain=1.0, hold=hold, gamma0=0.3,
                          f=0.05, times=times)
    print("wall time per run (s), whole batch / replicas:")
    for k, v in times.items():
        print(f"  {k:20s} {v:.2f}")
    print(f"total {time.perf_counter() - t0:.0f} s; (a) {'PASS' if ok_a else 'FAIL'}, "
          f"(b) {'PASS' if ok_b else 'FAIL'}, (d) {'PASS' if ok_d else 'FAIL'}")


if __name__ == "__main__":
    main()
