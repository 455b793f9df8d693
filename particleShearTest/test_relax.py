"""The constitution's relaxation in the engine (particleShear.engine.relax) against its definition.

* Over short blocks the engine's free relaxation follows the documented classes' step loop of
  ``free_pre_equilibration`` (MODEL_SPEC, section 6.3, written out here with
  ``mechanical_simulation_step``) on the same ensemble: both integrate the same equations, the
  engine with its sums in another order, so positions and velocities agree to rounding.  Over 40–80
  steps rounding of ~1e-16 per operation grows by at most a few orders of magnitude in a damped
  system; 1e-12 of each quantity's scale leaves room for that and still fails for any
  difference of physics (one step more or less, a missed contact or a wrong μ moves spheres by
  ≫ 1e-6 of their scale).  The relations and their states are the same sets, numbered in the same
  order of formation.
* A relaxed random packing is relaxed: the damped levels remove most of the elastic energy of
  the random placement and the large overlaps.
* The drift removal gives each replica zero mean velocity (the classes' unweighted mean).
* A replica's relaxation is the same bit for bit with or without companions.
"""
import unittest

import numpy as np

from particleShear.engine.box import min_image
from particleShear.base.engine_adapter import relax_ensembles
from particleShear.engine.relax import relaxation_levels, remove_linear_drift
from particleShear.engine.state import BatchState
from particleShear.base.engine_adapter import state_from_ensembles, state_of_ensemble, state_of_ensembles
from particleShear.linkable.builders import adjustable_interface_constitution, relax_constitution


def state_block(ens):
    """The ensemble's per-sphere state, one row per field of ``FIELDS`` (a copy)."""
    return np.array(list(ens.sphere_arrays.values()))


#: a small scene of the run API's builder (nominal area fraction 1: a jammed packing)
SCENE = dict(N=40, packing_fraction=1.0, mu=0.1, Young_modulus_spheres=1000, cut_lines=3, anticipated_amplitude=0.1,
             central_repulsion_coefficient=1, doDrawing=False)

SPHERE_ROWS = ("x", "y", "phi", "xspeed", "yspeed", "omega")


def random_packing(seed, **kw):
    """The builder's ensemble at its first relaxation: spheres placed at random, at rest."""
    return next(adjustable_interface_constitution(**dict(SCENE, rng=seed, **kw))).ensemble


def constituted(seed, **kw):
    """A relaxed, crosslinked and cut ensemble (the builder with a tenth of its relaxation)."""
    return relax_constitution(adjustable_interface_constitution(**dict(SCENE, rng=seed, do_debug=True, **kw)))


def classes_free_pre_equilibration(ens, N):
    """The relaxation of MODEL_SPEC section 6.3 stepped by the documented classes: N frictionless steps
    per level from ``dt_max`` (damping 0.5 moving half-way to 1 per level, the step halved, the mean
    velocity removed) while the level step exceeds ``dt``, N frictionless and N frictional steps at
    ``dt``; shear off, μ restored."""
    def steps(n, cool, dt):
        for _ in range(n):
            ens.mechanical_simulation_step(cool, dt)
        ens.n_constitution_steps += n

    ens.applyingShear = False
    mu = ens.mu
    ens.mu = 0
    level_dt, cool = ens.dt_max, 0.5
    while level_dt > ens.dt:
        steps(N, cool, level_dt)
        level_dt /= 2
        cool = (1 + cool) / 2
        ens.correct_linear_drift()
    steps(N, 1, ens.dt)
    ens.mu = mu
    steps(N, 1, ens.dt)


class TestAgainstTheClasses(unittest.TestCase):
    def assert_same_relaxation(self, ref, eng, N, min_bonds=0):
        """The classes' step loop of ``free_pre_equilibration(N)`` against the engine's, on a copy
        (:func:`relax_ensembles`, and ``free_pre_equilibration`` itself every other call)."""
        a, b = ref.sphere_arrays, eng.sphere_arrays
        self.assertTrue(all(np.array_equal(a[k], b[k]) for k in SPHERE_ROWS))   # the same start
        n_levels = len(relaxation_levels(ref.dt, ref.dt_max))
        before = ref.n_constitution_steps
        classes_free_pre_equilibration(ref, N)
        self._calls = getattr(self, "_calls", 0) + 1
        if self._calls % 2:
            steps = relax_ensembles([eng], N)
        else:
            start = eng.n_constitution_steps
            eng.free_pre_equilibration(N)
            steps = eng.n_constitution_steps - start
        # the schedule's definition: N steps per coarse level, then two blocks of N at dt
        self.assertEqual(steps, N * (n_levels + 2))
        self.assertEqual(ref.n_constitution_steps - before, steps)
        self.assertEqual(eng.n_constitution_steps, ref.n_constitution_steps)
        self.assertAlmostEqual(eng.t, ref.t, delta=1e-12 * ref.t)
        self.assertEqual(eng.mu, ref.mu)
        for k in SPHERE_ROWS:
            a, b = ref.sphere_arrays[k], eng.sphere_arrays[k]
            scale = np.abs(a).max()   # 0 only for ω and φ without tangential forces: then both exactly 0
            self.assertTrue(scale > 0.0 or k in ("omega", "phi"), k)
            self.assertLessEqual(np.abs(a - b).max(), 1e-12 * scale, k)
        # the relations (and so what the crosslinking links) and their states are the same
        pr, pe = ref.pair_table, eng.pair_table
        self.assertEqual(pr.key[pr.active].tolist(), pe.key[pe.active].tolist())
        self.assertEqual(pr.state[pr.active].tolist(), pe.state[pe.active].tolist())
        # ... created in the same order (creation numbers order ``neighbors``)
        self.assertEqual(pr.birth[pr.active].tolist(), pe.birth[pe.active].tolist())
        self.assertEqual(pr.birth_count, pe.birth_count)
        self.assertGreaterEqual(int((pe.state == 2).sum()), min_bonds)
        xr, xe = pr.xi[:, pr.active], pe.xi[:, pe.active]
        self.assertLessEqual(np.abs(xr - xe).max(), 1e-12 * max(np.abs(xr).max(), 1e-300))
        return ref, eng

    def test_random_packing_levels_and_final_blocks(self):
        # two coarse levels (4 dt, 2 dt; damped, frictionless, drift removed) and the two blocks at dt
        ref, eng = random_packing(3), random_packing(3)
        for e in (ref, eng):
            e.dt_max = 4 * e.dt
        self.assertEqual(len(relaxation_levels(ref.dt, ref.dt_max)), 2)
        self.assert_same_relaxation(ref, eng, 20)
        # friction acted in the last block: some contact sticks with a history
        self.assertGreater(np.abs(eng.pair_table.xi).max(), 0.0)

    def test_velocity_verlet(self):
        # an ensemble set to velocity Verlet relaxes with it (the engine's predictor, the classes' step)
        ref, eng = random_packing(3), random_packing(3)
        for e in (ref, eng):
            e.dt_max = 2 * e.dt
            e.set_integrator("verlet")
        self.assert_same_relaxation(ref, eng, 20)

    def test_crosslinked_ensemble_with_bonds_and_friction(self):
        # after crosslinking and cutting (bonds scaled by 1/irc, 1/irt): one level at 2 dt, then dt
        kw = dict(mu=0.3, interface_reenforcement_central=2, interface_reenforcement_tangential=1.5)
        ref, eng = constituted(5, **kw), constituted(5, **kw)
        self.assertEqual(len(relaxation_levels(ref.dt, ref.dt_max)), 1)
        self.assert_same_relaxation(ref, eng, 30, min_bonds=20)

    def test_frictionless_without_viscosity(self):
        # μ = 0 and no bonds: the classes skip the tangential kernel (every contact slips, ξ = 0)
        ref, eng = random_packing(4, mu=0.0, relative_viscosity=0.0), random_packing(4, mu=0.0, relative_viscosity=0.0)
        for e in (ref, eng):
            e.dt_max = 2 * e.dt
        ref, eng = self.assert_same_relaxation(ref, eng, 20)
        pe = eng.pair_table
        self.assertTrue(np.all(pe.xi == 0.0))
        self.assertTrue(np.all(pe.state[pe.active] == 1))   # SLIP

    def test_mu_zero_blocks_of_the_builder(self):
        # the builder's "μ = 0: free(n)" block: the ensemble's μ is 0 while it runs, restored after
        from particleShear.linkable.builders import Relaxation, _free_mu0
        ref, eng = constituted(6), constituted(6)
        for e in (ref, eng):
            e.dt_max = 2 * e.dt
        seen = []
        for e, serve in ((ref, lambda r: classes_free_pre_equilibration(r.ensemble, r.N)), (eng, lambda r: r.run())):
            gen = _free_mu0(e, 15, 0.1)
            request = next(gen)
            self.assertIsInstance(request, Relaxation)
            seen.append(request.key)
            self.assertEqual(e.mu, 0)
            serve(request)
            with self.assertRaises(StopIteration):
                next(gen)
            self.assertEqual(e.mu, 0.1)
        self.assertEqual(seen[0], seen[1])
        for k in SPHERE_ROWS:
            scale = np.abs(ref.sphere_arrays[k]).max()
            self.assertLessEqual(np.abs(ref.sphere_arrays[k] - eng.sphere_arrays[k]).max(), 1e-12 * scale, k)


def energies(e):
    """Kinetic energy, elastic energy ½k·overlap² of the linear law (c = 0) and the largest
    relative overlap of an ensemble (all pairs; reference units)."""
    a = e.sphere_arrays
    n = len(e.sphereList)
    i, j = np.triu_indices(n, 1)
    dx, dy, _, _ = min_image(a["x"][j] - a["x"][i], a["y"][j] - a["y"][i], e.size_x, e.size_y, 0.0)
    d0 = a["r"][i] + a["r"][j]
    overlap = np.maximum(d0 - np.hypot(dx, dy), 0.0)
    kinetic = 0.5 * np.sum(a["m"] * (a["xspeed"] ** 2 + a["yspeed"] ** 2) + a["inertia"] * a["omega"] ** 2)
    return kinetic, 0.5 * e.k * np.sum(overlap ** 2), float((overlap / d0).max())


class TestRelaxedState(unittest.TestCase):
    def test_relaxation_removes_the_energy_of_the_random_placement(self):
        # the builder's first relaxation (300 steps per level) of random packings with the linear law:
        # the placement overlaps spheres by up to ~90 % of their contact distance and stores all its
        # energy elastically; the damped levels remove it.  Observed: total energy 4–7 % of the start,
        # kinetic energy < 0.4 % of it, largest overlap < 19 %; bounds with a margin of ~2×.
        for seed in (4, 5, 6):
            with self.subTest(seed=seed):
                gen = adjustable_interface_constitution(**dict(SCENE, N=60, central_repulsion_coefficient=0, rng=seed))
                request = next(gen)
                e = request.ensemble
                k0, u0, ov0 = energies(e)
                self.assertEqual(k0, 0.0)
                self.assertGreater(ov0, 0.8)
                relax_ensembles([e], request.N)
                k1, u1, ov1 = energies(e)
                self.assertLess(k1 + u1, 0.15 * u0)
                self.assertLess(k1, 0.01 * u0)
                self.assertLess(ov1, 0.3)


class TestDriftRemoval(unittest.TestCase):
    def test_zero_mean_velocity_per_replica(self):
        # three replicas with different drifts: each loses its own mean velocity, to rounding of a sum
        # of N terms (N·ε relative to the largest velocity), and keeps its velocity differences
        rng = np.random.default_rng(1)
        s = BatchState(3, 50)
        s.vx[...] = rng.normal(size=150) + np.repeat([5.0, -3.0, 0.0], 50)
        s.vy[...] = rng.normal(size=150) * 2 + np.repeat([0.0, 7.0, -1.0], 50)
        before = (s.vx.copy(), s.vy.copy())
        remove_linear_drift(s)
        for b in range(3):
            rows = s.replica(b)
            for v, v0 in zip((s.vx, s.vy), before):
                scale = np.abs(v0[rows]).max()
                self.assertLessEqual(abs(v[rows].mean()), 50 * np.finfo(float).eps * scale)
                d, d0 = np.diff(v[rows]), np.diff(v0[rows])
                self.assertLessEqual(np.abs(d - d0).max(), 4 * np.finfo(float).eps * scale)


class TestBatchIndependence(unittest.TestCase):
    def test_replica_alone_equals_replica_in_a_batch(self):
        a1, a2 = random_packing(8), random_packing(8)
        other = random_packing(9, mu=0.0)
        for e in (a1, a2, other):
            e.dt_max = 4 * e.dt
        relax_ensembles([a1], 15)
        relax_ensembles([other, a2], 15)
        for k in SPHERE_ROWS:
            self.assertEqual(a1.sphere_arrays[k].tobytes(), a2.sphere_arrays[k].tobytes(), k)
        for name in ("key", "state", "xi", "d_eq", "active", "birth"):
            self.assertEqual(getattr(a1.pair_table, name).tobytes(), getattr(a2.pair_table, name).tobytes(), name)
        self.assertEqual(a1.t, a2.t)

    def test_result_does_not_depend_on_the_verlet_skin(self):
        # the candidate list only has to contain every contact: a thin skin (more rebuilds, fewer
        # candidates) and a thick one give the same contacts, and the zero terms of the other
        # candidates change no sum, so the same bits
        a, b = random_packing(10), random_packing(10)
        relax_ensembles([a], 40, skin_factor=0.5)
        relax_ensembles([b], 40, skin_factor=0.1)
        for k in SPHERE_ROWS:
            self.assertEqual(a.sphere_arrays[k].tobytes(), b.sphere_arrays[k].tobytes(), k)
        pa, pb = a.pair_table, b.pair_table
        self.assertEqual(pa.key[pa.active].tolist(), pb.key[pb.active].tolist())
        # the creation numbers follow the relations through the list rebuilds
        self.assertEqual(pa.birth[pa.active].tolist(), pb.birth[pb.active].tolist())
        self.assertEqual(pa.birth_count, pb.birth_count)

    def test_mismatched_schedules_are_refused(self):
        a, b = random_packing(1), random_packing(2)
        b.dt_max = 2 * b.dt
        with self.assertRaisesRegex(ValueError, "dt_max"):
            relax_ensembles([a, b], 5)
        with self.assertRaisesRegex(ValueError, "dt="):
            relaxation_levels(0.0, 1.0)
        with self.assertRaisesRegex(ValueError, "dt_max="):
            relaxation_levels(1.0, float("inf"))

    def test_write_back_needs_the_relations_numbered(self):
        # an engine that did not number its relations as they formed cannot give the ensemble the
        # order of its neighbors: refused, and the ensemble is left as it was
        from particleShear.base.engine_adapter import write_back
        from particleShear.engine.step import BatchEngine
        a = random_packing(3)
        eng = BatchEngine(state_of_ensemble(a), numbers_relations=False)
        eng.step(1.0, a.dt)
        x, t = a.sphere_arrays["x"].copy(), a.t
        with self.assertRaisesRegex(ValueError, "numbers_relations"):
            write_back(eng, 0, a)
        self.assertEqual((a.sphere_arrays["x"].tobytes(), a.t), (x.tobytes(), t))

    def test_write_back_needs_the_ensembles_own_state(self):
        # a copy of the ensemble (state_from_ensembles) is not handed back: the engine's spheres are not
        # the ensemble's, and nothing copies them
        from particleShear.base.engine_adapter import write_back
        from particleShear.engine.step import BatchEngine
        a, b = random_packing(3), random_packing(4)
        eng = BatchEngine(state_from_ensembles([a]), numbers_relations=True)
        eng.step(1.0, a.dt)
        with self.assertRaisesRegex(ValueError, "own state"):
            write_back(eng, 0, a)
        both = BatchEngine(state_of_ensembles([a, b]))
        with self.assertRaisesRegex(ValueError, "own state"):
            write_back(both, 0, b)

    def test_a_batch_steps_the_ensembles_own_rows(self):
        # state_of_ensembles: the batch's sphere arrays are the ensembles' rows, so a relaxed batch leaves
        # each ensemble exactly where the engine put its replica
        from particleShear.engine.step import BatchEngine
        a, b = random_packing(5), random_packing(6)
        s = state_of_ensembles([a, b])
        eng = BatchEngine(s)
        for _ in range(5):
            eng.step(1.0, a.dt)
        for k, e in enumerate((a, b)):
            rows = s.replica(k)
            for name, src in (("x", "x"), ("yspeed", "vy"), ("omega", "omega"), ("xforce", "fx")):
                self.assertEqual(e.sphere_arrays[name].tobytes(), getattr(s, src)[rows].tobytes())
            # replica k's pair list is the ensemble's own table: an edit there is the ensemble's
            d_eq = e.pair_table.d_eq
            self.assertGreater(len(d_eq), 0)
            s.pairs[k].d_eq[0] += 1.0
            self.assertEqual(e.pair_table.d_eq[0], d_eq[0] + 1.0)
        with self.assertRaisesRegex(ValueError, "twice"):
            state_of_ensembles([a, a])

    def test_rows_and_blocks_of_the_wrong_shape_are_refused(self):
        # a state on external rows needs B·N columns, an ensemble's block one row per field and one
        # column per sphere: anything else is refused before it is used
        import numpy as np

        from particleShear.base.fields import FIELDS
        from particleShear.engine.state import BatchState
        s = BatchState(2, 3)
        rows = dict(pos=np.zeros((2, 6)), vel=np.zeros((3, 6)), frc=np.zeros((3, 6)), phi=np.zeros(6),
                    r=np.ones(6), m=np.ones(6), inertia=np.ones(6))
        s.use_rows(**rows)
        self.assertIs(s.x.base, rows["pos"])         # the state's x is a view of the caller's rows
        with self.assertRaisesRegex(ValueError, r"pos has shape \(2, 5\).*\(2, 6\)"):
            s.use_rows(**{**rows, "pos": np.zeros((2, 5))})
        a = random_packing(5)
        with self.assertRaisesRegex(ValueError, "block has shape"):
            a.adopt_state_block(np.zeros((len(FIELDS), len(a.sphereList) + 1)))

    def test_a_refused_batch_leaves_the_ensembles_stepping_as_before(self):
        # a batch refused before any step (guards that differ, an unusable skin) leaves each ensemble
        # to step on exactly as its twin that was never batched, also one that kept the documented
        # step's engine on its block (the blocks a batch moves drop what was cached on them)
        from particleShear.base.stability import StabilityGuard
        for refuse in ("guards", "skin"):
            with self.subTest(refuse=refuse):
                a, b, twin = random_packing(3), random_packing(4), random_packing(3)
                for e in (a, twin):
                    e.mechanical_simulation_step(1, e.dt)
                if refuse == "guards":
                    a.stability_guard, b.stability_guard = StabilityGuard(interval=4), StabilityGuard(interval=8)
                with self.assertRaises(ValueError):
                    relax_ensembles([a, b], 2, **({"skin_factor": -1.0} if refuse == "skin" else {}))
                a.stability_guard = None
                for _ in range(3):
                    for e in (a, twin):
                        e.mechanical_simulation_step(1, e.dt)
                self.assertEqual(state_block(a).tobytes(), state_block(twin).tobytes())

    def test_a_failed_batch_leaves_every_ensemble_as_it_was(self):
        # the batch steps the ensembles' own rows: when one replica's guard stops it (a bound on the
        # kinetic energy no moving packing meets), every ensemble of the batch is put back, and a
        # retry gives the relaxation of ensembles that never failed
        from particleShear.base.stability import StabilityGuard
        from particleShear.engine.step import EngineInstability
        a, b = random_packing(7), random_packing(8)
        ra, rb = random_packing(7), random_packing(8)
        before = [(state_block(e), e.pair_table, e.t, e.step_count) for e in (a, b)]
        b.stability_guard = StabilityGuard(max_kinetic_energy=1e-30, interval=4)
        with self.assertRaises(EngineInstability):
            relax_ensembles([a, b], 6)
        for e, (block, pt, t, steps) in zip((a, b), before):
            self.assertEqual(state_block(e).tobytes(), block.tobytes())
            for name in ("key", "state", "xi", "active", "birth"):
                self.assertEqual(getattr(e.pair_table, name).tobytes(), getattr(pt, name).tobytes(), name)
            self.assertEqual((e.t, e.step_count), (t, steps))
        b.stability_guard = None
        relax_ensembles([a, b], 6)
        relax_ensembles([ra, rb], 6)
        for e, r in ((a, ra), (b, rb)):
            self.assertEqual(state_block(e).tobytes(), state_block(r).tobytes())
            self.assertEqual(e.pair_table.key.tobytes(), r.pair_table.key.tobytes())


if __name__ == "__main__":
    unittest.main()
