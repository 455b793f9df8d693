"""Contact laws through the engine: the registry (particleShear.engine.laws), the run parameter
``contact_law`` with the plateau parameters, the documented callbacks, and a law added in the one place.

The analytic forces are the laws' formulas written out here, independently of the package; the
engine's force on sphere 1 of a two-sphere scene at rest along +x is the law's value (n_12 = +x,
no viscous or tangential force at rest).  Their tolerance, 1e-13 relative, covers the different
association of a few O(1) floating-point operations.  Batches are compared to single runs bit for
bit (docs/engine.md, "Runs").
"""
import math
import os
import tempfile
import unittest

import numpy as np

from particleShear import (CircleBasicElasticity, PlateauConfiguration, SphereLinkable, doParticleShearSimulation,
                           elastic_force_law, elastic_force_law_plateau, elastic_force_law_tensile)
from particleShear.engine import laws
from particleShear.base.engine_adapter import state_from_ensembles
from particleShear.engine.step import BatchEngine
from particleShear.run.batch import batches, run_batch
from particleShear.simulation.output import sidecar_path
from particleShearTest.test_batch import QUICK, InlineExecutor, assert_same_result
from particleShearTest.test_cli import run_main
from particleShearTest.test_force_laws import _pair_scene

RTOL = 1e-13
K, D0 = 2.0, 120.0          # spring constant and contact distance of _pair_scene


def plateau_analytic(d, d0, k, c, begin, end, slope):
    """The plateau law written out: the default law of the transformed distance (0 beyond contact)."""
    if d > d0:
        return 0.0
    pb, pe = begin * d0, end * d0
    if d >= pe:
        dp = d
    elif d >= pb:
        dp = pe + (d - pe) * slope
    else:
        dp = d * (pe + (pb - pe) * slope) / pb
    return -k * (1 - c) * (d0 - dp) - k * c * d0 * (d0 / max(dp, d0 / 1000) - 1)


def hertz(d, d0, k, c):
    """Hertz-like law: ``f = −k·d0·(1 − d/d0)^(3/2)`` inside contact (c unused)."""
    return -k * d0 * np.maximum(1 - d / d0, 0.0) ** 1.5


def engine_force(d, laws_=None, link=False, c=0.0, stretch=None):
    """x force on sphere 1 of the two-sphere scene at distance d, from one engine step.

    The step's kick gives sphere 1 (at rest, mass 1, no damping) ``v_x = F_x·dt/m``; with
    ``dt = 2⁻³⁰`` the scaling is exact, so ``F_x = v_x·m/dt`` is the force of the force phase."""
    ens, s1, s2 = _pair_scene(d, link=link, c=c)
    if stretch is not None:
        s2.x = 200.0 + stretch
    s = state_from_ensembles([ens], laws=laws_)
    s.applying_shear = False
    dt = 2.0 ** -30
    BatchEngine(s, guard=False).step(1.0, dt)
    return float(s.vx[0]) * float(s.m[0]) / dt


class ClassCallbacks(unittest.TestCase):
    """Restores the documented callbacks and the plateau configuration after each test."""

    def setUp(self):
        self._saved = (CircleBasicElasticity.__dict__["call_back_elastic_force_law"],
                       SphereLinkable.__dict__["call_back_elastic_force_law_tensile"], PlateauConfiguration.values())

    def tearDown(self):
        CircleBasicElasticity.call_back_elastic_force_law = self._saved[0]
        SphereLinkable.call_back_elastic_force_law_tensile = self._saved[1]
        (PlateauConfiguration.relative_plateau_begin, PlateauConfiguration.relative_plateau_end,
         PlateauConfiguration.relative_plateau_slope) = self._saved[2]


class TestPlateauThroughTheEngine(ClassCallbacks):
    # distances below the plateau, on it, above it, at and beyond contact (d0 = 120)
    DISTANCES = (10.0, 30.0, 50.0, 90.0, 110.0, 120.0, 125.0)

    def test_two_spheres_against_the_analytic_force(self):
        for params in ((0.3, 0.8, 0.1), (0.2, 0.9, 0.0), (0.45, 0.6, 1.0)):
            for c in (0.0, 0.5, 1.0):
                for d in self.DISTANCES:
                    with self.subTest(params=params, c=c, d=d):
                        got = engine_force(d, [("plateau", params)], c=c)
                        ref = plateau_analytic(d, D0, K, c, *params)
                        self.assertLessEqual(abs(got - ref), RTOL * abs(ref), (got, ref))
                        if d >= D0:
                            self.assertEqual(got, 0.0)

    def test_laws_differ_on_the_plateau(self):
        # a physical check of the test itself: on the plateau the force is smaller than the linear law's
        self.assertLess(abs(engine_force(60.0, [("plateau", (0.3, 0.8, 0.1))])), abs(engine_force(60.0)))

    def test_bonds_take_the_law_below_and_the_tensile_law_above_d_eq(self):
        params = (0.3, 0.8, 0.1)
        got = engine_force(60.0, [("plateau", params)], link=True, c=1.0)
        ref = plateau_analytic(60.0, D0, K, 1.0, *params)
        self.assertLessEqual(abs(got - ref), RTOL * abs(ref))
        # the bond (d_eq = r_i + r_j = 120) stretched to 130: attraction k (d − d_eq) towards +x
        got = engine_force(100.0, [("plateau", params)], link=True, stretch=130.0)
        self.assertLessEqual(abs(got - K * 10.0), RTOL * K * 10.0)

    def test_class_attribute_way_equals_the_parameter(self):
        CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
        (PlateauConfiguration.relative_plateau_begin, PlateauConfiguration.relative_plateau_end,
         PlateauConfiguration.relative_plateau_slope) = (0.25, 0.7, 0.2)
        for d in self.DISTANCES:
            with self.subTest(d=d):
                by_callback = engine_force(d, c=0.5)
                CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law
                by_parameter = engine_force(d, [("plateau", (0.25, 0.7, 0.2))], c=0.5)
                CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
                self.assertEqual(by_callback, by_parameter)

    def test_one_law_per_batch(self):
        ens, _, _ = _pair_scene(60.0)
        ens2, _, _ = _pair_scene(60.0)
        with self.assertRaisesRegex(ValueError, "laws="):
            state_from_ensembles([ens, ens2], laws=[("plateau", (0.3, 0.8, 0.1)), None])


class TestPlateauRuns(ClassCallbacks):
    RUNS = [dict(QUICK, seed=21, theMu=0.05, do_permanent_links=True, cut_lines=2, contact_law="plateau"),
            dict(QUICK, seed=22, theMu=0.05, do_permanent_links=True, cut_lines=2, contact_law="plateau",
                 plateau_begin=0.2, plateau_end=0.9, plateau_slope=0.3),
            dict(QUICK, seed=23, theMu=0.05, do_permanent_links=False, cut_lines=0, contact_law="plateau",
                 plateau_begin=0.4, plateau_end=0.6, plateau_slope=0.0),
            dict(QUICK, seed=24, theMu=0.05, do_permanent_links=True, cut_lines=0, contact_law="plateau",
                 plateau_slope=1.0, central_repulsion_coefficient=0.5)]

    @classmethod
    def setUpClass(cls):
        cls.batch = run_batch(cls.RUNS)
        cls.single = [doParticleShearSimulation(**kw, return_result=True) for kw in cls.RUNS]

    def test_batch_of_four_equals_the_single_runs(self):
        self.assertEqual(len(batches(self.RUNS, 4)), 1)       # one batch: the parameters are per replica
        for a, b in zip(self.batch, self.single):
            assert_same_result(self, a, b)

    def test_the_law_changes_the_moduli(self):
        linear = doParticleShearSimulation(**dict(self.RUNS[0], contact_law="linear"), return_result=True)
        self.assertNotEqual(linear.G_surface, self.single[0].G_surface)
        # the parameters matter: two replicas of one seed with other plateaus give other moduli
        other = doParticleShearSimulation(**dict(self.RUNS[0], plateau_slope=0.5), return_result=True)
        self.assertNotEqual(other.G_surface, self.single[0].G_surface)

    def test_parameter_equals_the_class_attribute_way(self):
        kw = dict(self.RUNS[1])
        CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
        (PlateauConfiguration.relative_plateau_begin, PlateauConfiguration.relative_plateau_end,
         PlateauConfiguration.relative_plateau_slope) = (kw.pop("plateau_begin"), kw.pop("plateau_end"),
                                                         kw.pop("plateau_slope"))
        kw.pop("contact_law")
        by_class = doParticleShearSimulation(**kw, return_result=True)
        a, b = by_class, self.single[1]
        for key in a.series:
            self.assertEqual(np.asarray(a.series[key]).tobytes(), np.asarray(b.series[key]).tobytes(), key)
        self.assertEqual((a.G_surface, a.G_internal), (b.G_surface, b.G_internal))

    def test_drawn_run_runs_the_same_law(self):
        # a drawn run is the engine's run with observers: the law's numbers bit for bit, and the
        # documented callback is left as it was
        drawn = doParticleShearSimulation(**dict(self.RUNS[1], doDrawing=True, renderer="none"), return_result=True)
        self.assertIs(CircleBasicElasticity.__dict__["call_back_elastic_force_law"], self._saved[0])
        for key in ("stress_surface", "stress_internal"):
            a, b = np.asarray(drawn.series[key]), np.asarray(self.single[1].series[key])
            self.assertEqual(a.tobytes(), b.tobytes(), key)

    def test_the_law_must_agree_within_a_batch(self):
        mixed = [self.RUNS[0], dict(self.RUNS[0], contact_law="linear", seed=5)]
        self.assertEqual(len(batches(mixed, 4)), 2)
        with self.assertRaisesRegex(ValueError, "contact_law"):
            run_batch(mixed)

    def test_recorded_in_header_sidecar_and_table(self):
        import json

        from particleShear.sweep.runner import run_sweep
        with tempfile.TemporaryDirectory() as tmp:
            res = doParticleShearSimulation(**dict(self.RUNS[1], root_folder=tmp, saveData=True), return_result=True)
            with open(res.output_path) as fh:
                self.assertIn("\n\tContact law: plateau (plateau_begin 0.2, plateau_end 0.9, plateau_slope 0.3)\n",
                              fh.read())
            with open(sidecar_path(res.output_path)) as fh:
                p = json.load(fh)["parameters"]
            self.assertEqual((p["contact_law"], p["plateau_begin"], p["plateau_end"], p["plateau_slope"]),
                             ("plateau", 0.2, 0.9, 0.3))
            spec = {"parameters": {k: v for k, v in self.RUNS[2].items() if k not in ("seed", "verbose", "plateau_slope")},
                    "grid": {"plateau_slope": [0.0, 0.5]}, "seeds": {"root": 4}}
            rows = run_sweep(spec, os.path.join(tmp, "sweep"), executor=InlineExecutor(), progress=False)
            self.assertEqual([(r["contact_law"], r["plateau_slope"]) for r in rows], [("plateau", 0.0),
                                                                                      ("plateau", 0.5)])
            self.assertNotEqual(rows[0]["Gp_surface"], rows[1]["Gp_surface"])


class TestRunIdentity(unittest.TestCase):
    def test_plateau_parameters_name_a_run_of_the_plateau_law_only(self):
        from particleShear.simulation.provenance import run_identity
        base = dict(QUICK, seed=1)

        def rid(**kw):
            return run_identity(dict(base, **kw), 1, ())
        # a linear run does not depend on the plateau parameters, and "linear" is the run without the parameter
        self.assertEqual(rid(), rid(contact_law="linear", plateau_slope=0.5))
        self.assertNotEqual(rid(), rid(contact_law="plateau"))
        self.assertNotEqual(rid(contact_law="plateau"), rid(contact_law="plateau", plateau_slope=0.5))


class TestUserCallbacks(ClassCallbacks):
    """A law assigned to the documented callbacks runs in the engine: on arrays, or pair by pair."""

    KW = dict(QUICK, seed=31, theMu=0.05, do_permanent_links=True, cut_lines=2)

    @staticmethod
    def cubic_arrays(d, d0, k, c):
        return -k * (d0 - d) * (1 + (d0 - d) / d0)

    @staticmethod
    def cubic_numbers(d, d0, k, c):
        if not isinstance(d, float):
            raise TypeError("numbers only")
        return -k * (d0 - d) * (1 + (d0 - d) / d0)

    def run_with(self, central, tensile=None, **kw):
        CircleBasicElasticity.call_back_elastic_force_law = central
        if tensile is not None:
            SphereLinkable.call_back_elastic_force_law_tensile = tensile
        return doParticleShearSimulation(**dict(self.KW, **kw), return_result=True)

    def test_scalar_only_law_equals_its_array_form(self):
        calls = []

        def counted(d, d0, k, c):
            calls.append(d)
            return self.cubic_numbers(d, d0, k, c)
        by_pair = self.run_with(counted)
        self.assertGreater(len(calls), 1000)        # pair by pair, numbers only
        by_array = self.run_with(self.cubic_arrays)
        for key in by_pair.series:
            self.assertEqual(np.asarray(by_pair.series[key]).tobytes(), np.asarray(by_array.series[key]).tobytes(), key)
        self.assertNotEqual(by_pair.G_surface, self.run_with(elastic_force_law).G_surface)

    def test_scalar_only_tensile_law_equals_its_array_form(self):
        def tensile_numbers(d, d_eq, k):
            if not isinstance(d, float):
                raise TypeError("numbers only")
            return 1.5 * k * (d - d_eq)

        def tensile_arrays(d, d_eq, k):
            return 1.5 * k * (d - d_eq)
        # a loose packing sheared far: bonds stretch beyond d_eq (at φ = 1.5 every bond stays compressed)
        loose = dict(packing_fraction=1.0, theAmplitude=0.5)
        a = self.run_with(elastic_force_law, tensile_numbers, **loose)
        b = self.run_with(elastic_force_law, tensile_arrays, **loose)
        for key in a.series:
            self.assertEqual(np.asarray(a.series[key]).tobytes(), np.asarray(b.series[key]).tobytes(), key)
        builtin = self.run_with(elastic_force_law, elastic_force_law_tensile, **loose)
        self.assertNotEqual(a.G_surface, builtin.G_surface)
        # and on two linked spheres stretched from d_eq = 120 to 130: 1.5 k (d − d_eq) towards +x
        SphereLinkable.call_back_elastic_force_law_tensile = tensile_numbers
        self.assertLessEqual(abs(engine_force(100.0, link=True, stretch=130.0) - 1.5 * K * 10.0), RTOL * 30.0)

    def test_two_spheres_with_a_scalar_law(self):
        CircleBasicElasticity.call_back_elastic_force_law = self.cubic_numbers
        for d in (60.0, 100.0, 130.0):
            ref = 0.0 if d > D0 else -K * (D0 - d) * (1 + (D0 - d) / D0)
            self.assertLessEqual(abs(engine_force(d) - ref), RTOL * abs(ref))


class TestAddingALaw(unittest.TestCase):
    """Deliverable 7 of issue 20: a law registered in the one place runs in scenes and batches."""

    def setUp(self):
        laws.register_law("hertz_like", hertz)

    def tearDown(self):
        laws.unregister_law("hertz_like")

    def test_two_spheres_against_the_analytic_force(self):
        for d in (20.0, 60.0, 100.0, 119.0, 120.0, 121.0):
            with self.subTest(d=d):
                ref = -K * D0 * math.pow(1 - d / D0, 1.5) if d < D0 else 0.0
                got = engine_force(d, [("hertz_like", ())])
                self.assertLessEqual(abs(got - ref), RTOL * abs(ref), (got, ref))

    def test_batch_of_two_equals_the_single_runs(self):
        runs = [dict(QUICK, seed=41, theMu=0.05, do_permanent_links=True, cut_lines=2, contact_law="hertz_like"),
                dict(QUICK, seed=42, theMu=0.02, do_permanent_links=False, cut_lines=0, contact_law="hertz_like")]
        batch = run_batch(runs)
        for kw, a in zip(runs, batch):
            assert_same_result(self, a, doParticleShearSimulation(**kw, return_result=True))
        linear = doParticleShearSimulation(**dict(runs[0], contact_law="linear"), return_result=True)
        self.assertNotEqual(batch[0].G_surface, linear.G_surface)

    def test_registry_refuses_bad_registrations(self):
        with self.assertRaisesRegex(ValueError, "registered"):
            laws.register_law("hertz_like", hertz)
        with self.assertRaisesRegex(ValueError, "built in"):
            laws.register_law("linear", hertz, replace=True)
        with self.assertRaisesRegex(ValueError, "callable"):
            laws.register_law("other", 3)
        with self.assertRaisesRegex(ValueError, "not built in"):
            laws.unregister_law("plateau")


class TestBadInput(unittest.TestCase):
    """Bad law parameters are refused before any work, naming the parameter (and the flag)."""

    CASES = [(dict(contact_law="platau"), ValueError, r"contact_law='platau'.*did you mean 'plateau'"),
             (dict(contact_law=3), ValueError, "contact_law=3"),
             (dict(plateau_begin=0.0), ValueError, "plateau_begin=0.0 is out of range"),
             (dict(plateau_begin=0.9), ValueError, "plateau_begin=0.9 is out of range"),
             (dict(plateau_end=1.2), ValueError, "plateau_end=1.2 is out of range"),
             (dict(plateau_slope=-0.1), ValueError, "plateau_slope=-0.1 is out of range"),
             (dict(plateau_slope=1.5), ValueError, "plateau_slope=1.5 is out of range"),
             (dict(plateau_slope=float("nan")), ValueError, "plateau_slope=nan"),
             (dict(plateau_begin="0.3"), TypeError, "plateau_begin='0.3'"),
             (dict(plateau_end=True), TypeError, "plateau_end=True")]

    def test_api(self):
        for kw, exc, message in self.CASES:
            with self.subTest(kw=kw):
                with self.assertRaisesRegex(exc, message):
                    doParticleShearSimulation(N=20, doDrawing=False, verbose=False, **kw)

    def test_misnamed_parameters_are_pointed_to(self):
        from particleShear.run.guard import UnknownParameterError
        for name, meant in (("law", "contact_law"), ("plateau_start", "plateau_begin"), ("plateau_slop", "plateau_slope")):
            with self.subTest(name=name):
                with self.assertRaises(UnknownParameterError) as cm:
                    doParticleShearSimulation(**{name: 0.2})
                self.assertEqual(cm.exception.suggestions[0], meant)

    def test_batch_and_series(self):
        with self.assertRaisesRegex(ValueError, r"plateau_end=1\.2"):
            run_batch([dict(QUICK), dict(QUICK, plateau_end=1.2)])
        from particleShear import doParticleShearSimulationSeries
        with self.assertRaisesRegex(ValueError, "did you mean 'plateau'"):
            doParticleShearSimulationSeries(N=20, N_repetitions=1, doDrawing=False, contact_law="plateu")

    def test_cli(self):
        for argv, message in ((["--contact-law", "platau"], "platau"),
                              (["--plateau-end", "1.5"], "plateau-end"),
                              (["--plateau-slope", "x"], "plateau-slope")):
            with self.subTest(argv=argv):
                rc, out, err = run_main(["--N", "20", "--quiet"] + argv)
                self.assertEqual(rc, 2, err)
                self.assertIn(message, err)
                self.assertEqual(out, "")

    def test_cli_runs_the_plateau_law(self):
        from particleShearTest.test_cli import TINY
        import json
        rc, out, err = run_main(TINY + ["--contact-law", "plateau", "--plateau-slope", "0.25", "--json"])
        self.assertEqual(rc, 0, err)
        row = json.loads(out)
        self.assertEqual((row["contact_law"], row["plateau_slope"]), ("plateau", 0.25))


if __name__ == "__main__":
    unittest.main()
