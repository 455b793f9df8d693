"""Accuracy against run time: what a time step, a sphere count, a number of periods buys (not a test).

Four studies, all through the public entry point ``doParticleShearSimulation`` (so the numbers
are those a user gets), run on a ``ProcessPoolExecutor`` (default 2 workers):

1. **Time-step convergence** of G′, G″ (both estimators: ``G_internal`` from the overall stress
   tensor, ``G_surface`` from the external forces) and of the peak overlap
   ``max(1 − d/(r_i + r_j))`` over transient contacts during the protocol, for
   ``time_step_factor`` = 8 … 1/8 (dt of the measurement relative to the reference time-step rule, docs/parameters.md; one seed gives
   the same initial packing for every factor), for the default crosslinked scene and for frictional
   spheres without links, with both integrators ("euler" = reference, "verlet").  Error against the
   finest run and against a Richardson extrapolation; observed order of convergence.  A coarse
   factor that trips the stability guard is recorded as "unstable".
   Along the way: the largest relative asymmetry ``|σ01 − σ10| / (|σ00| + |σ11|)`` of the overall
   stress tensor over all recorded steps, and the peculiar momentum of the mobile spheres
   ``|Σ m (v − γ̇ (y − Ly/2) e_x)|`` relative to the plate momentum scale ``Σ m · A·2πf·Ly/2``.
2. **Statistics**: mean and standard deviation over seeds of G′, G″ for N = 45 … 2,400 (cell
   500 × 500 µm, packing fraction 1.5, so radii shrink as 1/√N and dt with them) and for
   3 vs 6 excitation periods, with run times.
3. **Largest stable time step** per regime: bisection on ``time_step_factor`` (log scale) with the
   stability guard (:class:`particleShear.base.stability.SimulationInstabilityError`) as oracle,
   short runs (0.5 + 1 + 0.25 periods), each rebuilt from the same seed (same packing).
4. Tables (Markdown), JSON, CSV and a log-log plot drawn with matplotlib (extra ``[plot]``).

Peak overlap, momentum and the tensor history are read through a read-only hook: the study
runs ``doParticleShearSimulation`` with the simulation class replaced by a subclass whose
``createExperiment`` keeps the tensor history and wraps the installed stability guard in a
recorder (the guard is called by the ensemble after every force phase, with the pair
geometry ``ens._g`` of that step).  The recorder reads, never writes, so G is bit-identical
to a plain call (checked at start-up, see ``_self_check``).

Usage::

    python benchmarks/accuracy_study.py [--quick] [--out DIR] [--workers 2]
    python benchmarks/accuracy_study.py --out docs/accuracy_data            # regenerate docs/accuracy.md's data
    python benchmarks/accuracy_study.py --out docs/accuracy_data --replot   # redraw its accuracy.png from the JSON

``--quick`` (< 3 min on 2 cores) uses N = 45 scenes, four factors and fewer seeds; the full
study (~15–25 min on 2 cores) is what ``docs/accuracy.md`` reports.  Output in ``DIR``
(default ``./accuracy-study``, a scratch folder: the tracked ``docs/accuracy_data`` is written only
when named with ``--out``): ``accuracy_results.json``, ``convergence.csv``,
``statistics.csv``, ``stability.csv``, ``accuracy_tables.md`` and ``accuracy.png``.
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import concurrent.futures  # noqa: E402
import csv  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import particleShear.run.api as api  # noqa: E402
from particleShear.base.stability import SimulationInstabilityError  # noqa: E402
from particleShear.simulation.simulations import Simulation_interlocking_rheology  # noqa: E402

#: quiet, no drawing, full result — common to every run
BASE = dict(doDrawing=False, plotStress=False, verbose=False, return_result=True)
#: the two scenes of the convergence study (everything else: doParticleShearSimulation defaults)
SCENES = {
    "crosslinked": dict(),
    "frictional": dict(do_permanent_links=False, cut_lines=0),
}
#: regimes of the stable-time-step map (crosslinked default scene unless stated)
REGIMES = {
    "default crosslinked": dict(),
    "frictional spheres": dict(do_permanent_links=False, cut_lines=0),
    "amplitude 2.0": dict(theAmplitude=2.0),
    "packing fraction 2.5": dict(packing_fraction=2.5),
    "stiff E = 1e7 Pa": dict(Young_modulus_spheres=1e7),
    "mu = 1": dict(theMu=1.0),
    "low viscosity rv = 0.01": dict(relative_viscosity=0.01),
}


# ---------------------------------------------------------------------------------------------
# read-only recording hook
# ---------------------------------------------------------------------------------------------
class RunRecorder:
    """Wraps the stability guard; records peak overlap and peculiar momentum of the protocol.

    ``check(ens, step, phase, dt)`` is called by the ensemble after every force phase.  It first
    delegates to the wrapped guard (so a diverging run still raises), then, during the
    protocol only, reads the pair geometry of the step.
    """

    def __init__(self, inner):
        self.inner = inner
        self.min_ratio = math.inf      # smallest d/(r_i+r_j) of a transient contact
        self.p_max = 0.0               # largest |peculiar momentum| (mg·µm/s per m)
        self.p_first = None
        self.p_last = None
        self.n = 0
        self.mass = None               # total sphere mass (mg per m depth)

    def check(self, ens, step=None, phase=None, dt=None):
        if self.mass is None:
            self.mass = float(ens._a["m"].sum())
        if self.inner is not None:
            self.inner.check(ens, step=step, phase=phase, dt=dt)
        if phase != "protocol":
            return
        g = ens._g
        if g is not None and g.P:
            r = g.d / g.d0
            if g.trans is not None:
                r = r[g.trans]
            if r.size:
                self.min_ratio = min(self.min_ratio, float(r.min()))
        a = ens._a
        mob = ens._mobile_mask()
        m = a["m"] if mob is None else np.where(mob, a["m"], 0.0)
        rate = ens.shear_rate or 0.0
        px = float(m @ (a["xspeed"] - rate * (a["y"] - ens.size_y / 2)))
        py = float(m @ a["yspeed"])
        p = math.hypot(px, py)
        self.p_max = max(self.p_max, p)
        if self.p_first is None:
            self.p_first = (px, py)
        self.p_last = (px, py)
        self.n += 1


class _Hooks:
    recorder = None
    keep_tensors = False


class RecordingSimulation(Simulation_interlocking_rheology):
    """The simulation of ``doParticleShearSimulation`` plus the read-only hooks above."""

    def createExperiment(self, *args, **kwargs):
        exp = Simulation_interlocking_rheology.createExperiment(self, *args, **kwargs)
        if _Hooks.keep_tensors:
            exp.keep_tensor_history = True
        ens = self.theEnsemble
        _Hooks.recorder = RunRecorder(ens.stability_guard)
        ens.stability_guard = _Hooks.recorder
        return exp


api.Simulation_interlocking_rheology = RecordingSimulation


# ---------------------------------------------------------------------------------------------
# one run
# ---------------------------------------------------------------------------------------------
def run_case(job):
    """Run one job dict (``params`` for doParticleShearSimulation + bookkeeping); return a result dict."""
    params = dict(BASE, **job["params"])
    _Hooks.keep_tensors = bool(job.get("tensors", False))
    out = dict(job)
    t0 = time.perf_counter()
    try:
        r = api.doParticleShearSimulation(**params)
    except SimulationInstabilityError as e:
        out.update(status="unstable", wall=time.perf_counter() - t0, step=e.step, phase=e.phase,
                   suggested_dt=e.suggested_dt, reason=e.reason)
        return out
    rec = _Hooks.recorder
    out.update(status="ok", wall=time.perf_counter() - t0, wall_measurement=r.timings.get("protocol", 0.0)
               + r.timings.get("pre_equilibration", 0.0), wall_constitution=r.timings.get("constitution", 0.0),
               dt=r.dt, f=r.f, N_steps=r.N_steps,
               Gp_int=r.G_internal[0], Gpp_int=r.G_internal[1], Gp_surf=r.G_surface[0], Gpp_surf=r.G_surface[1],
               peak_overlap=(1 - rec.min_ratio) if math.isfinite(rec.min_ratio) else 0.0)
    A = params.get("theAmplitude", 0.2)
    if rec is not None and rec.n:
        # momentum scale: total mass × peak plate speed A·2πf·Ly/2 (Ly = 500 µm)
        scale = rec.mass * A * 2 * math.pi * r.f * 250.0
        out["momentum_max_rel"] = rec.p_max / scale
        out["momentum_drift_rel"] = math.hypot(rec.p_last[0] - rec.p_first[0], rec.p_last[1] - rec.p_first[1]) / scale
    T = r.series.get("tensors")
    if T is not None and len(T):
        al = T[:, 8]
        asym = np.abs(al[:, 0, 1] - al[:, 1, 0]) / (np.abs(al[:, 0, 0]) + np.abs(al[:, 1, 1]))
        out["symmetry_max"] = float(asym.max())
        out["symmetry_median"] = float(np.median(asym))
    return out


# ---------------------------------------------------------------------------------------------
# bisection of the largest stable factor
# ---------------------------------------------------------------------------------------------
def stable_factor(job):
    """Bisection (log₂) of the largest stable ``time_step_factor`` for one regime and integrator.

    Short runs (pre 0.5, 1 period, post 0.25), each from the same seed (same packing); the oracle is
    the stability guard.  Returns the bracket [stable, unstable] and every probe.
    """
    params = dict(job["params"], pre_periods=0.5, periods=1, post_periods=0.25)
    probes = []

    def probe(factor):
        res = run_case(dict(params=dict(params, time_step_factor=factor), ))
        probes.append(dict(factor=factor, status=res["status"], phase=res.get("phase"), step=res.get("step"),
                           peak_overlap=res.get("peak_overlap"), wall=res["wall"], reason=res.get("reason"),
                           dt0=res["dt"] / factor if res["status"] == "ok" else None))
        return res["status"] == "ok"

    lo, hi = None, None
    f = 1.0
    if probe(f):
        lo = f
        while hi is None and f < job.get("f_max", 256):
            f *= 4
            if probe(f):
                lo = f
            else:
                hi = f
    else:
        hi = f
        while lo is None and f > 1 / 64:
            f /= 4
            if probe(f):
                lo = f
            else:
                hi = f
    if lo is not None and hi is not None:
        for _ in range(job.get("bisections", 5)):
            mid = math.sqrt(lo * hi)
            if probe(mid):
                lo = mid
            else:
                hi = mid
    return dict(job, stable=lo, unstable=hi, probes=probes)


# ---------------------------------------------------------------------------------------------
# analysis
# ---------------------------------------------------------------------------------------------
QUANTITIES = ("Gp_int", "Gpp_int", "Gp_surf", "Gpp_surf", "peak_overlap")


def convergence_analysis(rows):
    """Per (scene, integrator, quantity): reference values, errors, observed order."""
    out = {}
    for (scene, integ) in sorted({(r["scene"], r["integrator"]) for r in rows}):
        sel = sorted([r for r in rows if r["scene"] == scene and r["integrator"] == integ and r["status"] == "ok"],
                     key=lambda r: r["factor"])
        if len(sel) < 3:
            continue
        fine = sel[0]
        res = {}
        for q in QUANTITIES:
            v = {r["factor"]: r[q] for r in sel}
            fs = sorted(v)
            h1, h2, h3 = fs[0], fs[1], fs[2]
            d12 = v[h2] - v[h1]
            d23 = v[h3] - v[h2]
            p3 = math.log(abs(d23 / d12)) / math.log(h2 / h1) if d12 and d23 else float("nan")
            if math.isfinite(p3) and 0.3 < p3 < 4:
                rich = v[h1] - d12 / ((h2 / h1) ** p3 - 1)
            else:
                rich = float("nan")
            errs = {f: abs(v[f] - v[h1]) / abs(v[h1]) if v[h1] else float("nan") for f in fs}
            pts = [(math.log(f), math.log(errs[f])) for f in fs[1:] if errs[f] > 0]
            slope = float("nan")
            if len(pts) >= 2:
                xs, ys = zip(*pts)
                slope = float(np.polyfit(xs, ys, 1)[0])
            res[q] = dict(values=v, finest=v[h1], richardson=rich, order_three_finest=p3, order_fit=slope,
                          rel_error_vs_finest=errs)
        out[f"{scene}/{integ}"] = dict(scene=scene, integrator=integ, finest_factor=fine["factor"], q=res)
    return out


def statistics_analysis(rows):
    groups = {}
    for r in rows:
        if r["status"] != "ok":
            continue
        groups.setdefault((r["scene"], r["N"], r["periods"]), []).append(r)
    out = []
    for (scene, N, P), rs in sorted(groups.items()):
        row = dict(scene=scene, N=N, periods=P, seeds=len(rs), wall_mean=float(np.mean([r["wall"] for r in rs])),
                   dt=rs[0]["dt"], N_steps=rs[0]["N_steps"])
        for q in ("Gp_int", "Gpp_int", "Gp_surf", "Gpp_surf"):
            x = np.array([r[q] for r in rs])
            row[q + "_mean"] = float(x.mean())
            row[q + "_std"] = float(x.std(ddof=1)) if len(x) > 1 else float("nan")
        out.append(row)
    return out


# ---------------------------------------------------------------------------------------------
# plot (matplotlib, log-log; extra [plot])
# ---------------------------------------------------------------------------------------------
COLORS = {("crosslinked", "euler"): "#c81e1e", ("crosslinked", "verlet"): "#f08c14",
          ("frictional", "euler"): "#1e3cc8", ("frictional", "verlet"): "#14aac8"}


def draw_plot(results, path):
    """Two log-log panels: relative error of G′ against wall time and against the time-step factor.

    Errors are relative to the finest time step of the same scene and integrator (both
    estimators: internal = solid line and circles, surface = dashed line and squares); crosses on
    the top edge mark factors stopped by the stability guard; the horizontal dotted lines are the
    seed-to-seed spread (std/mean of G′ internal at the convergence N); grey guides have slopes 1
    and 2.  Drawn with matplotlib on an Agg canvas (:func:`particleShear.plot.save_figure`).
    """
    from particleShear.plot import _figure, save_figure
    conv = results["convergence_rows"]
    ana = results["convergence"]
    stats = {(s["scene"], s["N"], s["periods"]): s for s in results["statistics"]}
    N0 = results["config"]["N_conv"]
    fig = _figure(12, 5.2)
    p1, p2 = fig.subplots(1, 2, sharey=True)
    for key, a in sorted(ana.items()):
        scene, integ = a["scene"], a["integrator"]
        col = COLORS.get((scene, integ), "black")
        rows = {float(r["factor"]): r for r in conv if r["scene"] == scene and r["integrator"] == integ
                and r["status"] == "ok"}
        for q, mk, ls, name in (("Gp_int", "o", "-", "G′ internal"), ("Gp_surf", "s", "--", "G′ surface")):
            e = {float(k): v for k, v in a["q"][q]["rel_error_vs_finest"].items() if v > 0}
            pts_f = sorted(e.items())
            pts_t = sorted((rows[f]["wall"], v) for f, v in e.items() if f in rows)
            label = f"{scene}, {integ}, {name}"
            if pts_t:
                p1.plot(*zip(*pts_t), color=col, marker=mk, ls=ls, mfc="white" if mk == "s" else col, label=label)
            if pts_f:
                p2.plot(*zip(*pts_f), color=col, marker=mk, ls=ls, mfc="white" if mk == "s" else col)
        bad = [float(r["factor"]) for r in conv if r["scene"] == scene and r["integrator"] == integ
               and r["status"] != "ok"]
        if bad:
            p2.plot(bad, [1.0] * len(bad), ls="none", marker="x", color=col, ms=8,
                    transform=p2.get_xaxis_transform(), clip_on=False)
    for scene in SCENES:
        s = stats.get((scene, N0, 3))
        if s and s["Gp_int_mean"] and math.isfinite(s["Gp_int_std"]):
            rel = s["Gp_int_std"] / abs(s["Gp_int_mean"])
            for p in (p1, p2):
                p.axhline(rel, color=COLORS[(scene, "euler")], ls=":", lw=1.5,
                          label=f"{scene}: seed spread (std/mean, N={N0})" if p is p1 else None)
    fs = np.array(sorted({float(r["factor"]) for r in conv}))
    errs = [v for a in ana.values() for q in ("Gp_int", "Gp_surf") for v in a["q"][q]["rel_error_vs_finest"].values()
            if v > 0]
    y1 = math.sqrt(min(errs) * max(errs)) if errs else 1e-2  # guides through the middle of the data (at f = 1)
    for order in (1, 2):
        p2.plot(fs, y1 * fs ** order, color="0.55", lw=1, ls=(0, (4, 4)))
        p2.annotate(f"slope {order}", (fs[-1], y1 * fs[-1] ** order), fontsize="small", color="0.4",
                    xytext=(-40, 0), textcoords="offset points")
    from matplotlib.ticker import NullFormatter
    walls = [r["wall"] for r in conv if r["status"] == "ok"]
    for p, ticks in ((p1, [v for v in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000)
                           if walls and min(walls) / 1.5 <= v <= max(walls) * 1.5]), (p2, list(fs))):
        p.set_xscale("log")
        p.set_yscale("log")
        p.set_xticks(ticks, [f"{v:g}" for v in ticks])
        p.xaxis.set_minor_formatter(NullFormatter())
        p.grid(True, which="both", color="0.9", lw=0.6)
    p1.set_xlabel("wall time of the run (s)")
    p2.set_xlabel("time_step_factor (dt / default rule)")
    p1.set_ylabel("relative error of G′ against the finest dt (–)")
    p1.set_title("Error of G′ against run time")
    p2.set_title("Error of G′ against time step")
    p1.plot([], [], ls="none", marker="x", color="0.3", label="× on the top edge: stopped by the stability guard")
    try:
        fig.legend(*p1.get_legend_handles_labels(), loc="outside lower center", ncol=3, fontsize="small")
    except ValueError:  # matplotlib < 3.7: no "outside" locations
        fig.legend(*p1.get_legend_handles_labels(), loc="lower center", ncol=3, fontsize="small")
    save_figure(fig, path, dpi=110)
    return fig


def replot(folder):
    """Redraw ``accuracy.png`` in ``folder`` from its ``accuracy_results.json`` (no simulation)."""
    with open(os.path.join(folder, "accuracy_results.json")) as fh:
        results = json.load(fh)
    path = os.path.join(folder, "accuracy.png")
    draw_plot(results, path)
    return path


# ---------------------------------------------------------------------------------------------
# tables
# ---------------------------------------------------------------------------------------------
def _g(x, fmt="{:.4g}"):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return fmt.format(x)


def tables(results):
    cfg = results["config"]
    L = []
    L.append(f"Command: `{cfg['command']}`  \nMachine: {cfg['machine']}; {cfg['workers']} worker processes; "
             f"total wall time {cfg['wall_total']:.0f} s.\n")
    L.append("### Time-step convergence (seed %d, N = %d)\n" % (cfg["seed"], cfg["N_conv"]))
    L.append("Wall time = whole call (constitution included, identical for every factor) with two runs in "
             "parallel. Peak overlap = max over the protocol of 1 − d/(r_i+r_j) over transient contacts. "
             "Asym. = max over all steps of |σ01−σ10|/(|σ00|+|σ11|) of the overall tensor. p_max = largest "
             "peculiar momentum of the mobile spheres / (Σm·A·2πf·Ly/2).\n")
    L.append("| scene | integrator | factor | dt (s) | steps | wall (s) | G′ int (Pa) | G″ int (Pa) | G′ surf (Pa) "
             "| G″ surf (Pa) | peak overlap | asym. | p_max |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in sorted(results["convergence_rows"], key=lambda r: (r["scene"], r["integrator"], -r["factor"])):
        if r["status"] != "ok":
            L.append(f"| {r['scene']} | {r['integrator']} | {r['factor']:g} | – | – | {r['wall']:.1f} | unstable: "
                     f"{r.get('phase')} step {r.get('step')} | | | | | | |")
            continue
        L.append(f"| {r['scene']} | {r['integrator']} | {r['factor']:g} | {r['dt']:.3g} | {r['N_steps']} | "
                 f"{r['wall']:.1f} | {r['Gp_int']:.2f} | {r['Gpp_int']:.2f} | {r['Gp_surf']:.2f} | "
                 f"{r['Gpp_surf']:.2f} | {r['peak_overlap']:.4f} | {_g(r.get('symmetry_max'), '{:.1e}')} | "
                 f"{_g(r.get('momentum_max_rel'), '{:.1e}')} |")
    L.append("")
    L.append("### Errors and observed order\n")
    L.append("Relative error against the finest factor; Richardson value from the three finest factors "
             "(only when their observed order lies in 0.3…4); p₃ = log₂ of the ratio of successive "
             "differences of the three finest; p_fit = least-squares slope of log error vs log factor.\n")
    fs = sorted({r["factor"] for r in results["convergence_rows"]}, reverse=True)
    head = "| scene / integrator | quantity | finest | Richardson | p₃ | p_fit | " + " | ".join(
        f"err @{f:g}" for f in fs) + " |"
    L.append(head)
    L.append("|" + "---|" * (6 + len(fs)))
    for key, a in sorted(results["convergence"].items()):
        for q in QUANTITIES:
            c = a["q"][q]
            e = c["rel_error_vs_finest"]
            cells = []
            for f in fs:
                fk = f if f in e else str(f)
                v = e.get(fk)
                cells.append("unstable" if v is None else (f"{v:.1e}" if v > 0 else "ref"))
            L.append(f"| {key} | {q} | {c['finest']:.4g} | {_g(c['richardson'])} | {_g(c['order_three_finest'], '{:.2f}')}"
                     f" | {_g(c['order_fit'], '{:.2f}')} | " + " | ".join(cells) + " |")
    L.append("")
    L.append("### Sample-to-sample spread (std over seeds)\n")
    L.append("| scene | N | periods | seeds | dt (s) | steps | wall/run (s) | G′ int mean ± std (Pa) | "
             "G″ int mean ± std | G′ surf mean ± std | G″ surf mean ± std | std/mean G′ int | std of mean G′ int |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for s in results["statistics"]:
        rel = s["Gp_int_std"] / abs(s["Gp_int_mean"]) if s["Gp_int_mean"] else float("nan")
        L.append(f"| {s['scene']} | {s['N']} | {s['periods']} | {s['seeds']} | {s['dt']:.3g} | {s['N_steps']} | "
                 f"{s['wall_mean']:.1f} | {s['Gp_int_mean']:.1f} ± {s['Gp_int_std']:.1f} | "
                 f"{s['Gpp_int_mean']:.1f} ± {s['Gpp_int_std']:.1f} | {s['Gp_surf_mean']:.1f} ± {s['Gp_surf_std']:.1f} | "
                 f"{s['Gpp_surf_mean']:.1f} ± {s['Gpp_surf_std']:.1f} | {rel:.1%} | "
                 f"{rel / math.sqrt(s['seeds']):.1%} |")
    L.append("")
    L.append("### Largest stable time step (bisection on time_step_factor, guard as oracle)\n")
    L.append("| regime | integrator | default dt (s) | largest stable factor | first unstable factor | "
             "margin (× default dt) | probes | failing phase: reason |")
    L.append("|---|---|---|---|---|---|---|---|")
    for b in results["stability"]:
        bad = [p for p in b["probes"] if p["status"] != "ok"]
        phases = sorted({f"{p['phase']}: {str(p.get('reason') or '')[:40]}" for p in bad})
        L.append(f"| {b['regime']} | {b['integrator']} | {_g(b.get('dt0'), '{:.3g}')} | {_g(b['stable'], '{:.3g}')} | "
                 f"{_g(b['unstable'], '{:.3g}')} | {_g(b['stable'], '{:.2g}')} | {len(b['probes'])} | "
                 f"{', '.join(phases) or '–'} |")
    L.append("")
    return "\n".join(L)


# ---------------------------------------------------------------------------------------------
# main
# ---------------------------------------------------------------------------------------------
def build_jobs(quick, seed):
    if quick:
        N_conv, factors = 45, (4, 2, 1, 0.5)
        stat_plan = [(45, 3, (1, 2, 3)), (150, 3, (1, 2)), (45, 6, (1, 2))]
        regimes = ["default crosslinked"]
        integrators_bisect = ("euler",)
        bis = 3
    else:
        N_conv, factors = 150, (8, 4, 2, 1, 0.5, 0.25, 0.125)
        stat_plan = [(45, 3, tuple(range(1, 11))), (150, 3, tuple(range(1, 9))), (600, 3, tuple(range(1, 5))),
                     (2400, 3, (1, 2, 3)), (150, 6, tuple(range(1, 9)))]
        regimes = list(REGIMES)
        integrators_bisect = ("euler", "verlet")
        bis = 5
    jobs = []
    for scene, sp in SCENES.items():
        for integ in ("euler", "verlet"):
            for f in factors:
                cost = (N_conv / 150) / f
                jobs.append(dict(kind="conv", scene=scene, integrator=integ, factor=f, tensors=True, cost=cost,
                                 params=dict(sp, N=N_conv, seed=seed, time_step_factor=f, integrator=integ)))
    if not quick:
        # a single frictional packing is chaotic in dt; its seed mean is what converges
        for f in (8, 4, 2, 1, 0.5):
            for s2 in (seed + 1, seed + 2):
                jobs.append(dict(kind="convseed", scene="frictional", integrator="euler", factor=f, seed=s2,
                                 cost=1 / f, params=dict(SCENES["frictional"], N=N_conv, seed=s2,
                                                         time_step_factor=f, integrator="euler")))
    for N, P, seeds in stat_plan:
        for scene, sp in SCENES.items():
            if N == 2400 and scene == "frictional":
                continue   # the N dependence is shown on the crosslinked default scene
            if P == 6 and scene == "frictional" and quick:
                continue
            for s in seeds:
                cost = (N / 150) ** 1.5 * (P + 3) / 6
                jobs.append(dict(kind="stat", scene=scene, N=N, periods=P, seed=s, cost=cost,
                                 params=dict(sp, N=N, periods=P, seed=s)))
    for name in regimes:
        for integ in integrators_bisect:
            jobs.append(dict(kind="bisect", regime=name, integrator=integ, cost=1.5, bisections=bis,
                             params=dict(REGIMES[name], seed=seed, integrator=integ,
                                         N=45 if quick else 150)))
    return jobs, N_conv


def _dispatch(job):
    if job["kind"] == "bisect":
        return stable_factor(job)
    return run_case(job)


def _self_check():
    """The hooks must not change the physics: a hooked run equals a plain one bit for bit."""
    kw = dict(BASE, N=20, do_permanent_links=False, cut_lines=0, relative_frequency=0.2, pre_periods=0.5,
              periods=1, post_periods=0.5, seed=7)
    hooked = run_case(dict(params=kw, tensors=True))
    api.Simulation_interlocking_rheology = Simulation_interlocking_rheology
    try:
        plain = api.doParticleShearSimulation(**kw)
    finally:
        api.Simulation_interlocking_rheology = RecordingSimulation
    assert (hooked["Gp_int"], hooked["Gpp_int"]) == tuple(plain.G_internal), "recording hook changed the run"
    assert (hooked["Gp_surf"], hooked["Gpp_surf"]) == tuple(plain.G_surface), "recording hook changed the run"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="small scenes, < 3 min on 2 cores")
    ap.add_argument("--out", default="accuracy-study",
                    help="output folder (created; default ./accuracy-study); --out docs/accuracy_data "
                         "regenerates the data of docs/accuracy.md")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1, help="seed of the convergence and bisection runs")
    ap.add_argument("--replot", action="store_true",
                    help="only redraw accuracy.png from OUT/accuracy_results.json (no simulation)")
    args = ap.parse_args(argv)
    if args.replot:
        print("wrote " + replot(args.out))
        return
    os.makedirs(args.out, exist_ok=True)
    t_start = time.perf_counter()
    _self_check()
    jobs, N_conv = build_jobs(args.quick, args.seed)
    jobs.sort(key=lambda j: -j["cost"])
    rows = []
    with concurrent.futures.ProcessPoolExecutor(args.workers) as ex:
        futs = {ex.submit(_dispatch, j): j for j in jobs}
        for k, fut in enumerate(concurrent.futures.as_completed(futs), 1):
            r = fut.result()
            rows.append(r)
            tag = r.get("scene") or r.get("regime")
            extra = (f"stable={r['stable']} unstable={r['unstable']}" if r["kind"] == "bisect"
                     else f"{r['status']} G'int={r.get('Gp_int', float('nan')):.2f} wall={r['wall']:.1f}s")
            print(f"[{k}/{len(jobs)} {time.perf_counter() - t_start:6.0f}s] {r['kind']} {tag} "
                  f"{r.get('integrator', '')} f={r.get('factor', '')} N={r.get('N', '')} "
                  f"P={r.get('periods', '')} seed={r.get('seed', '')}: {extra}", flush=True)
    conv_rows = [r for r in rows if r["kind"] == "conv"]
    stat_rows = [r for r in rows if r["kind"] == "stat"]
    seed_rows = [r for r in rows if r["kind"] == "convseed"] + [
        dict(r, seed=args.seed) for r in conv_rows if r["scene"] == "frictional" and r["integrator"] == "euler"]
    # the convergence runs at factor 1 are seed-`seed` members of the N_conv, 3-period statistics
    stab = [r for r in rows if r["kind"] == "bisect"]
    for b in stab:
        b["probes"].sort(key=lambda p: p["factor"])
        b["dt0"] = next((p["dt0"] for p in b["probes"] if p["dt0"]), None)
    results = dict(
        config=dict(command="python benchmarks/accuracy_study.py" + (" --quick" if args.quick else "")
                    + f" --out {args.out}",
                    quick=args.quick, seed=args.seed, N_conv=N_conv, workers=args.workers,
                    machine=f"{platform.machine()}, {os.cpu_count()} CPUs, Python {platform.python_version()}, "
                            f"NumPy {np.__version__}",
                    wall_total=time.perf_counter() - t_start),
        convergence_rows=conv_rows, convergence=convergence_analysis(conv_rows),
        statistics=statistics_analysis(stat_rows), statistics_rows=stat_rows, stability=stab,
        seed_mean_convergence=seed_mean_analysis(seed_rows))
    results["cheapest"] = cheapest_within(results, 0.01)
    with open(os.path.join(args.out, "accuracy_results.json"), "w") as fh:
        json.dump(results, fh, indent=1, default=float)
    _csv(os.path.join(args.out, "convergence.csv"), conv_rows,
         ("scene", "integrator", "factor", "status", "dt", "N_steps", "wall", "wall_measurement", "Gp_int", "Gpp_int",
          "Gp_surf", "Gpp_surf", "peak_overlap", "symmetry_max", "momentum_max_rel", "momentum_drift_rel", "phase",
          "step"))
    _csv(os.path.join(args.out, "statistics.csv"), stat_rows,
         ("scene", "N", "periods", "seed", "status", "dt", "N_steps", "wall", "Gp_int", "Gpp_int", "Gp_surf",
          "Gpp_surf", "peak_overlap", "momentum_max_rel"))
    _csv(os.path.join(args.out, "stability.csv"),
         [dict(regime=b["regime"], integrator=b["integrator"], **p) for b in stab for p in b["probes"]],
         ("regime", "integrator", "factor", "status", "phase", "step", "reason", "peak_overlap", "wall"))
    md = tables(results) + "\n" + seed_mean_text(results["seed_mean_convergence"]) + "\n" + cheapest_text(
        results["cheapest"])
    with open(os.path.join(args.out, "accuracy_tables.md"), "w") as fh:
        fh.write(md)
    draw_plot(results, os.path.join(args.out, "accuracy.png"))
    print(md)
    print(f"done in {time.perf_counter() - t_start:.0f} s; results in {args.out}")


def cheapest_within(results, tol):
    """Coarsest factor (cheapest run) such that it and every finer factor give G′ (both estimators)
    within ``tol`` of the converged value (Richardson extrapolation when available, else the finest run);
    None when even the second-finest factor is outside the band.
    """
    out = {}
    for key, a in results["convergence"].items():
        rows = {r["factor"]: r for r in results["convergence_rows"] if r["scene"] == a["scene"]
                and r["integrator"] == a["integrator"] and r["status"] == "ok"}
        best = None
        for f in sorted(rows):      # from fine to coarse: stop at the first factor outside the band
            r = rows[f]
            ok = True
            for q in ("Gp_int", "Gp_surf"):
                c = a["q"][q]
                ref = c["richardson"] if math.isfinite(c["richardson"]) else c["finest"]
                if abs(r[q] - ref) > tol * abs(ref):
                    ok = False
            if not ok:
                break
            if f > a["finest_factor"]:
                best = dict(factor=f, wall=r["wall"], dt=r["dt"])
        out[key] = best
    return out


def seed_mean_analysis(rows):
    """Mean ± std over seeds of G′/G″ per factor (frictional scene, euler), for factors run with > 1 seed."""
    out = []
    for f in sorted({r["factor"] for r in rows}, reverse=True):
        rs = [r for r in rows if r["factor"] == f and r["status"] == "ok"]
        if len(rs) < 2:
            continue
        row = dict(factor=f, seeds=sorted(r["seed"] for r in rs), wall=float(np.mean([r["wall"] for r in rs])))
        for q in ("Gp_int", "Gpp_int", "Gp_surf", "Gpp_surf"):
            x = np.array([r[q] for r in rs])
            row[q] = (float(x.mean()), float(x.std(ddof=1)))
        out.append(row)
    return out


def seed_mean_text(rows):
    if not rows:
        return ""
    L = ["### Frictional spheres: seed mean against the time step (euler, same seeds at every factor)\n",
         "| factor | seeds | wall/run (s) | G′ int | G″ int | G′ surf | G″ surf |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        L.append(f"| {r['factor']:g} | {','.join(map(str, r['seeds']))} | {r['wall']:.1f} | "
                 + " | ".join(f"{r[q][0]:.1f} ± {r[q][1]:.1f}" for q in ("Gp_int", "Gpp_int", "Gp_surf", "Gpp_surf"))
                 + " |")
    return "\n".join(L) + "\n"


def cheapest_text(ch):
    L = ["### Cheapest setting within 1 % of the converged G′ (both estimators, seed and N fixed)\n",
         "| scene / integrator | time_step_factor | dt (s) | wall (s) |", "|---|---|---|---|"]
    for key, b in sorted(ch.items()):
        if b is None:
            L.append(f"| {key} | none within 1 % | | |")
        else:
            L.append(f"| {key} | {b['factor']:g} | {b['dt']:.3g} | {b['wall']:.1f} |")
    return "\n".join(L) + "\n"


def _csv(path, rows, cols):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for r in rows:
            w.writerow([r.get(c, "") for c in cols])


if __name__ == "__main__":
    sys.exit(main())
