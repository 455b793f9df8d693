"""The state's contacts (engine/contacts.py): the flat candidate list, its history and the lists' bookkeeping.

* The history written back into the pair tables is the history: a new engine on the state, whose
  first step rebuilds every list from the tables, holds the same relations with the same state, ξ
  and creation numbers as the contacts it replaced, and the same creation counters.
* A second engine on the same state restarts the bookkeeping (every list due, its constants and
  counts anew) and continues bit for bit as one engine running all the steps: the trajectories do
  not depend on when the lists were built (NumPy, and the compiled backend when Numba is there).
* The contacts are the engine's and the state's, not a copy's: ``concat``, ``to_backend`` and a
  pickled copy have none, and an engine starts them from the tables.
"""
import copy
import functools
import pickle
import unittest

import numpy as np

from particleShear.base.engine_adapter import state_from_ensembles
from particleShear.engine import numba_driver
from particleShear.engine.contacts import Contacts
from particleShear.engine.state import BatchState
from particleShear.engine.step import BatchEngine
from particleShearTest.test_engine import constituted
from particleShearTest.test_numba_driver import _bits

BONDS = dict(theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.2)
FRICTION = dict(theMu=0.3, do_permanent_links=False, cut_lines=0, theAmplitude=0.1)
BACKENDS = ("numpy", "numba") if numba_driver.available() else ("numpy",)


@functools.lru_cache(maxsize=None)
def _constituted():
    return constituted(21, **BONDS), constituted(22, **FRICTION)


def scene(backend):
    """Two constituted replicas (bonds and friction; friction alone; copies), sheared, and their schedule."""
    runs = _constituted()
    s = state_from_ensembles([e for _, e, _ in runs], backend=backend)
    s.rng = [copy.deepcopy(g) for g in s.rng]          # (each scene draws from generators of its own)
    sc = runs[0][2]
    s.applying_shear = True
    s.rate[:] = [40.0 * sc["A"] * sc["f"], -60.0 * sc["A"] * sc["f"]]
    return s, sc


def relations(c, b):
    """Replica b's relations in the contacts ``c``: (i, j, state, ξ bits, creation number) per relation."""
    lo, hi = int(c.C.offsets[b]), int(c.C.offsets[b + 1])
    a = np.asarray(c.active[lo:hi])
    return (c.C.ai_host[lo:hi][a], c.C.aj_host[lo:hi][a], np.asarray(c.state_p[lo:hi])[a],
            _bits(np.asarray(c.xi)[:, lo:hi][:, a]), np.asarray(c.birth[lo:hi])[a])


class TestContacts(unittest.TestCase):

    def test_a_new_engine_starts_them(self):
        s, sc = scene("numpy")
        eng = BatchEngine(s, guard=False, numbers_relations=True)
        c = s.contacts
        self.assertIsInstance(c, Contacts)
        self.assertIsNone(c.C)
        self.assertTrue(c.need.all())
        self.assertTrue(np.isinf(c.bound).all())
        eng.steps(30, sc["cool"], sc["dt"])
        eng.flush()
        self.assertTrue((c.rebuilds >= 1).all())
        counters = [p.birth_count for p in s.pairs]
        self.assertGreater(min(counters), 0)          # relations were numbered (so the next check can fail)
        BatchEngine(s, guard=False)
        self.assertIsNot(s.contacts, c)
        self.assertIsNone(s.contacts.C)
        self.assertTrue(s.contacts.need.all())
        np.testing.assert_array_equal(s.contacts.rebuilds, 0)
        np.testing.assert_array_equal(s.contacts.next_birth, counters)

    def test_the_tables_carry_the_history_to_a_new_engine(self):
        for backend in BACKENDS:
            with self.subTest(backend=backend):
                s, sc = scene(backend)
                eng = BatchEngine(s, guard=False, numbers_relations=True)
                eng.steps(60, sc["cool"], sc["dt"])
                eng.flush()
                old = s.contacts
                fresh = BatchEngine(s, guard=False, numbers_relations=True)
                fresh.neighbours()                    # every list anew from the tables
                new = s.contacts
                self.assertIsNot(new, old)
                np.testing.assert_array_equal(new.next_birth, old.next_birth)
                sticking = 0
                for b in range(s.B):
                    want, got = relations(old, b), relations(new, b)
                    self.assertGreater(len(want[0]), 0)
                    for name, w, g in zip(("i", "j", "state", "xi", "birth"), want, got):
                        np.testing.assert_array_equal(g, w, err_msg=f"replica {b}: {name}")
                    sticking += int((want[3] != _bits(np.zeros(1))).any())
                self.assertGreater(sticking, 0)      # some ξ is not 0 (its carry-over is checked)

    def test_a_second_engine_continues_as_one_engine(self):
        for backend in BACKENDS:
            for integrator in ("euler", "verlet"):
                with self.subTest(backend=backend, integrator=integrator):
                    (one, sc), (two, _) = scene(backend), scene(backend)
                    whole = BatchEngine(one, guard=False, integrator=integrator, numbers_relations=True)
                    whole.steps(100, sc["cool"], sc["dt"])
                    whole.flush()
                    first = BatchEngine(two, guard=False, integrator=integrator, numbers_relations=True)
                    first.steps(40, sc["cool"], sc["dt"])
                    first.flush()
                    # (the Verlet predictor is the state's: the second engine continues it)
                    second = BatchEngine(two, guard=False, integrator=integrator, numbers_relations=True)
                    second.steps(60, sc["cool"], sc["dt"])
                    second.flush()
                    # the second engine built every list at its first step: other lists, the same numbers
                    self.assertTrue((two.contacts.rebuilds >= 1).all())
                    for name in ("pos", "vel", "phi", "gamma", "t"):
                        np.testing.assert_array_equal(_bits(getattr(two, name)), _bits(getattr(one, name)),
                                                      err_msg=name)
                    for b in range(one.B):
                        p, q = whole.pairs_of(b), second.pairs_of(b)
                        self.assertEqual(q.birth_count, p.birth_count)
                        for name in ("i", "j", "state", "birth"):
                            np.testing.assert_array_equal(getattr(q, name)[q.active], getattr(p, name)[p.active],
                                                          err_msg=name)
                        np.testing.assert_array_equal(_bits(q.xi[:, q.active]), _bits(p.xi[:, p.active]))
                        self.assertEqual(two.rng[b].bit_generator.state, one.rng[b].bit_generator.state)

    def test_copies_have_none(self):
        s, sc = scene("numpy")
        eng = BatchEngine(s, guard=False)
        eng.steps(5, sc["cool"], sc["dt"])
        self.assertIsNotNone(s.contacts)
        self.assertIsNone(BatchState.concat([s, s]).contacts)
        self.assertIsNone(pickle.loads(pickle.dumps(s)).contacts)
        if "numba" in BACKENDS:
            self.assertIsNone(s.to_backend("numba").contacts)
        self.assertIs(s.to_backend("numpy"), s)      # (the same state: its own contacts)


if __name__ == "__main__":
    unittest.main()
