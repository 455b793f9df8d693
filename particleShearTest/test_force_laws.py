"""Central force laws (eq. S1-5a/b, S1-6; docs/engine.md) and the reference numbers of Appendix A.1.

Sign convention: negative = repulsion.  The reference numbers are compared to
1e-12 relative (an exact 0 where the reference prints 0).
"""
import math
import unittest

import numpy as np

from particleShear import (CircleBasicElasticity, EnsembleLinkable, PlateauConfiguration, SphereLinkable,
                           TensileConfiguration, distance_transform_plateau, elastic_force_law,
                           elastic_force_law_plateau, elastic_force_law_tensile,
                           elastic_force_law_tensile_exponential)

RTOL = 1e-12

# Appendix A.1: d, d0, k, c, elastic_force_law, elastic_force_law_plateau (defaults 0.3/0.8/0.1)
A1_TABLE = [
    (110, 120, 1, 0, -10.0, -10.0),
    (110, 120, 1, 1, -10.9090909090909, -10.9090909090909),
    (110, 120, 1, 0.5, -10.45454545454545, -10.45454545454545),
    (60, 120, 2, 1, -240.0, -71.68831168831169),
    (0.05, 120, 1, 1, -119880.0, -115080.0),
    (0.0, 120, 1, 1, -119880.0, -119880.0),
    (120, 120, 1, 1, 0.0, 0.0),
    (121, 120, 1, 1, 0, 0),
]


def assert_ref(tc, got, ref, msg=""):
    """Relative 1e-12 against the reference value; exact equality where the reference is 0."""
    if ref == 0:
        tc.assertEqual(got, 0, msg)
    else:
        tc.assertLessEqual(abs(got - ref) / abs(ref), RTOL, f"{msg}: got {got!r}, reference {ref!r}")


class TestAppendixA1(unittest.TestCase):
    """Every number of Appendix A.1."""

    def test_elastic_force_law_table(self):
        for d, d0, k, c, ref, _ in A1_TABLE:
            with self.subTest(d=d, d0=d0, k=k, c=c):
                assert_ref(self, elastic_force_law(d, d0, k, c), ref, "elastic_force_law")

    def test_plateau_law_table(self):
        self.assertEqual((PlateauConfiguration.relative_plateau_begin, PlateauConfiguration.relative_plateau_end,
                          PlateauConfiguration.relative_plateau_slope), (0.3, 0.8, 0.1))
        for d, d0, k, c, _, ref in A1_TABLE:
            with self.subTest(d=d, d0=d0, k=k, c=c):
                assert_ref(self, elastic_force_law_plateau(d, d0, k, c), ref, "elastic_force_law_plateau")

    def test_tensile_laws(self):
        self.assertEqual(TensileConfiguration.d_exponential, 0.2)
        assert_ref(self, elastic_force_law_tensile(130, 120, 2), 20, "tensile")
        assert_ref(self, elastic_force_law_tensile_exponential(130, 120, 2), 16.356449750378697,
                   "tensile exponential")

    def test_distance_transform_plateau(self):
        for d, ref in ((100, 100), (50, 91.4), (30, 75.0), (10, 25.0)):
            with self.subTest(d=d):
                assert_ref(self, distance_transform_plateau(d, 36, 96, 0.1), ref, "distance_transform_plateau")

    def test_array_evaluation_matches_scalar(self):
        """The engine calls the laws on pair arrays: element-wise identical to the scalar calls."""
        d = np.array([row[0] for row in A1_TABLE], dtype=float)
        for law in (elastic_force_law, elastic_force_law_plateau):
            for c in (0, 0.5, 1):
                arr = np.asarray(law(d, 120.0, 1.5, c), dtype=float)
                scal = np.array([law(float(v), 120.0, 1.5, c) for v in d], dtype=float)
                np.testing.assert_array_equal(arr, scal)


def central_law_definition(d, d0, k, c):
    """The compressive law written out from eq. S1-5a/b and the cap of eq. S1-6, independently of the
    package: F = −k(1−c)(d0−d) − k·c·d0·(d0/max(d, d0/1000) − 1) for d ≤ d0, else 0 (negative = repulsion).
    Returns (F, scale) with scale = |linear part| + |divergent part|, the magnitude rounding is relative to."""
    if d > d0:
        return 0.0, 0.0
    linear = -k * (1 - c) * (d0 - d)
    divergent = -k * c * d0 * (d0 / max(d, d0 / 1000) - 1)
    return linear + divergent, abs(linear) + abs(divergent)


class TestLawProperties(unittest.TestCase):
    """Properties of docs/engine.md that hold for every d0, k and c in [0, 1]."""

    CS = (0.0, 0.1, 0.25, 0.5, 0.75, 1.0)

    def test_law_equals_its_definition(self):
        # random geometry over the linear, blended, divergent and capped ranges; the package groups the
        # constants differently (a few roundings), so 1e-14 of the terms' magnitude bounds the difference
        rng = np.random.default_rng(2)
        d0 = rng.uniform(1.0, 150.0, 400)
        d = d0 * np.concatenate((rng.uniform(0.0, 0.002, 50), rng.uniform(0.002, 1.2, 350)))
        for k in (1.0, 3.14e9):
            for c in self.CS:
                for a, b in zip(d, d0):
                    with self.subTest(d=a, d0=b, k=k, c=c):
                        ref, scale = central_law_definition(float(a), float(b), k, c)
                        got = elastic_force_law(float(a), float(b), k, c)
                        self.assertLessEqual(abs(got - ref), 1e-14 * scale)

    def test_slope_k_at_contact_for_any_c(self):
        # one-sided difference from inside the contact: analytically
        # (F(d0) - F(d0-h))/h = k(1-c) + k c d0/(d0-h) = k (1 + c h/(d0-h)); with h = 1e-7 d0 the
        # truncation is ≤ 1e-7 relative and rounding of F ≈ 1e-7·k·d0 adds ≈ 1e-9, so 1e-6 is ample.
        for d0 in (1.0, 47.3, 120.0):
            for k in (1.0, 3.14e9):
                for c in self.CS:
                    with self.subTest(d0=d0, k=k, c=c):
                        h = 1e-7 * d0
                        slope = (elastic_force_law(d0, d0, k, c) - elastic_force_law(d0 - h, d0, k, c)) / h
                        self.assertLess(abs(slope - k) / k, 1e-6)
                        # both parts are Hookean at contact, so the blend is too: the divergent law alone
                        # (c = 1) and the linear law alone (c = 0) bracket every blend
                        f = elastic_force_law(d0 - h, d0, k, c)
                        f0 = elastic_force_law(d0 - h, d0, k, 0.0)
                        f1 = elastic_force_law(d0 - h, d0, k, 1.0)
                        self.assertLessEqual(f1, f * (1 - 1e-15) + 0.0)
                        self.assertGreaterEqual(f0, f * (1 + 1e-15) + 0.0)

    def test_blend_is_linear_in_c(self):
        for d in (0.5, 30.0, 90.0, 119.0):
            f0 = elastic_force_law(d, 120.0, 2.0, 0.0)
            f1 = elastic_force_law(d, 120.0, 2.0, 1.0)
            for c in self.CS:
                with self.subTest(d=d, c=c):
                    ref = (1 - c) * f0 + c * f1
                    self.assertLessEqual(abs(elastic_force_law(d, 120.0, 2.0, c) - ref), 1e-13 * abs(ref))

    def test_zero_at_and_beyond_contact(self):
        for law in (elastic_force_law, elastic_force_law_plateau):
            for c in self.CS:
                for d in (120.0, math.nextafter(120.0, math.inf), 121.0, 240.0, 1e9):
                    with self.subTest(law=law.__name__, c=c, d=d):
                        self.assertEqual(law(d, 120.0, 3.0, c), 0.0)
        # repulsive inside the contact
        for c in self.CS:
            self.assertLess(elastic_force_law(math.nextafter(120.0, 0.0), 120.0, 3.0, c), 0.0)

    def test_cap(self):
        """The divergent part is frozen for d < d0/1000 at -999 k c d0 (eq. S1-6)."""
        d0, k = 120.0, 2.0
        for c in self.CS:
            bound = k * d0 * ((1 - c) + 999 * c)
            frozen = -999 * k * c * d0
            for d in (0.0, 1e-9, 0.05, d0 / 1000 * 0.999):
                with self.subTest(c=c, d=d):
                    f = elastic_force_law(d, d0, k, c)
                    expected = -k * (1 - c) * (d0 - d) + frozen
                    self.assertLessEqual(abs(f - expected), 1e-13 * abs(expected))
                    self.assertLessEqual(abs(f), bound * (1 + 1e-15))
            # continuous at the clamp (a step of 1e-12·d_c in d changes F by ≈ k·c·d0·1e-12, far below 1e-9 of
            # the bound), monotone repulsion growing with overlap (differences ≥ −rounding of F)
            dc = d0 / 1000
            self.assertLessEqual(abs(elastic_force_law(dc, d0, k, c) - elastic_force_law(dc * (1 - 1e-12), d0, k, c)),
                                 1e-9 * bound)
            ds = np.linspace(0.0, d0, 2001)
            fs = np.array([elastic_force_law(float(v), d0, k, c) for v in ds])
            self.assertTrue(np.all(np.diff(fs) >= -1e-12 * bound))

    def test_plateau_slope_one_reproduces_default(self):
        saved = PlateauConfiguration.relative_plateau_slope
        try:
            PlateauConfiguration.relative_plateau_slope = 1
            for c in self.CS:
                for d in (1.0, 30.0, 60.0, 100.0, 119.0):
                    with self.subTest(c=c, d=d):
                        a = elastic_force_law_plateau(d, 120.0, 2.0, c)
                        b = elastic_force_law(d, 120.0, 2.0, c)
                        self.assertLessEqual(abs(a - b), 1e-13 * abs(b))
        finally:
            PlateauConfiguration.relative_plateau_slope = saved

    def test_distance_transform_is_continuous(self):
        # slopes are ≤ 1 (µm per µm): a step of 1e-12 relative (≤ 1e-10 µm) moves the value by ≤ 1e-10 µm;
        # a jump at an edge would be O(1 µm)
        pb, pe, s = 36.0, 96.0, 0.1
        for edge in (pb, pe):
            lo = distance_transform_plateau(edge * (1 - 1e-12), pb, pe, s)
            hi = distance_transform_plateau(edge, pb, pe, s)
            self.assertLessEqual(abs(lo - hi), 1e-9)


def _pair_scene(d, mu=0.0, nut=0.0, link=False, c=0.0):
    """Two spheres (d0 = 120) at distance d along x, at rest; ν = k_t = 0 so only the law acts centrally."""
    ens = EnsembleLinkable(500, 500, 0, k=2.0, nu=0.0, k_t=0.0, nu_t=nut, mu=mu)
    s1 = SphereLinkable("grey", 200.0, 250.0, 120, 1, 1, force_register=ens, size_x=500, size_y=500)
    s2 = SphereLinkable("grey", 200.0 + d, 250.0, 120, 1, 2, force_register=ens, size_x=500, size_y=500)
    ens.sphereList.append(s1)
    ens.sphereList.append(s2)
    ens.set_central_repulsion_coefficient(c)
    if link:
        s1.establish_permanent_link(s2)
    return ens, s1, s2


def _central_force_on_1(ens, s1):
    ens.mechanical_simulation_step_calculate_forces()
    # n_12 = +x: a repulsive (negative) law value pushes sphere 1 towards -x
    return s1.xforce


class TestCallbackMechanism(unittest.TestCase):
    """docs/engine.md: the class attribute is looked up at every call and used in all three places."""

    def setUp(self):
        self._saved = CircleBasicElasticity.__dict__["call_back_elastic_force_law"]
        self._saved_t = SphereLinkable.__dict__["call_back_elastic_force_law_tensile"]

    def tearDown(self):
        CircleBasicElasticity.call_back_elastic_force_law = self._saved
        SphereLinkable.call_back_elastic_force_law_tensile = self._saved_t

    def test_default_is_elastic_force_law(self):
        self.assertIs(self._saved, elastic_force_law)
        self.assertIs(self._saved_t, elastic_force_law_tensile)

    def test_plateau_callback_changes_forces(self):
        d = 60.0  # deep overlap: inside the plateau region (0.3 d0 … 0.8 d0) the two laws differ
        ens, s1, _ = _pair_scene(d)
        f_default = _central_force_on_1(ens, s1)
        self.assertLessEqual(abs(f_default - elastic_force_law(d, 120.0, 2.0, 0.0)), 1e-13 * abs(f_default))
        CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
        ens.reset_force()
        f_plateau = _central_force_on_1(ens, s1)
        ref = elastic_force_law_plateau(d, 120.0, 2.0, 0.0)
        self.assertNotAlmostEqual(f_default, f_plateau, places=3)
        self.assertLessEqual(abs(f_plateau - ref), 1e-13 * abs(ref))
        # restoring the default restores the forces of an ensemble that already exists
        CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law
        ens.reset_force()
        self.assertEqual(_central_force_on_1(ens, s1), f_default)

    def test_scalar_only_user_law(self):
        calls = []

        def cubic_law(d, d0, k, c):  # plain Python: breaks on arrays (`if` on an array)
            calls.append(d)
            if d > d0:
                return 0
            return -k * (d0 - d) ** 3 / d0 ** 2 - c

        d = 100.0
        ens, s1, _ = _pair_scene(d)
        CircleBasicElasticity.call_back_elastic_force_law = cubic_law
        f = _central_force_on_1(ens, s1)
        self.assertTrue(calls)
        ref = -2.0 * 20.0 ** 3 / 120.0 ** 2
        self.assertLessEqual(abs(f - ref), 1e-13 * abs(ref))

    def test_callback_sets_coulomb_bound(self):
        """A fast tangential slip saturates at |μ·law(d, d0, k, c)| of the active callback (docs/engine.md)."""
        d, mu = 60.0, 0.3
        for law in (elastic_force_law, elastic_force_law_plateau):
            with self.subTest(law=law.__name__):
                CircleBasicElasticity.call_back_elastic_force_law = law
                ens, s1, s2 = _pair_scene(d, mu=mu, nut=1e6, c=0.5)
                s2.yspeed = 1.0  # v_t·ν_t = 1e6 ≫ μ|F_n|: both visits slip
                ens.mechanical_simulation_step_calculate_forces()
                bound = abs(mu * law(d, 120.0, 2.0, 0.5))
                # t_12 = (0, 1): sphere 1 is dragged along +y with the full Coulomb force
                self.assertLessEqual(abs(s1.yforce - bound), 1e-13 * bound)
                self.assertEqual(s1.neighbors[0].interface_type, "slip")

    def test_callback_in_compressed_link(self):
        d = 60.0
        ens, s1, _ = _pair_scene(d, link=True, c=1.0)
        CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
        f = _central_force_on_1(ens, s1)
        ref = elastic_force_law_plateau(d, 120.0, 2.0, 1.0)
        self.assertLessEqual(abs(f - ref), 1e-13 * abs(ref))

    def test_tensile_callback_in_stretched_link(self):
        ens, s1, s2 = _pair_scene(100.0, link=True)
        s2.x = 200.0 + 130.0  # stretched beyond d_eq = 120
        f_lin = _central_force_on_1(ens, s1)
        self.assertLessEqual(abs(f_lin - 2.0 * 10.0), 1e-12 * 20.0)  # attraction k (d - d_eq) towards +x
        SphereLinkable.call_back_elastic_force_law_tensile = elastic_force_law_tensile_exponential
        ens.reset_force()
        f_exp = _central_force_on_1(ens, s1)
        ref = elastic_force_law_tensile_exponential(130.0, 120.0, 2.0)
        self.assertLessEqual(abs(f_exp - ref), 1e-12 * ref)



class TestEngineLawConstants(unittest.TestCase):
    """The elastic term from its constants (what the classes and the engine evaluate) is bit-identical to the
    documented laws: the compressive law on contacts, and on bonds the same law below d_eq and the tensile law above."""

    def test_term_constants_equal_the_law(self):
        from particleShear.base.laws import elastic_force_law, elastic_force_law_tensile
        from particleShear.engine.terms import elastic_term, term_constants

        rng = np.random.default_rng(11)
        d0 = rng.uniform(20, 60, 500)
        d = d0 * rng.uniform(0.0005, 1.3, 500)   # beyond the cap, overlapping, touching and apart
        d[:5] = d0[:5]                           # exactly at contact
        for k in (1.0, 3.14e9):
            for c in (0.0, 0.3, 1.0):
                with self.subTest(k=k, c=c, pairs="contacts"):
                    f, law = elastic_term(term_constants(d0, None, None, k, c, 0.0, 0.0, 0.0, 0.0), d)
                    np.testing.assert_array_equal(law, elastic_force_law(d, d0, k, c))
                    np.testing.assert_array_equal(f, law)
                with self.subTest(k=k, c=c, pairs="bonds"):
                    perm = np.ones(len(d), dtype=bool)
                    f, law = elastic_term(term_constants(d0, perm, d0, k, c, 0.0, 0.0, 0.0, 0.0, prc=0.5), d)
                    ref = np.array([elastic_force_law_tensile(a, b, k) if a > b else elastic_force_law(a, b, k, c)
                                    for a, b in zip(d, d0)])
                    np.testing.assert_array_equal(law, ref)
                    np.testing.assert_array_equal(f, 0.5 * ref)


def _engine_central(d, d0, k, c, bond):
    """Central law of one candidate through the engine (:meth:`PairConstants.set_bonds`, :func:`central_term`)."""
    from particleShear.engine.forces import PairConstants
    from particleShear.engine.state import BatchState, ReplicaPairs
    from particleShear.engine.terms import central_term

    s = BatchState(1, 2)
    s.r[:] = d0 / 2
    s.k[:], s.c[:], s.prc[:], s.prt[:], s.keep[:] = k, c, 1.0, 1.0, 1.0
    s.pairs[0] = ReplicaPairs([0], [1], [2 if bond else 0], np.zeros((2, 1)), [d0], [True])
    C = PairConstants(s, np.array([0, 1]))
    C.set_bonds(s, np.array([2 if bond else 0], dtype=np.int8), np.array([d0]))
    f, law = central_term(C, np.array([d]), np.zeros(1), np.ones(1, dtype=bool))
    return float(f[0]), float(law[0])


class TestOneLawEverywhere(unittest.TestCase):
    """The documented callbacks, the classes' array step and the engine evaluate one law (docs/engine.md).

    The same pair geometry (d0 = 120 µm, k = 2, at rest, no viscosity, no friction) must give the
    same central force, bit for bit, in all three: they share the arithmetic of
    ``particleShear.engine.laws``, so the tolerance is 0.  The distances cover the linear, blended
    and divergent laws, the cap d0/d ≤ 1000 (eq. S1-6) and a bond in compression and in tension.
    """

    CASES = [  # (d, c, bonded)
        (100.0, 0.0, False), (100.0, 0.5, False), (100.0, 1.0, False), (60.0, 1.0, False),
        (0.05, 1.0, False), (0.05, 0.3, False), (100.0, 0.3, True), (60.0, 1.0, True), (130.0, 0.5, True),
    ]

    def test_same_force_in_callback_class_step_and_engine(self):
        d0, k = 120.0, 2.0
        for d, c, bonded in self.CASES:
            with self.subTest(d=d, c=c, bonded=bonded):
                ens, s1, s2 = _pair_scene(d, link=bonded, c=c)
                d_geo = s2.x - s1.x   # the distance the step sees (200 + d − 200 need not be d)
                if d_geo > d0:
                    ref = elastic_force_law_tensile(d_geo, d0, k)
                    self.assertGreater(ref, 0)   # a stretched bond attracts
                else:
                    ref = elastic_force_law(d_geo, d0, k, c)
                    self.assertLess(ref, 0)      # a compressed pair repels
                self.assertIs(type(ref), float)
                self.assertEqual(_central_force_on_1(ens, s1), ref)          # along n_12 = +x
                f_engine, law_engine = _engine_central(d_geo, d0, k, c, bonded)
                self.assertEqual(law_engine, ref)
                self.assertEqual(f_engine, ref)


if __name__ == "__main__":
    unittest.main()
