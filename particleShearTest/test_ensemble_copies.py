"""Copies and pickles of the documented ensembles (docs/classes.md, "The documented classes", the item
"Copies and pickles").

* Every documented ensemble class, with and without spheres, bonds, steps or the Verlet
  integrator, is deep-copied and pickled: the copy holds its own state block (its field views are
  views of it again), replica cells, pair table, predictor, generator and spheres (each pointing at
  the copy); the caches (memo and its engine, the force phase's records, the force register) and
  the window handles are not carried.
* A copy continues bit for bit as the original: the state block, the pair table's relations, clock
  and strain after the same steps, the same generator draws; stepped alternately with another
  protocol the two do not interfere; a copy between two Verlet steps continues the predictor (the
  table's other candidate rows follow each engine's own neighbour-list rebuilds: :func:`bits`).
The steps are the documented ones, on the engine the documented step makes (``backend="auto"``:
``PARTICLESHEAR_BACKEND`` or the default backend).
"""
import copy
import pickle
import threading
import unittest

import numpy as np

from particleShear.base.canvas import (CanvasPoints, CanvasPointsBasicElasticity, CanvasPointsBasicElasticityLeesEdwards,
                                       CanvasPointsFrictionElasticityLeesEdwards, CanvasPointsMass,
                                       CanvasPointsNeighbors, CanvasPointsShear)
from particleShear.base.canvas_base import SphereList
from particleShear.base.engine_adapter import state_of_ensemble
from particleShear.base.register import Force_register
from particleShear.linkable import (CanvasPointsLinkable, EnsembleCompactParticles,
                                    EnsembleCompactParticlesAdjustableInterfaceStrength, EnsembleLinkable,
                                    SphereLinkable)
from particleShear.objects import Sphere, SphereFrictionLeesEdwards, SphereLeesEdwards
from particleShear.objects.ensembles import Ensemble, EnsembleFriction, EnsembleFrictionLeesEdwards, EnsembleLeesEdwards
from particleShearTest.test_engine import constituted

DT, COOL, RATE = 1e-2, 0.9, 0.5
#: the shear rate of the gel's steps (1/s): a strain of about 1e-4 a step
GEL_RATE = 500.0

#: the two ways of copying an ensemble
COPIES = {"deepcopy": copy.deepcopy, "pickle": lambda obj: pickle.loads(pickle.dumps(obj))}

#: the base canvases and the sphere class each is filled with by hand
CANVASES = ((CanvasPoints, Sphere), (CanvasPointsMass, Sphere), (CanvasPointsNeighbors, Sphere),
            (CanvasPointsShear, Sphere), (CanvasPointsBasicElasticity, Sphere),
            (CanvasPointsBasicElasticityLeesEdwards, SphereLeesEdwards),
            (CanvasPointsFrictionElasticityLeesEdwards, SphereFrictionLeesEdwards),
            (CanvasPointsLinkable, SphereLinkable))
#: the ensembles that place N random spheres themselves
ENSEMBLES = (Ensemble, EnsembleFriction, EnsembleLeesEdwards, EnsembleFrictionLeesEdwards, EnsembleLinkable,
             EnsembleCompactParticles)


def canvas(cls, sphere_cls, n):
    """A 200 µm canvas ``cls`` with ``n`` overlapping spheres ``sphere_cls`` on a jittered grid."""
    c = cls(200, 200)
    rng = np.random.default_rng(n)
    for k in range(n):
        c.sphereList.append(sphere_cls("grey", 40 * (k % 5) + 20 + rng.random(), 40 * (k // 5) + 20, 48, 1))
    c.set_random_generator(np.random.default_rng(7))
    return c


def ensemble(cls, n):
    """A jammed ensemble ``cls`` of ``n`` random spheres, seeded."""
    e = cls(200, 200, 0, packing_fraction=1.0)
    e.set_random_generator(np.random.default_rng(n))
    e._create_spheres(n, 1)
    return e


def every_ensemble(n):
    """``(name, ensemble, dt)`` of every documented class with ``n`` spheres and its time step (s);
    linkable ones bonded where n > 0, and with spheres a constituted gel of the run's builder too."""
    out = [(cls.__name__, canvas(cls, sphere_cls, n), DT) for cls, sphere_cls in CANVASES]
    out += [(cls.__name__, ensemble(cls, n), DT) for cls in ENSEMBLES]
    for _, e, _ in out:
        if n and hasattr(e, "makeAllLinksPermanent"):
            e.makeAllLinksPermanent()
    if n:
        gel = constituted(3, N=n)[1]
        out.append(("constituted " + type(gel).__name__, gel, gel.dt))
    return out


def stepped(e, n, rate=RATE, dt=DT):
    """``e`` after ``n`` documented steps of ``dt`` (s) at shear rate ``rate`` (1/s, plates shearing); returns ``e``."""
    e.applyingShear = True
    for _ in range(n):
        if hasattr(e, "setShearRate"):
            e.setShearRate(rate)
        else:                                          # (no Lees-Edwards cell: the plates' rate)
            e.shear_rate = rate
        e.mechanical_simulation_step(COOL, dt)
    return e


def gel(steps=5, integrator="euler"):
    """``(ensemble, dt)``: a constituted gel of 30 spheres (the run's builder) after ``steps`` steps of ``integrator``."""
    e = constituted(3)[1]
    e.set_integrator(integrator)
    return stepped(e, steps, GEL_RATE, e.dt), e.dt


def bits(e):
    """The bytes of everything a step advances: the state block, the replica cells, the pair table's
    relations and its counter of creation numbers, the predictor.

    The table's other rows (candidates that are no relation) are those of the last neighbour-list
    update of the engine that stepped the ensemble: a copy's engine makes its lists afresh (as an
    ensemble's after :meth:`invalidate_caches`), so its updates fall on other steps; the forces of
    a candidate that is no relation are exact zeros, which leave the sums' bits as they are.
    """
    out = {"block": e._st.tobytes(), "replica": e._replica.tobytes()}
    if hasattr(e, "pair_table"):
        pt = e.pair_table
        out.update({"pairs." + name: getattr(pt, name)[..., pt.active].tobytes() for name in pt.ARRAYS})
        out["births"] = pt.birth_count
        out["half"] = None if e._predictor.half is None else e._predictor.half.tobytes()
    return out


def table(e):
    """The bytes of every array of the pair table of ``e``."""
    pt = e.pair_table
    return [getattr(pt, name).tobytes() for name in pt.ARRAYS]


def arrays(e):
    """The arrays of ``e`` a copy must not share: the state block, the replica cells, the pair table, the predictor."""
    pt = state_of_ensemble(e).pairs[0] if hasattr(e, "pair_table") else None   # (the ensemble's own table)
    out = [e._block, e._replica]      # (read after state_of_ensemble, which may fit the block)
    if pt is not None:
        out += [getattr(pt, name) for name in pt.ARRAYS]
        out += [] if e._predictor.half is None else [e._predictor.half]
    return out


class CopiesTest(unittest.TestCase):
    """Every documented ensemble class is copied and pickled into an independent ensemble of its own."""

    def assert_own_copy(self, e, c):
        self.assertIs(type(c), type(e))
        self.assertIs(type(c.sphereList), SphereList)
        self.assertIs(c.sphereList._canvas, c)
        self.assertEqual(len(c.sphereList), len(e.sphereList))
        for k, (s, t) in enumerate(zip(e.sphereList, c.sphereList)):
            self.assertIsNot(t, s)
            self.assertIs(t.__dict__["_ens"], c)
            self.assertEqual((t.__dict__["_idx"], t.x, t.r), (k, s.x, s.r))
        self.assertEqual(bits(c), bits(e))
        for name, row in list(c.sphere_arrays.items()) + [("_st", c._st), ("_pos", c._pos), ("_vel", c._vel), ("_frc", c._frc)]:
            self.assertTrue(row.size == 0 or np.shares_memory(row, c._block), name)    # views of its own block
        for mine in arrays(c):
            self.assertFalse(any(np.shares_memory(mine, theirs) for theirs in arrays(e)))
        self.assertIsNot(c._rng, e._rng)
        self.assertEqual(c._rng.random(4).tolist(), e._rng.random(4).tolist())       # the same stream, continued

    def assert_no_caches(self, c):
        self.assertIsNone(c._memo.peek("engine"))
        self.assertIsNone(getattr(c, "force_register", Force_register())._phase)
        for name in ("_g", "_force_record", "_engine_pairs"):     # (left out: the class defaults, None, read)
            self.assertNotIn(name, vars(c), name)

    def test_every_class_copies_with_and_without_spheres(self):
        for n in (0, 10):
            for name, e, dt in every_ensemble(n):
                if n and hasattr(e, "mechanical_simulation_step"):
                    stepped(e, 3, dt=dt)                 # an engine, records and a register to leave behind
                for how, make in COPIES.items():
                    with self.subTest(cls=name, n=n, copy=how):
                        c = make(e)
                        self.assert_own_copy(e, c)
                        self.assert_no_caches(c)

    def test_the_copy_is_independent(self):
        for how, make in COPIES.items():
            with self.subTest(copy=how):
                e, dt = gel()
                c = make(e)
                self.assertTrue(all(s.__dict__["_ens"] is c for particle in c.particles for s in particle))
                before = bits(e), table(e)
                c.sphereList[0].x += 1.0
                c.t, c.shear, c.mu = 1.0, 0.5, 0.0
                state_of_ensemble(c).pairs[0].xi[:] = 1.0       # (the copy's own table)
                c.makeAllLinksPermanent()
                c.sphereList.append(SphereLinkable("grey", 10, 10, 20))
                stepped(c, 3, dt=dt)
                self.assertEqual((bits(e), table(e)), before)
                self.assertEqual(len(e.sphereList), 30)
                self.assertEqual((len(c.sphereList), c.sphereList[30].__dict__["_idx"]), (31, 30))

    def test_the_window_handles_are_left_out(self):
        lock = threading.Lock()                      # (as a Tk object: neither copied nor pickled)
        for name, e, _ in every_ensemble(4):
            e.theCanvas = e._renderer = lock
            for s in e.sphereList:
                s.theCanvas = lock
            if hasattr(e, "theTkSimulation"):
                e.theTkSimulation = lock
            for how, make in COPIES.items():
                with self.subTest(cls=name, copy=how):
                    c = make(e)
                    self.assertEqual((c.theCanvas, c._renderer, getattr(c, "theTkSimulation", False)),
                                     (False, None, False))
                    self.assertEqual([s.theCanvas for s in c.sphereList], [False] * 4)
                    self.assertIs(e.theCanvas, lock)
                    self.assertIs(e.sphereList[0].theCanvas, lock)


class CopiesContinueTest(unittest.TestCase):
    """A copy steps as its original would: the same bits after the same documented steps."""

    def test_a_copy_continues_bit_for_bit(self):
        for how, make in COPIES.items():
            with self.subTest(copy=how):
                e, dt = gel()
                c = make(e)
                stepped(e, 40, GEL_RATE, dt)
                stepped(c, 40, GEL_RATE, dt)
                self.assertEqual(bits(c), bits(e))
                self.assertEqual((c.t, c.shear, c.step_count), (e.t, e.shear, e.step_count))
                self.assertEqual(c._rng.random(3).tolist(), e._rng.random(3).tolist())

    def test_every_stepping_class_continues_bit_for_bit(self):
        for name, e, dt in every_ensemble(10):
            if not hasattr(e, "mechanical_simulation_step"):
                continue
            stepped(e, 3, dt=dt)
            for how, make in COPIES.items():
                with self.subTest(cls=name, copy=how):
                    c = stepped(make(e), 10, dt=dt)
                    before = bits(e)
                    self.assertEqual(bits(c), bits(stepped(e, 10, dt=dt)))
                    self.assertNotEqual(bits(c), before)      # (the steps change the bits compared)

    def test_stepped_alternately_they_do_not_interfere(self):
        for how, make in COPIES.items():
            with self.subTest(copy=how):
                e, dt = gel()
                alone, other = make(e), make(e)
                for _ in range(20):                    # the original at one rate, its copy at another
                    stepped(e, 1, GEL_RATE, dt)
                    stepped(other, 2, -2 * GEL_RATE, dt)
                stepped(alone, 20, GEL_RATE, dt)
                self.assertEqual(bits(e), bits(alone))
                self.assertNotEqual(bits(other), bits(e))

    def test_a_verlet_copy_continues_the_predictor(self):
        for how, make in COPIES.items():
            with self.subTest(copy=how):
                e, dt = gel(integrator="verlet")
                self.assertIsNotNone(e._predictor.half)
                c = make(e)
                stepped(e, 20, GEL_RATE, dt)
                stepped(c, 20, GEL_RATE, dt)
                self.assertEqual(bits(c), bits(e))

    def test_a_copy_inside_a_step_finishes_it_as_after_invalidate_caches(self):
        # a copy keeps no record of a force phase: made between a step's force phase and its
        # movement, it finishes the step as the original does with its caches dropped there (a
        # kick and a movement without the phase's record: no ξ rule), and steps on (its lists are
        # due until its first force phase builds them)
        for how, make in COPIES.items():
            with self.subTest(copy=how):
                e, dt = gel()
                e.setShearRate(500)
                e.mechanical_simulation_step_calculate_forces()
                c = make(e)
                e.invalidate_caches()
                for x in (c, e):
                    x.mechanical_simulation_step_calculate_acceleration(COOL, dt)
                    x.mechanical_simulation_step_calculate_movement(dt)
                    stepped(x, 5, GEL_RATE, dt)
                self.assertEqual(bits(c), bits(e))


if __name__ == "__main__":
    unittest.main()
