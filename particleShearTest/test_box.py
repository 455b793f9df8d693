"""The Lees-Edwards box is written once (particleShear.engine.box).

* every finite coordinate, however large, ends inside the half-open cell (wrap) or the half-open
  intervals ``[−L/2, L/2)`` (minimum image): the closed-form fold is clipped against rounding;
* one crossing of ``y = Ly`` moves x by exactly ``−Ly·γ`` and vx by exactly ``−Ly·γ̇`` (docs/engine.md);
  a NaN height stays NaN and is moved by no period;
* the device form of the box (every pass, then the fold) gives NumPy's numbers, for ordinary,
  huge, infinite and NaN coordinates;
* the period counts of the minimum image: −1, 0 or +1 for differences of positions inside the
  cell, with ``raw − counts·periods = separation`` in the reference's order of subtraction;
* the random normals at ``d = 0`` (``engine.forces.normals``) are drawn from the replica's
  generator, one uniform ``u`` per pair in pair order, ``n = (cos 2πu, sin 2πu)``.
"""
import unittest

import numpy as np

from particleShear.engine import box
from particleShear.engine import xp as xpmod
from particleShearTest.test_backend import STANDIN, standin_registered

L = 500.0


def huge_values(n, seed):
    """Log-uniform magnitudes 1e3 … 1e300 with random signs: thousands to 1e297 periods of a 500 µm cell."""
    rng = np.random.default_rng(seed)
    return 10 ** rng.uniform(3, 300, n) * rng.choice([-1.0, 1.0], n)


def inside(v, lo, hi):
    return (v >= lo) & (v < hi)


class TestEveryFiniteCoordinateEndsInside(unittest.TestCase):
    """The documented post-condition holds for any finite input (before the clip, ~1.7 % of these did not)."""

    def test_wrap(self):
        v = huge_values(20000, 1)
        x, y, vx = v.copy(), v[::-1].copy(), np.zeros(len(v))
        box.wrap(x, y, vx, L, L, 123.4, 0.3)
        self.assertTrue(inside(x, 0.0, L).all() and inside(y, 0.0, L).all(),
                        (x[~inside(x, 0.0, L)][:3], y[~inside(y, 0.0, L)][:3]))

    def test_minimum_image(self):
        v = huge_values(20000, 2)
        dx, dy = box.min_image(v, v[::-1], L, L, 123.4)[:2]
        self.assertTrue(inside(dx, -L / 2, L / 2).all() and inside(dy, -L / 2, L / 2).all())

    def test_exact_where_representable(self):
        # 10⁹ periods of 512 µm (a power of two): k·L is exact, so the fold must give the remainder exactly
        Lp = 512.0
        n = 10 ** 9
        dx, dy, ky, kx = box.min_image(np.array([3.0 + n * Lp]), np.array([-5.0 - n * Lp]), Lp, Lp, 0.0)
        self.assertEqual((dx[0], dy[0], ky[0], kx[0]), (3.0, -5.0, -n, n))


class TestCrossingsAreExact(unittest.TestCase):
    """A sphere through the top re-enters at the bottom, moved by −Ly·γ in x and −Ly·γ̇ in vx."""

    def test_one_crossing(self):
        Ly, Lx, gamma, rate = 400.0, 500.0, 0.3, 2.5
        x, y, vx = np.array([200.0, 200.0, 50.0]), np.array([401.0, -1.0, 7.0]), np.array([3.0, 3.0, 3.0])
        box.wrap(x, y, vx, Lx, Ly, Ly * gamma, rate)
        np.testing.assert_array_equal(y, [1.0, 399.0, 7.0])
        np.testing.assert_array_equal(x, [200.0 - Ly * gamma, 200.0 + Ly * gamma, 50.0])
        np.testing.assert_array_equal(vx, [3.0 - Ly * rate, 3.0 + Ly * rate, 3.0])

    def test_nan_height_moves_no_period(self):
        # the NaN sphere is not moved by a period (its vx, (y' − y)·γ̇, is NaN); the other one wraps as alone
        x, y, vx = np.array([10.0, 20.0]), np.array([np.nan, 510.0]), np.array([1.0, 1.0])
        moved = box.wrap(x, y, vx, L, L, 100.0, 0.5)
        self.assertTrue(moved)
        self.assertTrue(np.isnan(y[0]))
        self.assertEqual(x[0], 10.0)
        self.assertEqual((x[1], y[1], vx[1]), (20.0 - 100.0 + L, 10.0, 1.0 - L * 0.5))

    def test_hair_below_zero_ends_inside(self):
        # y + Ly rounds onto Ly: the reference's sequential loops would leave y = Ly, outside [0, Ly)
        x, y, vx = np.array([10.0]), np.array([-1e-14]), np.array([0.0])
        box.wrap(x, y, vx, L, L, 0.0, 0.0)
        self.assertTrue(inside(y, 0.0, L).all(), y)


class TestDeviceFormGivesNumPysNumbers(unittest.TestCase):
    """On a device every pass runs and the fold is applied to what is still outside: the same numbers."""

    def test_min_image_and_wrap(self):
        rng = np.random.default_rng(3)
        n = 400
        dx = rng.uniform(-2.5 * L, 2.5 * L, n)
        dy = rng.uniform(-2.5 * L, 2.5 * L, n)
        dx[:40], dy[40:80] = huge_values(40, 4), huge_values(40, 5)   # folded
        dx[80], dy[81], dy[82], dx[83] = np.inf, -np.inf, np.nan, np.nan
        shift = rng.uniform(-900.0, 900.0, n)
        rate = rng.normal(size=n)
        Ls = np.full(n, L)
        with standin_registered():
            dev = xpmod.get_backend(STANDIN)
            D = [dev.asarray(a) for a in (dx, dy, Ls, shift)]
            got = [xpmod.to_host(a, "state") for a in box.min_image(D[0], D[1], D[2], D[2], D[3])]
            want = box.min_image(dx, dy, Ls, Ls, shift)
            for g, w in zip(got, want):
                np.testing.assert_array_equal(g, w)
            host = [dx.copy(), dy.copy(), rate.copy()]
            box.wrap(host[0], host[1], host[2], Ls, Ls, shift, rate)
            X, Y, V, LL, S, R = (dev.asarray(a) for a in (dx, dy, rate, Ls, shift, rate))
            self.assertIsNone(box.wrap(X, Y, V, LL, LL, S, R))
            for g, w in zip((X, Y, V), host):
                np.testing.assert_array_equal(xpmod.to_host(g, "state"), w)


class TestCountsAndNormals(unittest.TestCase):
    """The period counts of the minimum image and the random normals at ``d = 0``."""

    def test_period_counts(self):
        rng = np.random.default_rng(8)
        x = rng.uniform(0, L, 300)
        y = rng.uniform(0, L, 300)
        i, j = np.triu_indices(300, 1)
        rx, ry = x[j] - x[i], y[j] - y[i]          # differences of positions inside the cell
        shift = 0.37 * L
        dx, dy, ky, kx = box.min_image(rx, ry, L, L, shift)
        self.assertTrue(set(np.unique(ky)) <= {-1, 0, 1} and set(np.unique(kx)) <= {-1, 0, 1})
        self.assertTrue((ky != 0).any() and (kx != 0).any())
        # the separation is the raw difference less the periods counted, subtracted in the reference's order
        np.testing.assert_array_equal(dy, ry - L * ky)
        np.testing.assert_array_equal(dx, (rx - shift * ky) - L * kx)

    def test_random_normals_follow_the_generator(self):
        from particleShear.engine.forces import normals
        dx = np.array([0.0, 3.0, 0.0, 0.0, -4.0])
        dy = np.array([0.0, 4.0, 0.0, 0.0, 0.0])
        d = np.sqrt(dx * dx + dy * dy)
        rng = np.random.default_rng(21)
        nx, ny = normals(dx, dy, d, None, (rng,))
        u = np.random.default_rng(21).random(4)     # an independent copy of the stream
        np.testing.assert_array_equal(nx[[0, 2, 3]], np.cos(2 * np.pi * u[:3]))
        np.testing.assert_array_equal(ny[[0, 2, 3]], np.sin(2 * np.pi * u[:3]))
        np.testing.assert_array_equal((nx[[1, 4]], ny[[1, 4]]), ([0.6, -1.0], [0.8, 0.0]))
        self.assertEqual(rng.random(), u[3])         # exactly one draw per pair at d = 0

if __name__ == "__main__":
    unittest.main()
