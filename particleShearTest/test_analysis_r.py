"""The downstream R evaluation's definitions (particleShear.analysis.demodulation and .curves).

Each rule is checked against the issue's definition written out independently here (a literal,
sequential transcription), against closed forms, and on the edge cases the definitions name.
"""
import math
import os
import tempfile
import unittest

import numpy as np

from particleShear.analysis import (demodulate, evaluate_run, jump_corrected, measurement_periods,
                                    stress_curve_points, yield_point)


def sequential_jump_correction(m, threshold_fraction=0.15):
    """The R rule, literally: jump list first, then in-place tail shifts in increasing order."""
    m = [float(x) for x in m]
    thr = threshold_fraction * (max(m) - min(m))
    jumps = [i for i in range(len(m) - 1) if abs(m[i + 1] - m[i]) > thr]
    for i in jumps:
        if 1 <= i <= len(m) - 2:
            shift = -(m[i + 1] - m[i]) + (m[i] - m[i - 1])
            for j in range(i + 1, len(m)):
                m[j] += shift
    return np.array(m)


class JumpCorrection(unittest.TestCase):
    def test_steps_removed_from_a_ramp(self):
        m = np.array([0, 1, 2, 10, 11, 12, 3, 4, 5.0])
        np.testing.assert_array_equal(jump_corrected(m), np.arange(9.0))

    def test_equals_the_sequential_definition(self):
        rng = np.random.default_rng(7)
        for trial in range(20):
            x = np.cumsum(rng.normal(size=400)) * rng.uniform(0.1, 10)
            for k in rng.integers(1, 399, size=4):
                x[k:] += rng.normal(scale=40)
            frac = rng.choice([0.01, 0.05, 0.15, 0.3])
            ref = sequential_jump_correction(x, frac)
            # the tail shifts are summed in another order: round-off of the running sums only
            np.testing.assert_allclose(jump_corrected(x, frac), ref, rtol=0, atol=1e-12 * np.max(np.abs(ref)))

    def test_consecutive_jumps_use_values_corrected_so_far(self):
        m = np.array([0.0, 0.0, 10.0, 20.0, 20.0, 20.0])     # jumps at i = 1 and i = 2
        ref = sequential_jump_correction(m)
        np.testing.assert_array_equal(jump_corrected(m), ref)
        np.testing.assert_array_equal(ref, np.zeros(6))

    def test_first_and_last_increment_never_corrected(self):
        m = np.array([100.0, 0.0, 0.1, 0.2, -50.0])          # jumps at i = 0 and i = n - 2 = 3
        out = jump_corrected(m)
        self.assertEqual(out[1] - out[0], -100.0)            # i = 0 is outside 1 <= i <= n-2
        np.testing.assert_allclose(out[4] - out[3], 0.1)     # i = 3 = n-2 is corrected

    def test_bad_threshold(self):
        with self.assertRaisesRegex(ValueError, "jump_threshold"):
            jump_corrected([1.0, 2.0, 3.0], 0)


class Demodulate(unittest.TestCase):
    f = 3963.3
    dt = 1e-7

    def signal(self, periods=2.0, t0=0.37e-3):
        t = t0 + np.arange(int(periods / self.f / self.dt)) * self.dt
        ph = 2 * math.pi * self.f * (t - t[0])
        return t, ph

    def test_projection_definition(self):
        t, ph = self.signal()
        gamma0, Gp, Gpp = 0.2, 1165.0, 150.0
        m = gamma0 * (Gp * np.sin(ph) + Gpp * np.cos(ph)) + 3.0 * np.sin(3 * ph)
        a, b = np.sin(ph), np.cos(ph)
        ref = ((a @ m) / (a @ a) / gamma0, (b @ m) / (b @ b) / gamma0)
        got = demodulate(t, m, self.f, gamma0, correct_jumps=False)
        np.testing.assert_allclose(got, ref, rtol=1e-12)
        # over whole periods the projections are the Fourier amplitudes (discretisation: dt·f ~ 4e-4)
        np.testing.assert_allclose(got, (Gp, Gpp), rtol=1e-3)

    def test_jump_removed_before_projection(self):
        t, ph = self.signal()
        m = 0.5 * (1000 * np.sin(ph) + 100 * np.cos(ph))
        clean = demodulate(t, m, self.f, 0.5)
        jumped = m.copy()
        jumped[len(m) // 3:] += 400.0                       # a step of 40 % of the range
        self.assertGreater(abs(demodulate(t, jumped, self.f, 0.5, correct_jumps=False)[1] - clean[1]), 10)
        # corrected: one increment replaced by its predecessor, so the tail is off by at most
        # max|Δ²m| ≈ 500 Pa·(2πf·dt)²; a constant offset δ projects to < 4/π·δ/γ₀ on sin or cos
        delta = np.max(np.abs(np.diff(m, 2)))
        np.testing.assert_allclose(demodulate(t, jumped, self.f, 0.5), clean, rtol=0, atol=4 / math.pi * delta / 0.5)

    def test_empty_and_bad_input(self):
        self.assertTrue(all(math.isnan(x) for x in demodulate([], [], self.f)))
        with self.assertRaisesRegex(ValueError, "f="):
            demodulate([0.0, 1.0], [0.0, 1.0], 0)
        with self.assertRaisesRegex(ValueError, "strain_amplitude"):
            demodulate([0.0, 1.0], [0.0, 1.0], 1.0, strain_amplitude=-1)
        with self.assertRaisesRegex(ValueError, "one length"):
            demodulate([0.0, 1.0], [0.0], 1.0)


class MeasurementPeriods(unittest.TestCase):
    def test_labels(self):
        f = 2.0
        t = np.array([0.0, 0.99, 1.0, 1.49, 1.5, 2.5, 2.5001, 3.0])
        np.testing.assert_array_equal(
            measurement_periods(t, f, pre_periods=2, periods=3),
            ["pre", "pre", "initiation", "initiation", "oscillatory_measurement", "oscillatory_measurement",
             "post", "post"])

    def test_no_initiation_for_one_period(self):
        t = np.linspace(0, 3, 31)
        lab = measurement_periods(t, 1.0, pre_periods=1, periods=1)
        self.assertNotIn("initiation", set(lab))
        np.testing.assert_array_equal(lab[(t >= 1) & (t <= 2)], "oscillatory_measurement")


class YieldPoint(unittest.TestCase):
    def test_model_sweep_log_interpolation_exact(self):
        A = np.geomspace(1e-3, 3, 23)
        for Ac, r in ((0.1, 0.3), (0.05, 0.8), (0.2, 0.15)):
            x = A / Ac
            Gp, Gpp = 1e3 / (1 + x**2), r * 1e3 * x / (1 + x**2)
            # log G′ − log G″ = −log r − log x is linear in log A: the interpolation is exact
            self.assertAlmostEqual(yield_point(A, Gp, Gpp) / (Ac / r), 1.0, delta=1e-12)

    def test_linear_interpolation_by_hand(self):
        s = [0.1, 0.2, 0.4]
        Gp = [100.0, 80.0, 20.0]
        Gpp = [10.0, 40.0, 60.0]
        # from above: 0.4 (G′<G″), 0.2 (G′>G″) -> zero of Δ = (-40, 40) halfway in strain
        self.assertAlmostEqual(yield_point(s, Gp, Gpp, "linear"), 0.3, delta=1e-15)
        self.assertAlmostEqual(stress_curve_points(s, Gp, Gpp)["yield"][1], 50.0, delta=1e-12)
        self.assertAlmostEqual(stress_curve_points(s, Gp, Gpp)["yield"][2], 50.0, delta=1e-12)

    def test_no_crossover_and_crossover_at_first_point(self):
        s = [0.01, 0.1, 1.0]
        self.assertTrue(math.isnan(yield_point(s, [1.0, 1.0, 1.0], [2.0, 2.0, 2.0])))
        self.assertEqual(yield_point(s, [5.0, 5.0, 5.0], [1.0, 1.0, 1.0]), 1.0)
        self.assertEqual(yield_point(s[::-1], [5.0, 5.0, 5.0], [1.0, 1.0, 1.0], "linear"), 1.0)

    def test_bad_interpolation(self):
        with self.assertRaisesRegex(ValueError, "interpolation"):
            yield_point([1.0], [1.0], [1.0], "cubic")


class StressCurvePoints(unittest.TestCase):
    def test_by_hand(self):
        # strains e-folds apart: ln s_k = k, so the slopes are plain differences of G′
        s = np.exp(np.arange(-7.0, 0.0))            # 7 points, s = e^-7 … e^-1 (0.0009 … 0.37)
        Gp = np.array([100, 100, 90, 60, 40, 35, 20.0])
        Gpp = np.array([5, 8, 20, 15, 10, 12, 30.0])
        d = np.diff(Gp)                             # [0, -10, -30, -20, -5, -15]
        p = np.concatenate(([d[0]], d, [d[-1]]))
        D = -(p[:-1] + p[1:]) / 2                   # [0, 5, 20, 25, 12.5, 10, 15]
        np.testing.assert_allclose(D, [0, 5, 20, 25, 12.5, 10, 15])
        pts = stress_curve_points(s, Gp, Gpp, guess_softening_strain=0.01, guess_soft_plateau_strain=0.1)
        self.assertEqual(pts["low_strain_plateau"], (s[0], 100.0, 5.0))
        # window 0.002 … 0.05: s[1..4]; largest G″ there at 0-based 2; largest D within ±3: 0-based 3
        soft = pts["softening"]
        np.testing.assert_allclose(soft, (math.exp((-5 + -4) / 2), 75.0, 17.5), rtol=1e-14)
        # candidates: s >= 1.5·soft strain (0.0167) and s <= 0.3: 0-based 3, 4, 5 (s[6] = 0.37 > 0.3)
        # smallest G″ there: 0-based 4; smallest D within ±3 (positions 1…6): 0-based 1 -> position 2.5
        np.testing.assert_allclose(pts["soft_plateau"], (math.exp(-4.5), 75.0, 17.5), rtol=1e-14)

    def test_zero_outside_the_window_can_win(self):
        # G′ rising everywhere: every slope negative inside the window, so the 0 outside wins
        s = np.geomspace(1e-4, 1, 9)
        Gp = np.linspace(100, 200, 9)
        Gpp = np.array([1, 1, 1, 1, 1, 9, 1, 1, 1.0])
        pts = stress_curve_points(s, Gp, Gpp, guess_softening_strain=s[5])
        # i1 = 5; D < 0 on 2…8, the first 0 of the product is at position 0 -> (5 + 0)/2 = 2.5
        ls = np.log(s)
        np.testing.assert_allclose(pts["softening"], (math.exp((ls[2] + ls[3]) / 2), (Gp[2] + Gp[3]) / 2, 1.0),
                                   rtol=1e-14)

    def test_soft_plateau_search_widens(self):
        s = np.array([0.001, 0.01, 0.1, 1.0, 10.0, 100.0])
        Gp = np.array([100, 90, 60, 30, 20, 10.0])
        Gpp = np.array([5, 20, 15, 12, 8, 9.0])
        # soft plateau guess far below the data: no candidate until the bound 3h·3^k reaches 10
        pts = stress_curve_points(s, Gp, Gpp, guess_softening_strain=0.01, guess_soft_plateau_strain=1e-4)
        self.assertTrue(math.isfinite(pts["soft_plateau"][0]))
        # beyond 2187·h nothing is searched
        pts = stress_curve_points(s[:3], Gp[:3], Gpp[:3], guess_softening_strain=0.01,
                                  guess_soft_plateau_strain=1e-9)
        self.assertTrue(math.isnan(pts["soft_plateau"][0]))

    def test_repeated_smallest_strain_is_averaged(self):
        s = [0.01, 0.01, 0.1, 1.0]
        pts = stress_curve_points(s, [100.0, 110.0, 50.0, 5.0], [10.0, 12.0, 20.0, 30.0])
        self.assertEqual(pts["low_strain_plateau"], (0.01, 105.0, 11.0))


class EvaluateRun(unittest.TestCase):
    """The R pipeline on a real run: read back from its file, same numbers as on the series."""

    @classmethod
    def setUpClass(cls):
        from particleShear import doParticleShearSimulation
        cls.tmp = tempfile.TemporaryDirectory()
        cls.res = doParticleShearSimulation(cls.tmp.name, N=20, pre_periods=1, periods=3, post_periods=1,
                                            relative_frequency=0.1, doDrawing=False, saveData=True, seed=3,
                                            return_result=True, verbose=False)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_file_and_series_agree_and_follow_the_definition(self):
        from particleShear.simulation.formats import read_run
        run = read_run(self.res.output_path)
        self.assertEqual(run.frequency, self.res.f)
        self.assertEqual(run.strain_amplitude, 0.2)
        self.assertEqual((run.pre_periods, run.periods), (1.0, 3.0))
        from_file = evaluate_run(self.res.output_path)
        from_series = evaluate_run(self.res)
        for est in ("surface", "internal"):
            np.testing.assert_allclose(from_file[est], from_series[est], rtol=1e-12)
        # independently: the samples (pre+1)/f <= t <= (pre+P)/f, sequential jump correction, projection
        t = np.asarray(self.res.series["t"])
        f = self.res.f
        keep = (t >= 2 / f) & (t <= 4 / f)
        tt = t[keep] - t[keep][0]
        m = sequential_jump_correction(np.asarray(self.res.series["stress_surface"])[keep])
        a, b = np.sin(2 * math.pi * f * tt), np.cos(2 * math.pi * f * tt)
        np.testing.assert_allclose(from_series["surface"], ((a @ m) / (a @ a) / 0.2, (b @ m) / (b @ b) / 0.2),
                                   rtol=1e-9)
        # the package's own estimate uses the same window with its drift rule: close, not equal
        self.assertLess(abs(from_series["surface"][0] / self.res.G_surface[0] - 1), 0.05)

    def test_needs_a_series(self):
        with self.assertRaisesRegex(ValueError, "series"):
            evaluate_run(type("R", (), {"series": {}, "parameters": {}})())

    def test_path_of_a_missing_file(self):
        with self.assertRaises(ValueError):
            evaluate_run(os.path.join(self.tmp.name, "nothing.txt"))


if __name__ == "__main__":
    unittest.main()
