"""``PairTable.replace``: the candidate set of a rebuild, against a reference made with Python sets.

The new table holds, in ``(i, j)`` order with ``i < j``, each pair of the given candidates once
(whatever their order, orientation or repeats) plus the rows the rebuild keeps (bonds; with
``keep_relations`` also relations; with ``keep_existing`` every row); a row present before carries
its state, ξ, ``d_eq``, relation flag and creation number, a new row starts empty.  A sorted
candidate list (what the searches return) and the same pairs shuffled, reversed and repeated give
the same table.

The relation edits of the documented classes: ``open_relations`` numbers the rows that were no
relation in the order given and leaves the others as they are; ``close_relations`` ends transient
relations (ξ = 0) and never a bond; ``relations_of`` lists a sphere's relations by creation number.
"""
import unittest

import numpy as np

from particleShear.engine.state import PERMANENT, SLIP, STICK, PairTable


def table(rng, n_spheres=40, n_pairs=120):
    """A table of random distinct pairs with random history (some bonds, some relations)."""
    pairs = set()
    while len(pairs) < n_pairs:
        i, j = rng.integers(0, n_spheres, 2)
        if i != j:
            pairs.add((min(i, j), max(i, j)))
    i, j = np.array(sorted(pairs)).T
    n = len(i)
    return PairTable(i, j, state=rng.choice([STICK, SLIP, PERMANENT], n), xi=rng.normal(size=(2, n)),
                     d_eq=rng.random(n), active=rng.random(n) < 0.5, birth=rng.integers(1, 100, n))


def reference(old, i, j, keep_existing, keep_relations):
    """The rows of the replaced table as {(i, j): (state, ξ_ij, ξ_ji, d_eq, active, birth)}."""
    before = {(a, b): (old.state[k], old.xi[0, k], old.xi[1, k], old.d_eq[k], old.active[k], old.birth[k])
              for k, (a, b) in enumerate(zip(old.i.tolist(), old.j.tolist()))}
    keys = {(min(a, b), max(a, b)) for a, b in zip(i.tolist(), j.tolist())}
    for k, key in enumerate(zip(old.i.tolist(), old.j.tolist())):
        bond = old.state[k] == PERMANENT
        if keep_existing or bond or (keep_relations and old.active[k]):
            keys.add(key)
    empty = (STICK, 0.0, 0.0, 0.0, False, 0)
    return {key: before.get(key, empty) for key in sorted(keys)}


def rows(t):
    return {(a, b): (t.state[k], t.xi[0, k], t.xi[1, k], t.d_eq[k], t.active[k], t.birth[k])
            for k, (a, b) in enumerate(zip(t.i.tolist(), t.j.tolist()))}


class TestReplace(unittest.TestCase):
    def check(self, seed, keep_existing, keep_relations):
        rng = np.random.default_rng(seed)
        old = table(rng)
        # new candidates: some old pairs, some new ones
        new = set(zip(old.i[rng.random(len(old)) < 0.6].tolist(), old.j[rng.random(len(old)) < 0.6].tolist()))
        new = {(a, b) for a, b in new if a < b}
        while len(new) < 150:
            a, b = rng.integers(0, 40, 2)
            if a != b:
                new.add((min(a, b), max(a, b)))
        i, j = np.array(sorted(new)).T
        expected = reference(old, i, j, keep_existing, keep_relations)
        # the sorted list of a search, and the same pairs shuffled, either orientation, repeated
        order = rng.permutation(np.r_[np.arange(len(i)), rng.integers(0, len(i), 30)])
        flip = rng.random(len(order)) < 0.5
        si, sj = np.where(flip, j[order], i[order]), np.where(flip, i[order], j[order])
        for name, (ci, cj) in (("sorted", (i, j)), ("shuffled", (si, sj))):
            with self.subTest(seed=seed, input=name, keep_existing=keep_existing, keep_relations=keep_relations):
                t = table(np.random.default_rng(seed))
                t.replace(ci, cj, keep_existing=keep_existing, keep_relations=keep_relations)
                self.assertEqual(list(zip(t.i.tolist(), t.j.tolist())), list(expected))
                self.assertEqual(rows(t), expected)
                self.assertTrue((np.diff(t.key) > 0).all())        # sorted, each pair once

    def test_against_sets(self):
        for seed in range(6):
            for keep_existing, keep_relations in ((False, False), (False, True), (True, True)):
                self.check(seed, keep_existing, keep_relations)

    def test_kept_bonds_beyond_the_candidates(self):
        rng = np.random.default_rng(7)
        old = table(rng)
        t = table(np.random.default_rng(7))
        t.replace(np.array([0]), np.array([1]), keep_relations=False)   # almost nothing found: bonds kept
        self.assertEqual(rows(t), reference(old, np.array([0]), np.array([1]), False, False))
        self.assertEqual(int((t.state == PERMANENT).sum()), int((old.state == PERMANENT).sum()))



class TestRelationEdits(unittest.TestCase):
    def test_open_close_and_order(self):
        rng = np.random.default_rng(7)
        t = table(rng)
        before = t.copy()
        t.next_births(1000)                        # the counter starts at 0: the next number is 1000
        slots = rng.permutation(len(t.i))[:30]
        new = t.open_relations(slots)
        was_off = ~before.active[slots]
        np.testing.assert_array_equal(new, slots[was_off])                    # in the order given
        np.testing.assert_array_equal(t.birth[new], 1000 + np.arange(len(new)))
        self.assertEqual(t.birth_count, 1000 + len(new))                       # the next number to give
        kept = slots[~was_off]
        np.testing.assert_array_equal(t.birth[kept], before.birth[kept])      # relations keep their number
        self.assertTrue(t.active[slots].all())
        t.close_relations(slots)
        bond = t.state[slots] == PERMANENT
        np.testing.assert_array_equal(t.active[slots], bond)
        self.assertTrue((t.xi[:, slots[~bond]] == 0).all())
        np.testing.assert_array_equal(t.xi[:, slots[bond]], before.xi[:, slots[bond]])
        for p in range(40):
            rows = t.relations_of(p)
            want = sorted((int(t.birth[k]), k) for k in range(len(t.i)) if t.active[k] and p in (t.i[k], t.j[k]))
            self.assertEqual(rows.tolist(), [k for _, k in want])
            only = t.relations_of(p, bonds=False)
            self.assertEqual(only.tolist(), [k for _, k in want if t.state[k] != PERMANENT])

    def test_relations_with_a_sphere_outside_the_ensemble(self):
        """A relation of an ensemble's sphere to a sphere of no ensemble lives on the outside sphere's own
        list, for every ensemble-built sphere (1.0.2: ``establish_permanent_link`` makes the back-link)."""
        from particleShear import EnsembleLinkable, SphereLinkable
        ens = EnsembleLinkable(100, 100, 2)
        inside = ens.sphereList[0]
        outside = SphereLinkable("red", inside.x + 1.0, inside.y, 2 * inside.r)
        self.assertIsNone(inside.test_neighbor_relation(outside))
        self.assertIsNone(inside.establish_permanent_link(outside))
        self.assertEqual([(r.theSphere is inside, r.interface_type) for r in outside.neighbors],
                         [(True, "permanent")])

if __name__ == "__main__":
    unittest.main()
