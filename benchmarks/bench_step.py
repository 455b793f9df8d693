"""Cost of one protocol step of a frictional, crosslinked ensemble under shear (not a test).

One protocol step = setShearRate + forces (neighbour update, central, tangential,
links) + register totals + every stress tensor + acceleration (kick, damping)
+ movement (ξ, drift, strain, wrap) + reset — the per-step sequence of the protocol (docs/engine.md).

Scenes: EnsembleLinkable with random bimodal spheres (radius ratio 1.4) at packing
fraction 1.5 in a cell that grows with N (the sphere size of the default 150-sphere
500 × 500 µm run), relaxed with damping, then ``makeAllLinksPermanent()`` and a
few ``cutLine``s; μ = 0.01, c = 1, k = k_t = π/8·8000·1e6, ν = ν_t ≈ 2e3, masses
~0.1 mg/m, dt ≈ 1.1e-7 s, plates on, sinusoidal shear (A = 0.2, f ≈ 4 kHz).

The N = 150 step is also timed on the scene a default run measures (the builder's crosslinked
particles after pre-equilibration), which is calmer than the relaxed-random scene above.

Baselines measured in the same run: the legacy O(N²) pure-Python neighbour test of
the reference (all ordered pairs, one relation search each) at N = 150, a
plain all-pairs NumPy minimum-image distance computation per step at N = 150 and 1,000,
and the same protocol step on a 40-sphere scene (the fixed cost of the ~145 NumPy calls
and the Python around them, which no vectorisation removes).

The documented step loop of the README (what scripts written against 1.0.2 run: setShearRate,
forces, totals, ``ev.evaluate_stress_tensors(ens.force_register, ens.movableSphereList(),
ens.shear_rate)``, acceleration, movement) is timed at N = 150 against the protocol step above,
in alternating blocks on one scene of the same run.

Targets (one core): ≤ 300 µs/step at N = 150, ≤ 1 µs per particle-step at N = 10,000,
growth ≤ N^1.1 between 1,000 and 10,000; documented loop ≤ 1.15× the protocol step.

Usage: python benchmarks/bench_step.py [--quick]
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

import numpy as np  # noqa: E402

from particleShear import EnsembleLinkable, SphereLinkable, StressTensorEvaluation  # noqa: E402

E = 8000.0
K = math.pi / 8 * E * 1e6          # 3.14e9 mg s^-2 per m depth
NU = 1981.6636488030053            # relative viscosity 0.1 (spec A.2)
DT = 1.1263984473304288e-07        # default final dt (spec A.2)
F_EXC = 3963.327297606011          # excitation frequency (Hz)
AMPLITUDE = 0.2
PHI = 1.5
R_MODEL = 28.209479177387816       # r_model of the default 150-sphere cell (µm)
M_MODEL = 0.125                    # model mass (mg/m)
BF = 1.4


def cell_order(xs, ys, L, width):
    """Order of the spheres by the square cell (side ``width``, µm) of their placement, row by row
    (cells along x within a row of cells along y), then by x within a cell: neighbours get near
    labels, so their rows lie near each other in memory."""
    nc = max(1, int(L // width))
    cx = np.minimum((xs / L * nc).astype(int), nc - 1)
    cy = np.minimum((ys / L * nc).astype(int), nc - 1)
    return np.lexsort((xs, cx, cy))


def build(n, seed=1, by_cell=False):
    """Frictional crosslinked ensemble of n spheres, relaxed, linked and cut, plates on.

    ``by_cell``: the same placement (same positions and sizes) labelled in :func:`cell_order`
    (cells of 1.25 large-sphere diameters) instead of the order drawn.
    """
    L = math.sqrt(n * math.pi * R_MODEL ** 2 / PHI)
    rng = np.random.default_rng(seed)
    r_b = math.sqrt(L * L * PHI / (n * math.pi)) / ((math.sqrt(BF) + 1 / math.sqrt(BF)) / 2)
    ens = EnsembleLinkable(L, L, 0, k=K, nu=NU, k_t=K, nu_t=NU, mu=0.0)
    ens.set_random_generator(rng)
    large = rng.integers(0, 2, n)
    xs = rng.random(n) * L
    ys = rng.random(n) * L
    if by_cell:
        order = cell_order(xs, ys, L, 2.5 * r_b * math.sqrt(BF))
        large, xs, ys = large[order], xs[order], ys[order]
    for p in range(n):
        r = r_b * (math.sqrt(BF) if large[p] else 1 / math.sqrt(BF))
        s = SphereLinkable("grey", float(xs[p]), float(ys[p]), 2 * r, M_MODEL * r * r / (r_b * r_b), p,
                           force_register=ens, size_x=L, size_y=L)
        ens.sphereList.append(s)
    # frictionless damped relaxation (linear law first: random placement has deep overlaps)
    ens.set_central_repulsion_coefficient(0)
    for _ in range(40):
        ens.mechanical_simulation_step(cool_factor=0.7, dt=4 * DT)
    ens.set_central_repulsion_coefficient(1)
    for _ in range(20):
        ens.mechanical_simulation_step(cool_factor=0.9, dt=2 * DT)
    ens.mu = 0.01
    ens.test_neighbor_relation()
    ens.makeAllLinksPermanent()
    n_cuts = max(3, int(round(5 * math.sqrt(n / 150))))
    for _ in range(n_cuts):
        ens.cutRandomLine()
    ens.applyingShear = True
    ens.t = 0
    return ens


def protocol_steps(ens, ev, n_steps, cool=0.99969060716623):
    """Time n_steps protocol steps; returns the list of per-step wall times (s)."""
    times = []
    w = 2 * math.pi * F_EXC
    for _ in range(n_steps):
        t0 = time.perf_counter()
        ens.setShearRate(AMPLITUDE * w * math.cos(w * ens.t))
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        ens.evaluate_stress_tensors(ev)
        ev.evaluate_quasistatic_shear_stress()
        ev.evaluate_externally_applied_shear_stress()
        ens.mechanical_simulation_step_calculate_acceleration(cool, DT)
        ens.mechanical_simulation_step_calculate_movement(DT)
        ens.reset_force()
        times.append(time.perf_counter() - t0)
    return times


def documented_steps(ens, ev, n_steps, cool=0.99969060716623):
    """Time n_steps of the README's step loop (documented API only); returns per-step wall times (s)."""
    times = []
    w = 2 * math.pi * F_EXC
    for _ in range(n_steps):
        t0 = time.perf_counter()
        ens.setShearRate(AMPLITUDE * w * math.cos(w * ens.t))
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        ev.evaluate_stress_tensors(ens.force_register, ens.movableSphereList(), ens.shear_rate)
        ens.mechanical_simulation_step_calculate_acceleration(cool, DT)
        ens.mechanical_simulation_step_calculate_movement(DT)
        times.append(time.perf_counter() - t0)
    return times


def documented_vs_protocol(n_blocks, block=50):
    """Median µs/step of the documented loop and of the protocol step, alternating blocks on one scene."""
    ens = build(150, seed=2)
    ev = StressTensorEvaluation(ens.size_x, ens.size_y)
    protocol_steps(ens, ev, 20)
    documented_steps(ens, ev, 20)
    doc, prot = [], []
    for _ in range(n_blocks):
        doc += documented_steps(ens, ev, block)
        prot += protocol_steps(ens, ev, block)
    return median_us(doc), median_us(prot)


def _le_closest(dx, dy, Lx, Ly, shear):
    """The reference's scalar Lees-Edwards minimum image: periods removed one at a time (y first, which
    moves x by ``Ly·γ``); differences of positions inside the cell need at most a few passes."""
    for _ in range(4):
        if dy > Ly / 2:
            dy, dx = dy - Ly, dx - Ly * shear
        elif dy < -Ly / 2:
            dy, dx = dy + Ly, dx + Ly * shear
        if dx > Lx / 2:
            dx -= Lx
        elif dx < -Lx / 2:
            dx += Lx
    return dx, dy


def legacy_neighbour_loop(xs, ys, rs, L, shear, relations):
    """The reference's O(N²) pure-Python neighbour update: every ordered pair, LE minimum image,
    linear search of the relation list by index."""
    n = len(xs)
    for i in range(n):
        rel = relations[i]
        for j in range(n):
            if i == j:
                continue
            dx, dy = _le_closest(xs[j] - xs[i], ys[j] - ys[i], L, L, shear)  # scalar minimum image, as the reference
            touching = math.sqrt(dx * dx + dy * dy) < rs[i] + rs[j]
            found = -1
            for q, idx in enumerate(rel):
                if idx == j:
                    found = q
            if not touching and found >= 0:
                del rel[found]
            if touching and found < 0:
                rel.append(j)


def numpy_all_pairs_step(x, y, r, L, shift):
    from particleShear.engine.box import min_image
    i, j = np.triu_indices(len(x), 1)
    dx, dy = min_image(x[j] - x[i], y[j] - y[i], L, L, shift)[:2]
    d = np.sqrt(dx * dx + dy * dy)
    return int(np.count_nonzero(d < r[i] + r[j]))


def median_us(times):
    return statistics.median(times) * 1e6


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer steps and sizes 150 / 1,000 / 10,000 still")
    args = ap.parse_args()
    quick = args.quick
    sizes = (150, 1000, 10000)
    steps = {150: 200 if quick else 1000, 1000: 60 if quick else 300, 10000: 10 if quick else 60}
    warm = {150: 20, 1000: 10, 10000: 3}

    print(f"particleShear protocol-step benchmark ({'quick' if quick else 'full'}); numpy {np.__version__}, "
          f"threads pinned to 1")
    per = {}
    scenes = {}
    for n in sizes:
        t0 = time.perf_counter()
        ens = build(n)
        t_build = time.perf_counter() - t0
        ev = StressTensorEvaluation(ens.size_x, ens.size_y)
        protocol_steps(ens, ev, warm[n])
        times = protocol_steps(ens, ev, steps[n])
        per[n] = median_us(times)
        scenes[n] = ens
        links = len(ens.permanent_pairs()[0])
        contacts = len(ens.contact_pairs()[0])
        mobile = len(ens.movableSphereList())
        print(f"N = {n:6d}: {per[n]:10.1f} µs/step (median of {len(times)}), {per[n] / n:7.3f} µs/particle-step"
              f"  [L = {ens.size_x:.0f} µm, relations {contacts}, links {links}, mobile {mobile}, "
              f"terms {'+'.join(ens.active_terms)}; build {t_build:.1f} s]")
    expo = math.log(per[10000] / per[1000]) / math.log(10)
    print(f"scaling exponent 1,000 → 10,000: N^{expo:.2f}")

    # baselines, same run
    ens = scenes[150]
    a_x = np.array([s.x for s in ens.sphereList])
    a_y = np.array([s.y for s in ens.sphereList])
    a_r = np.array([s.r for s in ens.sphereList])
    L = ens.size_x
    rels = [[] for _ in range(len(a_x))]
    xs, ys, rs = a_x.tolist(), a_y.tolist(), a_r.tolist()
    legacy = []
    for _ in range(2 if quick else 5):
        t0 = time.perf_counter()
        legacy_neighbour_loop(xs, ys, rs, L, ens.shear, rels)
        legacy.append(time.perf_counter() - t0)
    leg = median_us(legacy)
    print(f"baseline legacy pure-Python O(N²) neighbour update alone, N = 150: {leg:10.1f} µs/step "
          f"→ full vectorised step is {leg / per[150]:.1f}× faster")
    for n in (150, 1000):
        e = scenes[n]
        x = np.array([s.x for s in e.sphereList])
        y = np.array([s.y for s in e.sphereList])
        r = np.array([s.r for s in e.sphereList])
        bt = []
        for _ in range(20 if n == 150 else 5):
            t0 = time.perf_counter()
            numpy_all_pairs_step(x, y, r, e.size_x, e.size_y * e.shear)
            bt.append(time.perf_counter() - t0)
        b = median_us(bt)
        print(f"baseline NumPy all-pairs LE distances alone, N = {n:5d}: {b:10.1f} µs/step "
              f"→ ratio full step / baseline = {per[n] / b:.2f}")
    # the same step on the scene a default run measures: the default builder (crosslinked particles, 5 cut
    # lines), pre-equilibrated with plates; relaxed, so the Verlet list and the images rarely change
    from bench_scenes import build as build_default_scene
    _, real, _ = build_default_scene(150, 1, 0.01, True, 5)
    ev = StressTensorEvaluation(real.size_x, real.size_y)
    protocol_steps(real, ev, 50)
    real_us = median_us(protocol_steps(real, ev, 200 if quick else 1000))
    print(f"same step on the default run's pre-equilibrated scene, N = 150: {real_us:10.1f} µs/step")
    # fixed cost of a step: the same protocol step on a 40-sphere scene (the smallest whose cell
    # still keeps the periodic images between wraps, like the larger ones; little arithmetic)
    tiny = build(40, seed=3)
    ev = StressTensorEvaluation(tiny.size_x, tiny.size_y)
    protocol_steps(tiny, ev, 20)
    fixed = median_us(protocol_steps(tiny, ev, 200 if quick else 1000))
    print(f"baseline fixed per-step cost (same step, N = 40): {fixed:10.1f} µs/step "
          f"→ N = 150 step minus fixed cost = {per[150] - fixed:.1f} µs")
    doc_us, prot_us = documented_vs_protocol(4 if quick else 20)
    ratio = doc_us / prot_us
    print(f"documented step loop (README, movableSphereList(), setShearRate every step), N = 150: "
          f"{doc_us:10.1f} µs/step vs protocol step {prot_us:.1f} µs/step (same scene, alternating blocks) "
          f"→ ratio {ratio:.3f}")
    ok = (per[150] <= 300, per[10000] / 10000 <= 1.0, expo <= 1.1, ratio <= 1.15)
    print(f"targets: N=150 ≤ 300 µs: {'met' if ok[0] else 'MISSED'}; "
          f"N=10,000 ≤ 1 µs/particle-step: {'met' if ok[1] else 'MISSED'}; "
          f"growth ≤ N^1.1: {'met' if ok[2] else 'MISSED'}; "
          f"documented loop ≤ 1.15× protocol: {'met' if ok[3] else 'MISSED'}")


if __name__ == "__main__":
    main()
