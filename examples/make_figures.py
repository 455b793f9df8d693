"""Make the README's three pictures at 150 dpi (needs ``pip install ".[plot]"`` from this source).

1. ``trace.png``: one run's strain and stress traces and its Lissajous loop (``result.plot``).
2. ``sweep.png``: G′ and G″ against strain amplitude of a small real sweep (crosslinked,
   uncrosslinked and bulk control; 3 amplitudes × :data:`SEEDS` seeds, N = 40, 3 periods), saved as
   ``sweep_results.csv`` in the sweep runner's column layout and plotted by
   ``particleShear.plot.plot_sweep``.
3. ``snapshot.png``: a captioned snapshot of that first run at the strain maximum.

They are written to ``./particleShear-figures`` by default, never over the tracked files; to
regenerate the README's pictures, name their folder explicitly.

Usage (from the repository root, ~6 min of one core: 45 runs of ~8 s)::

    python examples/make_figures.py [--out DIR] [--workers 2]     # DIR default ./particleShear-figures
    python examples/make_figures.py --out docs/figures             # regenerate the README's pictures
    python examples/make_figures.py --out DIR --replot-sweep       # redraw sweep.png from DIR/sweep_results.csv
"""
import argparse
import csv
import glob
import json
import os
import shutil
import tempfile

import numpy as np

from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries
from particleShear.plot import plot_sweep, save_figure

#: resolution of the raster figures (dots per inch)
DPI = 150
SMALL = dict(N=40, pre_periods=0.5, periods=3, post_periods=0.5, doDrawing=False, plotStress=False)
#: seeds per point of sweep.png: the bootstrap interval of a mean of n seeds is widened by Student's
#: t(n − 1) (analysis.sweep_summary); t is 12.7 at n = 2, 4.3 at 3, 2.8 at 5, so 5 seeds give bars
#: ~4.5× narrower than 2 for the same spread, bars that separate the materials — within ~6 min of one core
SEEDS = 5
COLUMNS = ["run_id", "status", "error", "Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal",
           "theAmplitude", "theMu", "do_permanent_links", "cut_lines", "N", "relative_frequency", "verdict", "spawn_key"]


def trace_and_snapshot(out, work):
    res = doParticleShearSimulation(work, theAmplitude=0.2, cut_lines=4, saveOutputImages=True, imageFileType="png",
                                    seed=1, verbose=False, return_result=True, **SMALL)
    save_figure(res.plot(), os.path.join(out, "trace.png"), dpi=DPI)
    # the snapshot nearest to the first strain maximum: t = (pre + 1/4)/f
    t_max = (SMALL["pre_periods"] + 0.25) / res.f
    step = int(round(t_max / res.dt))
    frames = sorted(glob.glob(os.path.join(res.image_folder, "image*.png")))
    best = min(frames, key=lambda p: abs(int(os.path.basename(p)[5:12]) - step))
    shutil.copyfile(best, os.path.join(out, "snapshot.png"))
    return res


def small_sweep(out, work, workers):
    res = doParticleShearSimulationSeries(amplitudes=[0.02, 0.1, 0.5], mu=[0.01], cut_lines=4, do_bulk_control=True,
                                          do_uncrosslinked_control=True, N_repetitions=SEEDS, seed=7,
                                          max_workers=workers, **SMALL)
    path = os.path.join(out, "sweep_results.csv")
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        for k, r in enumerate(res):
            p = r.parameters
            ok = all(np.isfinite(r.G_surface)) and all(np.isfinite(r.G_internal))
            w.writerow([k, "ok" if ok else "error", "", *r.G_surface, *r.G_internal, p["theAmplitude"], p["theMu"],
                        p["do_permanent_links"], p["cut_lines"], p["N"], p["relative_frequency"],
                        getattr(r, "verdict", "") or "", json.dumps([int(k) for k in r.spawn_key])])
    return replot_sweep(out)


def replot_sweep(out):
    """Redraw sweep.png from the saved ``sweep_results.csv`` (no simulation)."""
    fig = plot_sweep(os.path.join(out, "sweep_results.csv"), path=False)
    save_figure(fig, os.path.join(out, "sweep.png"), dpi=DPI)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="particleShear-figures",
                    help="folder of the pictures (created; default ./particleShear-figures); "
                         "--out docs/figures regenerates the README's pictures")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--replot-sweep", action="store_true", help="only redraw sweep.png from OUT/sweep_results.csv")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    if args.replot_sweep:
        replot_sweep(args.out)
        return
    with tempfile.TemporaryDirectory() as work:
        trace_and_snapshot(args.out, work)
        small_sweep(args.out, work, args.workers)
    for name in ("trace.png", "sweep.png", "snapshot.png"):
        print(os.path.join(args.out, name), os.path.getsize(os.path.join(args.out, name)), "bytes")


if __name__ == "__main__":
    main()
