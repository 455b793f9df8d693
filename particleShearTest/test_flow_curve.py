"""Herschel-Bulkley fit of a flow curve (particleShear.analysis.flow_curve)."""
import unittest

import numpy as np

from particleShear.analysis import fit_flow_curve, flow_curve_table, herschel_bulkley_bootstrap, herschel_bulkley_fit

RATE = np.logspace(-2, 2, 9)


class TestFit(unittest.TestCase):
    def test_exact_data_recovered(self):
        # exact data: the profile minimum is rss = 0 at the true parameters; the golden section
        # resolves n to ~1e-13, so 1e-6 relative is far from the round-off floor
        for sy, K, n in [(5.0, 2.0, 0.5), (0.0, 3.0, 0.4), (2.0, 1.5, 1.0), (10.0, 0.1, 1.8), (0.5, 4.0, 0.1)]:
            hb = herschel_bulkley_fit(RATE, sy + K * RATE ** n)
            self.assertAlmostEqual(hb.sigma_y, sy, delta=1e-6 * max(sy, K))   # sy = 0: absolute
            self.assertLess(abs(hb.K - K), 1e-6 * K)
            self.assertLess(abs(hb.n - n), 1e-6 * n)
            np.testing.assert_allclose(hb.stress(RATE), sy + K * RATE ** n, rtol=1e-6)

    def test_power_law_noise_never_negative_yield_stress(self):
        rng = np.random.default_rng(3)
        clamped = 0
        for _ in range(40):
            s = 2.0 * RATE ** 0.7 * (1 + 0.05 * rng.standard_normal(RATE.size))
            hb = herschel_bulkley_fit(RATE, s)
            self.assertGreaterEqual(hb.sigma_y, 0.0)
            clamped += hb.sigma_y == 0.0
        self.assertGreater(clamped, 0)      # the constraint σ_y >= 0 was exercised

    def test_degenerate_fits_say_why(self):
        # inside the bounds: no reason; σ_y = 0 exactly (a power law); n on its upper bound 2 (a cubic rises faster
        # than any law with n <= 2); n -> 0 (a stress that does not depend on the rate: σ_y and K trade off)
        from particleShear.analysis.flow_curve import N_LOW
        self.assertEqual(herschel_bulkley_fit(RATE, 5.0 + 2.0 * RATE ** 0.5).degenerate, ())
        power = herschel_bulkley_fit(RATE, 2.0 * RATE ** 0.7)
        self.assertEqual(power.sigma_y, 0.0)
        self.assertEqual(len(power.degenerate), 1)
        self.assertIn("sigma_y on its bound 0", power.degenerate[0])
        steep = herschel_bulkley_fit(RATE, 1.0 + RATE ** 3)
        self.assertEqual(steep.n, 2.0)
        self.assertTrue(any("on its upper bound 2" in r for r in steep.degenerate), steep.degenerate)
        flat = herschel_bulkley_fit(RATE, 10.0 + 0.001 * np.log(RATE / 1e-3))   # slope d ln σ / d ln γ̇ ~ 1e-4
        self.assertLess(flat.n, N_LOW)
        self.assertTrue(any("at its lower bound 0" in r for r in flat.degenerate), flat.degenerate)

    def test_minimum_against_independent_grid(self):
        # independent evaluation: unconstrained lstsq on a fine n grid never beats the fit
        rng = np.random.default_rng(5)
        s = (4.0 + 1.2 * RATE ** 0.6) * (1 + 0.03 * rng.standard_normal(RATE.size))
        hb = herschel_bulkley_fit(RATE, s)
        best = min(np.linalg.lstsq(np.column_stack([np.ones_like(RATE), RATE ** n]), s, rcond=None)[1][0]
                   for n in np.linspace(0.01, 2, 2000))
        self.assertLessEqual(hb.rss, best * (1 + 1e-9))
        self.assertAlmostEqual(hb.rss, float(np.sum((s - hb.stress(RATE)) ** 2)), delta=1e-12 * hb.rss + 1e-300)

    def test_zero_weight_drops_a_point(self):
        s = 5.0 + 2.0 * RATE ** 0.5
        s[4] += 50.0
        w = np.ones_like(RATE)
        w[4] = 0.0
        a = herschel_bulkley_fit(RATE, s, weights=w)
        b = herschel_bulkley_fit(np.delete(RATE, 4), np.delete(s, 4))
        self.assertAlmostEqual(a.n, b.n, delta=1e-9)
        self.assertAlmostEqual(a.sigma_y, b.sigma_y, delta=1e-8)

    def test_bad_inputs(self):
        s = 1 + RATE
        for args, word in [((RATE[:-1], s), "lengths"), ((np.r_[RATE[:-1], np.nan], s), r"rate\[8\]=nan"),
                           ((np.r_[0.0, RATE[1:]], s), r"rate\[0\]=0.0"), ((RATE, np.r_[s[:-1], np.inf]), r"stress\[8\]=inf"),
                           ((RATE[:2], s[:2]), "rate"), ((RATE, -s), "stress")]:
            with self.assertRaisesRegex(ValueError, word):
                herschel_bulkley_fit(*args)
        with self.assertRaisesRegex(ValueError, "weights"):
            herschel_bulkley_fit(RATE, s, weights=-np.ones_like(RATE))
        S = np.ones((RATE.size, 3))
        for kw, word in [({"n_boot": 0}, "n_boot"), ({"n_boot": 1.5}, "n_boot"), ({"confidence": 1.0}, "confidence"),
                         ({"rng": "x"}, "rng")]:
            with self.assertRaisesRegex(ValueError, word):
                herschel_bulkley_bootstrap(RATE, S, **kw)
        with self.assertRaisesRegex(ValueError, "shape"):
            herschel_bulkley_bootstrap(RATE, S[:-1])


class TestBootstrap(unittest.TestCase):
    TRUTH = (3.0, 1.0, 0.6)

    def table(self, rng, seeds=12):
        rate = np.logspace(-1, 2, 8)
        sy, K, n = self.TRUTH
        return rate, (sy + K * rate ** n)[:, None] * (1 + 0.05 * rng.standard_normal((rate.size, seeds)))

    def test_point_fit_is_fit_of_nan_means(self):
        rate, S = self.table(np.random.default_rng(1))
        S[2, :4] = np.nan
        S[5, :] = np.nan                             # a rate with no finite run: dropped
        res = herschel_bulkley_bootstrap(rate, S, n_boot=20, rng=0)
        keep = np.arange(rate.size) != 5
        ref = herschel_bulkley_fit(rate[keep], np.nanmean(S[keep], axis=1))
        # noisy data: the rss is flat to round-off within ~√eps of its minimum in n, and the two
        # fits scale the rates differently, so they agree to ~1e-8, not to round-off
        self.assertAlmostEqual(res.yield_stress, ref.sigma_y, delta=1e-6 * ref.sigma_y)
        self.assertAlmostEqual(res.fit.n, ref.n, delta=1e-6 * ref.n)

    def test_same_seed_same_intervals(self):
        rate, S = self.table(np.random.default_rng(2))
        a = herschel_bulkley_bootstrap(rate, S, n_boot=100, rng=7)
        b = herschel_bulkley_bootstrap(rate, S, n_boot=100, rng=7)
        self.assertEqual(dict(a.intervals), dict(b.intervals))

    def test_coverage(self):
        # 95 % percentile intervals of 12 seeds undercover a little (bootstrap spread √(11/12) of the
        # standard error, normal not Student quantiles): true coverage about 0.92.  With 30 trials the
        # count covered is binomial, mean 27.6, sd √(30·0.92·0.08) ≈ 1.5; the bound 24 (80 %) is
        # 2.4 sd below, so only a real defect (coverage well under 90 %) fails it.
        rng = np.random.default_rng(11)
        covered = np.zeros(3, int)
        for _ in range(30):
            rate, S = self.table(rng)
            res = herschel_bulkley_bootstrap(rate, S, n_boot=200, rng=rng)
            for i, (name, true) in enumerate(zip(("sigma_y", "K", "n"), self.TRUTH)):
                lo, hi = res.intervals[name]
                covered[i] += lo <= true <= hi
        self.assertTrue((covered >= 24).all(), covered)


class TestFromTable(unittest.TestCase):
    """A steady-shear sweep's table (rows as load_results gives them) into the fit."""

    @staticmethod
    def rows(law, tau=1e-3, reps=3, failed=()):
        out = []
        for rep in range(reps):
            for rel in (0.08, 0.01, 0.04, 0.02):        # table order need not be rate order
                ok = (rel, rep) not in failed
                out.append({"protocol": "steady", "status": "ok" if ok else "failed", "repetition": rep,
                            "relative_rate": rel, "strain_rate": rel / tau if ok else None,
                            "stress_surface": law(rel / tau) + 0.1 * (rep - 1) if ok else None})
        return out

    def test_grouping_and_exact_recovery(self):
        law = lambda g: 4.0 + 0.5 * g ** 0.6     # noqa: E731
        rate, stress = flow_curve_table(self.rows(law, failed={(0.04, 2)}))
        np.testing.assert_array_equal(rate, [10.0, 20.0, 40.0, 80.0])
        self.assertEqual(stress.shape, (4, 3))
        self.assertTrue(np.isnan(stress[2, 2]) and np.isfinite(stress).sum() == 11)
        # repetitions offset by -0.1, 0, +0.1 Pa: the seed mean is the law itself, fitted exactly
        fit = fit_flow_curve(self.rows(law), n_boot=200, rng=1)
        self.assertAlmostEqual(fit.fit.sigma_y, 4.0, delta=1e-6)
        self.assertAlmostEqual(fit.fit.n, 0.6, delta=1e-6)
        lo, hi = fit.intervals["sigma_y"]
        self.assertLessEqual(lo, 4.0 + 1e-6)
        self.assertGreaterEqual(hi, 4.0 - 1e-6)

    def test_mixed_materials_and_no_steady_rows_refused(self):
        rows = self.rows(lambda g: g) + [dict(self.rows(lambda g: g, tau=2e-3)[0], repetition=5)]
        with self.assertRaisesRegex(ValueError, "mixes materials"):
            flow_curve_table(rows)
        with self.assertRaisesRegex(ValueError, "no rows of protocol 'steady'"):
            flow_curve_table([{"protocol": "creep", "status": "ok"}])
        with self.assertRaisesRegex(ValueError, "estimator"):
            flow_curve_table(self.rows(lambda g: g), estimator="plate")


if __name__ == "__main__":
    unittest.main()
