"""The force terms of ``particleShear.engine.terms`` as pure functions, and their one use by engine and classes.

* ``term_constants``: each constant against its definition (contacts: the law at r_i + r_j, no bound offset;
  bonds: the law at d_eq, −k of the tensile law, the permanent ratios, the viscosities scaled unless kept);
* ``elastic_term``: a separated contact gives +0, a stretched bond the tensile law ``k (d − d_eq)``, times
  the ratio; ``viscous_term``: ``ν·v_n`` on relations, 0 elsewhere;
* ``tangential_term``: the Coulomb bound is ``|μ·law|`` on contacts and none on bonds (a bond's spring
  force passes unclipped), and a second visit's constants act on the second visit only;
* ``pair_forces``: the force on i decomposes into ``f_n`` along n and ``f_t`` along t (to rounding of
  two products), and the torque split adds up to ``d·f_t`` in proportion to the radii;
* ``half_kick``: two half kicks are one kick of ``kick`` bit for bit (a power-of-two scaling is exact),
  plate spheres get no linear half kick;
* the classes and the engine evaluate a crosslinked frictional scene with these functions: the classes'
  force phase equals the terms evaluated by hand from the pair geometry, the register and the sphere sums.
"""
import unittest

import numpy as np

from particleShear.base.neighbours import PERMANENT
from particleShear.engine.integrate import half_kick, kick
from particleShear.engine.terms import (elastic_term, pair_forces, tangential_term, term_constants,
                                        viscous_term)
from particleShearTest.test_memo import _scene as memo_scene


def _pairs(P=400, seed=3):
    rng = np.random.default_rng(seed)
    d0 = rng.uniform(10.0, 30.0, P)
    d = d0 * rng.uniform(0.7, 1.3, P)
    perm = rng.random(P) < 0.4
    d_eq = d0 * rng.uniform(0.9, 1.1, P)
    return rng, d0, d, perm, d_eq


class TestTermConstants(unittest.TestCase):
    def test_constants_are_their_definition(self):
        rng, d0, d, perm, d_eq = _pairs()
        k, c, nu, k_t, nu_t, mu, prc, prt = 2.0, 0.3, 0.5, 1.5, 0.25, 0.4, 0.6, 3.0
        for keep in (0.0, 1.0):
            with self.subTest(keep=keep):
                K = term_constants(d0, perm, d_eq, k, c, nu, k_t, nu_t, mu, prc, prt, keep)
                dl = np.where(perm, d_eq, d0)
                np.testing.assert_array_equal(K.d_law, dl)
                np.testing.assert_array_equal(K.d_cap, dl / 1000)                    # cap d0/d ≤ 1000 (S1-6)
                np.testing.assert_array_equal(K.a_div, -k * c * dl)
                self.assertEqual(K.a_lin, -k * (1 - c))
                np.testing.assert_array_equal(K.ratio_c, np.where(perm, prc, 1.0))
                np.testing.assert_array_equal(K.k_t, np.where(perm, k_t * prt, k_t))
                np.testing.assert_array_equal(K.nu, np.where(perm & (keep == 0), nu * prc, nu))
                np.testing.assert_array_equal(K.nu_t, np.where(perm & (keep == 0), nu_t * prt, nu_t))
                np.testing.assert_array_equal(K.fc_inf, np.where(perm, np.inf, 0.0))

    def test_contacts_only_need_no_bond_constants(self):
        _, d0, d, _, _ = _pairs()
        K = term_constants(d0, None, None, 2.0, 1.0, 0.5, 1.5, 0.25, 0.4)
        self.assertIsNone(K.a_tens)
        self.assertEqual((K.ratio_c, K.fc_inf, K.nu, K.k_t), (1.0, 0.0, 0.5, 1.5))


class TestElasticAndViscous(unittest.TestCase):
    def test_separated_contacts_and_stretched_bonds(self):
        rng, d0, d, perm, d_eq = _pairs()
        k, prc = 2.0, 0.6
        K = term_constants(d0, perm, d_eq, k, 0.0, 0.5, 1.5, 0.25, 0.4, prc)
        f, law = elastic_term(K, d)
        apart = ~perm & (d > d0)
        stretched = perm & (d > d_eq)
        self.assertTrue(apart.any() and stretched.any())
        self.assertTrue((law[apart] == 0).all() and not np.signbit(law[apart]).any())   # +0 beyond contact
        np.testing.assert_allclose(law[stretched], k * (d - d_eq)[stretched], rtol=1e-15)  # attractive
        squeezed = ~perm & (d < d0)
        np.testing.assert_allclose(law[squeezed], -k * (d0 - d)[squeezed], rtol=1e-15)     # S1-5a, c = 0
        np.testing.assert_array_equal(f, law * np.where(perm, prc, 1.0))

    def test_viscous_term_acts_on_relations_only(self):
        rng, d0, d, perm, d_eq = _pairs()
        K = term_constants(d0, perm, d_eq, 2.0, 0.0, 0.5, 1.5, 0.25, 0.4, 0.6, 1.0, 0.0)
        vn = rng.normal(size=len(d))
        active = perm | (d < d0)
        f = viscous_term(K, vn, active)
        np.testing.assert_array_equal(f[~active], 0.0)
        np.testing.assert_array_equal(f[active], (np.where(perm, 0.5 * 0.6, 0.5) * vn)[active])
        np.testing.assert_array_equal(viscous_term(K, vn, None), K.nu * vn)


class TestTangential(unittest.TestCase):
    def test_coulomb_bound_on_contacts_none_on_bonds(self):
        rng, d0, d, perm, d_eq = _pairs()
        mu = 0.3
        K = term_constants(d0, perm, d_eq, 2.0, 0.0, 0.5, 1.5, 0.0, mu)
        law = elastic_term(K, d)[1]
        xi = rng.normal(scale=20.0, size=(2, len(d)))      # springs far beyond the bound of most contacts
        F, slip = tangential_term(K, np.zeros(len(d)), np.ones(len(d)), xi.copy(), law)
        bound = np.abs(mu * law)
        self.assertTrue((np.abs(F[0]) <= bound)[~perm].all())
        np.testing.assert_array_equal(F[0][perm], (K.k_t * xi[0])[perm])   # bonds: the spring, unclipped
        self.assertFalse(slip[perm].any())
        self.assertTrue(slip[~perm].any())

    def test_second_visit_constants(self):
        rng, d0, d, perm, d_eq = _pairs()
        d = np.minimum(d, 0.99 * np.minimum(d0, d_eq))       # every pair pressed: a bound of ≥ 0.3·2·0.1 µm·k
        K_i = term_constants(d0, perm, d_eq, 2.0, 0.0, 0.5, 1.5, 0.0, 0.3, prt=1.0)
        K_j = term_constants(d0, perm, d_eq, 2.0, 0.0, 0.5, 1.5, 0.0, 0.3, prt=2.0)
        law = elastic_term(K_i, d)[1]
        xi = rng.normal(scale=1e-3, size=(2, len(d)))      # small against every bound: nothing slips
        F, slip = tangential_term(K_i, np.zeros(len(d)), np.ones(len(d)), xi.copy(), law, K_j)
        self.assertFalse(slip.any())
        np.testing.assert_array_equal(F[0], K_i.k_t * xi[0])
        np.testing.assert_array_equal(F[1], K_j.k_t * xi[1])
        np.testing.assert_array_equal(F[1][perm], (3.0 * xi[1])[perm])     # k_t·prt of the second sphere


class TestPairForces(unittest.TestCase):
    def test_decomposition_and_torque_split(self):
        rng = np.random.default_rng(5)
        P = 300
        theta = rng.uniform(0, 2 * np.pi, P)
        nx, ny = np.cos(theta), np.sin(theta)
        fn, ft = rng.normal(size=P), rng.normal(size=P)
        ri, rj = rng.uniform(5, 15, P), rng.uniform(5, 15, P)
        d = (ri + rj) * rng.uniform(0.8, 1.0, P)
        w = np.array((ri, rj)) / (ri + rj)
        fx, fy, dF, tq = pair_forces(fn, ft, nx, ny, d, w)
        scale = np.abs(fn) + np.abs(ft)
        np.testing.assert_allclose(fx * nx + fy * ny, fn, rtol=0, atol=4e-16 * scale.max())   # along n
        np.testing.assert_allclose(-fx * ny + fy * nx, ft, rtol=0, atol=4e-16 * scale.max())  # along t
        np.testing.assert_array_equal(dF, d * ft)
        np.testing.assert_allclose(tq[0] + tq[1], d * ft, rtol=1e-15, atol=0)
        np.testing.assert_allclose(tq[0] / tq[1], ri / rj, rtol=1e-14)
        cx, cy, cdF, ctq = pair_forces(fn, None, nx, ny, d, w)
        np.testing.assert_array_equal(cx, fn * nx)
        self.assertIsNone(cdF)
        self.assertIsNone(ctq)


class TestHalfKick(unittest.TestCase):
    def test_two_half_kicks_are_one_kick(self):
        rng = np.random.default_rng(6)
        n = 30
        m = rng.uniform(0.5, 2.0, n)
        weights = np.stack((m, m, 0.5 * m * rng.uniform(1, 3, n) ** 2))
        frc = rng.normal(size=(3, n))
        vel = rng.normal(size=(3, n))
        expected = vel.copy()
        kick(expected, frc.copy(), weights, 1e-3)
        h = half_kick(frc, weights, 1e-3)
        np.testing.assert_array_equal(vel + 2 * h - vel, expected - vel)   # exact: dt/(2m) = (dt/m)/2
        mobile = rng.random(n) < 0.7
        hm = half_kick(frc, weights, 1e-3, mobile)
        np.testing.assert_array_equal(hm[:2, ~mobile], 0.0)
        np.testing.assert_array_equal(hm[:2, mobile], h[:2, mobile])
        np.testing.assert_array_equal(hm[2], h[2])                           # spins are kicked everywhere


def _scene():
    """The crosslinked frictional sheared scene of test_memo, ten steps on."""
    ens = memo_scene(seed=4, n=30)
    for _ in range(10):
        ens.mechanical_simulation_step(cool_factor=0.95, dt=1e-3)
    return ens


class TestClassesUseTheTerms(unittest.TestCase):
    def test_force_phase_equals_the_terms_by_hand(self):
        """Each sphere's force of the classes' force phase equals Σ ±F of the terms evaluated here from the pair
        geometry, with the second visit's constants of the sphere whose ratios differ (relative 1e-12 of the
        largest pair force: the sums are the same, in another order)."""
        ens = _scene()
        s = ens.sphereList[5]
        s.permanent_ratio_central = 0.5
        s.permanent_ratio_tangential = 2.0
        s.keep_viscosity_coefficients_constant = False    # its bonds' viscosities take the ratios too
        before = ens.pair_table                        # (a copy) the histories the force phase starts from
        ens.mechanical_simulation_step_calculate_forces()
        g = ens._g
        pt = ens.pair_table
        a = ens.sphere_arrays
        perm = pt.state[g.slots] == PERMANENT
        self.assertTrue(perm.any() and ((g.ai == 5) | (g.aj == 5))[perm].any())
        mine = np.arange(len(ens.sphereList)) == 5
        # each visit's constants by hand: the ratios of its own sphere
        crc = a["central_repulsion_coefficient"]
        self.assertTrue((crc == crc[0]).all())        # one value for every sphere
        c = float(crc[0])
        K_i, K_j = (term_constants(g.d0, perm, pt.d_eq[g.slots], ens.k, c, ens.nu, ens.k_t, ens.nu_t, ens.mu,
                                   np.where(mine, 0.5, 1.0)[rows], np.where(mine, 2.0, 1.0)[rows],
                                   a["keep_viscosity_coefficients_constant"][rows])
                    for rows in (g.ai, g.aj))
        xi = before.xi[:, before.find(g.ai, g.aj)]
        vel = np.array((a["xspeed"], a["yspeed"], a["omega"]))
        rv = vel[:2, g.aj] - vel[:2, g.ai]
        if g.dvx is not None:
            rv[0] += g.dvx
        vn = rv[0] * g.nx + rv[1] * g.ny
        vt = -rv[0] * g.ny + rv[1] * g.nx - (g.ri * vel[2, g.ai] + g.rj * vel[2, g.aj])
        fi, law = elastic_term(K_i, g.d)
        fi += viscous_term(K_i, vn, g.active)
        fj = elastic_term(K_j, g.d)[0] + viscous_term(K_j, vn, g.active)
        F = tangential_term(K_i, vt, (g.d < g.d0).astype(float), xi, law, K_j)[0]
        ft = (F[0] + F[1]) / 2
        n = len(ens.sphereList)
        total = np.zeros((3, n))
        for k, (on_i, on_j) in enumerate(((fi * g.nx - ft * g.ny, -(fj * g.nx - ft * g.ny)),
                                          (fi * g.ny + ft * g.nx, -(fj * g.ny + ft * g.nx)),
                                          (g.d * ft * g.ri / g.d0, g.d * ft * g.rj / g.d0))):
            np.add.at(total[k], g.ai, on_i)
            np.add.at(total[k], g.aj, on_j)
        scale = np.abs(fi).max()
        np.testing.assert_allclose(a["xforce"], total[0], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(a["yforce"], total[1], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(a["torque"], total[2], rtol=0, atol=1e-12 * scale * g.d.max())
        np.testing.assert_array_equal(pt.xi[:, g.slots], xi)   # the histories the rule left
        self.assertFalse(np.allclose(fi, fj))          # the visits differ on the sphere's bonds


if __name__ == "__main__":
    unittest.main()
