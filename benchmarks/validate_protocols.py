"""Validation of the rheometer's protocols over seeds (docs/protocols.md, issue 23 item 6).

(a) crosslinked solid, small strain (γ₀ = 0.005), low frequency (f·τ = 0.0125): the relaxation
    plateau G, the creep inverse (σ₀ − σ_res)/γ(∞) of a creep that strains by about γ₀, and the
    oscillatory G′ agree within their seed errors (the paired differences are printed as well:
    same seed = same packing, same time step, same residual stress σ_res);
(b) uncrosslinked (yield-stress) packing: a creep above the flow curve's yield stress flows at the
    rate that the same packing's flow curve (steady runs to a strain of 10, log-log interpolation)
    gives for the stress the controller held while the creep rate was measured (and, reported, for σ₀);
(d) the steady stress at the oscillation's peak rate γ₀ω against the oscillatory amplitude |G*|γ₀
    (measured: |G*|γ₀ ≥ σ_steady(γ₀ω) at γ₀ = 0.3 — the steady stress is a lower, not an upper bound).

Every protocol runs as one run_batch of all seeds. Prints mean ± standard error over seeds, paired
differences in units of their standard error and PASS/FAIL (|z| ≤ 3; one-sided z ≥ −3 for (d)),
and wall time per run.

    python benchmarks/validate_protocols.py                  # N=150, 8 seeds (docs/protocols.md)
    python benchmarks/validate_protocols.py --quick          # the test's configuration: N=40, 4 seeds
"""
import argparse
import time
import warnings

import numpy as np

from particleShear.analysis.rheometry import plateau
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


def unpaired(a, b):
    """Difference of two seed means, its error from the two seed errors, and z."""
    (ma, sa), (mb, sb) = mse(a), mse(b)
    se = float(np.hypot(sa, sb))
    return ma - mb, se, (ma - mb) / se if se > 0 else np.inf


def agreement(name, a, b, zmax=3.0):
    """Equality of two moduli within their seed errors (unpaired z, the verdict) and, printed,
    the paired difference over the same seeds (which also resolves the path dependence)."""
    m, se, z = unpaired(a, b)
    pm, pse, pz = paired(a, b)
    ok = abs(z) <= zmax
    print(f"  {name:38s} diff {m:+.4g} ± {se:.2g}  z = {z:+.2f}  {'PASS' if ok else 'FAIL'}"
          f"   (paired: {pm:+.4g} ± {pse:.2g}, z = {pz:+.2f})")
    return ok


def part_a(base, seeds, gamma0, f, hold, times):
    """Crosslinked solid at small strain and low frequency: three moduli of one packing per seed.

    Every run has ``theAmplitude = γ₀`` (the time step follows the amplitude), so one seed is one
    packing with one time step and one pre-equilibration: the relaxation and the creep start from
    the same state and the same residual plate stress σ_res.  The creep stress of a seed is
    σ₀ = σ_res + G_plateau·γ₀ of its relaxation, so that it strains the solid by about γ₀; a seed
    whose σ₀ would be ≤ 0 (σ_res < −G_plateau·γ₀; a creep stress must be positive) is left out of
    the creep comparisons.
    """
    b = dict(base, do_permanent_links=True, relative_frequency=f, theAmplitude=gamma0)
    osc = timed("oscillatory (a)", [dict(b, seed=s) for s in seeds], times)
    rel = timed("relaxation (a)", [dict(b, seed=s, protocol="relaxation", ramp_time=1.0, hold_time=hold)
                                   for s in seeds], times)
    gp = np.array([r.G_surface[0] for r in osc])
    gpl = np.array([r.summary["G_plateau_surface"] for r in rel])
    res = np.array([r.summary["residual_stress"] for r in rel])
    s0 = res + gpl * gamma0
    use = s0 > 0
    cr = timed("creep (a)", [dict(b, seed=s, protocol="creep", creep_stress=float(x), hold_time=hold)
                             for s, x in zip(np.asarray(seeds)[use], s0[use])], times)
    same_start = all(r.summary["residual_stress"] == x for r, x in zip(cr, res[use]))
    # the solid creeps from its residual plate stress σ_res (step 0 at rest) to σ₀
    gc = np.array([(r.summary["creep_stress"] - r.summary["residual_stress"]) / r.summary["strain_plateau"]
                   for r in cr])
    print(f"(a) crosslinked, γ₀ = {gamma0}, f·τ = {f}, hold {hold} τ; creep σ₀ = σ_res + G_plateau·γ₀ on "
          f"{int(use.sum())} of {len(seeds)} seeds (σ_res of creep and relaxation equal: {same_start})")
    line("G' oscillatory (Pa)", gp)
    line("G_plateau relaxation (Pa)", gpl)
    line("(σ₀ − σ_res)/strain_plateau creep (Pa)", gc)
    line("creep strain_plateau / γ₀", np.array([r.summary["strain_plateau"] for r in cr]) / gamma0)
    line("creep largest strain / strain_plateau", np.array([r.series["strain"].max() / r.summary["strain_plateau"]
                                                            for r in cr]))
    line("creep stress_tracking (second half)", np.array([r.summary["stress_tracking"] for r in cr]))
    ok = [agreement("G_plateau - G' (equality)", gpl, gp),
          agreement("σ₀/γ(∞) - G' (equality)", gc, gp[use]),
          agreement("σ₀/γ(∞) - G_plateau (equality)", gc, gpl[use])]
    return all(ok) and same_start, dict(gp=gp, gpl=gpl, gc=gc, use=use, same_start=same_start)


def part_b_d(base, seeds, rates, strain, hold, gamma0, f, times):
    b = dict(base, do_permanent_links=False, relative_frequency=f, theAmplitude=gamma0)
    peak = gamma0 * 2 * np.pi * f           # γ₀ω·τ
    all_rates = sorted(set(rates) | {peak})
    st = timed("steady (b,d)", [dict(b, seed=s, protocol="steady", relative_rate=r, total_strain=strain)
                                for s in seeds for r in all_rates], times)
    sig = np.array([r.summary["stress_surface"] for r in st]).reshape(len(seeds), len(all_rates))
    mean = sig.mean(axis=0)
    print(f"(b) uncrosslinked flow curve, strain {strain}: relative_rate -> σ (Pa)")
    for j, r in enumerate(all_rates):
        line(f"γ̇τ = {r:.4g}", sig[:, j])
        early = []                    # the start-up: the mean stress over strains 0.2–1
        for i in range(len(seeds)):
            rec = st[i * len(all_rates) + j].series
            g = rec["strain"] - rec["strain"][0]
            early.append(rec["stress_surface"][(g >= 0.2) & (g < 1.0)].mean())
        line("   mean over strains 0.2–1", np.array(early))
    lr, ls = np.log(all_rates), np.log(mean)
    order = np.argsort(ls)
    # σ₀ = the mean stress at the second-highest rate: above the lowest-rate stress (≥ σ_y), and
    # inside every seed's measured curve (no extrapolation at the top)
    s0 = float(np.exp(ls[order][-2]))
    cr = timed("creep (b)", [dict(b, seed=s, protocol="creep", creep_stress=s0, hold_time=hold) for s in seeds],
               times)
    tau = cr[0].tau
    crate = np.array([r.summary["creep_rate"] for r in cr]) * tau
    # the plate stress the controller held while the creep rate was measured (the window of
    # creep_rate: the last 20 % of the hold)
    held = np.array([plateau(r.series["t"], r.series["stress_surface"], 0.2).mean for r in cr])

    def flow_rate(i, stress):      # seed i's own flow curve, log-log interpolated at a stress (paired)
        o = np.argsort(sig[i])
        return float(np.exp(np.interp(np.log(stress), np.log(sig[i][o]), lr[o])))

    seed_rate = np.array([flow_rate(i, s0) for i in range(len(seeds))])
    held_rate = np.array([flow_rate(i, h) for i, h in enumerate(held)])
    print(f"    creep σ₀ = {s0:.4g} Pa (the mean stress at γ̇τ = {np.exp(lr[order][-2]):.4g})")
    line("creep_rate·τ", crate)
    line("stress held over the rate window (Pa)", held)
    line("stress_tracking (second half)", np.array([r.summary["stress_tracking"] for r in cr]))
    line("(held − σ₀)/σ₀ (rate window)", (held - s0) / s0)
    line("flow-curve rate·τ at the held stress", held_rate)
    line("flow-curve rate·τ at σ₀", seed_rate)
    ok_b = verdict("log creep rate - log flow rate (held)", np.log(np.abs(crate) + 1e-300), np.log(held_rate))
    verdict("log creep rate - log flow rate (σ₀)", np.log(np.abs(crate) + 1e-300), np.log(seed_rate))

    osc = timed("oscillatory (d)", [dict(b, seed=s) for s in seeds], times)
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
    return ok_b, ok_d, dict(sig=sig, rates=all_rates, s0=s0, crate=crate, seed_rate=seed_rate, held=held,
                            held_rate=held_rate,
                            gstar=gstar, speak=speak)


def part_scan(base, seeds, gamma0, freqs, ramps, hold, times):
    """Why (a) is measured at low frequency, and how much the loading path moves a modulus.

    The crosslinked solid's G′ at γ₀ against f·τ (the plate stress settles over ≈ 30–100 τ after a
    step strain, so G′ reaches the relaxation plateau only at periods longer than that), and the
    relaxation plateau after ramps of different durations (paired over seeds: same packing).
    """
    b = dict(base, do_permanent_links=True, theAmplitude=gamma0)
    print(f"(scan) crosslinked, γ₀ = {gamma0}")
    for f in freqs:
        osc = timed(f"oscillatory f·τ={f}", [dict(b, seed=s, relative_frequency=f) for s in seeds], times)
        line(f"G' at f·τ = {f} (Pa)", np.array([r.G_surface[0] for r in osc]))
        line(f"G'' at f·τ = {f} (Pa)", np.array([r.G_surface[1] for r in osc]))
    gs = []
    for rt in ramps:
        rel = timed(f"relaxation ramp {rt}", [dict(b, seed=s, relative_frequency=freqs[1], protocol="relaxation",
                                                   ramp_time=rt, hold_time=hold) for s in seeds], times)
        gs.append(np.array([r.summary["G_plateau_surface"] for r in rel]))
        line(f"G_plateau, ramp {rt} τ (Pa)", gs[-1])
        th = rel[0].curves["G_surface"][0] / rel[0].tau
        G_t = np.array([r.curves["G_surface"][1] for r in rel])
        for t_ in (10.0, 30.0, 100.0):
            k = int(np.argmin(np.abs(th - t_)))
            line(f"   G(t ≈ {th[k]:.3g} τ)/G_plateau", G_t[:, k] / gs[-1])
    for rt, g in zip(ramps[1:], gs[1:]):
        m, se, z = paired(g, gs[0])
        print(f"  {'G_plateau(ramp ' + str(rt) + ') - G_plateau(ramp ' + str(ramps[0]) + ')':38s} "
              f"diff {m:+.4g} ± {se:.2g}  z = {z:+.2f}")
    big = 4 * gamma0                  # the softening with strain, at the two higher frequencies
    b4 = dict(b, theAmplitude=big)
    for f in freqs[:2]:
        osc = timed(f"oscillatory 4γ₀ f·τ={f}", [dict(b4, seed=s, relative_frequency=f) for s in seeds], times)
        line(f"G' at γ₀ = {big:g}, f·τ = {f} (Pa)", np.array([r.G_surface[0] for r in osc]))
    rel = timed("relaxation 4γ₀", [dict(b4, seed=s, relative_frequency=freqs[1], protocol="relaxation",
                                        ramp_time=ramps[0], hold_time=hold) for s in seeds], times)
    line(f"G_plateau at γ₀ = {big:g}, ramp {ramps[0]} τ (Pa)", np.array([r.summary["G_plateau_surface"] for r in rel]))


#: the two configurations: N = 150 (docs/protocols.md, "Validation") and the test's quick one
CONFIGS = {
    "full": dict(N=150, cut_lines=5, seeds=8, gamma0_a=0.005, f_a=0.0125, hold=200.0,
                 rates=(0.03, 0.05, 0.07, 0.1, 0.15, 0.2), strain=10.0),
    "quick": dict(N=40, cut_lines=0, seeds=4, gamma0_a=0.02, f_a=0.0125, hold=200.0,
                  rates=(0.03, 0.05, 0.1, 0.15), strain=5.0),
}


def _setup(config, seeds=None, N=None):
    """The configuration, its seeds and the run arguments every part shares."""
    c = dict(CONFIGS[config])
    if N is not None:
        c["N"] = N
    base = dict(N=c["N"], cut_lines=c["cut_lines"], pre_periods=0.2, periods=3, post_periods=0,
                doDrawing=False, verbose=False)
    return c, list(range(1, (seeds or c["seeds"]) + 1)), base


def run_all(config, seeds=None, N=None):
    """Parts (a), (b) and (d) in one configuration of :data:`CONFIGS`; returns the verdicts and figures."""
    c, seeds, base = _setup(config, seeds, N)
    times = {}
    ok_a, a = part_a(base, seeds, gamma0=c["gamma0_a"], f=c["f_a"], hold=c["hold"], times=times)
    ok_b, ok_d, bd = part_b_d(base, seeds, rates=c["rates"], strain=c["strain"], hold=c["hold"], gamma0=0.3,
                              f=0.05, times=times)
    return dict(ok_a=ok_a, ok_b=ok_b, ok_d=ok_d, a=a, bd=bd, times=times)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=None, help="number of seeds (default: the configuration's)")
    p.add_argument("--N", type=int, default=None, help="spheres (default: the configuration's)")
    p.add_argument("--quick", action="store_true", help="the test's configuration: N=40, uncut, 4 seeds")
    p.add_argument("--scan", action="store_true", help="only G' against frequency and G_plateau against the "
                   "ramp time of the crosslinked solid (why (a) is measured at low frequency)")
    a = p.parse_args(argv)
    warnings.simplefilter("ignore")
    t0 = time.perf_counter()
    if a.scan:
        c, seeds, base = _setup("quick" if a.quick else "full", a.seeds, a.N)
        part_scan(base, seeds, c["gamma0_a"], (0.05, 0.0125, 0.005), (1.0, 5.0), c["hold"], {})
        print(f"total {time.perf_counter() - t0:.0f} s")
        return
    out = run_all("quick" if a.quick else "full", a.seeds, a.N)
    print("wall time per run (s), whole batch / replicas:")
    for k, v in out["times"].items():
        print(f"  {k:20s} {v:.2f}")
    print(f"total {time.perf_counter() - t0:.0f} s; (a) {'PASS' if out['ok_a'] else 'FAIL'}, "
          f"(b) {'PASS' if out['ok_b'] else 'FAIL'}, (d) {'PASS' if out['ok_d'] else 'FAIL'}")


if __name__ == "__main__":
    main()
