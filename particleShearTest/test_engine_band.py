"""The y band of the all-pairs search drops no pair within reach (docs/engine.md, "Neighbour lists and box").

``near_pairs_all`` tests on the host only the pairs whose ``|y_j − y_i|`` lies within
``2 r_max + skin`` (plus a relative margin of 1e-9) of 0 or of ``Ly``.  Its definition is still
"every pair ``i < j`` whose minimum-image distance is below ``r_i + r_j + skin``": the reference
here is that distance test applied to every pair of ``numpy.triu_indices`` (no band), and the two
must return the same arrays, also for pairs placed a few ulps inside and outside the reach across
the top and bottom boundary, where the band's edge is.
"""
import unittest

import numpy as np

from particleShear.engine.box import min_image
from particleShear.engine.neighbours import near_pairs_all


def every_pair_within_reach(x, y, r, Lx, Ly, shift, skin):
    """(i, j) of every pair i < j with (minimum-image distance)² < (r_i + r_j + skin)², testing all pairs."""
    i, j = np.triu_indices(len(x), 1)
    dx, dy, _, _ = min_image(x[j] - x[i], y[j] - y[i], Lx, Ly, shift)
    reach = r[i] + r[j] + skin
    near = dx * dx + dy * dy < reach * reach
    return i[near], j[near]


class TestYBand(unittest.TestCase):
    def assert_same(self, x, y, r, Lx, Ly, shift, skin, msg):
        got = near_pairs_all(x, y, r, Lx, Ly, shift, skin)
        ref = every_pair_within_reach(x, y, r, Lx, Ly, shift, skin)
        np.testing.assert_array_equal(got[0], ref[0], err_msg=msg)
        np.testing.assert_array_equal(got[1], ref[1], err_msg=msg)
        return len(ref[0])

    def test_random_packings_sheared(self):
        rng = np.random.default_rng(5)
        for N, L in ((2, 50.0), (40, 120.0), (150, 500.0), (199, 300.0)):
            r = np.where(rng.random(N) < 0.5, 20.0, 28.0) * L / 500
            x, y = rng.uniform(0, 1.1 * L, N), rng.uniform(0, L, N)
            for g in (0.0, 0.31, -0.77, 1.6):
                n = self.assert_same(x, y, r, 1.1 * L, L, L * g, 0.2 * r.max(), f"N={N}, γ={g}")
                if N >= 150:
                    self.assertGreater(n, 0)

    def test_pairs_at_the_reach_across_the_boundary(self):
        # sphere 0 at the bottom (y = 0), partners at the top one y-image away at x = 0: their
        # minimum-image distance is Ly − y_k, placed 1, 2, 4 ulps inside and outside the reach
        Lx, Ly, skin, rad = 200.0, 300.0, 3.0, 10.0
        reach = 2 * rad + skin
        ys = [0.0]
        for k in (1, 2, 4, 64):
            for side in (-1, 1):
                ys.append(Ly - reach + side * k * np.spacing(reach))   # |dy| = Ly − y: just within / beyond
                ys.append(reach + side * k * np.spacing(reach))        # direct, no image: |dy| = y
        y = np.array(ys)
        x = np.zeros_like(y)
        r = np.full(len(y), rad)
        n = self.assert_same(x, y, r, Lx, Ly, 0.0, skin, "sheared 0")
        self.assertGreater(n, 4, "pairs just within the reach are found")
        self.assertLess(n, len(y) * (len(y) - 1) // 2, "pairs just beyond are not")

    def test_heights_outside_the_cell_keep_every_pair(self):
        rng = np.random.default_rng(6)
        N, L = 60, 150.0
        r = np.full(N, 6.0)
        x, y = rng.uniform(0, L, N), rng.uniform(-L, 2 * L, N)          # not yet wrapped
        for g in (0.0, 0.4):
            self.assert_same(x, y, r, L, L, L * g, 1.2, f"unwrapped, γ={g}")
        y[3] = np.nan
        self.assert_same(x, y, r, L, L, 0.0, 1.2, "a NaN height")


if __name__ == "__main__":
    unittest.main()
