"""Neighbour search: the cell list with Lees-Edwards-shifted rows against an all-pairs oracle (docs/engine.md, "Neighbour lists and box").

The classes' ``candidate_pairs`` is the engine's ``near_pairs`` (all pairs below
``CELL_LIST_MIN_N`` spheres, the cell list from there: n = 70 and n ≥ 500 below test both).

The oracle here is written independently of the package: the minimum image of
docs/engine.md (y image first, shifting x by Ly·γ; half-open intervals; one period
subtracted at a time) over every pair, and the strict contact test
``d < r_i + r_j``.
"""
import math
import unittest

import numpy as np

from particleShear import EnsembleLinkable, SphereLinkable, StressTensorEvaluation
from particleShear.base.neighbours import all_pairs, candidate_pairs


def oracle_min_image(dx, dy, Lx, Ly, shear):
    dx = dx.copy()
    dy = dy.copy()
    while True:
        m = dy >= Ly / 2
        if not m.any():
            break
        dy[m] -= Ly
        dx[m] -= Ly * shear
    while True:
        m = dy < -Ly / 2
        if not m.any():
            break
        dy[m] += Ly
        dx[m] += Ly * shear
    while True:
        m = dx >= Lx / 2
        if not m.any():
            break
        dx[m] -= Lx
    while True:
        m = dx < -Lx / 2
        if not m.any():
            break
        dx[m] += Lx
    return dx, dy


def oracle_pairs(x, y, r, Lx, Ly, shear, extra=0.0, block=400):
    """Set of (i, j), i < j, with minimum-image distance < r_i + r_j + extra (row blocks bound the memory)."""
    n = len(x)
    out = set()
    for start in range(0, n, block):
        rows = np.arange(start, min(start + block, n))
        i = np.repeat(rows, n)
        j = np.tile(np.arange(n), len(rows))
        keep = i < j
        i, j = i[keep], j[keep]
        dx, dy = oracle_min_image(x[j] - x[i], y[j] - y[i], Lx, Ly, shear)
        d = np.sqrt(dx * dx + dy * dy)
        hit = d < r[i] + r[j] + extra
        out.update(zip(i[hit].tolist(), j[hit].tolist()))
    return out


def random_configuration(rng, n, Lx, Ly, packing_fraction=0.9, bimodal_factor=1.4):
    r_mean = math.sqrt(Lx * Ly * packing_fraction / (n * math.pi)) / ((math.sqrt(bimodal_factor) + 1 / math.sqrt(bimodal_factor)) / 2)
    big = rng.integers(0, 2, n).astype(bool)
    r = np.where(big, r_mean * math.sqrt(bimodal_factor), r_mean / math.sqrt(bimodal_factor))
    x = rng.random(n) * Lx
    y = rng.random(n) * Ly
    return x, y, r


class TestCandidatePairs(unittest.TestCase):
    """``candidate_pairs`` with skin 0 is the contact set; with a skin it is the skin-extended set."""

    SHEARS = (0.0, 0.37, -1.3, 2.0)

    def _check(self, n, Lx, Ly, shear, skin, seed):
        rng = np.random.default_rng(seed)
        x, y, r = random_configuration(rng, n, Lx, Ly)
        i, j = candidate_pairs(x, y, r, Lx, Ly, Ly * shear, skin)
        got = list(zip(i.tolist(), j.tolist()))
        self.assertTrue(np.all(i < j))
        self.assertEqual(got, sorted(got), "not in canonical (i, j) order")
        self.assertEqual(len(got), len(set(got)), "duplicate pairs")
        expected = oracle_pairs(x, y, r, Lx, Ly, shear, extra=skin)
        self.assertEqual(set(got), expected)
        # the test is meaningful: there are contacts, and some of them cross the periodic boundary
        self.assertGreater(len(expected), n // 2)
        ii = np.array([p[0] for p in expected])
        jj = np.array([p[1] for p in expected])
        crossing = (np.abs(x[jj] - x[ii]) >= Lx / 2) | (np.abs(y[jj] - y[ii]) >= Ly / 2)
        self.assertGreater(int(crossing.sum()), 0)
        if shear and n >= 500:
            # pairs through the sheared y boundary whose image is shifted in x
            ycross = np.abs(y[jj] - y[ii]) >= Ly / 2
            self.assertGreater(int(ycross.sum()), 0)

    def test_contacts_equal_all_pairs(self):
        for n in (70, 500, 3000):
            for shear in self.SHEARS:
                with self.subTest(n=n, shear=shear):
                    self._check(n, 500.0, 500.0, shear, 0.0, seed=n + abs(int(100 * shear)) + 7)

    def test_skin_extended_set(self):
        for n in (500, 3000):
            for shear in (0.37, -1.3):
                with self.subTest(n=n, shear=shear):
                    self._check(n, 500.0, 500.0, shear, 4.0, seed=n + 3)

    def test_rectangular_cell(self):
        for Lx, Ly in ((800.0, 300.0), (300.0, 700.0)):
            for shear in (0.37, 2.0):
                with self.subTest(Lx=Lx, Ly=Ly, shear=shear):
                    self._check(1500, Lx, Ly, shear, 0.0, seed=int(Lx + Ly))

    def test_large_offset_equivalent_to_reduced_offset(self):
        """γ and γ + Lx/Ly·k describe the same images: identical contact sets."""
        rng = np.random.default_rng(11)
        x, y, r = random_configuration(rng, 800, 500.0, 500.0)
        a = candidate_pairs(x, y, r, 500.0, 500.0, 500.0 * 0.3, 0.0)
        b = candidate_pairs(x, y, r, 500.0, 500.0, 500.0 * 2.3, 0.0)
        self.assertEqual(set(zip(*map(np.ndarray.tolist, a))), set(zip(*map(np.ndarray.tolist, b))))

    def test_all_pairs(self):
        i, j = all_pairs(5)
        self.assertEqual(list(zip(i.tolist(), j.tolist())),
                         [(0, 1), (0, 2), (0, 3), (0, 4), (1, 2), (1, 3), (1, 4), (2, 3), (2, 4), (3, 4)])


class TestEnsembleRelationsDuringShear(unittest.TestCase):
    """Verlet-skin correctness: after every neighbour update the active relations are exactly
    the current contacts (minimum image at the current offset) plus the permanent links."""

    def test_relations_equal_brute_force_over_sheared_run(self):
        rng = np.random.default_rng(2024)
        Lx = Ly = 500.0
        n = 300
        x, y, r = random_configuration(rng, n, Lx, Ly, packing_fraction=0.85)
        ens = EnsembleLinkable(Lx, Ly, 0, k=1.0, nu=0.5, k_t=1.0, nu_t=0.5, mu=0.3)
        for p in range(n):
            s = SphereLinkable("grey", float(x[p]), float(y[p]), 2 * float(r[p]), 1.0, p + 1,
                               force_register=ens, size_x=Lx, size_y=Ly)
            s.xspeed, s.yspeed = rng.normal(0, 2.0, 2)
            ens.sphereList.append(s)
        ens.set_central_repulsion_coefficient(1)
        for _ in range(30):  # relax the random placement a little
            ens.mechanical_simulation_step(cool_factor=0.9, dt=0.2)
        ens.test_neighbor_relation()
        ens.makeAllLinksPermanent()
        for angle in (0.3, 1.9, 2.7):
            ens.cutLine((250.0, 250.0), angle)
        perm0 = set(zip(*map(np.ndarray.tolist, ens.permanent_pairs())))
        self.assertGreater(len(perm0), 20)
        ens.setShearRate(0.25)  # 0.025 strain per step: the offset passes Lx/Ly·γ = 1 during the run
        ens.test_neighbor_relation()
        engine = ens._engine                      # the ensemble's step (kept while nothing is edited)
        rebuilds = int(engine.s.contacts.rebuilds[0])
        boundary_pairs = 0
        stretched_links = 0
        dt = 0.1
        for step in range(120):
            ens.test_neighbor_relation()
            xs = np.array([s.x for s in ens.sphereList])
            ys = np.array([s.y for s in ens.sphereList])
            rs = np.array([s.r for s in ens.sphereList])
            contacts = oracle_pairs(xs, ys, rs, Lx, Ly, ens.shear)
            got = set(zip(*map(np.ndarray.tolist, ens.contact_pairs())))
            self.assertEqual(got, contacts | perm0, f"step {step}, shear {ens.shear}")
            self.assertEqual(set(zip(*map(np.ndarray.tolist, ens.permanent_pairs()))), perm0)
            # the sphere-level view agrees with the pair table
            if step % 40 == 0:
                for p in (0, n // 2, n - 1):
                    partners = sorted(rel.theSphere.myindex - 1 for rel in ens.sphereList[p].neighbors)
                    self.assertEqual(partners, sorted({b for a, b in got if a == p} | {a for a, b in got if b == p}))
            ii = np.array([q[0] for q in contacts])
            jj = np.array([q[1] for q in contacts])
            boundary_pairs += int(np.sum(np.abs(ys[jj] - ys[ii]) >= Ly / 2))
            stretched_links += len(perm0 - contacts)
            ens.mechanical_simulation_step_calculate_forces()
            ens.record_total_particle_forces()
            ens.mechanical_simulation_step_calculate_acceleration(0.98, dt)
            ens.mechanical_simulation_step_calculate_movement(dt)
        self.assertGreater(ens.shear, 2.5)
        self.assertGreater(boundary_pairs, 0)
        self.assertGreater(stretched_links, 0)
        # the Verlet list was rebuilt several times (and not at every step) during the run
        self.assertIs(ens._engine, engine)
        calls = int(engine.s.contacts.rebuilds[0]) - rebuilds
        self.assertGreater(calls, 3)
        self.assertLess(calls, 120)



class TestVerletCriterionUnderAffineFlow(unittest.TestCase):
    """Spheres carried exactly by the shear flow have no peculiar displacement, yet pairs stretch
    (A·r) and boundary images shift; and a strain set directly moves images without any motion.
    Both must trigger a rebuild before a contact is missed."""

    def test_affine_motion_and_strain_jump(self):
        rng = np.random.default_rng(5)
        Lx = Ly = 500.0
        n = 260
        x, y, r = random_configuration(rng, n, Lx, Ly, packing_fraction=0.8)
        ens = EnsembleLinkable(Lx, Ly, 0, k=0.0, nu=0.0, k_t=0.0, nu_t=0.0, mu=0.0)  # no forces: pure flow
        for p in range(n):
            ens.sphereList.append(SphereLinkable("grey", float(x[p]), float(y[p]), 2 * float(r[p]), 1.0, p + 1,
                                                 force_register=ens, size_x=Lx, size_y=Ly))
        ens.setShearRate(0.5)   # velocities follow the flow γ̇ (y − Ly/2) exactly
        dt = 0.01               # 0.005 strain per step
        missed = []

        def check(tag):
            ens.test_neighbor_relation()
            xs, ys, rs = ens.sphere_arrays["x"], ens.sphere_arrays["y"], ens.sphere_arrays["r"]
            want = oracle_pairs(xs, ys, rs, Lx, Ly, ens.shear)
            got = set(zip(*map(np.ndarray.tolist, ens.contact_pairs())))
            if got != want:
                missed.append((tag, len(want - got), len(got - want)))

        changes = 0
        for step in range(120):   # strain 0.6 in total
            before = set(zip(*map(np.ndarray.tolist, ens.contact_pairs())))
            check(step)
            changes += len(before ^ set(zip(*map(np.ndarray.tolist, ens.contact_pairs()))))
            ens.mechanical_simulation_step_calculate_forces()
            ens.mechanical_simulation_step_calculate_acceleration(1.0, dt)
            ens.mechanical_simulation_step_calculate_movement(dt)
        self.assertGreater(changes, 50)   # the flow really makes and breaks contacts
        ens.setShearRate(0.0)
        for jump in (0.3, -0.45, 0.05):
            ens.shear = ens.shear + jump   # images move, spheres do not
            check(f"jump {jump}")
        self.assertEqual(missed, [])


def _of_the_package(obj):
    """Whether ``obj`` is an object, function or frame of particleShear's own code."""
    import types
    if isinstance(obj, types.FrameType):
        return "particleShear" in obj.f_code.co_filename
    if isinstance(obj, (types.FunctionType, types.MethodType)):
        code = getattr(obj, "__code__", None) or getattr(obj.__func__, "__code__", None)
        return code is not None and "particleShear" in code.co_filename
    return type(obj).__module__.startswith("particleShear")


class TestStepLeavesNoCyclicGarbage(unittest.TestCase):
    """A protocol step frees its per-step arrays by reference counting alone.

    Per-step objects that refer to themselves (e.g. a pair structure holding a dictionary that holds
    the structure) wait for Python's cyclic collector; at N ≳ 10⁴ the memory they pin comes back in
    large batches that the allocator returns to the system and page-faults in again (measured: 6 →
    26 ms per step at N = 10,000).  With relations changing every step."""

    def test_no_cycles_per_step(self):
        import gc
        from particleShearTest.test_invariants import random_ensemble
        for seed in (11, 12):
            with self.subTest(seed=seed):
                ens = random_ensemble(60, 300.0, seed=seed)
                ens.makeAllLinksPermanent()
                ens.cutLine((150.0, 150.0), 0.3)
                ens.applyingShear = True
                ev = StressTensorEvaluation(300.0, 300.0)
                for _ in range(3):
                    ens.mechanical_simulation_step(cool_factor=0.9, dt=1e-7)
                gc.collect()
                gc.disable()
                gc.set_debug(gc.DEBUG_SAVEALL)       # what the collector finds stays in gc.garbage
                try:
                    for k in range(20):
                        ens.setShearRate(3000 * math.cos(0.3 * k))
                        ens.mechanical_simulation_step_calculate_forces()
                        ens.record_total_particle_forces()
                        ens.evaluate_stress_tensors(ev)
                        ens.mechanical_simulation_step_calculate_acceleration(0.9997, 1e-7)
                        ens.mechanical_simulation_step_calculate_movement(1e-7)
                        ens.reset_force()
                    gc.collect()
                    # a cycle made by the step holds an object, function or frame of the package;
                    # garbage of another thread of the test process (a pool's watcher) does not count
                    ours = [o for o in gc.garbage if _of_the_package(o)]
                    self.assertEqual(ours, [], f"{len(ours)} objects of the package in reference cycles")
                finally:
                    gc.set_debug(0)
                    gc.garbage.clear()
                    gc.enable()


if __name__ == "__main__":
    unittest.main()
