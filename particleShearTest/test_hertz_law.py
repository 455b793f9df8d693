"""The Hertz contact law (particleShear/engine/contact_laws/hertz.py, eq. H-1 of docs/engine.md).

The analytic two-sphere force is written out here, independently of the package:
``F = −s·k·√R*·δ^{3/2}`` (lengths in µm, so the ``1/(1 µm)`` of eq. H-1 is 1) with
``R* = r_i r_j/(r_i + r_j)`` and ``δ = d0 − d``, negative (repulsive) for an overlap, 0 at and
beyond contact (MODEL_SPEC: the central force on i along n_ij, negative repels).  Through the
engine the force on sphere 1 of a two-sphere scene at rest along +x is read from one step (the
kick of a sphere of mass 1 with dt = 2⁻³⁰, an exact scaling): the tolerance 1e-13 relative covers
the different association of a few O(1) floating-point operations.  The δ^{3/2} scaling is checked
on the law itself: F(4δ)/F(δ) = 8 up to rounding (1e-14 relative, a few ulp of a product of
square roots).
"""
import math
import unittest

import numpy as np

from particleShear import EnsembleLinkable, SphereLinkable, doParticleShearSimulation
from particleShear.engine.contact_laws import LAWS, MODULES
from particleShear.engine.contact_laws.hertz import hertz
from particleShear.base.engine_adapter import state_from_ensembles
from particleShear.engine.step import BatchEngine
from particleShear.parameters import BY_NAME, EXTRA, defaults
from particleShear.simulation.provenance import identity_parameters
from particleShearTest.test_cli import run_main

RTOL = 1e-13
K = 2.0
R1, R2 = 40.0, 70.0                   # unequal radii (µm): d0 = 110, R* = 40·70/110
D0, RSTAR = R1 + R2, R1 * R2 / (R1 + R2)
QUICK = dict(N=30, periods=1, pre_periods=0, post_periods=0, relative_frequency=0.2, doDrawing=False,
             plotStress=False, verbose=False, seed=7)


def analytic(d, s=0.05, k=K, r1=R1, r2=R2):
    """Hertz force of two spheres on sphere 1 along n_12 (negative repels; 0 at and after contact)."""
    d0 = r1 + r2
    if d >= d0:
        return 0.0
    return -s * k * math.sqrt(r1 * r2 / (r1 + r2)) * (d0 - d) ** 1.5


def engine_force(d, s=0.05):
    """x force on sphere 1 (radius R1) of a two-sphere scene (radius R2 at distance d along +x), from
    one engine step with contact_law="hertz"."""
    ens = EnsembleLinkable(500, 500, 0, k=K, nu=0.0, k_t=0.0, nu_t=0.0, mu=0.0)
    s1 = SphereLinkable("grey", 200.0, 250.0, 2 * R1, 1, 1, force_register=ens, size_x=500, size_y=500)
    s2 = SphereLinkable("grey", 200.0 + d, 250.0, 2 * R2, 1, 2, force_register=ens, size_x=500, size_y=500)
    ens.sphereList.append(s1)
    ens.sphereList.append(s2)
    ens.set_central_repulsion_coefficient(0.0)
    state = state_from_ensembles([ens], laws=[("hertz", (s,))])
    state.applying_shear = False
    dt = 2.0 ** -30
    BatchEngine(state, guard=False).step(1.0, dt)
    return float(state.vx[0]) * float(state.m[0]) / dt


class TestHertzLaw(unittest.TestCase):
    def test_shipped_and_declared(self):
        self.assertIn("hertz", MODULES)
        self.assertEqual(LAWS["hertz"].parameters, {"hertz_scale": 0.05})
        p = BY_NAME["hertz_scale"]
        self.assertEqual((p.role, p.unit, p.low, p.low_open, p.default), ("law:hertz", "1", 0, True, 0.05))
        self.assertIn("hertz_scale", EXTRA)

    def test_two_unequal_spheres_against_the_analytic_force(self):
        for d in (60.0, 90.0, 105.0, 109.75, 110.0, 111.0, 150.0):    # 200 + d exact: d has no rounding
            with self.subTest(d=d):
                ref = analytic(d)
                got = engine_force(d)
                self.assertLessEqual(abs(got - ref), RTOL * abs(ref), (got, ref))
                self.assertLess(got, 0.0) if d < D0 else self.assertEqual(got, 0.0)

    def test_sign_and_zero_at_and_after_contact(self):
        d = np.array([D0 - 10.0, D0 - 1e-9, D0, D0 + 1.0, 2 * D0])
        f = hertz(d, D0, R1, R2, K, 1.0, 0.05)
        self.assertTrue(np.all(f[:2] < 0))
        self.assertTrue(np.all(f[2:] == 0))

    def test_force_scales_as_overlap_to_three_halves(self):
        for delta in (0.25, 1.0, 7.5, 30.0):     # d0 − δ and d0 − 4δ exact in binary: δ has no rounding
            with self.subTest(delta=delta):
                f1 = hertz(D0 - delta, D0, R1, R2, K, 0.0, 0.05)
                f4 = hertz(D0 - 4 * delta, D0, R1, R2, K, 0.0, 0.05)
                self.assertAlmostEqual(f4 / f1, 8.0, delta=8e-14)

    def test_force_scales_as_square_root_of_reduced_radius(self):
        # equal overlap, R* of (40, 70) against R* of (10, 10): F ratio √(R*₁/R*₂)
        a = hertz(D0 - 5.0, D0, R1, R2, K, 0.0, 0.05)
        b = hertz(20.0 - 5.0, 20.0, 10.0, 10.0, K, 0.0, 0.05)
        self.assertAlmostEqual(a / b, math.sqrt(RSTAR / 5.0), delta=1e-14)

    def test_out_of_range_scale_names_parameter_value_and_range(self):
        for bad in (0.0, -1.0, 2000.0):
            with self.subTest(bad=bad), self.assertRaisesRegex(ValueError, r"hertz_scale=.* allowed 0 < value <= 1000"):
                doParticleShearSimulation(**QUICK, contact_law="hertz", hertz_scale=bad)


class TestHertzRuns(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cls.hertz = doParticleShearSimulation(**QUICK, contact_law="hertz", return_result=True)
            cls.scaled = doParticleShearSimulation(**QUICK, contact_law="hertz", hertz_scale=0.1, return_result=True)
            cls.linear = doParticleShearSimulation(**QUICK, return_result=True)

    def test_runs_end_to_end(self):
        for r in (self.hertz, self.scaled):
            self.assertTrue(all(math.isfinite(g) for g in r.G))
        self.assertNotEqual(self.hertz.G, self.linear.G)
        self.assertNotEqual(self.hertz.G, self.scaled.G)

    def test_identity_holds_the_scale_only_for_hertz(self):
        full = dict(defaults(), **QUICK)
        self.assertIn("hertz_scale", identity_parameters(dict(full, contact_law="hertz")))
        self.assertNotIn("hertz_scale", identity_parameters(dict(full, hertz_scale=0.1)))
        self.assertNotEqual(self.hertz.run_id, self.scaled.run_id)

    def test_command_line(self):
        import json
        code, out, err = run_main(["--contact-law", "hertz", "--hertz-scale", "0.1", "--N", "30", "--periods", "1",
                                   "--pre-periods", "0", "--post-periods", "0", "--relative-frequency", "0.2",
                                   "--seed", "7", "--json", "--quiet"])
        self.assertEqual(code, 0, err)
        row = json.loads(out)
        self.assertEqual((row["contact_law"], row["hertz_scale"]), ("hertz", 0.1))
        self.assertEqual([row["Gp_surface"], row["Gpp_surface"]], list(self.scaled.G))
        code, out, err = run_main(["--contact-law", "hertz", "--hertz-scale", "0", "--N", "30"])
        self.assertNotEqual(code, 0)
        self.assertIn("--hertz-scale=0.0 is out of range: allowed 0 < value <= 1000", err)


class TestUserLawByModulePath(unittest.TestCase):
    """``contact_law="package.module:function"``: a law outside the package, imported where it is used."""

    def test_module_function_runs_as_its_law(self):
        import pathlib
        import sys
        import tempfile
        import warnings
        tmp = tempfile.mkdtemp(prefix="ps_userlaw_")
        pathlib.Path(tmp, "ps_user_law_45.py").write_text(
            "from particleShear.engine.contact_laws.hertz import hertz as _h\n"
            "def doubled(d, d0, r_i, r_j, k, c):\n"
            "    return _h(d, d0, r_i, r_j, k, c, 0.1)\n", encoding="utf-8")
        sys.path.insert(0, tmp)
        self.addCleanup(sys.path.remove, tmp)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            user = doParticleShearSimulation(**QUICK, contact_law="ps_user_law_45:doubled", return_result=True)
            ref = doParticleShearSimulation(**QUICK, contact_law="hertz", hertz_scale=0.1, return_result=True)
        self.assertEqual(user.G, ref.G)          # the same force law
        with self.assertRaisesRegex(ValueError, "contact_law='no_such_module_45:f' is invalid: cannot import it"):
            doParticleShearSimulation(**QUICK, contact_law="no_such_module_45:f")


if __name__ == "__main__":
    unittest.main()
