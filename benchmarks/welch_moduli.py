"""G′ and G″ of the current tree against a baseline tree over many seeds: Welch's t per quantity (not a test).

Two scenes, each run with seeds 1 … ``--seeds`` (≥ 16) in both trees:

* default: ``doParticleShearSimulation(doDrawing=False, plotStress=False, saveData=False, seed=s)``
  (crosslinked particles, 5 cut lines, μ = 0.01, N = 150; 13,439 protocol steps);
* frictional: the frictional sphere packing of README.md and docs/accuracy.md
  (``do_permanent_links=False, cut_lines=0``, μ = 0.01 unless ``--mu``), otherwise the same call.

Quantities: G′ and G″ (Pa) of the surface estimator (plate forces) and of the internal one (overall
stress tensor, eq. S1-24), i.e. ``result.G_surface`` and ``result.G_internal``.  For each scene and
quantity the script prints the mean and standard error of the mean of each tree and Welch's
t = (m_c − m_b) / √(s_c²/n_c + s_b²/n_b) with its Welch–Satterthwaite degrees of freedom; a change of
the summation order may move single runs (a frictional packing is chaotic in dt, docs/accuracy.md),
but not their distribution: |t| < 3 is required.  It also counts the seeds whose four numbers are
bit-identical between the trees.

Runs execute in worker processes with ``PYTHONPATH`` set to the tree and one thread each,
``--workers`` (default 2) at a time; each worker runs a chunk of seeds of one tree and scene.

Usage: python benchmarks/welch_moduli.py [--baseline PATH] [--current PATH] [--seeds 16] [--workers 2] [--mu 0.01] [--drawn]
"""
import argparse
import concurrent.futures
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_BASELINE = os.path.normpath(os.path.join(HERE, "..", "..", "baseline-e45c1fa"))   # beside the repo
QUANTITIES = (("G′ surface", "G_surface", 0), ("G″ surface", "G_surface", 1),
              ("G′ internal", "G_internal", 0), ("G″ internal", "G_internal", 1))


def scenes(mu, drawn=False):
    """The two scenes; ``drawn``: with ``doDrawing=True`` and no window (``renderer="none"``), the path
    a tree measures drawn runs on (the documented classes' own step in trees before observers)."""
    extra = {"doDrawing": True, "renderer": "none"} if drawn else {}
    return {"default": dict(extra),
            "frictional": dict(extra, do_permanent_links=False, cut_lines=0, theMu=mu)}


def worker(tree, scene_kw, seeds):
    """Run the seeds in this process (PYTHONPATH = tree); print one JSON list of results."""
    import warnings
    warnings.simplefilter("ignore")
    import particleShear
    from particleShear import doParticleShearSimulation
    where = os.path.realpath(particleShear.__file__)
    if not where.startswith(os.path.realpath(tree) + os.sep):
        raise RuntimeError(f"particleShear imported from {where}, not from the tree {tree}")
    out = []
    for s in seeds:
        t0 = time.perf_counter()
        kw = dict(dict(doDrawing=False, plotStress=False, saveData=False, verbose=False), **scene_kw)
        r = doParticleShearSimulation(seed=s, return_result=True, **kw)
        out.append({"seed": s, "G_surface": [float(v) for v in r.G_surface],
                    "G_internal": [float(v) for v in r.G_internal], "wall": time.perf_counter() - t0})
    print(json.dumps(out))


def run_job(tree, scene_kw, seeds):
    env = dict(os.environ, PYTHONPATH=tree, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    p = subprocess.run([sys.executable, os.path.abspath(__file__), "--worker", tree, "--scene-json",
                        json.dumps(scene_kw), "--seed-list", *map(str, seeds)],
                       capture_output=True, text=True, env=env, cwd=tempfile.gettempdir())
    if p.returncode != 0:
        raise RuntimeError(f"worker for {tree} {scene_kw} seeds {seeds} failed:\n{p.stderr[-3000:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def welch(a, b):
    """Welch's t of mean(a) − mean(b) and the Welch–Satterthwaite degrees of freedom."""
    na, nb = len(a), len(b)
    va, vb = statistics.variance(a) / na, statistics.variance(b) / nb
    d = statistics.fmean(a) - statistics.fmean(b)
    if va + vb == 0:
        return (0.0 if d == 0 else math.copysign(math.inf, d)), float("nan")
    dof = (va + vb) ** 2 / (va ** 2 / (na - 1) + vb ** 2 / (nb - 1))
    return d / math.sqrt(va + vb), dof


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default=DEFAULT_BASELINE, help=f"baseline tree (default {DEFAULT_BASELINE})")
    ap.add_argument("--current", default=os.path.dirname(HERE), help="current tree (default: this script's repo)")
    ap.add_argument("--seeds", type=int, default=16, help="seeds 1 … SEEDS per scene and tree (≥ 16 for the issue)")
    ap.add_argument("--workers", type=int, default=2, help="worker processes at a time")
    ap.add_argument("--mu", type=float, default=0.01, help="μ of the frictional scene (default: the docs' 0.01)")
    ap.add_argument("--drawn", action="store_true",
                    help="drawn runs without a window (doDrawing=True, renderer='none'), in both trees")
    ap.add_argument("--chunk", type=int, default=4, help="seeds per worker process")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    ap.add_argument("--scene-json", help=argparse.SUPPRESS)
    ap.add_argument("--seed-list", type=int, nargs="*", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(args.worker, json.loads(args.scene_json), args.seed_list)
        return
    if args.seeds < 2:
        ap.error(f"--seeds {args.seeds} is out of range: allowed an integer >= 2 (the issue asks >= 16)")
    if args.workers < 1 or args.chunk < 1:
        ap.error(f"--workers {args.workers} / --chunk {args.chunk} out of range: allowed integers >= 1")
    trees = {"baseline": os.path.abspath(args.baseline), "current": os.path.abspath(args.current)}
    for lab, path in trees.items():
        if not os.path.isdir(os.path.join(path, "particleShear")):
            ap.error(f"--{lab} {path!r} is not a tree with a particleShear package")
    sc = scenes(args.mu, args.drawn)
    seeds = list(range(1, args.seeds + 1))
    chunks = [seeds[i:i + args.chunk] for i in range(0, len(seeds), args.chunk)]
    print(f"Welch comparison of G′/G″: baseline {trees['baseline']}, current {trees['current']}; seeds 1–{args.seeds}; "
          f"{args.workers} worker processes", flush=True)
    t0 = time.perf_counter()
    jobs = [(scene, lab, ch) for scene in sc for ch in chunks for lab in trees]   # trees interleaved
    res = {(scene, lab): [] for scene in sc for lab in trees}
    with concurrent.futures.ThreadPoolExecutor(args.workers) as pool:
        futs = {pool.submit(run_job, trees[lab], sc[scene], ch): (scene, lab) for scene, lab, ch in jobs}
        for f in concurrent.futures.as_completed(futs):
            got = f.result()
            res[futs[f]] += got
            print(f"  {futs[f][0]}, {futs[f][1]}: seeds {got[0]['seed']}–{got[-1]['seed']} done "
                  f"[{time.perf_counter() - t0:.0f} s]", flush=True)
    wall = time.perf_counter() - t0
    worst = 0.0
    for scene, kw in sc.items():
        runs = {lab: sorted(res[(scene, lab)], key=lambda r: r["seed"]) for lab in trees}
        same = sum(rb["G_surface"] == rc["G_surface"] and rb["G_internal"] == rc["G_internal"]
                   for rb, rc in zip(runs["baseline"], runs["current"]))
        w = {lab: statistics.median(r["wall"] for r in runs[lab]) for lab in trees}
        print(f"\n{scene} scene {kw or '(all defaults)'}: {len(seeds)} seeds per tree, {same} of them bit-identical "
              f"between the trees; median wall per run baseline {w['baseline']:.2f} s, current {w['current']:.2f} s")
        print("| quantity (Pa) | baseline mean ± s.e. | current mean ± s.e. | Welch t | dof | |t| < 3 |")
        print("|---|---|---|---|---|---|")
        for name, attr, k in QUANTITIES:
            v = {lab: [r[attr][k] for r in runs[lab]] for lab in trees}
            t, dof = welch(v["current"], v["baseline"])
            worst = max(worst, abs(t))
            ms = {lab: (statistics.fmean(v[lab]), statistics.stdev(v[lab]) / math.sqrt(len(v[lab]))) for lab in trees}
            print(f"| {name} | {ms['baseline'][0]:.2f} ± {ms['baseline'][1]:.2f} | {ms['current'][0]:.2f} ± "
                  f"{ms['current'][1]:.2f} | {t:+.3f} | {dof:.1f} | {'PASS' if abs(t) < 3 else 'FAIL'} |")
    print(f"\nlargest |t| = {worst:.3f} ({'PASS' if worst < 3 else 'FAIL'}: required < 3); {wall:.0f} s")


if __name__ == "__main__":
    main()
