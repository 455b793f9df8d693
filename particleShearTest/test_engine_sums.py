"""Per-replica sums of the engine (``engine.forces.replica_sums``): each replica's sum is the sum of
its own candidates' rows, whatever the rest of the batch holds (empty replicas included); and the
per-candidate constants after a rebuild of some replicas (``PairConstants.splice``) are those of
a rebuild of the whole batch, bit for bit (every constant is elementwise in its pair).

The definition is checked against ``math.fsum`` (the correctly rounded sum); the tolerance is
the bound of a floating-point summation of n terms, n·ε·Σ|w|, with n ≤ 64 here.  That a replica's
sum does not depend on its batch is checked bit for bit: it is what makes a replica of a batch
equal its single run.
"""
import math
import unittest

import numpy as np

from particleShear.engine.forces import PairConstants, pair_roles, replica_sums
from particleShear.engine.state import PERMANENT, BatchState, ReplicaPairs
from particleShear.engine.step import BatchEngine


def constants(sizes, N=4):
    """PairConstants of a batch whose replica b has ``sizes[b]`` candidates (pair (0, 1) repeated)."""
    s = BatchState(len(sizes), N)
    s.r[:] = 1.0
    s.Lx[:] = s.Ly[:] = 10.0
    for b, n in enumerate(sizes):
        s.pairs[b] = ReplicaPairs(np.zeros(n, int), np.ones(n, int), np.zeros(n, np.int8), np.zeros((2, n)),
                                  np.zeros(n), np.zeros(n, bool))
    return PairConstants(s, np.concatenate(([0], np.cumsum(sizes))).astype(int))


class TestReplicaSums(unittest.TestCase):
    SIZES = ([3, 0, 5], [0, 4], [4, 0, 0], [0, 0], [7], [64, 1, 0, 17])

    def test_each_replica_sums_its_own_rows(self):
        rng = np.random.default_rng(5)
        for sizes in self.SIZES:
            with self.subTest(sizes=sizes):
                C = constants(sizes)
                W = rng.normal(size=(3, sum(sizes)))
                out = replica_sums(C, W)
                self.assertEqual(out.shape, (3, len(sizes)))
                lo = np.concatenate(([0], np.cumsum(sizes)))
                for b in range(len(sizes)):
                    for r in range(3):
                        seg = W[r, lo[b]:lo[b + 1]]
                        bound = len(seg) * np.finfo(float).eps * np.abs(seg).sum()
                        self.assertLessEqual(abs(out[r, b] - math.fsum(seg)), bound)
                        if len(seg) == 0:
                            self.assertEqual(out[r, b], 0.0)

    def test_a_replica_sum_does_not_depend_on_its_batch(self):
        rng = np.random.default_rng(6)
        sizes = [64, 0, 13, 100, 1]
        W = rng.normal(size=(2, sum(sizes)))
        batch = replica_sums(constants(sizes), W)
        lo = np.concatenate(([0], np.cumsum(sizes)))
        for b, n in enumerate(sizes):
            alone = replica_sums(constants([n]), np.ascontiguousarray(W[:, lo[b]:lo[b + 1]]))
            self.assertEqual(batch[:, b].tobytes(), alone[:, 0].tobytes())


def random_batch(B=4, N=30, seed=7):
    """B replicas of N random spheres with their own boxes, constants and one bond each."""
    rng = np.random.default_rng(seed)
    s = BatchState(B, N)
    s.Lx[:] = rng.uniform(150, 200, B)
    s.Ly[:] = rng.uniform(150, 200, B)
    s.x[:] = rng.uniform(0, 1, B * N) * s.Lx[s.rep]
    s.y[:] = rng.uniform(0, 1, B * N) * s.Ly[s.rep]
    s.r[:] = rng.uniform(8, 12, B * N)
    s.m[:] = s.inertia[:] = 1.0
    for name in ("k", "nu", "k_t", "nu_t", "mu", "c", "prc", "prt"):
        getattr(s, name)[:] = rng.uniform(0.1, 1.0, B)
    s.keep[:] = rng.integers(0, 2, B)
    for b in range(B):
        i, j = sorted(rng.choice(N, 2, replace=False))
        s.pairs[b] = ReplicaPairs([i], [j], [PERMANENT], np.zeros((2, 1)), [25.0], [True])
        s.rng[b] = np.random.default_rng(b)
    return s


class TestPairRoles(unittest.TestCase):
    """The one internal/external rule of the stresses (eqs. S1-16, S1-19): a pair is internal when
    both spheres are mobile and it acts inside the cell; otherwise each of its mobile spheres gets
    the pair's force as an external entry.  So every mobile sphere of a pair receives the pair's
    force exactly once, and an immobile one never."""

    def test_each_mobile_sphere_of_a_pair_receives_its_force_once(self):
        rng = np.random.default_rng(3)
        mi, mj, shifted = rng.random(500) < 0.7, rng.random(500) < 0.7, rng.random(500) < 0.2
        internal, ext_i, ext_j = pair_roles(mi, mj, shifted)
        self.assertFalse((internal & shifted).any())            # a pair through the boundary is external
        np.testing.assert_array_equal(2 * internal + ext_i + ext_j, mi.astype(int) + mj)
        self.assertFalse((internal & (ext_i | ext_j)).any())
        self.assertTrue(internal.any() and ext_i.any() and (mi & ~ext_i & ~internal).sum() == 0)
        # every sphere mobile: the boundary alone decides
        for got, want in zip(pair_roles(True, True, shifted), (~shifted, shifted, shifted)):
            np.testing.assert_array_equal(got, want)


class TestSplicedConstants(unittest.TestCase):
    def test_rebuilding_some_replicas_gives_the_constants_of_a_full_rebuild(self):
        s = random_batch()
        engine = BatchEngine(s, guard=False)
        engine.neighbours()                                   # first build: every replica
        for changed in ([1], [0, 3], [3], [0]):
            with self.subTest(changed=changed):
                s.x[:] = (s.x + 3.0) % s.Lx[s.rep]            # moved: the rebuilt lists differ
                contacts = s.contacts
                contacts.need[:] = False
                contacts.need[changed] = True
                before = contacts.rebuilds.copy()
                engine.neighbours()
                np.testing.assert_array_equal(contacts.rebuilds - before, np.isin(np.arange(s.B), changed))
                C = contacts.C
                engine.flush()                                 # every replica's list with its history
                offsets = np.concatenate(([0], np.cumsum([len(p.i) for p in s.pairs])))
                full = PairConstants(s, offsets)
                full.set_bonds(s, np.concatenate([p.state for p in s.pairs]),
                               np.concatenate([p.d_eq for p in s.pairs]))
                for name in PairConstants.PER_PAIR + ("scatter_idx", "offsets", "seg_rep", "seg_starts"):
                    a, b = getattr(C, name), getattr(full, name)
                    self.assertEqual((a.dtype, a.shape, a.tobytes()), (b.dtype, b.shape, b.tobytes()), name)


if __name__ == "__main__":
    unittest.main()
