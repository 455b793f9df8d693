"""Tests of :func:`particleShear.analysis.laos.laos`: LAOS moduli against closed forms.

The analytic material ``σ = Gγ + cγ³ + ηγ̇ + dγ̇³`` under ``γ = γ₀ sin θ``, ``θ = ωt + φ``, has
exact odd harmonics (``sin³θ = (3 sin θ − sin 3θ)/4``, ``cos³θ = (3 cos θ + cos 3θ)/4``)::

    G'_1 = G + 3cγ₀²/4     G'_3 = −cγ₀²/4     G''_1 = ηω + 3dγ₀²ω³/4     G''_3 = dγ₀²ω³/4

and every other odd order vanishes; so ``G_M = G``, ``G_L = G + cγ₀²``, ``η_M = η``,
``η_L = η + dγ₀²ω²``, ``e_3 = cγ₀²/4``, ``v_3 = dγ₀²ω²/4``.

Tolerance: the fit is a backward-stable least-squares solve on a design of sines and cosines of
condition number below 10 on a span of at least one period (checked below), whose entries are
rounded to about ``eps·kθ ≈ 1e-14`` for the phases used here; the relative error of the moduli
is then ~1e-12.  ``RTOL = 1e-9`` leaves three orders of margin, and a wrong formula (a factor,
a sign, a missing ``ω``) is off by far more.  Orders that vanish are compared with ``1e-9·|G*_1|``.
"""
import dataclasses
import math
import unittest

import numpy as np

from particleShear.analysis.laos import LaosResult, laos

RTOL = 1e-9

F = 4000.0                 # Hz, a typical excitation of the simulations
OMEGA = 2 * math.pi * F
G = 1.2e3                  # Pa
C = 4.0e2                  # Pa, cubic elastic coefficient (stiffening)
ETA = 0.03                 # Pa·s, so ηω ≈ 750 Pa
D = 2.0e-11                # Pa·s³, cubic viscous coefficient (dγ̇³ ≈ 0.3 ηγ̇ at γ̇₀ ≈ 1.3e4 1/s)


def analytic(t, gamma0, phi, G=G, c=C, eta=ETA, d=D, strain_offset=0.0):
    """Strain and stress of the analytic material (the strain offset does not load it)."""
    theta = OMEGA * t + phi
    g = gamma0 * np.sin(theta)
    gd = gamma0 * OMEGA * np.cos(theta)
    return g + strain_offset, G * g + c * g ** 3 + eta * gd + d * gd ** 3


def expected(gamma0, G=G, c=C, eta=ETA, d=D):
    """The closed forms of the module docstring."""
    w = OMEGA
    Gp1, Gp3 = G + 3 * c * gamma0 ** 2 / 4, -c * gamma0 ** 2 / 4
    Gpp1, Gpp3 = eta * w + 3 * d * gamma0 ** 2 * w ** 3 / 4, d * gamma0 ** 2 * w ** 3 / 4
    G_M, G_L = G, G + c * gamma0 ** 2
    eta_M, eta_L = eta, eta + d * gamma0 ** 2 * w ** 2
    I3_I1 = math.hypot(Gp3, Gpp3) / math.hypot(Gp1, Gpp1)
    return {"Gp1": Gp1, "Gp3": Gp3, "Gpp1": Gpp1, "Gpp3": Gpp3, "e3": c * gamma0 ** 2 / 4,
            "v3": d * gamma0 ** 2 * w ** 2 / 4, "v1": Gpp1 / w, "G_M": G_M, "G_L": G_L, "eta_M": eta_M,
            "eta_L": eta_L, "S": (G_L - G_M) / G_L, "T": (eta_L - eta_M) / eta_L, "I3_I1": I3_I1,
            "Q": I3_I1 / gamma0 ** 2}


def times(cycles, n_per_cycle=400, start=0.0):
    """Evenly spaced samples covering ``cycles`` periods (the end excluded)."""
    n = round(cycles * n_per_cycle)
    return start + np.arange(n) / (n_per_cycle * F)


class TestAnalyticMaterial(unittest.TestCase):
    """Closed-form moduli of σ = Gγ + cγ³ + ηγ̇ + dγ̇³ on whole and non-whole spans."""

    def check(self, r, gamma0):
        x = expected(gamma0)
        scale = math.hypot(x["Gp1"], x["Gpp1"])
        self.assertIsInstance(r, LaosResult)
        np.testing.assert_array_equal(r.n, np.arange(1, 16, 2))
        np.testing.assert_allclose(r.Gp[:2], [x["Gp1"], x["Gp3"]], rtol=RTOL)
        np.testing.assert_allclose(r.Gpp[:2], [x["Gpp1"], x["Gpp3"]], rtol=RTOL)
        np.testing.assert_allclose(r.Gp[2:], 0.0, atol=RTOL * scale)
        np.testing.assert_allclose(r.Gpp[2:], 0.0, atol=RTOL * scale)
        np.testing.assert_allclose(r.e[:2], [x["Gp1"], x["e3"]], rtol=RTOL)
        np.testing.assert_allclose(r.v[:2], [x["v1"], x["v3"]], rtol=RTOL)
        for name in ("G_M", "G_L", "eta_M", "eta_L", "I3_I1", "Q"):
            self.assertAlmostEqual(getattr(r, name) / x[name], 1.0, delta=RTOL, msg=name)
        # S and T are differences of O(1) moduli: their absolute error is RTOL-sized
        self.assertAlmostEqual(r.S, x["S"], delta=10 * RTOL)
        self.assertAlmostEqual(r.T, x["T"], delta=10 * RTOL)
        self.assertAlmostEqual(r.strain_amplitude, gamma0, delta=RTOL * gamma0)
        self.assertEqual(r.frequency, F)
        self.assertAlmostEqual(r.omega, OMEGA, delta=1e-12 * OMEGA)
        self.assertLess(r.residual_rms, RTOL * scale * gamma0)

    def test_whole_cycles_zero_phase(self):
        t = times(3)
        g, s = analytic(t, 0.5, 0.0)
        r = laos(t, g, s, F)
        self.check(r, 0.5)
        self.assertAlmostEqual(r.phase, 0.0, delta=1e-12)

    def test_non_whole_span_any_phase(self):
        """2.37 cycles, starting at an arbitrary phase and time: nothing leaks between orders."""
        for gamma0, phi, cycles in ((0.2, 1.234, 2.37), (1.0, -2.9, 1.61), (0.7, 0.4, 1.0)):
            with self.subTest(gamma0=gamma0, phi=phi, cycles=cycles):
                t = times(cycles, start=3.3e-3)
                g, s = analytic(t, gamma0, phi - OMEGA * 3.3e-3)
                r = laos(t, g, s, F)
                self.check(r, gamma0)
                # φ is the phase of the strain at t = 0 (modulo 2π)
                self.assertAlmostEqual(math.remainder(r.phase - (phi - OMEGA * 3.3e-3), 2 * math.pi), 0.0,
                                       delta=1e-9)

    def test_offsets_and_even_harmonics_do_not_leak(self):
        """A strain offset, a stress offset and even harmonics on a non-whole span: odd orders unchanged."""
        gamma0, phi = 0.6, 0.81
        t = times(2.37)
        g, s = analytic(t, gamma0, phi, strain_offset=0.05)
        theta = OMEGA * t + phi
        s = s + 150.0 + 80.0 * np.cos(2 * theta) - 40.0 * np.sin(4 * theta)
        r = laos(t, g, s, F)
        self.check(r, gamma0)

    def test_time_origin(self):
        """Moving the time origin moves φ by −ωΔt and leaves every modulus unchanged."""
        t = times(2.37)
        g, s = analytic(t, 0.5, 0.3)
        a = laos(t, g, s, F)
        b = laos(t + 1e-4, g, s, F)
        np.testing.assert_allclose(b.Gp, a.Gp, rtol=RTOL, atol=RTOL * abs(a.Gp[0]))
        np.testing.assert_allclose(b.Gpp, a.Gpp, rtol=RTOL, atol=RTOL * abs(a.Gp[0]))
        self.assertAlmostEqual(math.remainder(b.phase - (a.phase - OMEGA * 1e-4), 2 * math.pi), 0.0, delta=1e-9)

    def test_lissajous_curves_are_the_material_laws(self):
        """σ′(γ) = Gγ + cγ³ and σ″(γ̇) = ηγ̇ + dγ̇³: the elastic and viscous curves of the material."""
        gamma0 = 0.8
        t = times(2.37)
        g, s = analytic(t, gamma0, 2.0)
        curves = laos(t, g, s, F).lissajous(n_points=101)
        self.assertEqual(curves["theta"][0], 0.0)
        self.assertAlmostEqual(curves["theta"][-1], 2 * math.pi, delta=1e-15)
        gam, rate = curves["strain"], curves["strain_rate"]
        stress_scale = G * gamma0
        np.testing.assert_allclose(curves["elastic_stress"], G * gam + C * gam ** 3, rtol=0,
                                   atol=RTOL * stress_scale)
        np.testing.assert_allclose(curves["viscous_stress"], ETA * rate + D * rate ** 3, rtol=0,
                                   atol=RTOL * stress_scale)
        np.testing.assert_allclose(curves["stress"], curves["elastic_stress"] + curves["viscous_stress"],
                                   rtol=0, atol=1e-12 * stress_scale)
        np.testing.assert_allclose(rate, gamma0 * OMEGA * np.cos(curves["theta"]), rtol=1e-15, atol=1e-9)

    def test_elastic_and_viscous_stress_recompose_the_signal(self):
        """σ′(θ) + σ″(θ) at the samples' phases is the measured (odd) stress; scalars give scalars."""
        t = times(1.5)
        g, s = analytic(t, 0.4, -0.7)
        r = laos(t, g, s, F)
        theta = OMEGA * t + r.phase
        np.testing.assert_allclose(r.elastic_stress(theta) + r.viscous_stress(theta), s, rtol=0,
                                   atol=RTOL * np.max(np.abs(s)))
        self.assertIsInstance(r.elastic_stress(0.3), float)
        self.assertEqual(r.elastic_stress(0.0), 0.0)        # sin(n·0) = 0 for every order
        self.assertAlmostEqual(r.viscous_stress(np.pi / 2), 0.0, delta=RTOL * r.Gpp[0])   # cos(nπ/2) = 0, n odd

    def test_noise_within_its_standard_error(self):
        """White noise of rms σ_n gives G′_n, G″_n errors of rms σ_n·√(2/N)/γ₀ (seeded; 5 standard errors)."""
        gamma0 = 0.5
        t = times(3, n_per_cycle=1000)
        g, s = analytic(t, gamma0, 0.2)
        noise = 20.0
        rng = np.random.default_rng(20240521)
        r = laos(t, g, s + noise * rng.standard_normal(t.size), F)
        x = expected(gamma0)
        se = noise * math.sqrt(2 / t.size) / gamma0
        np.testing.assert_allclose(r.Gp[:2], [x["Gp1"], x["Gp3"]], rtol=0, atol=5 * se)
        np.testing.assert_allclose(r.Gpp[:2], [x["Gpp1"], x["Gpp3"]], rtol=0, atol=5 * se)
        np.testing.assert_allclose(r.Gp[2:], 0.0, atol=5 * se)
        self.assertAlmostEqual(r.residual_rms / noise, 1.0, delta=0.05)   # 3000 samples: ±1.3 % rms

    def test_design_conditioning(self):
        """The premise of RTOL: the fitted basis is well conditioned on the spans used here."""
        for cycles in (1.0, 1.61, 2.37, 3.0):
            t = times(cycles)
            theta = np.multiply.outer(OMEGA * t + 0.3, np.arange(1, 16))
            design = np.column_stack((np.ones(t.size), np.sin(theta), np.cos(theta)))
            self.assertLess(np.linalg.cond(design), 10.0, msg=str(cycles))


class TestLinearResponse(unittest.TestCase):
    """A linear viscoelastic response: no higher harmonics, S = T = 0, G_M = G_L."""

    def test_pure_sine(self):
        gamma0 = 0.3
        t = times(2.37)
        g, s = analytic(t, gamma0, 0.9, c=0.0, d=0.0)
        r = laos(t, g, s, F)
        self.assertAlmostEqual(r.Gp[0] / G, 1.0, delta=RTOL)
        self.assertAlmostEqual(r.Gpp[0] / (ETA * OMEGA), 1.0, delta=RTOL)
        self.assertLess(r.I3_I1, RTOL)
        self.assertLess(r.Q, RTOL / gamma0 ** 2)
        self.assertAlmostEqual(r.S, 0.0, delta=RTOL)
        self.assertAlmostEqual(r.T, 0.0, delta=RTOL)
        self.assertAlmostEqual(r.G_M / r.G_L, 1.0, delta=RTOL)
        self.assertAlmostEqual(r.eta_M / r.eta_L, 1.0, delta=RTOL)
        self.assertAlmostEqual(r.eta_L / ETA, 1.0, delta=RTOL)

    def test_orders_up_to_n_max(self):
        t = times(2)
        g, s = analytic(t, 0.3, 0.0)
        r = laos(t, g, s, F, n_max=4)
        np.testing.assert_array_equal(r.n, [1, 3])
        r1 = laos(t, g, s, F, n_max=1)
        np.testing.assert_array_equal(r1.n, [1])
        self.assertTrue(math.isnan(r1.I3_I1) and math.isnan(r1.Q))
        # with only order 1 fitted, G_M = G_L = G'_1 exactly
        self.assertEqual(r1.G_M, r1.G_L)

    def test_result_is_frozen(self):
        t = times(1)
        g, s = analytic(t, 0.3, 0.0)
        r = laos(t, g, s, F)
        with self.assertRaises(dataclasses.FrozenInstanceError):
            r.G_M = 0.0
        for name in ("n", "Gp", "Gpp", "e", "v"):
            with self.assertRaises(ValueError, msg=name):
                getattr(r, name)[0] = 0


class TestBadInput(unittest.TestCase):
    """Each bad input is refused with a ValueError naming the parameter."""

    def setUp(self):
        self.t = times(2)
        self.g, self.s = analytic(self.t, 0.3, 0.0)

    def refused(self, name, *args, **kwargs):
        with self.assertRaises(ValueError) as cm:
            laos(*args, **kwargs)
        self.assertIn(name, str(cm.exception))
        return str(cm.exception)

    def test_shapes(self):
        t, g, s = self.t, self.g, self.s
        self.refused("strain", t, g[:-1], s, F)
        self.refused("stress", t, g, s[:-1], F)
        self.refused("t", t.reshape(8, -1), g, s, F)
        self.refused("stress", t, g, s.reshape(8, -1), F)

    def test_non_finite(self):
        t, g, s = self.t, self.g, self.s
        for name, k in (("t", 0), ("strain", 1), ("stress", 2)):
            for bad in (math.nan, math.inf):
                args = [t.copy(), g.copy(), s.copy()]
                args[k][17] = bad
                msg = self.refused(name, *args, F)
                self.assertIn("17", msg)

    def test_frequency(self):
        for f in (0.0, -F, math.nan, math.inf, "4000", None, True):
            self.refused("f", self.t, self.g, self.s, f)

    def test_n_max(self):
        for n_max in (0, -3, 2.5, 3.0, "15", True):
            self.refused("n_max", self.t, self.g, self.s, F, n_max=n_max)
        self.assertEqual(len(laos(self.t, self.g, self.s, F, n_max=np.int64(5)).n), 3)

    def test_too_few_samples(self):
        t = times(2, n_per_cycle=30)          # 60 samples < 4·15 + 2 = 62
        g, s = analytic(t, 0.3, 0.0)
        msg = self.refused("samples", t, g, s, F)
        self.assertIn("62", msg)
        self.assertEqual(len(laos(t, g, s, F, n_max=14).n), 7)    # 60 >= 58

    def test_aliasing(self):
        t = times(3, n_per_cycle=22)          # 66 samples, but 22 per period <= 2·15
        g, s = analytic(t, 0.3, 0.0)
        self.refused("sampling rate", t, g, s, F)

    def test_span_shorter_than_a_period(self):
        t = times(0.9, n_per_cycle=400)
        g, s = analytic(t, 0.3, 0.0)
        msg = self.refused("period", t, g, s, F)
        self.assertIn("1/f", msg)
        t1 = times(1.0)                       # exactly one period (the end excluded) is enough
        g1, s1 = analytic(t1, 0.3, 0.0)
        self.assertAlmostEqual(laos(t1, g1, s1, F).Gp[0] / expected(0.3)["Gp1"], 1.0, delta=RTOL)

    def test_not_increasing(self):
        t = self.t.copy()
        t[[5, 6]] = t[[6, 5]]
        self.refused("strictly increasing", t, self.g, self.s, F)

    def test_no_strain(self):
        for g in (np.zeros_like(self.t), np.full_like(self.t, 0.2)):
            self.refused("strain", self.t, g, self.s, F)

    def test_lissajous_points(self):
        r = laos(self.t, self.g, self.s, F)
        for n_points in (1, 0, 2.5, True):
            with self.assertRaises(ValueError) as cm:
                r.lissajous(n_points)
            self.assertIn("n_points", str(cm.exception))


if __name__ == "__main__":
    unittest.main()
