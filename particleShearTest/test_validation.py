"""Input validation: bad input raises ValueError (TypeError for non-numbers) naming the parameter,
before anything is changed."""
import math
import unittest

from particleShear import (EnsembleFrictionLeesEdwards, EnsembleLinkable, SphereFrictionLeesEdwards, SphereLinkable,
                           StressTensorEvaluation)

NAN, INF = float("nan"), float("inf")


def sphere(x=100.0, y=100.0, diameter=20.0, m=1.0, index=1):
    return SphereLinkable("grey", x, y, diameter, m, index, size_x=500, size_y=500)


class _Base(unittest.TestCase):
    def assertRejects(self, name_pattern, fn, *args, **kwargs):
        with self.assertRaisesRegex((ValueError, TypeError), name_pattern):
            fn(*args, **kwargs)


class TestSphereConstruction(_Base):

    def test_non_positive_diameter(self):
        for d in (0, -1.0, -1e-300):
            with self.subTest(diameter=d):
                self.assertRejects(r"\bdiameter\b", sphere, diameter=d)
                self.assertRejects(r"\bdiameter\b", SphereFrictionLeesEdwards, "grey", 1, 1, d, 1)

    def test_non_finite_diameter(self):
        for d in (NAN, INF):
            with self.subTest(diameter=d):
                self.assertRejects(r"\bdiameter\b", sphere, diameter=d)

    def test_non_positive_or_non_finite_mass(self):
        for m in (0, -2.0, NAN, INF):
            with self.subTest(m=m):
                self.assertRejects(r"\bm\b", sphere, m=m)

    def test_non_finite_coordinates(self):
        for v in (NAN, INF, -INF):
            with self.subTest(v=v):
                self.assertRejects(r"\bx\b", sphere, x=v)
                self.assertRejects(r"\by\b", sphere, y=v)

    def test_non_numeric_coordinate(self):
        with self.assertRaisesRegex(TypeError, r"\bx\b"):
            sphere(x="12")


class TestEnsembleConstruction(_Base):

    def test_non_positive_box(self):
        for bad in (0, -500.0, NAN, INF):
            with self.subTest(size=bad):
                self.assertRejects(r"\bsize_x\b", EnsembleLinkable, bad, 500, 0)
                self.assertRejects(r"\bsize_y\b", EnsembleLinkable, 500, bad, 0)
                self.assertRejects(r"\bsize_x\b", EnsembleFrictionLeesEdwards, bad, 500, 10)

    def test_negative_constants(self):
        for name in ("k", "nu", "k_t", "nu_t", "mu"):
            for bad in (-1.0, -1e-12, NAN):
                with self.subTest(name=name, value=bad):
                    # N = 50: the check must come before the spheres are created
                    self.assertRejects(rf"\b{name}\b", EnsembleLinkable, 500, 500, 50, **{name: bad})

    def test_zero_constants_are_allowed(self):
        ens = EnsembleLinkable(500, 500, 0, k=0, nu=0, k_t=0, nu_t=0, mu=0)
        self.assertEqual((ens.k, ens.nu, ens.k_t, ens.nu_t, ens.mu), (0, 0, 0, 0, 0))

    def test_stress_evaluator_box(self):
        for bad in (0, -500.0, NAN):
            with self.subTest(size=bad):
                self.assertRejects(r"\bsize_x\b", StressTensorEvaluation, bad, 500)
                self.assertRejects(r"\bsize_y\b", StressTensorEvaluation, 500, bad)


class TestAppend(_Base):

    def test_non_finite_speed_rejected(self):
        # rejected at assignment, before the sphere can reach an ensemble
        for name in ("xspeed", "yspeed"):
            for bad in (NAN, INF):
                with self.subTest(name=name, value=bad):
                    ens = EnsembleLinkable(500, 500, 0)
                    s = sphere()
                    self.assertRejects(rf"\b{name}\b", setattr, s, name, bad)
                    ens.sphereList.append(s)
                    self.assertRejects(rf"\b{name}\b", setattr, s, name, bad)
                    setattr(s, name, 1.0)
                    self.assertEqual(getattr(ens.sphereList[0], name), 1.0)

    def test_sphere_in_two_ensembles(self):
        a = EnsembleLinkable(500, 500, 0)
        b = EnsembleLinkable(500, 500, 0)
        s = sphere()
        a.sphereList.append(s)
        with self.assertRaises(ValueError):
            b.sphereList.append(s)
        self.assertEqual(len(b.sphereList), 0)
        with self.assertRaises(ValueError):
            a.sphereList.append(s)  # the same ensemble twice
        self.assertEqual(len(a.sphereList), 1)

    def test_link_to_itself(self):
        s = sphere()
        with self.assertRaisesRegex(ValueError, "itself"):
            s.establish_permanent_link(s)  # free sphere
        ens = EnsembleLinkable(500, 500, 0)
        ens.sphereList.append(s)
        other = sphere(x=110.0, index=2)
        ens.sphereList.append(other)
        with self.assertRaisesRegex(ValueError, "itself"):
            s.establish_permanent_link(s)
        self.assertEqual(s.neighbors, [])
        s.establish_permanent_link(other)  # a proper link still works
        self.assertEqual([r.interface_type for r in s.neighbors], ["permanent"])


class TestAssignmentsAfterAppend(_Base):
    """Scripts set speeds and constants by attribute after appending (as the manual's scenarios do):
    the same rules apply, and a rejected value leaves the old one in place."""

    def setUp(self):
        self.ens = EnsembleLinkable(500, 500, 0)
        self.s = sphere()
        self.ens.sphereList.append(self.s)

    def test_non_finite_coordinates_and_speeds(self):
        for name in ("x", "y", "xspeed", "yspeed"):
            for bad in (NAN, INF):
                with self.subTest(name=name, value=bad):
                    old = getattr(self.s, name)
                    self.assertRejects(rf"\b{name}\b", setattr, self.s, name, bad)
                    self.assertEqual(getattr(self.s, name), old)

    def test_non_positive_radius_and_mass(self):
        for name in ("r", "m"):
            for bad in (0.0, -1.0, NAN):
                with self.subTest(name=name, value=bad):
                    old = getattr(self.s, name)
                    self.assertRejects(rf"\b{name}\b", setattr, self.s, name, bad)
                    self.assertEqual(getattr(self.s, name), old)

    def test_negative_ensemble_constants(self):
        for name in ("k", "nu", "k_t", "nu_t", "mu"):
            with self.subTest(name=name):
                old = getattr(self.ens, name)
                self.assertRejects(rf"\b{name}\b", setattr, self.ens, name, -1.0)
                self.assertEqual(getattr(self.ens, name), old)
                setattr(self.ens, name, 0)  # zero is allowed (the manual's scenarios use it)
                self.assertEqual(getattr(self.ens, name), 0)


if __name__ == "__main__":
    unittest.main()
