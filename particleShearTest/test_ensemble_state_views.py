"""The documented ensembles' clock, strain, rate and μ are views of the engine's state (issue 46).

* After ``state_of_ensembles`` the state's ``t``, ``gamma``, ``rate`` and ``mu`` are the ensembles'
  replica cells (``base.fields.REPLICA_FIELDS``), for a batch of one and for a joint batch: a value
  written on either side is read on the other, and nothing is copied back.
* ``state_from_ensembles`` stays a copy (a measurement's batch writes nothing into the ensemble).
* The documented step loop advances the ensemble's clock and strain through those cells and gives
  the bits of the engine's own steps on a copy, also after a strain and a μ set from outside between
  steps (the lists rebuilt, the candidates' μ renewed: what ``_hand_to_engine`` keeps of the old
  copying), also for a strain set between a step's force phase and its movement.
* ``untouched_on_failure`` puts the cells back with the spheres.
"""
import copy
import os
import unittest
from unittest import mock

import numpy as np

from particleShear.base.canvas import CanvasPointsFrictionElasticityLeesEdwards
from particleShear.base.engine_adapter import (state_from_ensembles, state_of_ensemble, state_of_ensembles,
                                               untouched_on_failure)
from particleShear.engine import numba_driver
from particleShear.engine.step import BatchEngine
from particleShear.engine.xp import BACKEND_ENV
from particleShear.base.register import KeptTerms
from particleShear.objects.ensembles import EnsembleFrictionLeesEdwards, EnsembleLeesEdwards

#: the ensemble's attribute and the state's array of each replica value
VALUES = (("t", "t"), ("shear", "gamma"), ("shear_rate", "rate"), ("mu", "mu"))
DT, COOL = 1e-2, 0.9
#: the host backends here (the documented loop's compiled phases and the NumPy step)
BACKENDS = ("numpy", "numba") if numba_driver.available() else ("numpy",)


def ensemble(seed=1, mu=0.3):
    """A small jammed frictional Lees-Edwards ensemble, clock, strain and rate not zero."""
    e = EnsembleFrictionLeesEdwards(200, 200, 30, packing_fraction=1.0, mu=mu)
    e.set_random_generator(np.random.default_rng(seed))
    e.t, e.shear = 0.25, 0.01
    e.setShearRate(0.5)
    return e


def engine_on_copy(ens):
    """The engine's own steps on a copy of ``ens`` (its generator copied too), as the documented step makes it."""
    s = state_from_ensembles([ens], backend="numpy")
    s.applying_shear = bool(ens.applyingShear)
    s.rng = [copy.deepcopy(g) for g in s.rng]
    return BatchEngine(s, skin_factor=ens.neighbour_skin, guard=False, keep_terms=True, terms_to=KeptTerms(),
                       lees_edwards=True,
                       strain_only_while_shearing=False)


class StateCellsTest(unittest.TestCase):

    def assert_views(self, ensembles, s):
        for b, e in enumerate(ensembles):
            for k, (name, row) in enumerate(VALUES):
                with self.subTest(b=b, value=name):
                    self.assertTrue(np.shares_memory(e._replica, getattr(s, row)))
                    setattr(e, name, 0.125 + k + b)               # the ensemble's write, the state's value
                    self.assertEqual(getattr(s, row)[b], 0.125 + k + b)
                    getattr(s, row)[b] = 2.5 + k + b              # the state's write, the ensemble's value
                    value = getattr(e, name)
                    self.assertIs(type(value), float)
                    self.assertEqual(value, 2.5 + k + b)
        for b, e in enumerate(ensembles):                          # each replica its own cells
            self.assertEqual([getattr(e, name) for name, _ in VALUES], [2.5 + k + b for k in range(len(VALUES))])

    def test_a_batch_of_one_holds_the_ensembles_cells(self):
        e = ensemble()
        self.assert_views([e], state_of_ensemble(e))

    def test_a_joint_batch_holds_each_ensembles_cells(self):
        es = [ensemble(1), ensemble(2)]
        s = state_of_ensembles(es)
        self.assert_views(es, s)
        for row in ("t", "gamma", "rate", "mu"):              # one joint array per value
            self.assertEqual(getattr(s, row).shape, (2,))

    def test_the_measurements_batch_is_a_copy(self):
        e = ensemble()
        s = state_from_ensembles([e])
        self.assertEqual((s.t[0], s.gamma[0], s.rate[0], s.mu[0]), (0.25, 0.01, 0.5, 0.3))
        for name, row in VALUES:
            self.assertFalse(np.shares_memory(e._replica, getattr(s, row)))
            getattr(s, row)[0] = 7.0
        self.assertEqual([e.t, e.shear, e.shear_rate, e.mu], [0.25, 0.01, 0.5, 0.3])

    def test_values_are_checked_and_copied_with_the_ensemble(self):
        e = CanvasPointsFrictionElasticityLeesEdwards(100, 100, mu=0)
        e.t = 0
        e.shear += 1
        self.assertEqual((e.t, e.shear, e.mu), (0.0, 1.0, 0.0))
        with self.assertRaisesRegex(ValueError, "mu=-1 is out of range"):
            e.mu = -1
        twin = copy.deepcopy(e)
        twin.t = 3
        self.assertEqual((e.t, twin.t, twin.shear), (0.0, 3.0, 1.0))
        self.assertFalse(hasattr(EnsembleLeesEdwards(100, 100, 0), "mu"))     # frictionless: no μ

    def test_an_integer_reads_back_as_given_until_the_cell_changes(self):
        # 1.0.2's values were plain attributes: an int assigned stayed an int; a step's value is a float
        e = CanvasPointsFrictionElasticityLeesEdwards(100, 100, mu=0)
        s = state_of_ensemble(e)
        for name, row in VALUES:
            with self.subTest(value=name):
                setattr(e, name, 2)
                self.assertIs(type(getattr(e, name)), int)
                self.assertEqual(getattr(e, name), 2)
                getattr(s, row)[0] = 2.5                     # the engine's write: the cell's float
                self.assertIs(type(getattr(e, name)), float)
                self.assertEqual(getattr(e, name), 2.5)
                setattr(e, name, 1.0)                        # a float assigned stays a float
                self.assertIs(type(getattr(e, name)), float)
        self.assertIs(type(CanvasPointsFrictionElasticityLeesEdwards(100, 100, mu=0).mu), int)

    def test_a_shallow_copy_has_its_own_values_and_the_originals_spheres(self):
        # as 1.0.2's copy.copy: the sphere objects shared, the clock, strain, rate and μ the copy's own
        e = ensemble()
        twin = copy.copy(e)
        self.assertEqual([getattr(twin, n) for n, _ in VALUES], [getattr(e, n) for n, _ in VALUES])
        before = [getattr(e, n) for n, _ in VALUES]
        for k, (name, _) in enumerate(VALUES):
            setattr(twin, name, 9.0 + k)
        self.assertEqual([getattr(e, n) for n, _ in VALUES], before)
        twin.sphereList[0].x = 3.25          # a sphere of the copy is the original's
        self.assertEqual(e.sphereList[0].x, 3.25)

    def test_a_failed_run_puts_the_cells_back(self):
        e = ensemble()
        with self.assertRaises(RuntimeError), untouched_on_failure(e):
            s = state_of_ensemble(e)
            s.t[0], s.mu[0] = 9.0, 0.0
            raise RuntimeError("unstable")
        self.assertEqual((e.t, e.mu), (0.25, 0.3))


class DocumentedLoopTest(unittest.TestCase):

    def assert_same_bits(self, e, eng):
        s = eng.s
        self.assertEqual((e.t, e.shear, e.shear_rate, e.mu), (s.t[0], s.gamma[0], s.rate[0], s.mu[0]))
        self.assertTrue(np.array_equal(e._pos, s.pos))
        self.assertTrue(np.array_equal(e._vel, s.vel))

    def steps(self, e, eng, n):
        for _ in range(n):
            e.mechanical_simulation_step(COOL, DT)
            eng.step(COOL, DT)

    def test_the_clock_and_strain_advance_in_the_cells(self):
        # the documented loop and the engine's own steps on the ensemble's state (as the run driver's
        # measurement on an ensemble), on every host backend
        for backend in BACKENDS:
            with self.subTest(backend=backend), mock.patch.dict(os.environ, {BACKEND_ENV: backend}):
                e = ensemble()
                t, gamma = e.t, e.shear
                for _ in range(10):
                    e.mechanical_simulation_step(COOL, DT)
                    t, gamma = t + DT, gamma + 0.5 * DT          # (the engine's repeated additions)
                self.assertEqual((e.t, e.shear), (t, gamma))
                self.assertTrue(np.shares_memory(e._engine.s.t, e._replica))
                eng = BatchEngine(state_of_ensemble(e, backend=backend), skin_factor=e.neighbour_skin, guard=False,
                                  lees_edwards=True, strain_only_while_shearing=False)
                eng.steps(5, COOL, DT)
                eng.step(COOL, DT)
                for _ in range(6):
                    t, gamma = t + DT, gamma + 0.5 * DT
                self.assertEqual((e.t, e.shear), (t, gamma))

    def test_the_documented_steps_are_the_engines(self):
        e = ensemble()
        eng = engine_on_copy(e)
        self.steps(e, eng, 20)
        self.assert_same_bits(e, eng)

    def test_a_strain_and_a_mu_set_from_outside_reach_the_engine(self):
        e = ensemble()
        eng = engine_on_copy(e)
        self.steps(e, eng, 10)
        e.shear += 0.3                     # the images move by Ly·Δγ = 60 µm: the lists must be rebuilt
        eng.s.gamma[0] += 0.3
        eng.s.contacts.need[:] = True
        self.steps(e, eng, 10)
        self.assert_same_bits(e, eng)
        e.mu = 0.0                         # the candidates' μ and the frictionless replicas anew
        eng.set_mu(0.0)
        self.steps(e, eng, 10)
        self.assert_same_bits(e, eng)
        self.assertFalse(e._engine.s.contacts.C.mu.any())

    def test_a_strain_set_inside_a_step_reaches_the_next_force_phase(self):
        # a strain set between a step's force phase and its movement: the movement starts from it,
        # and the next force phase must see the images moved by Ly·Δγ (the lists rebuilt), as the
        # engine's own phases on a copy do when told so
        e = ensemble()
        eng = engine_on_copy(e)
        self.steps(e, eng, 5)
        e.mechanical_simulation_step_calculate_forces()
        e.record_total_particle_forces()
        g = eng.force_phase()[0]
        e.setShear(e.shear + 0.3)
        eng.s.gamma[0] += 0.3
        e.mechanical_simulation_step_calculate_acceleration(COOL, DT)
        eng.accelerate(COOL, DT, g)
        e.mechanical_simulation_step_calculate_movement(DT)
        eng.move(DT, g)
        eng.s.contacts.need[:] = True
        self.steps(e, eng, 5)
        self.assert_same_bits(e, eng)

if __name__ == "__main__":
    unittest.main()
