"""An engine's configuration is fixed at its construction (issue 46 item 1).

:class:`~particleShear.engine.step.BatchEngine` holds its configuration in a frozen
:class:`~particleShear.engine.config.EngineConfig`: what the keyword arguments said is what the
configuration reports, and neither the configuration nor the engine's read-only properties of its
fields can be assigned afterwards.  Units: µm, s, mg per m depth.
"""
import dataclasses
import unittest

import numpy as np

from particleShear import EnsembleLinkable, SphereLinkable
from particleShear.base.engine_adapter import state_from_ensembles, state_of_ensemble
from particleShear.base.register import KeptTerms
from particleShear.engine.config import EngineConfig
from particleShear.engine.step import BatchEngine

CONFIG_FIELDS = ("integrator", "skin_factor", "check_interval", "guard", "min_distance_ratio",
                 "max_kinetic_energy", "keep_terms", "numbers_relations", "lees_edwards",
                 "strain_only_while_shearing")
#: the engine's read-only properties of its configuration
READ_ONLY = ("config", "integrator", "keep_terms", "terms_to", "check_interval", "min_distance_ratio", "max_kinetic_energy",
             "numbers_relations", "skin", "guard", "guard_dev", "lees_edwards", "strain_advances")


def ensemble(n=3):
    """A row of ``n`` spheres (40 µm) in a 400 µm Lees-Edwards cell."""
    ens = EnsembleLinkable(400.0, 400.0, 0, k=3.0, nu=0.1, k_t=3.0, nu_t=0.1, mu=0.1)
    for i in range(n):
        ens.sphereList.append(SphereLinkable("grey", 60.0 + 100.0 * i, 200.0, 40.0, 2.0, i, force_register=ens))
    return ens


class TestEngineConfig(unittest.TestCase):

    def test_fields_are_the_documented_ones(self):
        self.assertEqual(tuple(f.name for f in dataclasses.fields(EngineConfig)), CONFIG_FIELDS)

    def test_keywords_are_reported_by_the_config(self):
        given = dict(integrator="verlet", skin_factor=0.3, check_interval=7, guard=False, min_distance_ratio=0.02,
                     max_kinetic_energy=12.5, keep_terms=True, numbers_relations=False, lees_edwards=False,
                     strain_only_while_shearing=True)
        eng = BatchEngine(state_from_ensembles([ensemble()]), **given, terms_to=KeptTerms())
        self.assertEqual(dataclasses.asdict(eng.config), given)
        self.assertEqual(eng.config, EngineConfig(**given))
        for name, value in given.items():        # (the engine's properties of the same names)
            if name not in ("skin_factor", "guard", "lees_edwards", "strain_only_while_shearing"):
                self.assertEqual(getattr(eng, name), value, name)
        np.testing.assert_array_equal(eng.guard, [False])
        np.testing.assert_array_equal(eng.skin, 0.3 * 20.0)
        np.testing.assert_array_equal(eng.lees_edwards, [0.0])

    def test_defaults_do_not_depend_on_whose_memory_the_state_is(self):
        # the configuration is what is given: an ensemble's own state decides nothing in the engine
        own = BatchEngine(state_of_ensemble(ensemble()))
        self.assertEqual(own.config, EngineConfig())
        self.assertFalse(own.numbers_relations)
        self.assertTrue(BatchEngine(state_of_ensemble(ensemble()), numbers_relations=True).numbers_relations)
        copy = BatchEngine(state_from_ensembles([ensemble()]))
        self.assertEqual(copy.config, EngineConfig(numbers_relations=False))
        self.assertIsNone(copy.lees_edwards)
        self.assertIsNone(copy.strain_advances)

    def test_config_given_whole(self):
        cfg = EngineConfig(integrator="verlet", guard=(True, False), check_interval=2)
        eng = BatchEngine(state_from_ensembles([ensemble(), ensemble()]), config=cfg)
        self.assertEqual(eng.config, cfg.replace(numbers_relations=False))
        np.testing.assert_array_equal(eng.guard, [True, False])
        with self.assertRaisesRegex(ValueError, "either as config or as keyword"):
            BatchEngine(state_from_ensembles([ensemble()]), config=cfg, keep_terms=True)

    def test_invalid_configuration(self):
        for bad in (dict(skin_factor=0.0), dict(integrator="leapfrog"), dict(check_interval=0)):
            with self.subTest(**bad), self.assertRaises(ValueError):
                EngineConfig(**bad)
            with self.subTest(engine=bad), self.assertRaises(ValueError):
                BatchEngine(state_from_ensembles([ensemble()]), **bad)

    def test_configuration_cannot_be_changed_after_construction(self):
        kept = KeptTerms()
        eng = BatchEngine(state_from_ensembles([ensemble()]), keep_terms=True, terms_to=kept, check_interval=3)
        cfg = eng.config
        for name in CONFIG_FIELDS:
            with self.subTest(field=name), self.assertRaises(dataclasses.FrozenInstanceError):
                setattr(cfg, name, getattr(cfg, name))
        for name in READ_ONLY:
            with self.subTest(attribute=name), self.assertRaises(AttributeError):
                setattr(eng, name, getattr(eng, name))
        with self.assertRaises(ValueError):          # the per-replica guard is read-only too
            eng.guard[0] = False
        self.assertIs(eng.config, cfg)
        self.assertEqual((eng.keep_terms, eng.check_interval), (True, 3))
        self.assertIs(eng.terms_to, kept)

    def test_kept_terms_need_their_receiver(self):
        # keep_terms and terms_to come together (the terms are handed out, the engine keeps none)
        for bad in (dict(keep_terms=True), dict(terms_to=KeptTerms()), dict(keep_terms=True, terms_to="register"),
                    dict(config=EngineConfig(keep_terms=True))):
            with self.subTest(bad=bad), self.assertRaisesRegex(ValueError, "keep_terms=.*terms_to="):
                BatchEngine(state_from_ensembles([ensemble()]), **bad)
        self.assertIsNotNone(BatchEngine(state_from_ensembles([ensemble()]), config=EngineConfig(keep_terms=True),
                                         terms_to=KeptTerms()))

    def test_the_engine_keeps_no_terms_of_its_phases(self):
        """Each NumPy force phase hands its terms to ``terms_to`` as a new value (the forces of the
        phase's totals are the forces it wrote), also the phase of an unsound guard verdict, before
        it raises; the engine holds no attribute of them."""
        from particleShear.engine.step import EngineInstability
        from particleShearTest.test_engine import constituted

        got = []
        ens = constituted(31)[1]
        eng = BatchEngine(state_from_ensembles([ens], backend="numpy"), keep_terms=True, terms_to=got.append,
                          check_interval=1)
        eng.set_rate(np.array([300.0]))
        for k in range(3):
            g, _ = eng.force_phase()
            self.assertEqual(len(got), k + 1)
            np.testing.assert_array_equal(got[-1]["totals"], eng.s.frc)
            np.testing.assert_array_equal(got[-1]["dx"], g.dx)
            eng.accelerate(0.999, ens.dt, g)
            eng.move(ens.dt, g)
        eng.step(0.999, ens.dt)
        self.assertEqual(len(got), 4)
        self.assertEqual(len({id(t) for t in got}), 4)
        self.assertFalse(any("terms" == name for name in vars(eng)))
        eng.s.vel *= 1e6            # an unsound state: the guard raises after the terms are handed out
        with self.assertRaises(EngineInstability):
            eng.force_phase()
        self.assertEqual(len(got), 5)
        np.testing.assert_array_equal(got[-1]["totals"], eng.s.frc)

    def test_configuration_is_the_same_objects_at_every_read(self):
        # numba_step._key compares the configuration by identity, step after step
        eng = BatchEngine(state_from_ensembles([ensemble()]), lees_edwards=False, strain_only_while_shearing=True)
        for name in READ_ONLY:
            self.assertIs(getattr(eng, name), getattr(eng, name), name)
        eng.s.applying_shear = True
        self.assertIsNone(eng.strain_advances)      # held only while not shearing
        eng.s.applying_shear = False
        np.testing.assert_array_equal(eng.strain_advances, [0.0])

    def test_strain_held_while_not_shearing(self):
        for shearing in (False, True):
            with self.subTest(shearing=shearing):
                eng = BatchEngine(state_from_ensembles([ensemble()], backend="numpy"),
                                  strain_only_while_shearing=True)
                eng.s.applying_shear = shearing
                eng.set_rate(np.array([0.5]))
                eng.step(1.0, 1e-3)
                self.assertEqual(float(eng.s.gamma[0]), 0.5e-3 if shearing else 0.0)


class TestCanvasEngineConfig(unittest.TestCase):
    """A documented canvas configures its engine when it makes it (and makes a new one for another)."""

    def test_canvas_engine_configured_at_construction(self):
        from particleShear.objects.ensembles import Ensemble, EnsembleFriction, EnsembleFrictionLeesEdwards
        for cls, le, held in ((Ensemble, False, True), (EnsembleFriction, False, True),
                              (EnsembleFrictionLeesEdwards, True, False)):
            with self.subTest(cls=cls.__name__):
                ens = cls(400.0, 400.0, 6)
                ens.mechanical_simulation_step_calculate_forces()
                eng = ens._engine
                self.assertEqual((eng.config.lees_edwards, eng.config.strain_only_while_shearing), (le, held))
                ens.use_lees_edwards = not le          # another configuration: another engine
                ens.mechanical_simulation_step_calculate_forces()
                self.assertIsNot(ens._engine, eng)
                self.assertEqual(ens._engine.config.lees_edwards, not le)


if __name__ == "__main__":
    unittest.main()
