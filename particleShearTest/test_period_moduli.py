"""Tests of :mod:`particleShear.analysis.periods`: per-period G′, G″, their spread, trend and steadiness.

The synthetic stress holds, in excitation period k (``k ≤ f t − pre < k + 1``), exactly
``γ₀ (G′_k sin 2π(f t − pre) + G″_k cos 2π(f t − pre))`` plus a constant offset, with baselines
before and after the excitation.  On an evenly spaced whole period ``Σ sin·cos = Σ sin = Σ cos = 0``,
so each period's projection returns its own ``G′_k``, ``G″_k`` up to rounding (~1e-14 relative
for 64 samples): ``RTOL = 1e-9`` leaves a wide margin.  Means, standard errors and trends are
compared with NumPy computations of their definitions on the *known* per-period values.
"""
import dataclasses
import math
import unittest

import numpy as np

from particleShear.analysis.periods import (
    PeriodModuli,
    measured_period_count,
    period_moduli,
)
from particleShear.simulation.evaluation import demodulation

RTOL = 1e-9
F = 4000.0           # Hz
A = 0.25             # strain amplitude
N = 64               # samples per period


def signal(Gp, Gpp, pre=1.0, post=0.5, offset=0.0, n=N, aligned=False, noise=0.0, rng=None, closed=False):
    """Times and stress of a protocol of ``len(Gp)`` excitation periods with per-period moduli.

    ``aligned=False`` puts the samples half a spacing off the period boundaries (no sample on a
    boundary); ``aligned=True`` puts samples on them.  ``closed=True`` continues the last period's
    sinusoid onto the sample at ``f t − pre = P`` (otherwise it belongs to the after-baseline).
    """
    P = len(Gp)
    i = np.arange(round((pre + P + post) * n))
    t = (i + (0.0 if aligned else 0.5)) / (n * F)
    u = F * t - pre
    k = np.floor(u).astype(int)
    inside = (u >= 0) & ((u <= P) if closed else (u < P))
    kk = np.clip(k, 0, P - 1)
    gp, gpp = np.asarray(Gp, float)[kk], np.asarray(Gpp, float)[kk]
    s = np.where(inside, A * (gp * np.sin(2 * np.pi * u) + gpp * np.cos(2 * np.pi * u)), 0.0) + offset
    if noise:
        s = s + noise * rng.standard_normal(s.size)
    return t, s


class TestPerPeriodValues(unittest.TestCase):
    """A G′ changing linearly from period to period, G″ constant, with baselines and an offset."""

    def setUp(self):
        self.P = 6
        self.Gp_true = 900.0 + 25.0 * np.arange(self.P)     # Pa, +25 Pa per period
        self.Gpp_true = np.full(self.P, 300.0)              # Pa
        self.t, self.s = signal(self.Gp_true, self.Gpp_true, offset=40.0)
        self.r = period_moduli(self.t, self.s, F, A, 1.0, self.P)

    def test_each_period_exact(self):
        r = self.r
        self.assertIsInstance(r, PeriodModuli)
        np.testing.assert_array_equal(r.period, np.arange(1, self.P))     # P >= 2: period 0 skipped
        self.assertEqual(r.n_periods, self.P - 1)
        self.assertEqual(r.n_expected, self.P - 1)
        np.testing.assert_allclose(r.Gp, self.Gp_true[1:], rtol=RTOL)
        np.testing.assert_allclose(r.Gpp, self.Gpp_true[1:], rtol=RTOL)

    def test_mean_and_standard_error(self):
        r, g = self.r, self.Gp_true[1:]
        self.assertAlmostEqual(r.Gp_mean / np.mean(g), 1.0, delta=RTOL)
        self.assertAlmostEqual(r.Gp_se / (np.std(g, ddof=1) / np.sqrt(g.size)), 1.0, delta=1e-6)
        self.assertAlmostEqual(r.Gpp_mean / 300.0, 1.0, delta=RTOL)
        self.assertLess(r.Gpp_se, RTOL * 300.0)

    def test_trend_detected(self):
        r = self.r
        # slope 25 Pa per period over the index span 5 − 1 = 4 periods
        self.assertAlmostEqual(r.Gp_trend / (25.0 * 4), 1.0, delta=1e-6)
        self.assertLess(r.Gp_trend_se, RTOL * 900.0)
        self.assertLess(abs(r.Gpp_trend), RTOL * 300.0)
        self.assertIs(r.steady, False)

    def test_trend_against_polyfit(self):
        """Arbitrary per-period values: trend and its error are the OLS slope and its standard error × span."""
        rng = np.random.default_rng(7)
        Gp = 1000.0 + 30.0 * rng.standard_normal(9)
        Gpp = 200.0 + 10.0 * rng.standard_normal(9)
        t, s = signal(Gp, Gpp)
        r = period_moduli(t, s, F, A, 1.0, 9)
        k = np.arange(1, 9)
        for got, got_se, mean_se, y in ((r.Gp_trend, r.Gp_trend_se, r.Gp_se, Gp[1:]),
                                        (r.Gpp_trend, r.Gpp_trend_se, r.Gpp_se, Gpp[1:])):
            (slope, _), cov = np.polyfit(k, y, 1, cov=True)     # cov scaled by χ²/(n − 2)
            span = k[-1] - k[0]
            self.assertAlmostEqual(got, slope * span, delta=1e-9 * np.max(np.abs(y)))
            self.assertAlmostEqual(got_se / (math.sqrt(cov[0, 0]) * span), 1.0, delta=1e-6)
            self.assertAlmostEqual(mean_se / (np.std(y, ddof=1) / math.sqrt(8)), 1.0, delta=1e-6)

    def test_no_drift_correction(self):
        """A linear drift D·t shifts every G′ by −D/(π f γ₀) and leaves G″ alone (no correction is applied).

        The shift is the ratio of ∫u sin 2πu = −1/(2π) to ∫sin² 2πu = 1/2 over a period; the sum over
        N evenly spaced samples differs from the integrals by a factor 1 + (π/N)²/6 ≈ 1 + 4e-4
        for N = 64, hence the tolerance 1e-3.  G″: ∫u cos 2πu = 0 over a whole period.
        """
        D = 2e5                                              # Pa/s
        r = period_moduli(self.t, self.s + D * self.t, F, A, 1.0, self.P)
        np.testing.assert_allclose(r.Gp - self.Gp_true[1:], -D / (math.pi * F * A), rtol=1e-3)
        np.testing.assert_allclose(r.Gpp, self.Gpp_true[1:], rtol=RTOL)
        self.assertAlmostEqual(r.Gp_trend / (25.0 * 4), 1.0, delta=1e-6)   # a constant shift: same trend

    def test_result_is_frozen(self):
        with self.assertRaises(dataclasses.FrozenInstanceError):
            self.r.steady = True
        with self.assertRaises(ValueError):
            self.r.Gp[0] = 0.0


class TestWindow(unittest.TestCase):
    """The periods measured are those of demodulation's window: e = 1 if P >= 2 else 0."""

    Gp = 1000.0 + 100.0 * np.arange(6)      # a distinct G′ in every period

    def measure(self, P, **kwargs):
        t, s = signal(self.Gp[:P], np.full(P, 50.0), **kwargs)
        return period_moduli(t, s, F, A, 1.0, P)

    def test_single_period_measured(self):
        r = self.measure(1)
        np.testing.assert_array_equal(r.period, [0])
        np.testing.assert_allclose(r.Gp, [1000.0], rtol=RTOL)
        self.assertEqual(r.n_periods, 1)
        self.assertTrue(math.isnan(r.Gp_se) and math.isnan(r.Gpp_se))
        self.assertTrue(math.isnan(r.Gp_trend) and math.isnan(r.Gp_trend_se))
        self.assertIsNone(r.steady)

    def test_first_period_skipped(self):
        r = self.measure(2)
        np.testing.assert_array_equal(r.period, [1])
        np.testing.assert_allclose(r.Gp, [1100.0], rtol=RTOL)
        r = self.measure(4)
        np.testing.assert_allclose(r.Gp, [1100.0, 1200.0, 1300.0], rtol=RTOL)

    def test_two_periods_give_an_error_but_no_verdict(self):
        r = self.measure(3)
        self.assertEqual(r.n_periods, 2)
        self.assertAlmostEqual(r.Gp_se, np.std([1100.0, 1200.0], ddof=1) / math.sqrt(2), delta=1e-9 * 1200)
        self.assertAlmostEqual(r.Gp_trend, 100.0, delta=1e-9 * 1200)
        self.assertTrue(math.isnan(r.Gp_trend_se))
        self.assertIsNone(r.steady)

    def test_samples_on_the_boundaries(self):
        """Samples on the period boundaries go to the period that starts there (half-open periods)."""
        r = self.measure(5, aligned=True)
        np.testing.assert_allclose(r.Gp, self.Gp[1:5], rtol=RTOL)

    def test_fractional_periods(self):
        t, s = signal(self.Gp[:3], np.full(3, 50.0))
        r = period_moduli(t, s, F, A, 1.0, 2.5)      # window [pre+1, pre+2.5]: one whole period
        np.testing.assert_array_equal(r.period, [1])
        self.assertEqual(r.n_expected, 1)

    def test_periods_not_covered_are_left_out(self):
        t, s = signal(self.Gp[:5], np.full(5, 50.0), post=0.0)
        cut = F * t - 1.0 < 3.5                      # the data stop in the middle of period 3
        r = period_moduli(t[cut], s[cut], F, A, 1.0, 5)
        np.testing.assert_array_equal(r.period, [1, 2])
        self.assertEqual((r.n_periods, r.n_expected), (2, 4))
        coarse = self.measure(4, n=6)                # 6 samples per period < 8
        self.assertEqual(coarse.n_periods, 0)
        self.assertTrue(math.isnan(coarse.Gp_mean) and math.isnan(coarse.Gp_se))
        self.assertIsNone(coarse.steady)
        gap = self.measure(4)                        # a hole of 1/4 period inside period 2
        t, s = signal(self.Gp[:4], np.full(4, 50.0))
        u = F * t - 1.0
        keep = ~((u > 2.3) & (u < 2.55))
        r = period_moduli(t[keep], s[keep], F, A, 1.0, 4)
        np.testing.assert_array_equal(r.period, [1, 3])
        np.testing.assert_allclose(r.Gp, gap.Gp[[0, 2]], rtol=RTOL)

    def test_long_protocol_short_record(self):
        """Only the periods the data reach are looked at: a protocol of 1e9 periods costs nothing more."""
        t, s = signal(self.Gp[:5], np.full(5, 50.0))
        r = period_moduli(t, s, F, A, 1.0, 1e9)
        self.assertEqual((r.n_periods, r.n_expected), (4, 10 ** 9 - 1))
        np.testing.assert_allclose(r.Gp, self.Gp[1:5], rtol=RTOL)

    def test_sample_order_does_not_matter(self):
        t, s = signal(self.Gp[:4], np.full(4, 50.0))
        perm = np.random.default_rng(3).permutation(t.size)
        r = period_moduli(t[perm], s[perm], F, A, 1.0, 4)
        np.testing.assert_allclose(r.Gp, self.Gp[1:4], rtol=RTOL)

    def test_measured_period_count(self):
        for P, n in ((1, 1), (1.5, 1), (2, 1), (2.5, 1), (3, 2), (5, 4), (0.5, 0), (1.99, 1)):
            self.assertEqual(measured_period_count(0.5, P), n, msg=str(P))
            t, s = signal(np.full(math.ceil(P), 1000.0), np.full(math.ceil(P), 10.0))
            self.assertEqual(period_moduli(t, s, F, A, 1.0, P).n_periods, n, msg=str(P))


class TestSteadiness(unittest.TestCase):
    """A stationary response with noise is steady; the false-alarm rate is Student's t's."""

    def test_stationary_noisy_signal_is_steady(self):
        """8 noisy periods without a trend: steady.

        Under no trend the verdict is a t-test that is wrong by chance (about 15 % for 8 periods
        and two moduli, see :meth:`test_false_alarm_rate`); this seed is one of the other 85 %.
        """
        rng = np.random.default_rng(2)
        P = 9
        t, s = signal(np.full(P, 1000.0), np.full(P, 300.0), noise=5.0, rng=rng)
        r = period_moduli(t, s, F, A, 1.0, P)
        self.assertEqual(r.n_periods, 8)
        self.assertIs(r.steady, True)
        # per-period errors of rms noise·√(2/N)/γ₀ (2.5 Pa here): the mean within 5 of its errors
        se = 5.0 * math.sqrt(2 / N) / A / math.sqrt(8)
        self.assertAlmostEqual(r.Gp_mean, 1000.0, delta=5 * se)
        self.assertAlmostEqual(r.Gpp_mean, 300.0, delta=5 * se)
        self.assertAlmostEqual(r.Gp_se / se, 1.0, delta=0.8)         # 7 degrees of freedom: a loose check

    def test_clean_stationary_signal_is_steady(self):
        """Without noise trend and error are both at rounding level: the 1e-9·|G*| floor decides."""
        r = period_moduli(*signal(np.full(7, 1000.0), np.full(7, 300.0)), F, A, 1.0, 7)
        self.assertIs(r.steady, True)

    def test_false_alarm_rate(self):
        """Under no trend each modulus crosses its t_c (α/2 two-sided) with probability 0.025.

        G′ and G″ errors of white noise are independent on a whole period (Σ sin·cos = 0), so
        ``steady`` is False with probability 1 − (1 − 0.025)² = 0.0494 ≤ ``false_alarm``; 400
        seeded trials at 5 periods: ±4 binomial standard deviations (0.011 each).
        """
        rng = np.random.default_rng(99)
        base = signal(np.full(6, 1000.0), np.full(6, 300.0))
        false = 0
        for _ in range(400):
            s = base[1] + 10.0 * rng.standard_normal(base[1].size)
            false += period_moduli(base[0], s, F, A, 1.0, 6).steady is False
        expected = 1 - (1 - 0.025) ** 2
        sd = math.sqrt(expected * (1 - expected) / 400)
        self.assertAlmostEqual(false / 400, expected, delta=4 * sd)

    def test_t_critical_against_the_closed_form_cdf(self):
        """t_c of 3 degrees of freedom against the closed-form distribution function and table values."""
        from particleShear.analysis.periods import t_critical
        tc = t_critical(3, 0.05)
        x = tc / math.sqrt(3)                 # P(|T| <= t) = (2/π)(atan x + x/(1 + x²)) for 3 dof
        self.assertAlmostEqual(2 / math.pi * (math.atan(x) + x / (1 + x * x)), 0.95, delta=1e-12)
        # one degree of freedom is Cauchy: t_c = tan(π(1 − α)/2) exactly
        self.assertAlmostEqual(t_critical(1, 0.05) / math.tan(math.pi * 0.95 / 2), 1.0, delta=1e-11)
        # two degrees of freedom: P(|T| <= t) = t/√(2 + t²) = q  ->  t_c² = 2q²/(1 − q²)
        a = 0.01
        q = 1 - a
        self.assertAlmostEqual(t_critical(2, a), math.sqrt(2 * q * q / (1 - q * q)), delta=1e-9)
        # many degrees of freedom approach the normal 1.959964
        self.assertAlmostEqual(t_critical(2000, 0.05), 1.959964, delta=2e-3)
        with self.assertRaisesRegex(ValueError, "dof"):
            t_critical(0, 0.05)
        with self.assertRaisesRegex(ValueError, "false_alarm"):
            period_moduli(*signal(np.full(4, 1000.0), np.full(4, 300.0)), F, A, 1.0, 4, false_alarm=1.5)


class TestAgainstDemodulation(unittest.TestCase):
    """On a clean stationary sinusoid the per-period mean is the package's demodulation.

    Both are exact projections of a pure sinusoid on whole, evenly sampled periods, so they agree
    to rounding (``RTOL``) when both hold the same samples.  The package's window is closed at both
    ends: on a grid with samples on the period boundaries it holds one more, at ``f t − pre = P``,
    where ``sin = 0`` and ``cos = 1``.  That sample adds nothing to the sine sums (G′ agrees to
    rounding); if the sinusoid continues there it adds an exactly proportional term to the cosine
    sums (G″ agrees too), and if the excitation has ended there (stress 0) it adds 1 to
    ``Σ cos² = N(P − e)/2`` only, so the package's G″ is smaller by the factor
    ``1/(1 + 2/(N(P − e)))``.  With no offset and zero baselines the package's drift estimate is 0.
    """

    def compare(self, pre, P, aligned, closed):
        t, s = signal(np.full(P, 850.0), np.full(P, 420.0), pre=pre, aligned=aligned, closed=closed)
        r = period_moduli(t, s, F, A, pre, P)
        _, _, Gp, Gpp = demodulation(t, s, F, A, baseline_pre_periods=pre, periods=P, baseline_post_periods=0)
        e = 1 if P >= 2 else 0
        in_window = (t >= (pre + e) / F) & (t <= (pre + P) / F)
        extra = int(np.count_nonzero(in_window)) - N * (P - e)       # the closing sample, if any
        self.assertIn(extra, (0, 1))
        self.assertEqual(extra, 1 if aligned else 0)
        return r, Gp, Gpp, extra

    def test_same_samples(self):
        for pre, P in ((1.0, 5), (0.5, 1), (2.0, 8)):
            with self.subTest(pre=pre, P=P):
                r, Gp, Gpp, _ = self.compare(pre, P, aligned=False, closed=False)
                self.assertAlmostEqual(r.Gp_mean / Gp, 1.0, delta=RTOL)
                self.assertAlmostEqual(r.Gpp_mean / Gpp, 1.0, delta=RTOL)
                self.assertAlmostEqual(Gp / 850.0, 1.0, delta=RTOL)
                self.assertAlmostEqual(Gpp / 420.0, 1.0, delta=RTOL)

    def test_closing_sample(self):
        for pre, P in ((1.0, 5), (2.0, 8), (1.0, 1)):
            e = 1 if P >= 2 else 0
            with self.subTest(pre=pre, P=P, sinusoid="continued"):
                r, Gp, Gpp, _ = self.compare(pre, P, aligned=True, closed=True)
                self.assertAlmostEqual(r.Gp_mean / Gp, 1.0, delta=RTOL)
                self.assertAlmostEqual(r.Gpp_mean / Gpp, 1.0, delta=RTOL)
            with self.subTest(pre=pre, P=P, sinusoid="ended"):
                r, Gp, Gpp, _ = self.compare(pre, P, aligned=True, closed=False)
                self.assertAlmostEqual(r.Gp_mean / Gp, 1.0, delta=RTOL)
                self.assertAlmostEqual(r.Gpp_mean / Gpp, 1 + 2 / (N * (P - e)), delta=RTOL)
                self.assertAlmostEqual(r.Gpp_mean / 420.0, 1.0, delta=RTOL)


class TestBadInput(unittest.TestCase):
    """Bad input is refused with a ValueError naming the parameter."""

    def setUp(self):
        self.t, self.s = signal(np.full(3, 1000.0), np.full(3, 10.0))

    def refused(self, name, *args):
        with self.assertRaises(ValueError) as cm:
            period_moduli(*args)
        self.assertIn(name, str(cm.exception))

    def test_arrays(self):
        t, s = self.t, self.s
        self.refused("stress", t, s[:-1], F, A, 1.0, 3)
        self.refused("t", t.reshape(2, -1), s.reshape(2, -1), F, A, 1.0, 3)
        for name, k in (("t", 0), ("stress", 1)):
            args = [t.copy(), s.copy()]
            args[k][3] = math.nan
            self.refused(name, *args, F, A, 1.0, 3)

    def test_numbers(self):
        t, s = self.t, self.s
        for f in (0.0, -1.0, math.inf, math.nan, "4000", None):
            self.refused("f", t, s, f, A, 1.0, 3)
        for a in (0.0, -0.1, math.nan, None):
            self.refused("strain_amplitude", t, s, F, a, 1.0, 3)
        for pre in (-0.5, math.inf, None):
            self.refused("pre_periods", t, s, F, A, pre, 3)
        for P in (0, -2, math.nan, None, True):
            self.refused("periods", t, s, F, A, 1.0, P)
        for args in ((-1.0, 3), (1.0, 0)):
            with self.assertRaises(ValueError):
                measured_period_count(*args)


if __name__ == "__main__":
    unittest.main()
