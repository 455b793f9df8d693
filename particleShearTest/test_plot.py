"""Figures (matplotlib, extra ``[plot]``): a run's trace and Lissajous loop, a sweep's G′/G″ vs amplitude.

The sweep test writes its own ``results.csv`` following the column contract of the sweep
runner (run_id, status, error, Gp_surface, Gpp_surface, Gp_internal, Gpp_internal, parameters)
and checks the plotted points against means and standard errors computed here with NumPy.
"""
import csv
import importlib.util
import math
import os
import sys
import tempfile
import unittest
from unittest import mock

import numpy as np

HAVE_MPL = importlib.util.find_spec("matplotlib") is not None

COLUMNS = ["run_id", "status", "error", "Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal",
           "theAmplitude", "theMu", "do_permanent_links", "cut_lines", "seed"]


def synthetic_result(G1=300.0, G2=60.0, A=0.2, f=2.0, pre=1.0, P=2.0, post=1.0):
    """A SimulationResult of an ideal linear viscoelastic solid: τ = G′γ + (G″/ω)γ̇ during the excitation."""
    from particleShear.run.api import SimulationResult
    t = np.linspace(0, (pre + P + post) / f, 801)
    on = (t >= pre / f) & (t <= (pre + P) / f)
    phase = 2 * np.pi * (f * t - pre)
    strain = np.where(on, A * np.sin(phase), 0.0)
    tau = np.where(on, A * (G1 * np.sin(phase) + G2 * np.cos(phase)), 0.0)
    series = {"t": t, "strain": strain, "strain_rate": np.zeros_like(t), "stress_surface": tau,
              "stress_internal": 1.1 * tau}
    return SimulationResult(G_surface=(G1, G2), G_internal=(1.1 * G1, 1.1 * G2), stress_surface=(A * G1, A * G2),
                            stress_internal=(1.1 * A * G1, 1.1 * A * G2),
                            parameters={"theAmplitude": A, "theMu": 0.01, "pre_periods": pre, "periods": P,
                                        "post_periods": post}, f=f, series=series)


def write_sweep_csv(folder):
    """3 amplitudes × 3 seeds × 4 groups (crosslinked μ=0.01 and 0.1, uncrosslinked, bulk control),
    plus one failed row with absurd moduli that must not count.  Returns the table of expected values."""
    rng = np.random.default_rng(5)
    groups = [("crosslinked", 0.01, True, 5), ("crosslinked", 0.1, True, 5), ("uncrosslinked", 0.01, False, 0),
              ("bulk control", 0.01, True, 0)]
    expected = {}
    rows = []
    k = 0
    for name, mu, links, cl in groups:
        for A in (0.01, 0.1, 1.0):
            vals = []
            for seed in range(3):
                gp, gpp, gpi, gppi = rng.uniform(50, 500, 4)
                vals.append((gp, gpp, gpi, gppi))
                rows.append([k, "ok", "", gp, gpp, gpi, gppi, A, mu, links, cl, seed])
                k += 1
            expected[(name, mu, A)] = np.array(vals)
    rows.append([k, "error", "SimulationInstabilityError: diverged", 1e12, 1e12, 1e12, 1e12, 0.1, 0.01, True, 5, 9])
    with open(os.path.join(folder, "results.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        w.writerows(rows)
    return expected


@unittest.skipUnless(HAVE_MPL, "matplotlib not installed (extra [plot])")
class TestResultPlot(unittest.TestCase):
    def test_trace_and_lissajous_with_labels_and_files(self):
        res = synthetic_result()
        with tempfile.TemporaryDirectory() as d:
            for ext, magic in ((".png", b"\x89PNG"), (".pdf", b"%PDF"), (".svg", b"<?xml")):
                path = os.path.join(d, "run" + ext)
                fig = res.plot(path)
                with open(path, "rb") as fh:
                    self.assertEqual(fh.read(len(magic)), magic)
        trace, strain_axis, loop = fig.axes[0], fig.axes[2], fig.axes[1]
        self.assertEqual(trace.get_xlabel(), "time t·f (periods)")
        self.assertEqual(trace.get_ylabel(), "shear stress τ (Pa)")
        self.assertIn("strain", strain_axis.get_ylabel())
        self.assertEqual(loop.get_xlabel(), "strain γ (–)")
        self.assertEqual(loop.get_ylabel(), "shear stress τ (Pa)")
        lines = {ln.get_label(): ln for ln in trace.get_lines() + strain_axis.get_lines()}
        np.testing.assert_array_equal(lines["τ surface (plate forces)"].get_ydata(), res.series["stress_surface"])
        np.testing.assert_array_equal(lines["τ internal (stress tensor)"].get_ydata(), res.series["stress_internal"])
        np.testing.assert_array_equal(lines["strain γ"].get_ydata(), res.series["strain"])
        # time in periods: x = t·f
        np.testing.assert_allclose(lines["strain γ"].get_xdata(), res.series["t"] * res.f, rtol=1e-12)
        # excitation window marked at t·f = pre and pre + P (periods)
        marks = sorted(ln.get_xdata()[0] for ln in trace.get_lines() if ln.get_linestyle() == ":")
        self.assertEqual(marks, [1.0, 3.0])
        self.assertEqual(len(fig.axes), 6)   # trace, loop, strain twin, elastic LB, viscous LB, text

    def test_stress_and_strain_zeros_at_the_same_height(self):
        # an offset stress (a residual stress of +40 % of its amplitude) makes the autoscaled zeros differ
        for offset in (0.0, 0.4, -0.9):
            res = synthetic_result()
            for key in ("stress_surface", "stress_internal"):
                res.series[key] = res.series[key] + offset * 60.0
            fig = res.plot()
            fig.canvas.draw()                # limits as drawn
            trace, strain_axis = fig.axes[0], fig.axes[2]
            zeros = []
            for a in (trace, strain_axis):
                lo, hi = a.get_ylim()
                self.assertLess(lo, 0)
                self.assertGreater(hi, 0)
                zeros.append(-lo / (hi - lo))
            self.assertAlmostEqual(zeros[0], zeros[1], delta=1e-9)
            # every sample stays inside the (widened, never narrowed) limits
            for a in (trace, strain_axis):
                lo, hi = a.get_ylim()
                for ln in a.get_lines():
                    y = np.asarray(ln.get_ydata(), dtype=float)
                    if len(y) > 2:
                        self.assertTrue(np.all((y >= lo) & (y <= hi)))

    def test_lissajous_loop_encloses_pi_Gpp_A2(self):
        # the loop τ(γ) of a linear viscoelastic solid encloses π·G″·A² per period (definition of G″)
        res = synthetic_result(G1=300.0, G2=60.0, A=0.2, P=1.0)
        loop = res.plot().axes[1]
        ln = loop.get_lines()[0]
        x, y = np.asarray(ln.get_xdata()), np.asarray(ln.get_ydata())
        area = 0.5 * abs(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
        self.assertAlmostEqual(area / (math.pi * 60.0 * 0.2 ** 2), 1.0, delta=2e-3)  # 400 points per period

    def test_headless_run_saves_the_stress_window_as_png(self):
        from particleShear import doParticleShearSimulation
        with tempfile.TemporaryDirectory() as d, mock.patch.dict(os.environ, {"DISPLAY": "", "WAYLAND_DISPLAY": ""}):
            res = doParticleShearSimulation(d, N=12, cut_lines=2, pre_periods=0.25, periods=0.5, post_periods=0.25,
                                            saveData=True, saveStressTensorData=False, seed=2, verbose=False,
                                            return_result=True)
            with open(res.output_path + "_stress.png", "rb") as fh:
                self.assertEqual(fh.read(4), b"\x89PNG")

    def test_missing_matplotlib_names_the_extra(self):
        from particleShear.plot import plot_result
        with mock.patch.dict(sys.modules, {"matplotlib.figure": None}):
            with self.assertRaisesRegex(ImportError, r'pip install "particleShear\[plot\]"'):
                plot_result(synthetic_result())


@unittest.skipUnless(HAVE_MPL, "matplotlib not installed (extra [plot])")
class TestSweepPlot(unittest.TestCase):
    def check_figure(self, fig, expected, estimator):
        ax = fig.axes[0]
        self.assertEqual(ax.get_xscale(), "log")
        self.assertEqual(ax.get_yscale(), "log")
        self.assertEqual(ax.get_xlabel(), "strain amplitude A (–)")
        self.assertIn("(Pa)", ax.get_ylabel())
        self.assertIn(estimator, ax.get_ylabel())
        by_label = {c.get_label(): c for c in ax.containers}
        gp_lines = [lab for lab in by_label if lab.startswith("G′ ")]
        gpp_lines = [lab for lab in by_label if lab.startswith("G″ ")]
        self.assertEqual(len(gp_lines), 4)   # one line per group and μ
        self.assertEqual(len(gpp_lines), 4)
        col = {"surface": (0, 1), "internal": (2, 3)}[estimator]
        for (name, mu) in {(k[0], k[1]) for k in expected}:
            for which, c in (("G′", col[0]), ("G″", col[1])):
                cont = by_label[f"{which} {name}, μ={mu:g}"]
                data_line = cont.lines[0]
                np.testing.assert_allclose(data_line.get_xdata(), [0.01, 0.1, 1.0])
                means = [expected[(name, mu, A)][:, c].mean() for A in (0.01, 0.1, 1.0)]
                np.testing.assert_allclose(data_line.get_ydata(), means, rtol=1e-12)
                # error bar = standard error s/√n (ddof = 1), drawn from mean − se to mean + se
                se = [expected[(name, mu, A)][:, c].std(ddof=1) / math.sqrt(3) for A in (0.01, 0.1, 1.0)]
                segs = cont.lines[2][0].get_segments()
                # the bar's end points are mean ± se in float64; their difference loses ~ε·mean/se ≲ 1e-14
                np.testing.assert_allclose([s[1][1] - s[0][1] for s in segs], 2 * np.array(se), rtol=1e-9)

    def test_groups_means_and_files(self):
        from particleShear.plot import plot_sweep
        with tempfile.TemporaryDirectory() as d:
            expected = write_sweep_csv(d)
            fig = plot_sweep(d)
            for name in ("G_vs_amplitude.png", "G_vs_amplitude.pdf"):
                self.assertGreater(os.path.getsize(os.path.join(d, name)), 1000)
            self.check_figure(fig, expected, "surface")
            fig = plot_sweep(os.path.join(d, "results.csv"), estimator="internal", path=False)
            self.check_figure(fig, expected, "internal")

    def test_cli_plot_subcommand(self):
        from particleShear.run.cli import main
        with tempfile.TemporaryDirectory() as d:
            write_sweep_csv(d)
            with mock.patch("sys.stdout"):
                self.assertEqual(main(["plot", d, "--estimator", "internal"]), 0)
            self.assertTrue(os.path.isfile(os.path.join(d, "G_vs_amplitude.pdf")))
            with mock.patch("sys.stderr"):
                self.assertEqual(main(["plot", os.path.join(d, "nothing_here")]), 2)
                with self.assertRaises(SystemExit):
                    main(["plot", d, "--estimator", "bogus"])

    def test_bad_estimator_is_named(self):
        from particleShear.plot import plot_sweep
        with self.assertRaisesRegex(ValueError, "estimator='tensor'"):
            plot_sweep(".", estimator="tensor")


if __name__ == "__main__":
    unittest.main()
