"""Spheres with parameters of their own, measured by the engine: each visit of a relation sees its
own sphere's c, permanent ratios and kept viscosities (1.0.2 evaluates a relation once from each
sphere, MODEL_SPEC, section 10; ``BatchState.visit``, ``PairConstants.set_visits``).

* Two spheres: the force on each is the law of its own visit — the compressive law of eq. S1-5 with
  its own c (against the independent definition of ``test_force_laws``), a bond's tensile law and
  its viscous force with its own permanent ratio — to rounding (1e-12 relative: one product and one
  sum of numbers ≈ 1e3).
* A constituted crosslinked scene whose spheres carry different c, permanent ratios and kept
  viscosities: the engine's measurement gives the documented classes' series and tensors to 1e-12
  of their scale (the two differ only in the order of sums; observed ≈ 5e-16).
* A replica with such spheres beside a uniform one: the batch equals the single runs bit for bit.
"""
import unittest

import numpy as np

from particleShear.engine.state import PER_SPHERE_PARAMETERS, PERMANENT, STICK, BatchState, ReplicaPairs
from particleShear.base.engine_adapter import state_from_ensembles
from particleShear.engine.step import BatchEngine, pre_equilibrate, protocol
from particleShear.simulation.experiment import OscillatoryShearExperiment
from particleShearTest.test_engine import classes_measurement, constituted
from particleShearTest.test_force_laws import central_law_definition as _definition
from particleShearTest.classes_loops import assert_same_register, classes_pre_equilibrate, classes_run_protocol


def state_block(ens):
    """The ensemble's per-sphere state, one row per field of ``FIELDS`` (a copy)."""
    return np.array(list(ens.sphere_arrays.values()))

K, NU = 1000.0, 7.0


def central_law_definition(d, d0, k, c):
    """The compressive law of eq. S1-5 from its independent definition (the value only)."""
    return _definition(d, d0, k, c)[0]


def two_spheres(d, visit, state=STICK, d_eq=0.0, v=0.0):
    """A batch of one with two spheres of radius 10 µm at distance ``d`` (µm) along x, sphere 1 moving
    at ``v`` µm/s away from sphere 0, no plates, and the per-sphere parameters ``visit`` (4, 2)."""
    s = BatchState(1, 2)
    s.x[:] = (100.0, 100.0 + d)
    s.y[:] = 100.0
    s.vx[:] = (0.0, v)
    s.r[:] = 10.0
    s.m[:] = s.inertia[:] = 1.0
    s.Lx[:] = s.Ly[:] = 400.0
    s.k[:], s.nu[:] = K, NU
    s.c[:], s.prc[:], s.prt[:], s.keep[:] = np.asarray(visit)[:, 0]
    s.visit = np.array(visit, dtype=float)
    s.applying_shear = False
    s.pairs[0] = ReplicaPairs([0], [1], [state], np.zeros((2, 1)), [d_eq], [state == PERMANENT])
    s.rng[0] = np.random.default_rng(0)
    eng = BatchEngine(s, guard=False)
    eng.force_phase()
    return s.fx.copy(), s.fy.copy()


def perturb(ens):
    """Give some spheres of ``ens`` parameters of their own through their handles."""
    n = len(ens.sphereList)
    for k in range(0, n, 3):
        ens.sphereList[k].permanent_ratio_central = 2.0
    for k in range(1, n, 4):
        ens.sphereList[k].permanent_ratio_tangential = 0.5
    for k in range(2, n, 5):
        ens.sphereList[k].central_repulsion_coefficient = 0.5
    for k in range(0, n, 7):
        ens.sphereList[k].keep_viscosity_coefficients_constant = 0.0


SCENE = dict(theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.2,
             keep_viscosity_coefficients_constant=True)


class TestTwoSpheres(unittest.TestCase):
    def assertClose(self, got, want):
        self.assertLessEqual(abs(got - want), 1e-12 * max(abs(want), 1.0), (got, want))

    def test_contact_each_sphere_its_own_c(self):
        d, c0, c1 = 17.0, 1.0, 0.4
        fx, fy = two_spheres(d, [[c0, c1], [1, 1], [1, 1], [1, 1]])
        # the force on i along n_ij = +x is the law of i's visit; j receives minus the law of its own
        self.assertClose(fx[0], central_law_definition(d, 20.0, K, c0))
        self.assertClose(fx[1], -central_law_definition(d, 20.0, K, c1))
        self.assertNotAlmostEqual(fx[0], -fx[1])          # the two laws differ at this overlap
        self.assertEqual(list(fy), [0.0, 0.0])

    def test_bond_each_sphere_its_own_permanent_ratio(self):
        d_eq = 19.0
        for d in (19.5, 18.5):          # stretched: the tensile law; compressed: the law at d_eq
            with self.subTest(d=d):
                fx, _ = two_spheres(d, [[1, 0.5], [2.0, 0.7], [1, 1], [1, 1]], state=PERMANENT, d_eq=d_eq)
                law_0 = K * (d - d_eq) if d > d_eq else central_law_definition(d, d_eq, K, 1.0)
                law_1 = K * (d - d_eq) if d > d_eq else central_law_definition(d, d_eq, K, 0.5)
                self.assertClose(fx[0], 2.0 * law_0)
                self.assertClose(fx[1], -0.7 * law_1)

    def test_bond_viscosity_kept_by_one_sphere_only(self):
        # at d = d_eq the elastic law is 0; the viscous force ν·v_n takes the permanent ratio where
        # the visiting sphere does not keep its viscosities (sphere 0), not where it does (sphere 1)
        v = 3.0
        fx, _ = two_spheres(19.0, [[1, 1], [2.0, 0.5], [1, 1], [0.0, 1.0]], state=PERMANENT, d_eq=19.0, v=v)
        self.assertClose(fx[0], NU * 2.0 * v)
        self.assertClose(fx[1], -NU * v)


class TestSceneAgainstClasses(unittest.TestCase):
    def test_series_and_tensors(self):
        _, ens_c, sc = constituted(7, **SCENE)
        _, ens_e, _ = constituted(7, **SCENE)
        perturb(ens_c)
        perturb(ens_e)
        ref = classes_measurement(ens_c, sc, keep_tensors=True)
        state = state_from_ensembles([ens_e])
        self.assertIsNotNone(state.visit)
        eng = BatchEngine(state)
        pre_equilibrate(eng, sc["N_pre"], sc["dt"], sc["dt_max"], sc["cool"])
        got = protocol(eng, sc["dt"], sc["f"], [sc["A"]], sc["cool"], 0.5, 1, 0.5, keep_tensors=True)
        self.assertGreater(len(ref["t"]), 200)
        for key in ("strain", "stress_internal", "stress_surface"):
            a, b = ref[key], got[key][:, 0]
            self.assertEqual(a.shape, b.shape)
            self.assertLessEqual(np.max(np.abs(a - b)), 1e-12 * np.max(np.abs(a)), key)
        a, b = np.asarray(ref["tensors"]), np.asarray(got["tensors"])[:, 0]
        for k in range(a.shape[1]):
            scale = np.max(np.abs(a[:, k]))
            self.assertLessEqual(np.max(np.abs(a[:, k] - b[:, k])), 1e-12 * scale, k)


class TestExperimentInTheEngine(unittest.TestCase):
    """``OscillatoryShearExperiment.oscillatory_shear_experiment`` of a script measures in the engine:
    on an ensemble of ``particleShear.objects`` (no ``dt`` of its own; frictionless or not) its series equal the classes'
    step loop to 1e-12 of their scale (sums in another order), and the ensemble is left in the final
    state of that loop (positions to 1e-12 of the cell: rounding over ~500 damped steps); the
    ensemble's stability guard guards it."""

    def test_objects_ensembles(self):
        from particleShear.objects.ensembles import EnsembleFrictionLeesEdwards, EnsembleLeesEdwards
        for cls, kw in ((EnsembleFrictionLeesEdwards, dict(mu=0.1, k_t=50, nu_t=0.1)), (EnsembleLeesEdwards, {})):
            with self.subTest(cls=cls.__name__):
                self.check_objects_ensemble(cls, kw)

    def check_objects_ensemble(self, cls, kw):
        def build():
            e = cls(200, 200, 0, packing_fraction=1.1, nu=0.5, k=100, **kw)
            e.set_random_generator(np.random.default_rng(5))
            e._create_spheres(20, 1)
            return e

        def experiment(e):
            exp = OscillatoryShearExperiment(e, 1e-3, 5.0, 0.05, False, dt_max=4e-3)
            exp.periods = 1
            return exp

        ens, ref = build(), build()
        self.assertFalse(hasattr(ens, "dt"))
        x = experiment(ens)
        G = x.oscillatory_shear_experiment(0.99, 4)
        y = experiment(ref)
        y.prepare_recording()
        ref.applyingShear = True
        classes_pre_equilibrate(y, 4, 0.99)
        ref.t = 0
        classes_run_protocol(y, 0.99)
        a, b = x.plotter.arrays(), y.plotter.arrays()
        self.assertEqual(len(a["t"]), len(b["t"]))
        for key in ("strain", "stress_internal", "stress_surface"):
            self.assertLessEqual(np.max(np.abs(a[key] - b[key])), 1e-12 * np.max(np.abs(b[key])), key)
        self.assertTrue(all(np.isfinite(G)))
        for name in ("x", "y"):
            self.assertLessEqual(np.max(np.abs(ens.sphere_arrays[name] - ref.sphere_arrays[name])), 1e-12 * 200, name)
        self.assertEqual((ens.t, ens.shear, ens.step_count), (ref.t, ref.shear, ref.step_count))
        # the force register holds the last step's forces, as the step loop leaves it
        assert_same_register(self, ens, ref)
        self.assertGreater(len(ens.force_register.pair_register), 0)
        self.assertEqual(len(ens.force_register.internal_moment_register) > 0, "k_t" in kw)   # tangential visits
        # the same relations, numbered in the order they formed (the order of ``neighbors``)
        pe, pr = ens.pair_table, ref.pair_table
        self.assertEqual(pe.key[pe.active].tolist(), pr.key[pr.active].tolist())
        self.assertEqual(pe.birth[pe.active].tolist(), pr.birth[pr.active].tolist())
        self.assertEqual(pe.birth_count, pr.birth_count)


    def test_register_and_tensors_after_the_protocol(self):
        # spheres with parameters of their own (j's visits have forces of their own): after a script's
        # run_protocol the six register lists are those of the step loop's last step, and so are the
        # tensors a script evaluates from the register afterwards (of the moved spheres, as after the loop)
        from particleShear.base.stress import StressTensorEvaluation
        runs = []
        for loops in (False, True):
            _, ens, sc = constituted(7, **SCENE)
            perturb(ens)
            exp = OscillatoryShearExperiment(ens, sc["dt"], sc["f"], sc["A"], False, dt_max=sc["dt_max"])
            exp.baseline_pre_periods, exp.periods, exp.baseline_post_periods = 0.5, 1, 0.5
            exp.keep_tensor_history = True
            if loops:
                classes_pre_equilibrate(exp, 4, sc["cool"])
                ens.t = 0
                classes_run_protocol(exp, sc["cool"], 80)
            else:
                exp.pre_equilibrate(4, sc["cool"])
                exp.run_protocol(sc["cool"], 80)
            runs.append((ens, exp))
        (ens, exp), (ref, _) = runs
        assert_same_register(self, ens, ref)
        got, want = (e.evaluate_stress_tensors(StressTensorEvaluation(e.size_x, e.size_y)).tensors for e in (ens, ref))
        scale = np.abs(want).max()
        self.assertGreater(scale, 0.0)
        for k in range(len(want)):
            self.assertLessEqual(np.abs(got[k] - want[k]).max(), 1e-12 * scale, k)

    def test_guard_of_the_ensemble(self):
        # the thresholds of the ensemble's StabilityGuard reach the engine's guard: a bound on the
        # kinetic energy far below that of any moving packing (1e-30) stops the run at the first check
        from particleShear.base.stability import SimulationInstabilityError, StabilityGuard
        _, ens, sc = constituted(7, **SCENE)
        ens.stability_guard = StabilityGuard(max_kinetic_energy=1e-30, interval=1)
        exp = OscillatoryShearExperiment(ens, sc["dt"], sc["f"], sc["A"], False, dt_max=sc["dt_max"])
        with self.assertRaises(SimulationInstabilityError) as caught:
            exp.oscillatory_shear_experiment(sc["cool"], sc["N_pre"])
        self.assertIn("kinetic energy", str(caught.exception))
        self.assertEqual(caught.exception.phase, "pre-equilibration")

    def test_a_failed_run_leaves_the_ensemble_as_it_was(self):
        # the engine steps the ensemble's own spheres and pair table; a run stopped by its guard (here
        # after a few steps of a protocol and of a relaxation) puts them back, so a retry starts from them
        from particleShear.base.stability import SimulationInstabilityError, StabilityGuard
        from particleShear.base.engine_adapter import relax_ensembles
        from particleShear.engine.step import EngineInstability
        _, ens, sc = constituted(7, **SCENE)
        exp = OscillatoryShearExperiment(ens, sc["dt"], sc["f"], sc["A"], False, dt_max=sc["dt_max"])
        exp.pre_equilibrate(4, sc["cool"])
        n = len(ens.sphereList)
        for run in ("protocol", "relaxation"):
            with self.subTest(run=run):
                block, pt = state_block(ens), ens.pair_table
                state = (ens.t, ens.shear, ens.step_count, ens.phase, ens.pair_table.birth_count)
                ens.stability_guard = StabilityGuard(max_kinetic_energy=1e-30, interval=8)
                with self.assertRaises(SimulationInstabilityError if run == "protocol" else EngineInstability):
                    exp.run_protocol(sc["cool"]) if run == "protocol" else relax_ensembles([ens], 20)
                ens.stability_guard = None
                self.assertEqual(state_block(ens).tobytes(), block.tobytes())
                for name in ("key", "state", "xi", "d_eq", "active", "birth"):
                    self.assertEqual(getattr(ens.pair_table, name).tobytes(), getattr(pt, name).tobytes(), name)
                self.assertEqual((ens.t, ens.shear, ens.step_count, ens.phase, ens.pair_table.birth_count), state)
        # ... and a run after it is the run of an ensemble that never failed
        _, ref, _ = constituted(7, **SCENE)
        x_ref = OscillatoryShearExperiment(ref, sc["dt"], sc["f"], sc["A"], False, dt_max=sc["dt_max"])
        x_ref.pre_equilibrate(4, sc["cool"])
        for e, x in ((ens, exp), (ref, x_ref)):
            x.run_protocol(sc["cool"], 30)
        self.assertEqual(state_block(ens).tobytes(), state_block(ref).tobytes())
        self.assertEqual(exp.plotter.arrays()["stress_surface"].tobytes(), x_ref.plotter.arrays()["stress_surface"].tobytes())


class TestBatchOfOwnAndShared(unittest.TestCase):
    def test_replicas_equal_their_single_runs(self):
        sc = constituted(5, **SCENE)[2]

        def ensemble(n):
            e = constituted(5 + n, **SCENE)[1]
            if n == 0:
                perturb(e)
            return e

        def measure(which):
            ensembles = [ensemble(n) for n in which]
            state = state_from_ensembles(ensembles)
            eng = BatchEngine(state)
            pre_equilibrate(eng, sc["N_pre"], sc["dt"], sc["dt_max"], sc["cool"])
            return state, protocol(eng, sc["dt"], sc["f"], [sc["A"]] * len(which), sc["cool"], 0.5, 1, 0.5), ensembles

        single = [measure([n]) for n in (0, 1)]
        self.assertIsNotNone(single[0][0].visit)
        self.assertIsNone(single[1][0].visit)        # shared parameters: one value per replica
        state, both, ensembles = measure([0, 1])
        # every sphere of the batch carries its own ensemble's values, the shared replica's included
        for k, name in enumerate(PER_SPHERE_PARAMETERS):
            want = np.concatenate([np.asarray(e.sphere_arrays[name][:state.N], dtype=float) for e in ensembles])
            np.testing.assert_array_equal(state.visit[k], want, name)
        for b in range(2):
            for key in ("stress_internal", "stress_surface", "strain"):
                self.assertEqual(both[key][:, b].tobytes(), single[b][1][key][:, 0].tobytes(), (b, key))


if __name__ == "__main__":
    unittest.main()
