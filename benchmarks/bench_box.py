"""Cost of the Lees-Edwards box in the classes' protocol step at N = 150, against a git revision (not a test).

The classes call the box through ``particleShear.base.kernels`` (``min_image``, ``le_wrap``,
``pair_geometry``).  ``--baseline REV`` loads that module as it was at revision REV (inside the
current package, so its relative imports resolve) and runs the protocol step of
``bench_step.py`` (N = 150, frictional, crosslinked and cut, plates on, sinusoidal shear) on one
scene, in alternating blocks of 100 steps with the current kernels and with REV's bound in the
canvas.  A revision whose canvas passed the fixed-passes hint gets it as that canvas computed
it.  It also times the functions alone on the scene's candidate pairs and spheres (best of 7).
The trajectories of the two are the same (the box gives the same numbers), so both time the
same scene.  Without ``--baseline`` only the current step is timed.

Usage: OMP_NUM_THREADS=1 python benchmarks/bench_box.py [--blocks K] [--baseline REV]
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import timeit  # noqa: E402

import bench_step as B  # noqa: E402
import particleShear.base.canvas as canvas  # noqa: E402
import particleShear.base.elastic_canvas as elastic_canvas  # noqa: E402
import particleShear.base.pair_canvas as pair_canvas  # noqa: E402
import particleShear.base.kernels as current  # noqa: E402
from particleShear import StressTensorEvaluation  # noqa: E402

NAMES = ("min_image", "le_wrap", "pair_geometry")


def set_kernel(name, fn):
    """Make every canvas module that calls kernel ``name`` call ``fn``."""
    for module in (canvas, pair_canvas, elastic_canvas):
        if hasattr(module, name):
            setattr(module, name, fn)


def baseline_kernels(rev, folder):
    """``particleShear.base.kernels`` of revision ``rev``, loaded as ``particleShear.base._kernels_baseline``."""
    root = subprocess.run(["git", "rev-parse", "--show-toplevel"], capture_output=True, text=True, check=True,
                          cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    src = subprocess.run(["git", "show", f"{rev}:particleShear/base/kernels.py"], capture_output=True, check=True,
                         cwd=root).stdout
    path = os.path.join(folder, "kernels_baseline.py")
    with open(path, "wb") as fh:
        fh.write(src)
    spec = importlib.util.spec_from_file_location("particleShear.base._kernels_baseline", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def bound(mod, ens):
    """The functions of ``mod`` as the canvas calls them (the old hint added where that canvas passed it)."""
    f = {name: getattr(mod, name) for name in NAMES}
    hint = getattr(mod, "in_cell_passes", None)
    if hint is not None and mod is not current:
        old = f["min_image"]

        def min_image(dx, dy, Lx, Ly, shift, shear_rate=0.0, passes=None, counts=False):
            if counts and passes is None and getattr(ens, "_in_cell", False):   # the old canvas's _passes()
                passes = hint(Lx, shift)
            return old(dx, dy, Lx, Ly, shift, shear_rate, passes, counts)
        f["min_image"] = min_image
    return f


def alone(mod, ens):
    """µs per call of min_image (the candidates, with counts) and le_wrap (one sphere out), best of 7."""
    a, pt = ens._a, ens._pairs
    x, y = a["x"], a["y"]
    dx, dy = x[pt.j] - x[pt.i], y[pt.j] - y[pt.i]
    L, sh = ens.size_x, ens._le_shift()
    kw = dict(passes=mod.in_cell_passes(L, sh)) if mod is not current and hasattr(mod, "in_cell_passes") else {}
    t_img = min(timeit.repeat(lambda: mod.min_image(dx, dy, L, L, sh, 3.0, counts=True, **kw), number=200,
                              repeat=7)) / 200
    xs = x.copy()
    xs[0] = -1.0

    def wrap():
        mod.le_wrap(xs.copy(), y.copy(), a["xspeed"].copy(), L, L, sh, 3.0)
    t_cp = min(timeit.repeat(lambda: (xs.copy(), y.copy(), a["xspeed"].copy()), number=200, repeat=7)) / 200
    t_wrap = min(timeit.repeat(wrap, number=200, repeat=7)) / 200 - t_cp
    return len(dx), t_img * 1e6, t_wrap * 1e6


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--blocks", type=int, default=20, help="blocks of 100 steps per variant")
    ap.add_argument("--baseline", default=None, help="git revision whose base/kernels.py runs alternately")
    args = ap.parse_args()
    ens = B.build(150, seed=2)
    ev = StressTensorEvaluation(ens.size_x, ens.size_y)
    with tempfile.TemporaryDirectory() as folder:
        variants = [("now", current)] + ([(args.baseline, baseline_kernels(args.baseline, folder))]
                                         if args.baseline else [])
        fns = {name: bound(mod, ens) for name, mod in variants}
        counts = {n: 0 for n in NAMES}
        for n in NAMES:   # count the calls of the current kernels in the warm-up
            f = fns["now"][n]
            fns["now"][n] = (lambda f, n: lambda *a, **k: (counts.__setitem__(n, counts[n] + 1), f(*a, **k))[1])(f, n)
        for name, _ in variants:
            for n in NAMES:
                set_kernel(n, fns[name][n])
            B.protocol_steps(ens, ev, 500)
        fns["now"] = bound(current, ens)   # without the counters
        times = {name: [] for name, _ in variants}
        for k in range(args.blocks):
            for name, _ in (variants if k % 2 == 0 else variants[::-1]):
                for n in NAMES:
                    set_kernel(n, fns[name][n])
                times[name] += B.protocol_steps(ens, ev, 100)
        for n in NAMES:
            set_kernel(n, getattr(current, n))
        print(f"classes' protocol step, N = 150 (bench_step scene), {args.blocks} alternating blocks of 100 steps; "
              f"calls in 500 warm-up steps: " + ", ".join(f"{n} {counts[n]}" for n in NAMES))
        for name, mod in variants:
            t = times[name]
            P, t_img, t_wrap = alone(mod, ens)
            print(f"{name:>10}: median {statistics.median(t) * 1e6:7.1f} µs/step, lower quartile "
                  f"{statistics.quantiles(t, n=4)[0] * 1e6:7.1f}; alone: min_image (P = {P}, counts) {t_img:5.1f} µs, "
                  f"le_wrap (N = 150, one sphere out) {t_wrap:5.1f} µs")
        if args.baseline:
            r = statistics.median(times["now"]) / statistics.median(times[args.baseline])
            print(f"now / {args.baseline}: {r:.3f} (median per step)")


if __name__ == "__main__":
    main()
