"""The engine's cell-list neighbour search against the all-pairs search (docs/engine.md, "Neighbour lists and box").

``near_pairs_cells`` bins spheres into cells of at least ``2 r_max + skin`` and searches the
3 × 3 cells around each sphere, the rows through ``y = 0`` / ``Ly`` at the x moved by the
Lees-Edwards offset.  Its definition is "exactly the pairs ``i < j`` whose minimum-image distance
is below ``r_i + r_j + skin``", which ``near_pairs_all`` evaluates by testing every pair; the two
must return the same arrays (same pairs, canonical ``(i, j)`` order).  One packing is also
checked against an oracle written independently of the package (``test_neighbours.oracle_pairs``).
Every comparison asserts first that the grid has at least 3 cells per side, so the cell list
itself (not its all-pairs fallback) is what is compared.
"""
import math
import unittest

import numpy as np

from particleShear.engine.neighbours import (CELL_LIST_MIN_N, build_candidates, cell_grid, near_pairs,
                                             near_pairs_all, near_pairs_cells)
from particleShear.engine.state import PERMANENT, ReplicaPairs
from particleShear.base.engine_adapter import state_from_ensembles
from particleShearTest.test_engine import constituted
from particleShearTest.test_neighbours import oracle_pairs

GAMMAS = (0.0, 0.3, -0.7, 1.9)


def packing(rng, N, Lx, Ly, r_small=5.0, ratio=1.4):
    """Uniformly random positions in the cell and bidisperse radii (half of each, ratio 1.4)."""
    r = np.where(rng.random(N) < 0.5, r_small, r_small * ratio)
    return rng.uniform(0, Lx, N), rng.uniform(0, Ly, N), r


class TestCellListEqualsAllPairs(unittest.TestCase):
    def assert_same(self, x, y, r, Lx, Ly, shift, skin, msg=""):
        nx, ny = cell_grid(Lx, Ly, 2 * float(r.max()) + skin, len(x))
        self.assertGreaterEqual(min(nx, ny), 3, f"{msg}: the cell list would fall back to all-pairs")
        ci, cj = near_pairs_cells(x, y, r, Lx, Ly, shift, skin)
        ai, aj = near_pairs_all(x, y, r, Lx, Ly, shift, skin)
        np.testing.assert_array_equal(ci, ai, err_msg=msg)
        np.testing.assert_array_equal(cj, aj, err_msg=msg)
        return len(ai)

    def test_random_bidisperse_packings_sheared(self):
        rng = np.random.default_rng(11)
        for N in (2, 3, 10, 64, 299, 300, 1000, 2500):
            L = math.sqrt(N * math.pi * 6.0 ** 2 / 0.9)         # a dense packing (area fraction ~0.9)
            L = max(L, 60.0)                                     # ≥ 3 cells of 2·7 + 3 µm per side
            x, y, r = packing(rng, N, 1.25 * L, L)
            for g in GAMMAS:
                n = self.assert_same(x, y, r, 1.25 * L, L, L * g, 3.0, f"N={N}, γ={g}")
                if N >= 300:
                    self.assertGreater(n, N, "a dense packing has more near pairs than spheres")

    def test_tall_and_wide_boxes(self):
        rng = np.random.default_rng(12)
        for Lx, Ly in ((2000.0, 52.0), (52.0, 2000.0), (4000.0, 55.0), (55.0, 4000.0)):   # 3 cells across
            N = int(Lx * Ly / 120)
            x, y, r = packing(rng, N, Lx, Ly)
            for g in GAMMAS:
                self.assert_same(x, y, r, Lx, Ly, Ly * g, 3.0, f"{Lx}×{Ly}, γ={g}")

    def test_spheres_on_cell_and_box_borders(self):
        # a lattice whose nodes lie exactly on the cell borders and on x = 0, y = 0, with a spacing of
        # half a cell, so that many pairs sit exactly at the reach or one cell apart; plus spheres just
        # inside the far borders and at −0.0
        Lx, Ly, skin = 170.0, 119.0, 3.0
        r0 = 7.0
        nx, ny = cell_grid(Lx, Ly, 2 * r0 + skin, 10 ** 6)
        cw, ch = Lx / nx, Ly / ny
        gx, gy = np.meshgrid(np.arange(2 * nx) * (cw / 2), np.arange(2 * ny) * (ch / 2))
        x = np.concatenate((gx.ravel(), [np.nextafter(Lx, 0), 0.0, -0.0, np.nextafter(Lx, 0), cw, 2 * cw]))
        y = np.concatenate((gy.ravel(), [0.0, np.nextafter(Ly, 0), np.nextafter(Ly, 0), np.nextafter(Ly, 0),
                                         np.nextafter(Ly, 0), 0.0]))
        r = np.full(len(x), r0)
        r[::3] = 5.5        # pairs at exactly r_i + r_j + skin for some spacings
        for g in GAMMAS + (cw / Ly, 0.5 * Lx / Ly, -1.0 * Lx / Ly):   # offsets by whole cells and half a box too
            self.assert_same(x, y, r, Lx, Ly, Ly * g, skin, f"γ={g}")

    def test_pairs_exactly_at_the_reach_across_a_border(self):
        # two spheres across the y boundary at exactly r_i + r_j + skin through the shifted image: not a
        # candidate (strict <); a hair closer: a candidate.  Both searches must agree with that definition.
        Lx = Ly = 200.0
        shift = 0.3 * Ly
        # sphere 1 near the top at x + shift: its image through y = 0 lies exactly below sphere 0
        # (dx = 110 − 50 − 60 = 0 exactly); its height gives |dy| = 16 exactly, or a hair less
        for y1, expect in ((188.0, 0), (np.nextafter(188.0, Ly), 1)):
            x = np.array([50.0, 50.0 + shift, 150.0])            # a third sphere far away
            y = np.array([4.0, y1, 100.0])
            r = np.array([6.0, 7.0, 6.0])                        # reach 6 + 7 + 3 = 16
            i, j = near_pairs_cells(x, y, r, Lx, Ly, shift, 3.0)
            ai, aj = near_pairs_all(x, y, r, Lx, Ly, shift, 3.0)
            np.testing.assert_array_equal(i, ai)
            np.testing.assert_array_equal(j, aj)
            self.assertEqual(len(i), expect, f"y1 = {y1!r}")

    def test_against_an_independent_oracle(self):
        rng = np.random.default_rng(13)
        N, Lx, Ly = 900, 420.0, 300.0
        x, y, r = packing(rng, N, Lx, Ly)
        for g in GAMMAS:
            i, j = near_pairs_cells(x, y, r, Lx, Ly, Ly * g, 3.0)
            self.assertEqual(set(zip(i.tolist(), j.tolist())), oracle_pairs(x, y, r, Lx, Ly, g, extra=3.0))

    def test_sparse_box_keeps_the_grid_small(self):
        rng = np.random.default_rng(14)
        N, L = 400, 1.0e5                                        # ~60,000² cells of 17 µm without coarsening
        nx, ny = cell_grid(L, L, 17.0, N)
        self.assertLessEqual(nx * ny, 2 * N + 9)
        x, y, r = packing(rng, N, L, L)
        x[:200] = rng.uniform(0, 40, 200)                        # a cluster, so that there are near pairs
        y[:200] = rng.uniform(0, 40, 200)
        self.assertGreater(self.assert_same(x, y, r, L, L, 0.3 * L, 3.0, "sparse"), 0)

    def test_small_box_falls_back_to_all_pairs(self):
        rng = np.random.default_rng(15)
        x, y, r = packing(rng, 400, 40.0, 400.0)                 # fewer than 3 cells across
        self.assertLess(cell_grid(40.0, 400.0, 17.0, 400)[0], 3)
        for f in (near_pairs_cells, near_pairs):
            i, j = f(x, y, r, 40.0, 400.0, 120.0, 3.0)
            ai, aj = near_pairs_all(x, y, r, 40.0, 400.0, 120.0, 3.0)
            np.testing.assert_array_equal(i, ai)
            np.testing.assert_array_equal(j, aj)

    def test_positions_outside_the_cell_and_non_finite(self):
        # spheres moved by whole periods (a y period with the offset of its image row) are the same
        # spheres: binned by their folded position, tested on the raw differences as the all-pairs
        # search tests them; a non-finite sphere has no pair (its distance test fails) and breaks nothing
        rng = np.random.default_rng(16)
        N, Lx, Ly, g = 700, 300.0, 260.0, 0.3
        x, y, r = packing(rng, N, Lx, Ly)
        k = rng.integers(-1, 2, (2, N))
        x2, y2 = x + Lx * k[0] + Ly * g * k[1], y + Ly * k[1]
        n = self.assert_same(x2, y2, r, Lx, Ly, Ly * g, 3.0, "outside")
        self.assertEqual(n, self.assert_same(x, y, r, Lx, Ly, Ly * g, 3.0, "inside"))
        x2[5], y2[9], x2[11] = np.nan, np.inf, -np.inf
        with np.errstate(invalid="ignore"):
            self.assert_same(x2, y2, r, Lx, Ly, Ly * g, 3.0, "non-finite")
            i, j = near_pairs_cells(x2, y2, r, Lx, Ly, Ly * g, 3.0)
        self.assertFalse(np.isin([5, 9, 11], np.concatenate((i, j))).any())

    def test_fewer_than_two_spheres(self):
        for N in (0, 1):
            i, j = near_pairs_cells(np.zeros(N), np.zeros(N), np.ones(N), 100.0, 100.0, 0.0, 1.0)
            self.assertEqual((len(i), len(j)), (0, 0))


class TestBuildCandidates(unittest.TestCase):
    def test_near_pairs_and_every_bond_in_canonical_order_with_history(self):
        rng = np.random.default_rng(21)
        N, Lx, Ly, g, skin = max(CELL_LIST_MIN_N, 600), 500.0, 360.0, -0.7, 3.0
        x, y, r = packing(rng, N, Lx, Ly)
        near = set(zip(*(a.tolist() for a in near_pairs_all(x, y, r, Lx, Ly, Ly * g, skin))))
        # bonds: one far beyond the reach (stretched), one that is also a near pair; a relation that is near
        a, b = next(iter(sorted(near)))
        far = (0, N - 1) if (0, N - 1) not in near else (1, N - 1)
        self.assertNotIn(far, near)
        # given in any order: the table puts its rows (and their history) in canonical (i, j) order
        old = ReplicaPairs([far[0], a], [far[1], b], [PERMANENT, PERMANENT], [[1.5, 0.25], [-0.5, 0.75]],
                           [30.0, 12.0], [True, True])
        new = build_candidates(x, y, r, Lx, Ly, Ly * g, skin, old)
        got = list(zip(new.i.tolist(), new.j.tolist()))
        self.assertEqual(got, sorted(near | {far}))               # near pairs + bonds, canonical, no duplicate
        for (p, q), xi0, xi1, d_eq in ((far, 1.5, -0.5, 30.0), ((a, b), 0.25, 0.75, 12.0)):
            k = got.index((p, q))
            self.assertEqual((int(new.state[k]), new.xi[0, k], new.xi[1, k], new.d_eq[k], bool(new.active[k])),
                             (PERMANENT, xi0, xi1, d_eq, True))
        others = np.ones(len(got), bool)
        others[[got.index(far), got.index((a, b))]] = False
        self.assertFalse(new.active[others].any())                # new candidates start at rest
        self.assertFalse(new.xi[:, others].any())


class TestEngineWithTheCellList(unittest.TestCase):
    def test_sheared_trajectory_bit_identical_to_the_all_pairs_search(self):
        # N = 400 > CELL_LIST_MIN_N: the engine's rebuilds use the cell list; with the all-pairs search
        # forced instead, the candidate lists, hence every force and position, must be the same bits
        from unittest import mock
        from particleShear.engine import neighbours
        from particleShear.engine.step import BatchEngine
        N = 400
        self.assertGreaterEqual(N, CELL_LIST_MIN_N)
        _, ens, sc = constituted(5, N, theMu=0.05, cut_lines=3)
        dt, f = sc["dt"], sc["f"]
        runs = []
        for min_n in (CELL_LIST_MIN_N, 10 ** 9):
            with mock.patch.object(neighbours, "CELL_LIST_MIN_N", min_n):
                s = state_from_ensembles([ens])
                eng = BatchEngine(s, skin_factor=0.2, guard=False)       # a thin skin: many rebuilds
                s.applying_shear = True
                eng.set_rate(np.array([0.5 * 2 * math.pi * f * 8]))     # 8× the protocol's peak rate
                for _ in range(150):
                    eng.step(1.0, dt)
                eng.flush()
                runs.append((s.pos.copy(), s.vel.copy(), [(p.i.copy(), p.j.copy()) for p in s.pairs],
                             int(eng.s.contacts.rebuilds[0])))
        (pos_c, vel_c, pairs_c, nb_c), (pos_a, vel_a, pairs_a, nb_a) = runs
        self.assertGreater(nb_c, 3)
        self.assertEqual(nb_c, nb_a)
        np.testing.assert_array_equal(pos_c, pos_a)
        np.testing.assert_array_equal(vel_c, vel_a)
        np.testing.assert_array_equal(pairs_c[0][0], pairs_a[0][0])
        np.testing.assert_array_equal(pairs_c[0][1], pairs_a[0][1])



class TestSkin(unittest.TestCase):
    """The Verlet skin decides only which pairs are candidates: the contacts of every step are exact
    for any skin and a candidate out of contact adds exact zeros to each sphere's force sum, so the
    trajectory is the same bits at any skin.  The stress samples are pairwise sums over the
    candidates, whose tree follows the candidates' count: they agree to a few units of the last
    place (pairwise summation of n terms errs by O(ε log n) relative; the bound 1e-13 is ~450 ε)."""

    def test_trajectories_do_not_depend_on_the_skin_and_samples_agree_to_rounding(self):
        from particleShear.engine.step import BatchEngine
        _, ens, sc = constituted(5, 60, theMu=0.05, cut_lines=3)
        dt, f = sc["dt"], sc["f"]
        for backend in ("numpy", "numba"):
            with self.subTest(backend=backend):
                runs = []
                for skin in (0.2, 0.7):
                    s = state_from_ensembles([ens], backend=backend)
                    eng = BatchEngine(s, skin_factor=skin, guard=False)
                    s.applying_shear = True
                    eng.set_rate(np.array([0.5 * 2 * math.pi * f * 8]))     # 8× the protocol's peak rate
                    samples = np.array([eng.step(1.0, dt, sample=True) for _ in range(150)])
                    eng.flush()
                    runs.append((s.pos.copy(), s.vel.copy(), s.pairs[0].copy(s.pairs[0].active), samples,
                                 int(eng.s.contacts.rebuilds[0])))
                (pos_a, vel_a, rel_a, tau_a, nb_a), (pos_b, vel_b, rel_b, tau_b, nb_b) = runs
                self.assertGreater(nb_a, nb_b)                    # the thin skin rebuilt more often
                np.testing.assert_array_equal(pos_a, pos_b)
                np.testing.assert_array_equal(vel_a, vel_b)
                for name in ("i", "j", "state", "xi"):
                    np.testing.assert_array_equal(getattr(rel_a, name), getattr(rel_b, name), name)
                scale = np.max(np.abs(tau_a))
                self.assertGreater(scale, 0)
                np.testing.assert_allclose(tau_a, tau_b, rtol=0, atol=1e-13 * scale)


if __name__ == "__main__":
    unittest.main()


class TestPlainPeriodicImages(unittest.TestCase):
    """A plain periodic cell (``lees_edwards=False``, the documented ``use_lees_edwards = False``) has
    its y images at the same x whatever the strain: two spheres overlapping across ``y = 0 / Ly``
    are a candidate and a relation at γ = 0.3 as at γ = 0, on every host backend (the search takes
    the force phase's image offset, 0 here, not ``Ly·γ``)."""

    def test_contact_across_the_y_edge_at_any_strain(self):
        from particleShear.engine import numba_driver
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_invariants import random_ensemble

        for backend in ("numpy", "numba") if numba_driver.available() else ("numpy",):
            for gamma in (0.0, 0.3):
                with self.subTest(backend=backend, gamma=gamma):
                    e = random_ensemble(2, 1000.0, seed=3, packing_fraction=0.05)
                    s = state_from_ensembles([e], backend=backend)
                    s.pos[:, 0], s.pos[:, 1] = (500.0, 1.0), (500.0, 999.0)    # 2 µm apart through the edge
                    self.assertLess(2.0, s.r[0] + s.r[1])
                    s.vel[...] = 0.0
                    s.gamma = np.array([gamma])
                    eng = BatchEngine(s, guard=False, lees_edwards=False)
                    eng.set_rate(np.zeros(1))
                    eng.step(1.0, 1e-9)
                    p = eng.pairs_of(0)
                    self.assertEqual((list(p.i), list(p.j)), ([0], [1]))
                    self.assertTrue(p.active[0])
