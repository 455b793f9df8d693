"""The state's Verlet predictor (engine/predictor.py): the half kick the next force phase sees.

* The predictor is the state's: a second Verlet engine built on a state (no ``half=``) continues
  bit for bit as one engine running all the steps, on NumPy and on the compiled backend; a second
  engine that starts without it does not (so the first check can fail).
* A documented ensemble's successive engines continue its own predictor: its step with the
  engine dropped halfway (``invalidate_caches``) gives the bits of its step without the drop.
* Where it is dropped: an Euler engine, rows that are not the state's (an ensemble that gained
  spheres), a relaxation (``relax_state``); ``half=`` sets it.
* A measurement that fails after dropping it (at its pre-equilibration) leaves the ensemble's
  predictor as it was (``untouched_on_failure``).
* Copies keep it (``to_backend``, pickling) and are copies (stepping one on the host leaves the
  source as it was); a state pickled before the predictor was the state's loads without one;
  ``concat`` joins the replicas' rows, zeros where a state had none (or rows not its own), none
  when no state had one.
"""
import pickle
import unittest
from unittest import mock

import numpy as np

from particleShear.base.engine_adapter import relax_state, state_from_ensembles
from particleShear.engine import numba_driver
from particleShear.engine.state import BatchState
from particleShear.engine.step import BatchEngine
from particleShearTest.test_contacts import scene
from particleShearTest.test_engine import constituted
from particleShearTest.test_numba_driver import _bits

BACKENDS = ("numpy", "numba") if numba_driver.available() else ("numpy",)
FRICTION = dict(theMu=0.3, do_permanent_links=False, cut_lines=0, theAmplitude=0.1)


def stepped(backend, split, drop=False):
    """The scene of :func:`~particleShearTest.test_contacts.scene` after 60 Verlet steps: in one
    engine (``split`` 0), or ``split`` steps in one and the rest in a second engine on the same
    state (without its predictor with ``drop``)."""
    s, sc = scene(backend)
    first = BatchEngine(s, guard=False, integrator="verlet")
    first.steps(split or 60, sc["cool"], sc["dt"])
    if split:
        first.flush()           # (the relation history into the tables, which the second engine reads)
        if drop:
            s.predictor.drop()
        BatchEngine(s, guard=False, integrator="verlet").steps(60 - split, sc["cool"], sc["dt"])
    return s


def assert_same_bits(test, a, b, names=("pos", "vel", "phi")):
    for name in names:
        np.testing.assert_array_equal(_bits(getattr(a, name)), _bits(getattr(b, name)), err_msg=name)


class TestPredictor(unittest.TestCase):

    def test_a_second_engine_continues_the_state_s_predictor(self):
        for backend in BACKENDS:
            with self.subTest(backend=backend):
                one, two = stepped(backend, 0), stepped(backend, 25)
                assert_same_bits(self, two, one)
                np.testing.assert_array_equal(_bits(two.predictor.half), _bits(one.predictor.half))
                # without the predictor the second engine's first force phase sees other velocities
                cut = stepped(backend, 25, drop=True)
                self.assertFalse(np.array_equal(_bits(cut.vel), _bits(one.vel)))

    def test_a_documented_ensemble_s_engines_continue_its_predictor(self):
        runs = []
        for drop_engine, drop_predictor in ((False, False), (True, False), (True, True)):
            _, e, sc = constituted(22, **FRICTION)
            e.set_integrator("verlet")
            e.applyingShear = True
            e.shear_rate = 4e3 * sc["A"] * sc["f"]
            for k in range(30):
                if k == 12 and drop_engine:
                    e.invalidate_caches()          # the next step makes a new engine on a new state
                    if drop_predictor:
                        e._predictor.drop()
                e.mechanical_simulation_step(sc["cool"], sc["dt"])
            runs.append(e._st[:, :len(e.sphereList)].copy())
        np.testing.assert_array_equal(_bits(runs[1]), _bits(runs[0]))
        self.assertFalse(np.array_equal(_bits(runs[2]), _bits(runs[0])))

    def test_a_failed_measurement_keeps_the_ensemble_s_predictor(self):
        # a measurement drops the predictor at its pre-equilibration; a run that fails there leaves the
        # ensemble as it was (untouched_on_failure), its predictor included
        sim, e, sc = constituted(22, **FRICTION)
        exp = sim.createExperiment(False, 1, False)
        e.set_integrator("verlet")
        for _ in range(5):
            e.mechanical_simulation_step(sc["cool"], sc["dt"])
        half = _bits(e._predictor.half)
        with mock.patch.object(type(exp), "_pre_equilibrate_in", side_effect=RuntimeError("injected")):
            with self.assertRaisesRegex(RuntimeError, "injected"):
                exp.pre_equilibrate(5, sc["cool"])
        np.testing.assert_array_equal(_bits(e._predictor.half), half)

    def test_where_it_is_dropped_or_set(self):
        s = stepped("numpy", 0)
        half = s.predictor.half
        self.assertEqual(half.shape, (3, s.B * s.N))
        BatchEngine(s, guard=False, integrator="verlet")
        self.assertIs(s.predictor.half, half)                       # continued
        BatchEngine(s, guard=False, integrator="euler")
        self.assertIsNone(s.predictor.half)                         # Euler has none
        given = np.ones((3, s.B * s.N))
        BatchEngine(s, guard=False, integrator="verlet", half=given)
        self.assertIs(s.predictor.half, given)                      # half= sets it
        s.predictor.half = np.ones((3, s.B * s.N + 1))
        BatchEngine(s, guard=False, integrator="verlet")
        self.assertIsNone(s.predictor.half)                         # not the state's rows
        s.predictor.half = given
        relax_state(s, 0, 1e-9, 1e-9, integrator="verlet")
        self.assertIsNone(s.predictor.half)                         # a relaxation starts afresh

    def test_copies_keep_it(self):
        s = stepped("numpy", 0)
        half = _bits(s.predictor.half)
        for copied in (s.to_backend("numba") if "numba" in BACKENDS else None, pickle.loads(pickle.dumps(s))):
            if copied is None:
                continue
            self.assertIsNot(copied.predictor, s.predictor)
            np.testing.assert_array_equal(_bits(copied.predictor.half), half)
            # a copy, also on the host: stepping it (in place) leaves the source as it was
            t, x = s.t.copy(), s.x.copy()
            BatchEngine(copied, guard=False, integrator="verlet").steps(3, 0.9, 1e-9)
            np.testing.assert_array_equal(s.t, t)
            np.testing.assert_array_equal(s.x, x)
        # a state pickled before the predictor was the state's loads without one
        old = dict(s.__getstate__())
        old.pop("predictor")
        loaded = object.__new__(BatchState)
        loaded.__setstate__(old)
        self.assertIsNone(loaded.predictor.half)
        BatchEngine(loaded, guard=False, integrator="verlet").steps(1, 0.9, 1e-9)

    def test_concat_joins_each_replica_s_rows(self):
        s = stepped("numpy", 0)
        _, e, _ = constituted(22, **FRICTION)
        other = state_from_ensembles([e, constituted(21, **FRICTION)[1]], backend="numpy")
        self.assertIsNone(other.predictor.half)
        joined = BatchState.concat([s, other])
        n = s.B * s.N
        np.testing.assert_array_equal(_bits(joined.predictor.half[:, :n]), _bits(s.predictor.half))
        np.testing.assert_array_equal(joined.predictor.half[:, n:], 0.0)
        self.assertIsNone(BatchState.concat([other, other]).predictor.half)
        # a predictor whose rows are not its state's (spheres gained since) is zeros, as none
        s.predictor.half = np.ones((3, n + 1))
        np.testing.assert_array_equal(BatchState.concat([s, other]).predictor.half[:, :n], 0.0)


if __name__ == "__main__":
    unittest.main()
