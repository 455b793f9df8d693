"""sweep_summary (particleShear.analysis.sweep): characteristics of mean G′/G″ curves and their bootstrap intervals.

The truths used here:

* a Maxwell-like model sweep G′ = G₀/(1+x²), G″ = rG₀x/(1+x²), x = A/A_c: G′ = G″ at x = 1/r, and
  log G′ − log G″ = −log(r x) is linear in log A, so the log-log interpolated flow point is exact;
  G′ falls to (1 − p) of its value at the smallest amplitude x₀ where x² = (1 + x₀²)/(1 − p) − 1
  (x ≈ 0.2294 for p = 5 %, 1/3 for 10 %), found by log-log interpolation up to the interpolation
  error bound h²/8 · max|f″| / min|f′| of f(u) = log G′(eᵘ) on the grid spacing h;
* the bootstrap of a mean over resampled seeds: identical seeds give a zero-width interval; two
  seeds a, b give replicate means a, (a+b)/2, b with probabilities ¼, ½, ¼, so the 2.5 % and 97.5 %
  percentiles are a and b;
* a percentile interval computed on the log of positive replicates and exponentiated is positive,
  and its ends are the geometric interpolation of the neighbouring order statistics; with the
  Student widening on the log scale the ends of two seeds a, b are m·(a/m)^w, m·(b/m)^w;
* coverage: for n normal seeds the percentile interval is about x̄ ± z·σ̂/√n with the ddof = 0
  deviation σ̂, i.e. it covers the true mean with probability P(|T_{n−1}| < z·√((n−1)/n)) (Student
  t), 0.904 for n = 10 and 95 %; the measured coverage over M independent sweeps is binomial.
"""
import math
import unittest
import warnings

import numpy as np

from particleShear.analysis.sweep import (
    CHARACTERISTICS,
    POINT_NAMES,
    SweepSummary,
    sweep_summary,
)

G0, R, AC = 1000.0, 0.5, 0.05        # plateau (Pa), G″/G′ ratio per unit x, characteristic amplitude


def model(A, g0=G0, r=R, ac=AC):
    x = np.asarray(A, float) / ac
    return g0 / (1 + x ** 2), r * g0 * x / (1 + x ** 2)


def t_cdf_interval(c, nu):
    """P(|T_nu| < c) for Student's t by Simpson's rule on its density (no SciPy)."""
    t = np.linspace(0.0, c, 20001)
    logk = math.lgamma((nu + 1) / 2) - math.lgamma(nu / 2) - 0.5 * math.log(nu * math.pi)
    f = np.exp(logk - (nu + 1) / 2 * np.log1p(t ** 2 / nu))
    h = t[1] - t[0]
    simpson = h / 3 * (f[0] + f[-1] + 4 * f[1:-1:2].sum() + 2 * f[2:-1:2].sum())
    return 2 * simpson


class ModelSweep(unittest.TestCase):
    """Exact and interpolation-bounded truths of the model sweep (two identical seeds per amplitude)."""

    @classmethod
    def setUpClass(cls):
        cls.x = np.logspace(-3, 2, 501)          # 100 points per decade
        cls.h = math.log(10) / 100               # grid spacing in log A
        A = AC * cls.x
        gp, gpp = model(A)
        cls.s = sweep_summary(np.repeat(A, 2), np.repeat(gp, 2), np.repeat(gpp, 2), n_boot=50, rng=0)

    def test_plateau_is_the_mean_at_the_smallest_amplitude(self):
        self.assertAlmostEqual(self.s.plateau, G0 / (1 + self.x[0] ** 2), delta=1e-12 * G0)
        self.assertEqual(self.s.amplitudes[0], AC * self.x[0])

    def test_flow_point_is_exact(self):
        # log G′ − log G″ = −log(r x): linear in log A, so log-log interpolation is exact
        self.assertAlmostEqual(self.s.flow_point / (AC / R), 1.0, delta=1e-12)

    def _bound(self, x_true):
        """Interpolation error bound (relative, in A) at x_true: h²/8 · max|f″| / min|f′| on the bracket."""
        u = np.linspace(math.log(x_true) - self.h, math.log(x_true) + self.h, 201)
        x2 = np.exp(2 * u)
        f1 = 2 * x2 / (1 + x2)                    # |f′| of f(u) = log G′
        f2 = 4 * x2 / (1 + x2) ** 2               # |f″|
        du = self.h ** 2 / 8 * f2.max() / f1.min()
        return math.expm1(du)

    def test_linear_limits_within_the_interpolation_bound(self):
        x0 = self.x[0]
        for p, value, approx in ((0.05, self.s.linear_limit_5, 0.2294), (0.10, self.s.linear_limit_10, 1 / 3)):
            x_true = math.sqrt((1 + x0 ** 2) / (1 - p) - 1)
            self.assertAlmostEqual(x_true, approx, delta=1e-4)       # the textbook values (x₀ → 0)
            bound = self._bound(x_true)
            self.assertLess(bound, 2e-4)                               # the grid is fine enough to mean something
            self.assertLessEqual(abs(value / (AC * x_true) - 1), bound, msg=f"p={p}")

    def test_identical_seeds_collapse_every_interval(self):
        s = self.s
        np.testing.assert_allclose(s.Gp_ci, np.c_[s.Gp_mean, s.Gp_mean], rtol=1e-12)
        np.testing.assert_allclose(s.Gpp_ci, np.c_[s.Gpp_mean, s.Gpp_mean], rtol=1e-12)
        for name in CHARACTERISTICS:
            v, (lo, hi) = s.value(name)
            if math.isfinite(v):
                np.testing.assert_allclose([lo, hi], [v, v], rtol=1e-9, err_msg=name)
                self.assertEqual(s.defined_fraction[name], 1.0)
            else:
                self.assertTrue(math.isnan(lo) and math.isnan(hi), name)
                self.assertEqual(s.defined_fraction[name], 0.0)

    def test_points_are_those_of_the_mean_curve(self):
        from particleShear.analysis.curves import stress_curve_points
        direct = stress_curve_points(self.s.amplitudes, self.s.Gp_mean, self.s.Gpp_mean)
        for name in POINT_NAMES:
            np.testing.assert_allclose(self.s.points[name], direct[name], rtol=1e-12, equal_nan=True)
            self.assertEqual(self.s.points_ci[name].shape, (3, 2))

    def test_frozen_and_read_only(self):
        with self.assertRaises(AttributeError):
            self.s.plateau = 1.0
        with self.assertRaises(ValueError):
            self.s.Gp_mean[0] = 1.0
        with self.assertRaises(TypeError):
            self.s.points["yield"] = (1, 2, 3)
        self.assertIsInstance(self.s, SweepSummary)

    def test_table_row(self):
        row = self.s.to_dict()
        self.assertEqual(row["n_runs"], 2 * len(self.x))
        self.assertEqual(row["n_amplitudes"], len(self.x))
        for name in CHARACTERISTICS:
            for suffix in ("", "_ci_low", "_ci_high", "_defined"):
                self.assertIsInstance(row[name + suffix], float)
        rows = self.s.curve_rows()
        self.assertEqual(len(rows), len(self.x))
        self.assertEqual(rows[0]["n_seeds"], 2)


class Bootstrap(unittest.TestCase):

    def test_two_seeds_give_their_values_as_the_interval(self):
        # replicate means a, (a+b)/2, b with probabilities 1/4, 1/2, 1/4: the 2.5 % / 97.5 % percentiles are a, b
        a, b = 900.0, 1100.0
        A = [0.01, 0.01, 0.1, 0.1, 1.0, 1.0]
        s = sweep_summary(A, [a, b, 500, 520, 10, 12], [1, 1, 2, 2, 50, 50], n_boot=4000, rng=3, student=False)
        self.assertEqual(s.plateau, (a + b) / 2)
        self.assertEqual(s.plateau_ci, (a, b))
        np.testing.assert_array_equal(s.Gp_ci, [[a, b], [500, 520], [10, 12]])   # resampled within each amplitude
        np.testing.assert_array_equal(s.n_seeds, [2, 2, 2])
        # Student width on the log scale: the replicates' log-deviations from the mean times √(n/(n−1))·t_{n−1}/z,
        # n = 2, so the ends are m·(a/m)^w and m·(b/m)^w, positive however large w
        from particleShear.analysis.periods import t_critical
        widen = math.sqrt(2.0) * t_critical(1, 0.05) / 1.959963984540054
        s = sweep_summary(A, [a, b, 500, 520, 10, 12], [1, 1, 2, 2, 50, 50], n_boot=4000, rng=3)
        np.testing.assert_allclose(s.plateau_ci, (1000 * (a / 1000) ** widen, 1000 * (b / 1000) ** widen), rtol=1e-9)

    def test_reproducible_from_rng(self):
        rng = np.random.default_rng(11)
        A = np.repeat(np.logspace(-3, 0, 6), 4)
        gp, gpp = model(A)
        gp, gpp = gp * (1 + 0.1 * rng.standard_normal(A.size)), gpp * (1 + 0.1 * rng.standard_normal(A.size))
        one = sweep_summary(A, gp, gpp, n_boot=300, rng=5).to_dict()
        two = sweep_summary(A, gp, gpp, n_boot=300, rng=5).to_dict()
        gen = sweep_summary(A, gp, gpp, n_boot=300, rng=np.random.default_rng(5)).to_dict()
        other = sweep_summary(A, gp, gpp, n_boot=300, rng=6).to_dict()
        np.testing.assert_equal(one, two)
        np.testing.assert_equal(one, gen)
        # another stream moves some interval end (a single end may fall on the same resample mean of 4 seeds)
        self.assertTrue(any(one[k] != other[k] for k in one if k.endswith("_ci_low") and math.isfinite(one[k])))
        self.assertEqual(one["plateau"], other["plateau"])                  # the point estimate has no randomness

    def test_censored_point_is_a_bound_without_interval(self):
        # at the smallest amplitude the mean G′ is 1, 2 or 3 (prob. 1/4, 1/2, 1/4) against G″ = 2, above it G′ < G″:
        # the mean curve has G′ > G″ nowhere, so its flow point lies below the smallest amplitude (an upper bound);
        # the quarter of the replicates with mean 3 cross between 0.1 and 0.2, the others are censored below
        A = np.repeat([0.1, 0.2, 0.5, 1.0], 2)
        s = sweep_summary(A, [1.0, 3.0, 1, 1, 1, 1, 1, 1], [2.0, 2.0, 5, 5, 5, 5, 5, 5], n_boot=4000, rng=2)
        for name in ("flow_point", "yield_strain"):
            v, (lo, hi) = s.value(name)
            self.assertEqual((v, s.flags[name]), (0.1, "upper_bound"), name)
            self.assertTrue(math.isnan(lo) and math.isnan(hi), name)     # a bound, never a zero-width interval
        self.assertEqual(s.to_dict()["flow_point_flag"], "upper_bound")
        # mirrored: G′ > G″ at every amplitude, the flow point beyond the largest one (a lower bound)
        up = sweep_summary(A, [9.0] * 8, [1.0] * 8, n_boot=200, rng=2)
        self.assertEqual((up.flow_point, up.flags["flow_point"]), (1.0, "lower_bound"))
        self.assertTrue(math.isnan(up.flow_point_ci[0]) and math.isnan(up.flow_point_ci[1]))
        # a flat G′ never falls 5 % below its plateau: the linear limits are beyond the range as well
        self.assertEqual((up.linear_limit_5, up.flags["linear_limit_5"]), (1.0, "lower_bound"))
        self.assertTrue(math.isnan(up.points["yield"][1]))   # no G′ at a yield point that was not reached

    def test_interval_open_where_replicates_are_censored(self):
        # crossover between the last two amplitudes, with G′ and G″ at the largest one 10 % apart and 20 % scatter
        # over 3 seeds: a sizeable share of the replicates has G′ > G″ there (censored above) — the upper end is the
        # largest amplitude and the flag says the interval is open there
        A = np.repeat([0.01, 0.1, 0.3, 1.0], 3)
        gp = np.array([100, 100, 100, 90, 90, 90, 60, 60, 60, 40, 50, 60.0])
        gpp = np.array([10, 10, 10, 20, 20, 20, 40, 40, 40, 55, 55, 55.0])
        s = sweep_summary(A, gp, gpp, n_boot=2000, rng=4)
        self.assertEqual(s.flags["flow_point"], "open_above")
        self.assertTrue(0.3 < s.flow_point < 1.0)
        self.assertEqual(s.flow_point_ci[1], 1.0)
        self.assertTrue(0.3 <= s.flow_point_ci[0] <= s.flow_point)

    def test_fewer_than_four_amplitudes_give_the_plateau_only(self):
        A = np.repeat([0.01, 0.1, 1.0], 3)
        gp, gpp = model(A)
        with self.assertWarnsRegex(UserWarning, r"3 distinct amplitudes: .* need >= 4"):
            s = sweep_summary(A, gp * np.tile([0.9, 1.0, 1.1], 3), gpp, n_boot=200, rng=0)
        self.assertEqual(s.flags["plateau"], "ok")
        self.assertTrue(s.plateau_ci[0] <= s.plateau <= s.plateau_ci[1])
        for name in CHARACTERISTICS:
            if name != "plateau":
                v, (lo, hi) = s.value(name)
                self.assertEqual(s.flags[name], "too_few_amplitudes", name)
                self.assertTrue(math.isnan(v) and math.isnan(lo) and math.isnan(hi), name)

    def test_moduli_intervals_are_positive_and_hold_the_estimate(self):
        # 2 seeds 10x apart: the Student factor for n = 2 is ≈ 9.2, which pushed a linear interval far below 0;
        # on the log scale the ends are m·(a/m)^w, m·(b/m)^w: positive by construction, around the mean
        A = np.repeat([0.01, 0.03, 0.1, 0.3, 1.0], 2)
        gp = np.array([100, 1000, 90, 900, 80, 700, 40, 300, 10, 60.0])
        gpp = np.array([10, 100, 10, 100, 20, 150, 30, 200, 40, 220.0])
        s = sweep_summary(A, gp, gpp, n_boot=2000, rng=7)
        for name in ("plateau",) + tuple(f"{p}_{q}" for p in POINT_NAMES for q in ("Gp", "Gpp")):
            v, (lo, hi) = s.value(name)
            if s.flags[name] == "ok":
                self.assertTrue(0 <= lo <= v <= hi, f"{name}: {v} [{lo}, {hi}]")
        self.assertGreater(s.plateau_ci[0], 0)
        self.assertTrue((s.Gp_ci >= 0).all() and (s.Gpp_ci >= 0).all())
        self.assertTrue((s.Gp_ci[:, 0] <= s.Gp_mean).all() and (s.Gp_mean <= s.Gp_ci[:, 1]).all())

    def test_modulus_interval_on_the_log_scale(self):
        from particleShear.analysis.sweep import modulus_interval
        # order statistics 10, 100, 1000, 10000 at confidence 0.5: the 25 % and 75 % points sit at positions 0.75
        # and 2.25, interpolated in log: 10^1.75 and 10^3.25 (linear interpolation would give 77.5 and 3250)
        lo, hi = modulus_interval([1000.0, 10.0, 10000.0, 100.0], 500.0, 0.5)
        self.assertAlmostEqual(lo, 10 ** 1.75, delta=1e-9 * lo)
        self.assertAlmostEqual(hi, 10 ** 3.25, delta=1e-9 * hi)
        # an end on a replicate <= 0 (log −∞) is 0, never negative; NaN replicates are left out
        self.assertEqual(modulus_interval([-5.0, -1.0, 50.0, 60.0, math.nan], 20.0, 0.5)[0], 0.0)
        for estimate in (0.0, -3.0, math.nan):
            self.assertTrue(all(math.isnan(v) for v in modulus_interval([1.0, 2.0], estimate, 0.9)))
        with self.assertRaisesRegex(ValueError, r"confidence=1.5 is out of range: allowed a number in \(0, 1\)"):
            modulus_interval([1.0, 2.0], 1.5, 1.5)
        with self.assertRaisesRegex(ValueError, r"samples is invalid: allowed a 1-D sequence"):
            modulus_interval([[1.0, 2.0]], 1.5, 0.9)

    def test_no_interval_without_an_estimate(self):
        rng = np.random.default_rng(3)
        A = np.repeat(np.logspace(-3, 0.5, 6), 3)
        for _ in range(20):
            gp0, gpp0 = model(A, ac=float(rng.uniform(0.001, 10)))
            s = sweep_summary(A, gp0 * rng.normal(1, 0.3, A.size), gpp0 * rng.normal(1, 0.3, A.size),
                              n_boot=100, rng=rng)
            for name in CHARACTERISTICS:
                v, (lo, hi) = s.value(name)
                if s.flags[name] not in ("ok", "open_above", "open_below", "open_both"):
                    self.assertTrue(math.isnan(lo) and math.isnan(hi), f"{name} {s.flags[name]}: {v} [{lo}, {hi}]")
                if math.isnan(v):
                    self.assertTrue(math.isnan(lo) and math.isnan(hi), name)

    def test_non_positive_means_give_nan_not_errors(self):
        A = np.repeat([0.01, 0.1, 1.0, 10.0], 2)
        gp = np.repeat([100.0, 99.9, 50.0, -10.0], 2)        # G′ < 0 at the largest amplitude (fluid-like)
        gpp = np.repeat([10.0, 20.0, 40.0, 60.0], 2)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            s = sweep_summary(A, gp, gpp, n_boot=100, rng=0)
        self.assertTrue(math.isnan(s.flow_point))           # crossing between G′ = 50 and G′ = −10: no log
        self.assertTrue(math.isfinite(s.linear_limit_5))    # 99.9 → 50 brackets the 5 % limit
        low = sweep_summary(A, np.repeat([100.0, 99.9, -5.0, -10.0], 2), gpp, n_boot=100, rng=0)
        self.assertTrue(math.isnan(low.linear_limit_5))      # the first value below 95 is negative
        neg = sweep_summary(A, -gp, gpp, n_boot=100, rng=0)
        self.assertTrue(math.isnan(neg.linear_limit_5) and math.isnan(neg.linear_limit_10))
        self.assertEqual(neg.plateau, -100.0)
        # a modulus <= 0 has no (log-scale) interval: the value is kept, flagged
        self.assertEqual(neg.flags["plateau"], "non_positive")
        self.assertTrue(math.isnan(neg.plateau_ci[0]) and math.isnan(neg.plateau_ci[1]))
        self.assertTrue(np.isnan(neg.Gp_ci[neg.Gp_mean <= 0]).all())

    def test_one_seed_per_amplitude_warns_and_collapses(self):
        A = np.logspace(-3, 0, 6)
        gp, gpp = model(A)
        with self.assertWarnsRegex(UserWarning, "one run"):
            s = sweep_summary(A, gp, gpp, n_boot=20, rng=0)
        self.assertEqual(s.plateau_ci, (s.plateau, s.plateau))
        with self.assertWarnsRegex(UserWarning, r"amplitude\(s\) \[0.001\]"):
            sweep_summary(np.r_[A, A[1:]], np.r_[gp, gp[1:]], np.r_[gpp, gpp[1:]], n_boot=20, rng=0)

    @staticmethod
    def coverage(M, n, sigma, seed, student):
        """Fraction of M noisy model sweeps (n seeds, normal multiplicative scatter sigma) whose intervals
        of the plateau and of the flow point hold the truth."""
        rng = np.random.default_rng(seed)
        A = np.repeat(AC * np.logspace(-2, 1.5, 5), n)         # flow point A_c/r = 0.1 inside
        gp0, gpp0 = model(A)
        plateau_true, flow_true = model(A[0])[0], AC / R
        hits = np.zeros(2)
        for _ in range(M):
            gp = gp0 * (1 + sigma * rng.standard_normal(A.size))
            gpp = gpp0 * (1 + sigma * rng.standard_normal(A.size))
            s = sweep_summary(A, gp, gpp, n_boot=200, rng=rng, student=student)
            hits += [s.plateau_ci[0] <= plateau_true <= s.plateau_ci[1],
                     s.flow_point_ci[0] <= flow_true <= s.flow_point_ci[1]]
        return hits / M

    def check_coverage(self, coverage, expected, tol):
        print(f"coverage: plateau {coverage[0]:.3f}, flow point {coverage[1]:.3f}; expected {expected:.3f} ± {tol:.3f}")
        for name, c in zip(("plateau", "flow_point"), coverage):
            self.assertLess(abs(c - expected), tol, msg=f"{name}: coverage {c:.3f}, expected {expected:.3f} ± {tol:.3f}")

    def test_coverage_with_student_width(self):
        """M noisy sweeps of 4 seeds each (10 % normal multiplicative noise): the default 95 % intervals hold
        the truth in ≈ 95 % of the sweeps (the Student-t width of a mean, carried into the flow point)."""
        M, expected = 250, 0.95
        # binomial: 3 standard deviations over M sweeps, plus 0.02 for the discreteness of resampling 4 seeds
        # and the nonlinearity of the flow point
        tol = 3 * math.sqrt(expected * (1 - expected) / M) + 0.02
        self.check_coverage(self.coverage(M, 4, 0.10, 20261202, student=True), expected, tol)

    def test_coverage_of_plateau_and_flow_point(self):
        """Plain percentile bootstrap (student=False), M noisy sweeps of n seeds: the 95 % intervals cover the
        truth about as often as the percentile bootstrap of a mean from n seeds should, P(|T_{n−1}| < z√((n−1)/n))."""
        M, n = 250, 10
        z = 1.959963984540054
        expected = t_cdf_interval(z * math.sqrt((n - 1) / n), n - 1)        # 0.904 for n = 10
        self.assertAlmostEqual(expected, 0.904, delta=0.002)
        # binomial: 3 standard deviations of a proportion over M sweeps, plus 0.02 for the normal approximation
        # of the bootstrap distribution (discrete resampling, percentiles of n_boot = 200 replicates, nonlinearity of the
        # flow point)
        tol = 3 * math.sqrt(expected * (1 - expected) / M) + 0.02
        self.check_coverage(self.coverage(M, n, 0.10, 20240521, student=False), expected, tol)


class BadInput(unittest.TestCase):
    A = (0.01, 0.1, 1.0)
    G = (1.0, 2.0, 3.0)

    def check(self, pattern, *args, **kw):
        with self.assertRaisesRegex(ValueError, pattern):
            sweep_summary(*args, **kw)

    def test_errors_name_parameter_value_and_range(self):
        A, G = self.A, self.G
        self.check(r"amplitude, Gp, Gpp .*equal lengths, got 3, 2, 3", A, G[:2], G)
        self.check(r"Gpp\[1\]=nan .*finite", A, G, [1.0, math.nan, 1.0])
        self.check(r"Gp\[2\]=inf .*finite", A, [1.0, 1.0, math.inf], G)
        self.check(r"amplitude\[0\]=0.0 .*amplitude > 0", [0.0, 0.1, 1.0], G, G)
        self.check(r"amplitude\[1\]=-0.1 .*amplitude > 0", [0.01, -0.1, 1.0], G, G)
        self.check(r"amplitude=\[0.1, 0.1, 0.1\] .*1 distinct .*at least 2", [0.1] * 3, G, G)
        self.check(r"amplitude is invalid: allowed a 1-D", [[0.1, 1.0]], [[1.0, 2.0]], [[1.0, 2.0]])
        self.check(r"Gp is invalid", A, ["a", "b", "c"], G)
        for bad in (0, -3):
            self.check(rf"n_boot={bad} is out of range: allowed an integer >= 1", A, G, G, n_boot=bad)
        for bad in (1.5, True, "10"):
            self.check(rf"n_boot={bad!r} is invalid: allowed an integer >= 1", A, G, G, n_boot=bad)
        for bad in (0, 1, 1.5, -0.2, math.nan, True):
            self.check(rf"confidence={bad!r} is out of range: allowed a number in \(0, 1\)", A, G, G,
                       confidence=bad)
        self.check(r"rng=-1 is out of range", A, G, G, rng=-1)
        self.check(r"rng='x' is invalid", A, G, G, rng="x")
        with self.assertRaisesRegex(ValueError, r"name='nope' is invalid"):
            sweep_summary(A + A, G + G, G + G, n_boot=5, rng=0).value("nope")


if __name__ == "__main__":
    unittest.main()
