"""What leaving out unneeded work buys: per-step cost and memory by scene and recording (not a test).

Scenes (the default builder EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters, N = 150, 500 × 500 µm, packing fraction 1.5, E = 8000 Pa, the
``doParticleShearSimulation`` defaults otherwise, seed 1, plates on, sinusoidal shear A = 0.2):

* frictionless spheres: μ = 0, no permanent links (no tangential term at all);
* frictional spheres: μ = 0.01, no links;
* crosslinked particles: μ = 0.01, links, 5 cut lines (the default scene);

each run twice through the experiment's protocol (OscillatoryShearExperiment.run_protocol, the engine's one
protocol loop on the ensemble's own state; each batch starts the protocol anew), in alternating batches with
the documented classes' step loop on a twin ensemble (the same run, so their ratio is read pair by pair):
recording nothing but the
scalar series (``keep_tensor_history=False``: only σ_xy of the overall tensor and the surface
stress are evaluated per step) and keeping every tensor of every step (``True``, what
``saveData`` with ``saveStressTensorData`` needs).

Reported per row: ``ensemble.active_terms``; the median wall time per protocol step (µs) over
``--batches`` batches of ``--steps`` steps (one core; the per-batch mean is one sample);
tracemalloc peak (MiB) of allocating the recording for the full default protocol
(13,439 steps) plus 200 steps (measured in a separate pass: tracemalloc slows execution).

Usage: python benchmarks/bench_scenes.py [--quick] [--steps 200] [--batches 15]
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")
#: the NumPy engine's figures (docs/performance.md: the documented classes' engine is made on the
#: default backend); PARTICLESHEAR_BACKEND=numba times the compiled one
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")

import argparse  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402

from particleShear import Simulation_interlocking_rheology  # noqa: E402

SCENES = {
    "frictionless spheres (μ = 0, no links)": dict(mu=0.0, do_permanent_links=False, cut_lines=0),
    "frictional spheres (μ = 0.01, no links)": dict(mu=0.01, do_permanent_links=False, cut_lines=0),
    "crosslinked particles (default)": dict(mu=0.01, do_permanent_links=True, cut_lines=5),
}


def build(N, seed, mu, do_permanent_links, cut_lines):
    """Builder ensemble + experiment exactly as doParticleShearSimulation makes them, pre-equilibrated."""
    sim = Simulation_interlocking_rheology(
        "", do_permanent_links=do_permanent_links, cut_lines=cut_lines, N=N, packing_fraction=1.5,
        bimodal_factor=1.4, amplitude=0.2, Young_modulus_spheres=8000, density=50, mu=mu, relative_viscosity=0.1,
        relative_y_scale_force=1e8, relative_frequency=0.025, avoid_horizontal_angle_degree=15,
        avoid_height_spanning_particles=True, central_repulsion_coefficient=1,
        keep_viscosity_coefficients_constant=False, cut_top_bottom=False, doDrawing=False, saveData=False)
    sim.baseline_pre_periods = 2
    sim.baseline_post_periods = 1
    sim.rng = seed
    sim.initEnsemble()
    exp = sim.createExperiment(False, periods=3, plotStress=False)
    f_step = 0.5 ** (exp.f * exp.dt)
    exp.pre_equilibrate(N=25, cool_factor=f_step)
    ens = sim.theEnsemble
    ens.t = 0
    ens.applyingShear = True
    return exp, ens, f_step


def classes_protocol(exp, cool, n):
    """n protocol steps of the documented classes' step loop on ``exp``'s ensemble (setShearRate,
    forces, totals, recording, acceleration, movement, reset), the loop scripts write."""
    ens, plotter, ev = exp.theEnsemble, exp.plotter, exp.theEvaluator
    w = 2 * math.pi * exp.f
    for _ in range(n):
        ens.setShearRate(exp.amplitude * w * math.cos(w * ens.t))
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        plotter.record(ens, ev)
        ens.mechanical_simulation_step_calculate_acceleration(cool, exp.dt)
        ens.mechanical_simulation_step_calculate_movement(exp.dt)
        ens.reset_force()


def per_step_us(pair, f_step, keep, steps, batches):
    """Median and best µs per step of ``run_protocol`` (the engine) and of the classes' step loop on
    the twin ensemble, in alternating batches, and the median of the per-batch ratios."""
    exp, twin = pair
    samples, ratios = ([], []), []
    for e in (exp, twin):
        e.keep_tensor_history = keep
        e.prepare_recording()
    exp.run_protocol(f_step, 20)                     # warm-up
    classes_protocol(twin, f_step, 20)
    for _ in range(batches):
        exp.prepare_recording()
        t0 = time.perf_counter()
        exp.run_protocol(f_step, steps)
        t1 = time.perf_counter()
        twin.prepare_recording()
        classes_protocol(twin, f_step, steps)
        t2 = time.perf_counter()
        samples[0].append((t1 - t0) / steps * 1e6)
        samples[1].append((t2 - t1) / steps * 1e6)
        ratios.append((t1 - t0) / (t2 - t1))
    return [(statistics.median(x), min(x)) for x in samples], statistics.median(ratios)


def peak_mib(exp, f_step, keep, steps=200):
    exp.keep_tensor_history = keep
    tracemalloc.start()
    exp.prepare_recording()
    exp.run_protocol(f_step, steps)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 2 ** 20


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--N", type=int, default=150)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--batches", type=int, default=15)
    args = ap.parse_args(argv)
    steps, batches = (50, 5) if args.quick else (args.steps, args.batches)
    rows = []
    for name, kw in SCENES.items():
        exp, ens, f_step = build(args.N, 1, **kw)
        twin = build(args.N, 1, **kw)[0]
        terms = ", ".join(ens.active_terms)
        for keep in (False, True):
            ((med, best), (c_med, c_best)), ratio = per_step_us((exp, twin), f_step, keep, steps, batches)
            mem = peak_mib(exp, f_step, keep)
            rows.append((name, terms, "all tensors kept" if keep else "nothing kept", med, best, mem, c_med, ratio))
            print(f"{name:42s} {rows[-1][2]:17s} {med:8.1f} µs/step (best {best:.1f})  peak {mem:6.2f} MiB; "
                  f"classes' loop {c_med:8.1f} µs/step (best {c_best:.1f}); ratio {ratio:.2f}", flush=True)
    print()
    print(f"N = {args.N}, {steps} steps × {batches} batches per row, one core\n")
    print("| scene | active_terms | recording | median µs/step | best µs/step | tracemalloc peak (MiB) "
          "| classes' step loop, median µs/step | run_protocol / classes' loop |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]:.0f} | {r[4]:.0f} | {r[5]:.2f} | {r[6]:.0f} | {r[7]:.2f} |")


if __name__ == "__main__":
    main()
