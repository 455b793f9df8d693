"""The engine's kernels as pure functions, and the engine's measurement against the documented classes.

* ``box.min_image`` gives the nearest Lees-Edwards image (checked against every image of a
  5×5 block) in the half-open intervals; ``box.wrap`` puts spheres in the cell at an equivalent
  image with the velocity of that image.
* ``laws.central_law`` is the law of eq. S1-5a/b with the cap of eq. S1-6 (checked against the
  definition written out in ``test_force_laws.central_law_definition`` and its defining properties:
  zero at contact, slope k, cap).
* ``neighbours.build_candidates`` holds every pair within ``r_i + r_j + skin`` of an all-pairs
  search over all images, and the Verlet bound keeps every contact of a sheared run in the list.
* The engine's measurement (pre-equilibration + protocol) of a constituted ensemble gives the
  τ_internal and τ_surface series of the documented classes' experiment to ≤ 1e-12 of the series'
  scale: both evaluate the same laws, differing only in the order of sums (rounding ≈ 1e-16,
  observed ≤ 2e-15 after ~600 steps) — with the Euler and with the velocity Verlet integrator.
"""
import math
import unittest

import numpy as np

from particleShear.engine.box import min_image, wrap
from particleShear.engine.laws import central_law, tensile_law
from particleShear.engine.neighbours import build_candidates, verlet_bound
from particleShear.engine.state import PERMANENT, BatchState, ReplicaPairs
from particleShear.base.engine_adapter import ensembles_of, state_from_ensembles, state_of_ensemble
from particleShear.engine.step import BatchEngine, pre_equilibrate, protocol
from particleShear.run.api import _build_simulation, _seed_sequence
from particleShear.run.batch import _REFERENCE_ARGUMENTS, _signature_defaults
from particleShear.simulation.experiment import OscillatoryShearExperiment
from particleShearTest.test_force_laws import central_law_definition
from particleShearTest.classes_loops import classes_pre_equilibrate, classes_run_protocol


def brute_image(dx, dy, Lx, Ly, shift):
    """Nearest image over a 5×5 block of images: (dx, dy) of the smallest |Δ|."""
    best = None
    for ky in range(-2, 3):
        for kx in range(-2, 3):
            ex = dx - ky * shift - kx * Lx
            ey = dy - ky * Ly
            d = ex * ex + ey * ey
            best = (d, ex, ey) if best is None or d < best[0] else best
    return best[1], best[2]


class TestBox(unittest.TestCase):
    def test_min_image_is_nearest_image(self):
        rng = np.random.default_rng(1)
        Lx, Ly = 300.0, 200.0
        for gamma in (0.0, 0.3, -0.45, 1.7):
            shift = Ly * gamma
            dx = rng.uniform(-Lx, Lx, 400)
            dy = rng.uniform(-Ly, Ly, 400)
            mx, my, ky, kx = min_image(dx, dy, Lx, Ly, shift)
            self.assertTrue(np.all((-Ly / 2 <= my) & (my < Ly / 2)))
            self.assertTrue(np.all((-Lx / 2 <= mx) & (mx < Lx / 2)))
            # counts reproduce the image (to rounding of the subtractions: |Δ| ≤ ~1000 µm, ε·1000 ≈ 2e-13 µm;
            # 1e-9 µm is far below any wrong image, which is off by a period of ≥ 200 µm)
            np.testing.assert_allclose(mx, dx - ky * shift - kx * Lx, rtol=0, atol=1e-9)
            np.testing.assert_allclose(my, dy - ky * Ly, rtol=0, atol=1e-9)
            # separations well inside the cell are the nearest image
            close = np.hypot(mx, my) < min(Lx, Ly) / 4
            self.assertGreater(int(close.sum()), 20)          # the comparison below is not vacuous
            for k in np.flatnonzero(close):
                ex, ey = brute_image(dx[k], dy[k], Lx, Ly, shift)
                self.assertAlmostEqual(mx[k], ex, delta=1e-9)
                self.assertAlmostEqual(my[k], ey, delta=1e-9)

    def test_wrap_equivalent_image_and_velocity(self):
        rng = np.random.default_rng(2)
        Lx, Ly, gamma, rate = 300.0, 200.0, 0.35, 40.0
        x0 = rng.uniform(-Lx, 2 * Lx, 500)
        y0 = rng.uniform(-Ly * 0.9, 1.9 * Ly, 500)
        vx0 = rng.normal(0, 1, 500)
        x, y, vx = x0.copy(), y0.copy(), vx0.copy()
        ones = np.ones(500)
        wrap(x, y, vx, Lx * ones, Ly * ones, Ly * gamma * ones, rate * ones)
        self.assertTrue(np.all((0 <= x) & (x < Lx) & (0 <= y) & (y < Ly)))
        ky = np.round((y0 - y) / Ly)                  # periods removed in y (up = +1)
        self.assertTrue(np.all(np.abs(y0 - ky * Ly - y) < 1e-9))
        # the same point of the sheared lattice: x0 − ky·Ly·γ, modulo Lx
        rem = np.mod(x0 - ky * Ly * gamma - x + Lx / 2, Lx) - Lx / 2
        self.assertLess(np.max(np.abs(rem)), 1e-9)
        # the image moves with the flow: vx changes by −ky·Ly·γ̇
        np.testing.assert_allclose(vx, vx0 - ky * Ly * rate, rtol=0, atol=1e-9)


class TestLaws(unittest.TestCase):
    def test_central_law_is_its_definition(self):
        # against eq. S1-5a/b and S1-6 written out in the test (not against base.laws, which shares the
        # engine's arithmetic); other grouping of the constants: ≤ 1e-14 of the terms' magnitude
        rng = np.random.default_rng(3)
        d0 = rng.uniform(10, 30, 300)
        d = d0 * rng.uniform(0.0001, 1.3, 300)
        for c in (0.0, 0.4, 1.0):
            for k in (1.0, 3.1e9):
                got = central_law(d, d0, k, c)
                ref, scale = np.array([central_law_definition(float(a), float(b), k, c) for a, b in zip(d, d0)]).T
                self.assertTrue(np.all(np.abs(got - ref) <= 1e-14 * scale))
                self.assertTrue(np.all(got[d > d0] == 0.0))

    def test_defining_properties(self):
        k, d0 = 2.0, 10.0
        self.assertEqual(central_law(np.array([d0]), d0, k, 1.0)[0], 0.0)      # zero at contact
        self.assertEqual(central_law(np.array([11.0]), d0, k, 0.5)[0], 0.0)    # nothing beyond contact
        h = 1e-6   # truncation c·h/(d0 − h) ≈ 1e-7 relative, rounding ε·k·d0/(k·h) ≈ 2e-9: 1e-4 is ample
        for c in (0.0, 0.5, 1.0):                                               # slope k at contact
            slope = (central_law(np.array([d0]), d0, k, c)[0] - central_law(np.array([d0 - h]), d0, k, c)[0]) / h
            self.assertAlmostEqual(slope, k, delta=1e-4 * k)
        cap = central_law(np.array([d0 / 1e6]), d0, k, 1.0)[0]                  # eq. S1-6: −999·k·d0 (a few roundings)
        self.assertAlmostEqual(cap, -999 * k * d0, delta=1e-9 * k * d0)
        self.assertEqual(tensile_law(12.0, 10.0, 3.0), 6.0)


class TestNeighbours(unittest.TestCase):
    def test_candidates_hold_every_near_pair_and_the_bonds(self):
        rng = np.random.default_rng(4)
        N, Lx, Ly, gamma, skin = 120, 200.0, 180.0, 0.27, 3.0
        x, y = rng.uniform(0, Lx, N), rng.uniform(0, Ly, N)
        r = rng.uniform(6, 10, N)
        old = ReplicaPairs([0, 3], [117, 5], [PERMANENT, 0], [[1.5, 0.0], [-0.5, 0.0]], [30.0, 0.0], [True, False])
        new = build_candidates(x, y, r, Lx, Ly, Ly * gamma, skin, old)
        have = set(zip(new.i.tolist(), new.j.tolist()))
        self.assertEqual(sorted(have), list(zip(new.i.tolist(), new.j.tolist())))   # canonical order
        for i in range(N):
            for j in range(i + 1, N):
                ex, ey = brute_image(x[j] - x[i], y[j] - y[i], Lx, Ly, Ly * gamma)
                if math.hypot(ex, ey) < r[i] + r[j] + skin:
                    self.assertIn((i, j), have)
        k = list(zip(new.i.tolist(), new.j.tolist())).index((0, 117))   # the bond is kept with its history
        self.assertEqual((int(new.state[k]), new.xi[0, k], new.xi[1, k], new.d_eq[k]), (PERMANENT, 1.5, -0.5, 30.0))

    def test_bound(self):
        self.assertEqual(verlet_bound(0.0, 0.0, 5.0), 0.0)
        self.assertEqual(verlet_bound(1.0, 0.0, 5.0), 2.0)
        self.assertEqual(verlet_bound(0.0, 0.1, 5.0), 1.0)


def constituted(seed, N=30, **kw):
    """A constituted ensemble of N spheres of the run API's builder and its schedule."""
    p = dict(_signature_defaults(), seed=seed, N=N, relative_frequency=0.2, pre_periods=0.5, periods=1,
             post_periods=0.5, doDrawing=False, plotStress=False, **kw)
    _, rng = _seed_sequence(seed)
    sim = _build_simulation({k: p[k] for k in _REFERENCE_ARGUMENTS}, rng, verbose=False, progress=None,
                            correct_drift_sign=False, reference_header=False, renderer="none", time_step_factor=1.0,
                            integrator="euler", stability_guard=False)
    sim.initEnsemble()
    e = sim.theEnsemble
    f = p["relative_frequency"] / sim.model.time_constant
    cool = p["cool_factor"] ** (1 / (1 / f / e.dt))
    return sim, e, dict(dt=e.dt, dt_max=e.dt_max, f=f, A=p["theAmplitude"], cool=cool,
                        N_pre=25 * int(sim.adjustment_factor_for_bounded_preequilibration_steps()))


def classes_measurement(ens, sc, keep_tensors=False):
    """The documented classes' step loop of the experiment (:mod:`particleShearTest.classes_loops`)
    of ``ens`` with schedule ``sc`` (0.5 + 1 + 0.5 periods): the recorded arrays of its plotter."""
    exp = OscillatoryShearExperiment(ens, sc["dt"], sc["f"], sc["A"], False, dt_max=sc["dt_max"])
    exp.baseline_pre_periods, exp.periods, exp.baseline_post_periods = 0.5, 1, 0.5
    exp.keep_tensor_history = keep_tensors
    ens.applyingShear = True
    exp.prepare_recording()
    classes_pre_equilibrate(exp, sc["N_pre"], sc["cool"])
    ens.t = 0
    classes_run_protocol(exp, sc["cool"])
    return exp.plotter.arrays()


class TestEngineAgainstClasses(unittest.TestCase):
    SCENES = (dict(theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.2),
              dict(theMu=0.0, do_permanent_links=True, cut_lines=3, theAmplitude=0.3),
              dict(theMu=0.3, do_permanent_links=False, cut_lines=0, theAmplitude=0.1))

    def test_measurement_series(self):
        cases = [(n, scene, "euler") for n, scene in enumerate(self.SCENES)] + [(0, self.SCENES[0], "verlet"),
                                                                               (1, self.SCENES[1], "verlet")]
        for n, scene, integrator in cases:
            with self.subTest(scene=n, integrator=integrator):
                _, ens_c, sc = constituted(7 + n, **scene)
                _, ens_e, _ = constituted(7 + n, **scene)
                ens_c.set_integrator(integrator)
                ref = classes_measurement(ens_c, sc)
                eng = BatchEngine(state_from_ensembles([ens_e]), integrator=integrator)
                pre_equilibrate(eng, sc["N_pre"], sc["dt"], sc["dt_max"], sc["cool"])
                got = protocol(eng, sc["dt"], sc["f"], [sc["A"]], sc["cool"], 0.5, 1, 0.5)
                self.assertGreater(len(ref["t"]), 200)
                for key in ("t", "strain", "strain_rate", "stress_internal", "stress_surface"):
                    a, b = ref[key], got[key][:, 0]
                    self.assertEqual(a.shape, b.shape)
                    self.assertLessEqual(np.max(np.abs(a - b)), 1e-12 * np.max(np.abs(a)), key)
                self.assertGreater(np.max(np.abs(ref["stress_surface"])), 0.0)


class TestFrictionlessReplicas(unittest.TestCase):
    """A replica with μ = 0 and no bond has no tangential force (Coulomb bound 0): the engine leaves
    the term out for it, so its relations all slip with ξ = 0 (the classes' rule), alone or beside a
    frictional replica, and a batch of both equals the single runs bit for bit."""

    def test_free_replica_alone_and_in_a_mixed_batch(self):
        scenes = [dict(theMu=mu, do_permanent_links=False, cut_lines=0, theAmplitude=0.2) for mu in (0.0, 0.3)]
        sc = constituted(3, **scenes[0])[2]

        def measure(which):
            ensembles = [constituted(3 + n, **scenes[n])[1] for n in which]
            eng = BatchEngine(state_from_ensembles(ensembles))
            pre_equilibrate(eng, sc["N_pre"], sc["dt"], sc["dt_max"], sc["cool"])
            return eng, protocol(eng, sc["dt"], sc["f"], [sc["A"]] * len(ensembles), sc["cool"], 0.5, 1, 0.5)

        single = [measure([n])[1] for n in (0, 1)]
        eng, both = measure([0, 1])
        for b in range(2):
            for key in ("stress_internal", "stress_surface", "strain"):
                self.assertEqual(both[key][:, b].tobytes(), single[b][key][:, 0].tobytes(), (b, key))
        # the free replica: every relation slips and carries no history; the frictional one sticks somewhere
        p0, p1 = eng.pairs_of(0), eng.pairs_of(1)
        self.assertGreater(int(p0.active.sum()), 0)
        self.assertTrue(np.all(p0.state[p0.active] == 1))
        self.assertTrue(np.all(p0.xi == 0.0))
        self.assertTrue(np.any(p1.state[p1.active] == 0))
        self.assertTrue(np.any(p1.xi != 0.0))


def two_sphere_replicas(specs, backend="auto"):
    """A batch state of two spheres per replica: each spec ``(positions, vy, mu, seed)`` (radius 1 µm,
    unit masses, a 10 µm cell, plates on), the pair (0, 1) a candidate."""
    s = BatchState(len(specs), 2, backend=backend)
    s.r[:], s.m[:], s.inertia[:] = 1.0, 1.0, 0.5
    s.Lx[:] = s.Ly[:] = 10.0
    s.k[:], s.nu[:], s.k_t[:], s.nu_t[:] = 1.0, 0.1, 1.0, 0.1
    s.prc[:] = s.prt[:] = s.keep[:] = 1.0
    for b, (xy, vy, mu, seed) in enumerate(specs):
        s.x[2 * b:2 * b + 2], s.y[2 * b:2 * b + 2] = xy
        s.vy[2 * b:2 * b + 2] = vy
        s.mu[b] = mu
        s.pairs[b] = ReplicaPairs([0], [1], [0], np.zeros((2, 1)), [0.0], [False])
        s.rng[b] = np.random.default_rng(seed)
    return s


class TestFrictionlessReplicaDrawsNothingForXi(unittest.TestCase):
    """A replica without friction or bonds has no ξ to integrate, so the ξ rule draws no random
    direction for it (at |R| = 0), alone or in a batch: two coincident spheres resting in the
    plate band (immobile, so R = 0 every step) beside a frictional replica give the single run's
    numbers and leave the replica's generator where the single run leaves it."""

    def test_coincident_plate_spheres_beside_a_frictional_replica(self):
        free = (([5.0, 5.0], [0.5, 0.5]), [0.0, 0.0], 0.0, 1)
        rough = (([5.0, 6.5], [5.0, 5.0]), [0.0, 1.0], 0.5, 2)     # sliding past each other
        runs = []
        for specs in ([free], [rough], [free, rough]):
            eng = BatchEngine(two_sphere_replicas(specs), guard=False)
            for _ in range(6):
                eng.step(1.0, 1e-3)
            runs.append(eng)
        batch = runs[2].s
        for b, single in enumerate(runs[:2]):
            rows = slice(2 * b, 2 * b + 2)
            for name in ("x", "y", "vx", "vy", "omega", "fx", "fy", "torque"):
                self.assertEqual(getattr(batch, name)[rows].tobytes(), getattr(single.s, name).tobytes(), (b, name))
            self.assertEqual(batch.rng[b].random(), single.s.rng[0].random(), b)
        # the free replica drew one direction per step, for its normal at d = 0 in the force phase
        # (the classes draw the same and integrate no ξ for it); nothing for the ξ rule
        expected = np.random.default_rng(1)
        for _ in range(6 + 1):
            expected.random()
        self.assertEqual(batch.rng[0].random(), expected.random())
        self.assertTrue(np.any(runs[2].s.contacts.xi[:, 1] != 0.0))        # the frictional pair sticks and integrates ξ


class TestStressRegistry(unittest.TestCase):
    """Every engine tensor against the documented classes' StressTensorEvaluation along a protocol
    (same states to ≈ 1e-15, see above; tolerance 1e-12 of the pressure scale, or of the tensor's own
    scale for the small kinetic terms), and the registry's names and output columns."""

    def test_tensors_along_a_protocol(self):
        from particleShear.base.stress import StressTensorEvaluation
        from particleShear.engine.stress import TENSORS
        _, ens_c, sc = constituted(21, theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.3)
        _, ens_e, _ = constituted(21, theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.3)
        ref = classes_measurement(ens_c, sc, keep_tensors=True)["tensors"]
        eng = BatchEngine(state_from_ensembles([ens_e]))
        pre_equilibrate(eng, sc["N_pre"], sc["dt"], sc["dt_max"], sc["cool"])
        got = protocol(eng, sc["dt"], sc["f"], [sc["A"]], sc["cool"], 0.5, 1, 0.5, keep_tensors=True)
        # every registry name is a documented tensor attribute of the classes (2×2 nested lists)
        probe = StressTensorEvaluation(100.0, 100.0)
        for t in TENSORS:
            value = getattr(probe, t.name)
            self.assertEqual(np.asarray(value).shape, (2, 2), t.name)
        tens = got["tensors"][:, 0]
        self.assertEqual(tens.shape, ref.shape)
        p = np.max(np.abs(ref[:, 0, 0, 0])) + np.max(np.abs(ref[:, 0, 1, 1]))
        for k, t in enumerate(TENSORS):
            with self.subTest(tensor=t.name):
                scale = p if t.name not in ("stress_tensor_spin_kinetic_energy",
                                            "stress_tensor_linear_acceleration_otsuki") \
                    else np.max(np.abs(ref[:, k])) + 1e-300
                self.assertGreater(np.max(np.abs(ref[:, k])), 0.0)
                self.assertLessEqual(np.max(np.abs(tens[:, k] - ref[:, k])), 1e-12 * scale)
        # the shear stresses G uses are the xy entries of the overall and external tensors bit for bit:
        # the same row sums in the one formula (engine.forces.shear_from_sums)
        np.testing.assert_array_equal(got["stress_internal"][:, 0], -tens[:, 8, 0, 1])
        np.testing.assert_array_equal(got["stress_surface"][:, 0], -tens[:, 2, 0, 1])

    def test_shear_stresses_are_the_tensors_xy_entries_with_sphere_parameters(self):
        """Spheres with parameters of their own (j's visit has its own central force, F_j ≠ F_i): the
        shear stresses of a step without tensors are the xy entries of the tensors of the same step,
        bit for bit, and each replica of a batch of two has the tensors of its single run."""
        def scene(seed):
            _, ens, sc = constituted(seed, theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.3)
            for s in ens.sphereList[::3]:
                s.permanent_ratio_central = 2.0
                s.permanent_ratio_tangential = 3.0
            ens.setShearRate(300.0)
            return ens, sc
        runs = {}
        for sample in (True, "tensors"):
            engines = [BatchEngine(state_from_ensembles([scene(seed)[0]]), guard=False) for seed in (3, 4)]
            batch = BatchEngine(state_from_ensembles([scene(seed)[0] for seed in (3, 4)]), guard=False)
            dt = scene(3)[1]["dt"]
            runs[sample] = [[e.step(0.999, dt, sample=sample) for _ in range(20)] for e in engines + [batch]]
            self.assertIsNotNone(batch.s.contacts.C.Kj)
        for k in range(20):
            for b in range(2):
                for r in range(2):      # τ_internal, τ_surface: single run, with or without tensors, batch
                    tau = runs[True][b][k][r][0]
                    self.assertEqual(runs["tensors"][b][k][r][0], tau)
                    self.assertEqual(runs["tensors"][2][k][r][b], tau)
                    self.assertEqual(runs[True][2][k][r][b], tau)
                T = runs["tensors"][b][k][2][0]
                self.assertEqual(T.tobytes(), runs["tensors"][2][k][2][b].tobytes())
                self.assertEqual(-T[8, 0, 1], runs[True][b][k][0][0])
                self.assertEqual(-T[2, 0, 1], runs[True][b][k][1][0])
        self.assertNotEqual(runs[True][0][-1][1][0], 0.0)

    def test_registry_matches_output_columns(self):
        from particleShear.engine.stress import TENSORS
        from particleShear.simulation.output import TABLE_COLUMNS
        stems = [c[:-3] for c in TABLE_COLUMNS if c.endswith("_00")]
        self.assertEqual([t.stem for t in TENSORS], stems)


class TestStateOfOneEnsemble(unittest.TestCase):
    """``state_of_ensemble``: the batch of one whose sphere arrays are the ensemble's own rows.
    The engine's steps on it write into the ensemble, and they are the steps of a copy
    (``state_from_ensembles``) bit for bit: the same arithmetic on the same numbers."""

    def test_steps_write_into_the_ensemble_as_on_a_copy(self):
        _, ens_v, sc = constituted(13, theMu=0.05, do_permanent_links=True, cut_lines=1)
        _, ens_c, _ = constituted(13, theMu=0.05, do_permanent_links=True, cut_lines=1)
        view, copy = state_of_ensemble(ens_v), state_from_ensembles([ens_c])
        self.assertEqual(ensembles_of(view), [ens_v])
        self.assertIsNone(ensembles_of(copy))
        for name, row in (("x", "x"), ("vy", "yspeed"), ("omega", "omega"), ("fx", "xforce"), ("r", "r")):
            self.assertTrue(np.shares_memory(getattr(view, name), ens_v.sphere_arrays[row]), name)
            self.assertFalse(np.shares_memory(getattr(copy, name), ens_c.sphere_arrays[row]), name)
        x0 = ens_c.sphere_arrays["x"].copy()
        ev, ec = BatchEngine(view), BatchEngine(copy)
        for e in (ev, ec):
            e.s.applying_shear = True
            e.set_rate(np.array([0.2]))
            for _ in range(60):
                e.step(0.99, sc["dt"])
        self.assertEqual(ens_c.sphere_arrays["x"].tobytes(), x0.tobytes())   # a copy leaves the ensemble alone
        self.assertFalse(np.array_equal(ens_v.sphere_arrays["x"], x0))        # the view moved the ensemble's spheres
        for name in BatchState.SPHERE_ARRAYS:
            self.assertEqual(getattr(view, name).tobytes(), getattr(copy, name).tobytes(), name)
        # a pickled (or device) copy of the view is no longer the ensemble's rows
        import pickle
        self.assertIsNone(ensembles_of(pickle.loads(pickle.dumps(view))))
        self.assertIsNone(ensembles_of(view.to_backend("numba")))


    def test_documented_steps_keep_their_state_through_appends(self):
        """The documented step fits the ensemble's state block to its spheres (contiguous (2|3, N) rows
        for the engine); a sphere appended between steps keeps its numbers, the old spheres theirs, and
        the next step runs on all of them."""
        from particleShear import SphereLinkable
        _, ens, sc = constituted(19, theMu=0.05, do_permanent_links=True, cut_lines=1)
        ens.setShearRate(200.0)
        for _ in range(5):
            ens.mechanical_simulation_step(0.99, sc["dt"])
        for name in ("_pos", "_vel", "_frc"):
            self.assertTrue(getattr(ens, name).flags["C_CONTIGUOUS"], name)
        a = ens.sphere_arrays
        before = {name: a[name].copy() for name in ("x", "y", "xspeed", "yspeed", "omega", "r", "m")}
        r = float(np.median(a["r"]))
        new = SphereLinkable("grey", 0.5 * ens.size_x, 0.5 * ens.size_y, 2 * r, float(np.median(a["m"])),
                             len(ens.sphereList), force_register=ens, size_x=ens.size_x, size_y=ens.size_y)
        ens.sphereList.append(new)
        for name, old in before.items():
            self.assertEqual(ens.sphere_arrays[name][:-1].tobytes(), old.tobytes(), name)
        self.assertEqual((ens.sphere_arrays["x"][-1], ens.sphere_arrays["y"][-1]), (new.x, new.y))
        ens.mechanical_simulation_step(0.99, sc["dt"])
        for name in ("_pos", "_vel", "_frc"):
            self.assertTrue(getattr(ens, name).flags["C_CONTIGUOUS"], name)
        self.assertTrue(all(np.isfinite(ens.sphere_arrays[k]).all() for k in ("x", "y")))
        self.assertEqual(ens._engine.s.N, len(ens.sphereList))


class TestPhasesOneByOne(unittest.TestCase):
    """A script's ``pre_equilibrate`` then ``run_protocol`` is the measurement of
    ``oscillatory_shear_experiment`` bit for bit: the same loops of the engine on the ensemble's own
    state, the Verlet predictor carried from one phase to the next through the ensemble; a
    ``run_protocol`` stopped after n steps is the first n steps, its evaluator holding the n-th
    step's tensors."""

    def test_phases_one_by_one_equal_the_whole_experiment(self):
        for integrator in ("euler", "verlet"):
            with self.subTest(integrator=integrator):
                runs = []
                for stop in (None, None, 40):
                    _, ens, sc = constituted(17, theMu=0.05, do_permanent_links=True, cut_lines=2)
                    ens.set_integrator(integrator)
                    exp = OscillatoryShearExperiment(ens, sc["dt"], sc["f"], sc["A"], False, dt_max=sc["dt_max"])
                    exp.baseline_pre_periods, exp.periods, exp.baseline_post_periods = 0.5, 1, 0.5
                    exp.keep_tensor_history = True
                    if not runs:
                        record, _ = exp.measure_in_engine(sc["cool"], sc["N_pre"])
                    else:
                        exp.pre_equilibrate(sc["N_pre"], sc["cool"])
                        self.assertEqual(ens.phase, "pre-equilibration")
                        self.assertEqual(exp.run_protocol(sc["cool"], stop), len(exp.plotter.arrays()["t"]))
                        record = exp.plotter.arrays()
                    runs.append((ens, exp, record))
                (e1, _, whole), (e2, x2, parts), (_, x3, first) = runs
                self.assertGreater(len(whole["t"]), 200)
                for key in ("t", "strain", "strain_rate", "stress_internal", "stress_surface", "tensors"):
                    self.assertEqual(np.asarray(whole[key]).tobytes(), parts[key].tobytes(), key)
                    self.assertEqual(np.asarray(whole[key])[:40].tobytes(), first[key].tobytes(), key)
                for row in ("x", "y", "phi", "xspeed", "yspeed", "omega"):
                    self.assertEqual(e1.sphere_arrays[row].tobytes(), e2.sphere_arrays[row].tobytes(), row)
                self.assertEqual((e1.t, e1.shear, e1.step_count, e1.phase), (e2.t, e2.shear, e2.step_count, "protocol"))
                self.assertEqual(e1.pair_table.birth.tobytes(), e2.pair_table.birth.tobytes())
                np.testing.assert_array_equal(x2.theEvaluator.tensors, np.asarray(whole["tensors"])[-1])
                np.testing.assert_array_equal(x3.theEvaluator.tensors, np.asarray(whole["tensors"])[39])
                self.assertEqual(x3.N_steps, 40)


class TestVerletListKeepsEveryContact(unittest.TestCase):
    def test_contacts_equal_all_pairs_during_shear(self):
        _, ens, sc = constituted(11, theMu=0.05, do_permanent_links=False, cut_lines=0, theAmplitude=0.5)
        s = state_from_ensembles([ens])
        eng = BatchEngine(s, skin_factor=0.2, guard=False)   # a thin skin: many rebuilds, the bound is exercised
        s.applying_shear = True
        rate = np.array([0.5 * 2 * math.pi * sc["f"] * 8])   # 8× the protocol's peak rate
        eng.set_rate(rate)
        N, Lx, Ly = s.N, s.Lx[0], s.Ly[0]
        i, j = np.triu_indices(N, 1)
        for step in range(300):
            eng.neighbours()
            dx, dy, _, _ = min_image(s.x[j] - s.x[i], s.y[j] - s.y[i], Lx, Ly, Ly * s.gamma[0])
            touching = set(zip(i[np.hypot(dx, dy) < s.r[i] + s.r[j]].tolist(),
                               j[np.hypot(dx, dy) < s.r[i] + s.r[j]].tolist()))
            cand = set(zip((eng.s.contacts.C.ai).tolist(), (eng.s.contacts.C.aj).tolist()))
            self.assertLessEqual(touching, cand, f"step {step}")
            eng.step(1.0, sc["dt"])
        self.assertGreater(int(eng.s.contacts.rebuilds[0]), 3)
        self.assertGreater(abs(s.gamma[0]), 0.01)


if __name__ == "__main__":
    unittest.main()
