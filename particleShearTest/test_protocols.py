"""The rheometer's protocols (docs/protocols.md): batching, the one-packing sweep's first step,
stress control, and bad input; the statistics of :mod:`particleShear.analysis.rheometry`."""
import math
import unittest

import numpy as np

from particleShear import doParticleShearSimulation
from particleShear.analysis.rheometry import block_average, final_rate, log_grid, steady_state, transient_end
from particleShear.run.batch import run_batch

SMALL = dict(N=30, cut_lines=0, relative_frequency=0.2, pre_periods=0.2, periods=2, post_periods=0,
             doDrawing=False, verbose=False)


def run(**kw):
    return doParticleShearSimulation(**dict(SMALL, **kw), return_result=True)


class TestBatchedEqualsSingle(unittest.TestCase):
    def test_steady_replicas_with_different_rates(self):
        kws = [dict(SMALL, seed=3, protocol="steady", relative_rate=0.02, total_strain=0.1),
               dict(SMALL, seed=4, protocol="steady", relative_rate=0.04, total_strain=0.1)]
        batch = run_batch(kws)
        for kw, res in zip(kws, batch):
            single = doParticleShearSimulation(**kw, return_result=True)
            self.assertEqual(len(res.series["t"]), len(single.series["t"]))
            for key in single.series:
                np.testing.assert_array_equal(res.series[key], single.series[key])
            self.assertEqual(res.summary["stress_surface"], single.summary["stress_surface"])
        # twice the rate over the same strain: half the steps (the record is cut per replica)
        self.assertAlmostEqual(len(batch[0].series["t"]) / len(batch[1].series["t"]), 2.0, delta=0.01)

    def test_creep_replicas_with_different_stresses(self):
        kws = [dict(SMALL, seed=5, protocol="creep", creep_stress=s, hold_time=20.0) for s in (20.0, 60.0)]
        batch = run_batch(kws)
        for kw, res in zip(kws, batch):
            single = doParticleShearSimulation(**kw, return_result=True)
            for key in single.series:
                np.testing.assert_array_equal(res.series[key], single.series[key])


    def test_amplitude_sweep_replicas_with_different_lists(self):
        # lists with the same time steps (docs/protocols.md, "Batches") batch; each replica equals its run
        kws = [dict(SMALL, seed=3, protocol="amplitude_sweep", sweep_amplitudes=[0.05, 0.1]),
               dict(SMALL, seed=4, protocol="amplitude_sweep", sweep_amplitudes=[0.04, 0.08])]
        batch = run_batch(kws)
        for kw, res in zip(kws, batch):
            single = doParticleShearSimulation(**kw, return_result=True)
            self.assertEqual(res.steps, single.steps)
            for key in single.series:
                np.testing.assert_array_equal(res.series[key], single.series[key])

class TestProtocols(unittest.TestCase):
    def test_frequency_sweep_first_step_is_the_independent_run(self):
        sweep = run(seed=7, protocol="frequency_sweep", sweep_frequencies=[0.2, 0.3])
        alone = run(seed=7, relative_frequency=0.2)
        self.assertEqual((sweep.steps[0]["Gp_surface"], sweep.steps[0]["Gpp_surface"]), tuple(alone.G_surface))
        self.assertEqual([s["position"] for s in sweep.steps], [0, 1])

    def test_amplitude_sweep_first_step_is_the_independent_run(self):
        sweep = run(seed=8, protocol="amplitude_sweep", sweep_amplitudes=[0.1, 0.3])
        alone = run(seed=8, theAmplitude=0.1)
        self.assertEqual((sweep.steps[0]["Gp_internal"], sweep.steps[0]["Gpp_internal"]), tuple(alone.G_internal))

    def test_relaxation_holds_the_step_strain(self):
        res = run(seed=2, protocol="relaxation", theAmplitude=0.1, ramp_time=1.0, hold_time=20.0)
        n_ramp = round(1.0 / (res.dt / res.tau))
        strain = res.series["strain"]
        # step 0 at rest, then n_ramp increments γ₀/n_ramp: the strain is γ₀ after them (rounding only)
        self.assertEqual((strain[0], strain[1], res.series["strain_rate"][0]), (0.0, 0.0, 0.0))
        np.testing.assert_allclose(strain[n_ramp + 1:], 0.1, rtol=1e-12)
        self.assertTrue(np.all(res.series["strain_rate"][n_ramp + 1:] == 0))
        self.assertIn("G_surface", res.curves)

    def test_creep_tracks_the_applied_stress(self):
        s0 = 40.0
        res = run(seed=1, protocol="creep", creep_stress=s0, hold_time=100.0)
        t, tau = res.series["t"], res.series["stress_surface"]
        late = t >= t[-1] / 2
        # step 0 at rest measures the residual stress σ_res; the controller holds the plate stress at
        # σ₀ and its integral term leaves no steady error: the late mean within 2 % of σ₀
        self.assertEqual(res.series["strain_rate"][0], 0.0)
        self.assertEqual(res.summary["residual_stress"], tau[0])
        self.assertLess(abs(tau[late].mean() - s0) / s0, 0.02)
        self.assertAlmostEqual(res.summary["stress_tracking"], (tau[late].mean() - s0) / s0, places=12)
        self.assertGreater(res.summary["strain_plateau"], 0)

    def test_relaxation_modulus_counts_from_the_residual_stress(self):
        # G(t) = (σ(t) − σ(0))/γ₀: two step strains of one packing (same seed, same time step for
        # amplitudes below the rule's threshold) give plateaus that agree at small strain, while
        # σ(t)/γ₀ alone would differ by σ_res·(1/γ₁ − 1/γ₂)
        a = run(seed=2, protocol="relaxation", theAmplitude=0.01, hold_time=20.0)
        b = run(seed=2, protocol="relaxation", theAmplitude=0.02, hold_time=20.0)
        res0 = a.summary["residual_stress"]
        self.assertEqual(res0, a.series["stress_surface"][0])
        G_a, G_b = a.summary["G_plateau_surface"], b.summary["G_plateau_surface"]
        self.assertLess(abs(G_a - G_b) / G_b, 0.05, (G_a, G_b, res0))
        self.assertGreater(abs(res0) * (1 / 0.01 - 1 / 0.02), 0.05 * G_b)    # the bias the origin removes

    def test_bad_input_before_any_work(self):
        cases = [dict(protocol="stedy"), dict(protocol="steady", relative_rate=0.0),
                 dict(protocol="steady", relative_rate=10.0), dict(protocol="creep"),
                 dict(protocol="creep", creep_stress=-1.0), dict(protocol="amplitude_sweep"),
                 dict(protocol="amplitude_sweep", sweep_amplitudes=[]),
                 dict(protocol="amplitude_sweep", sweep_amplitudes=[0.1, 0.3, 0.2]),
                 dict(protocol="relaxation", theAmplitude=5.0, ramp_time=0.01),
                 dict(protocol="creep", creep_stress=1.0, creep_response_time=1e-4)]
        for kw in cases:
            with self.subTest(**{k: str(v) for k, v in kw.items()}):
                with self.assertRaises(ValueError):
                    run(seed=1, **kw)
        with self.assertRaisesRegex(ValueError, "did you mean 'steady'"):
            run(seed=1, protocol="stedy")


class TestRheometryStatistics(unittest.TestCase):
    def test_blocking_error_of_an_ar1_series(self):
        # AR(1) x_k = φ x_{k-1} + e_k: the error of the mean is σ/√n·√((1+φ)/(1−φ)) (large n);
        # over 20 seeds the mean ratio of the blocked to the analytic error lies within 20 %
        phi, n, ratios = 0.9, 2 ** 14, []
        for seed in range(20):
            e = np.random.default_rng(seed).normal(size=n)
            x = np.empty(n)
            x[0] = e[0] / math.sqrt(1 - phi * phi)
            for k in range(1, n):
                x[k] = phi * x[k - 1] + e[k]
            sigma = 1 / math.sqrt(1 - phi * phi)
            ratios.append(block_average(x).sem / (sigma / math.sqrt(n) * math.sqrt((1 + phi) / (1 - phi))))
        self.assertLess(abs(np.mean(ratios) - 1), 0.2)

    def test_iid_error(self):
        x = np.random.default_rng(1).normal(size=4096)
        ba = block_average(x)
        # max over levels ≥ the naive error; iid data: within 30 % of it (scatter of coarse levels)
        self.assertGreaterEqual(ba.sem, x.std(ddof=1) / 64 - 1e-15)
        self.assertLess(ba.sem, 1.3 * x.std(ddof=1) / 64)

    def test_transient_end_of_a_decay(self):
        t = np.arange(4000.0)
        x = 10 * np.exp(-t / 100) + np.random.default_rng(2).normal(scale=0.1, size=t.size)
        i = transient_end(x)
        # the decay falls below the noise (0.1) at t = 100·ln(100) ≈ 460: MSER ends it near there
        self.assertTrue(200 <= i <= 1000, i)
        ss = steady_state(t, x)
        self.assertLess(abs(ss.mean), 4 * ss.sem + 0.01)

    def test_log_grid_of_a_power_law(self):
        t = np.linspace(1e-3, 10, 100000)
        tm, ym, _, count = log_grid(t, t ** -0.5)
        self.assertTrue(np.all(np.diff(np.log10(tm)) > 0))
        # bin means of a power law at the bins' geometric mean time: within the bins' curvature, 1 %
        np.testing.assert_allclose(ym, tm ** -0.5, rtol=0.01)
        self.assertEqual(count.sum(), 100000)

    def test_log_grid_spread_is_scatter_not_the_curves_fall(self):
        # a steeply falling curve without noise: the spread about each bin's trend in log t is only the
        # curvature left in a tenth of a decade (< 1 % of the value), at most half of std/√n
        t = np.linspace(1e-3, 10, 20000)
        y = np.exp(-t)
        tm, ym, sem, count = log_grid(t, y)
        many = count >= 3
        self.assertTrue(np.all(sem[many] < 1e-2 * np.abs(ym[many])))
        k = np.floor(np.log10(t / t[0]) * 10 + 1e-12).astype(int)
        naive = np.array([y[k == b].std(ddof=1) / np.sqrt((k == b).sum()) for b in np.unique(k)])
        self.assertTrue(np.all(sem[many] <= 0.5 * naive[many]))
        self.assertTrue(np.all(np.isnan(sem[~many])))           # no spread from fewer than 3 samples
        # white noise of σ = 0.01 on a flat curve: sem ≈ σ/√count (the residual's n − 2 degrees of freedom)
        y = 1.0 + np.random.default_rng(5).normal(scale=0.01, size=t.size)
        _, _, sem, count = log_grid(t, y)
        big = count >= 200
        ratio = sem[big] * np.sqrt(count[big]) / 0.01
        self.assertLess(abs(np.mean(ratio) - 1), 0.1)

    def test_final_rate_of_a_ramp(self):
        t = np.linspace(0, 10, 5000)
        y = 3.0 * t + np.random.default_rng(4).normal(scale=0.01, size=t.size)
        slope, se = final_rate(t, y)
        self.assertLess(abs(slope - 3.0), 4 * se)
        self.assertLess(se, 0.05)


if __name__ == "__main__":
    unittest.main()
