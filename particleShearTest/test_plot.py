"""Figures (matplotlib, extra ``[plot]``): a run's trace and Lissajous loop, a sweep's G′/G″ panels.

The sweep tests write their own ``results.csv`` with the sweep runner's header
(:func:`particleShear.sweep.table.table_columns`, rows by :func:`~particleShear.sweep.table.row_line`,
every parameter column filled with its default unless a run sets it) and check the plotted points
against means, standard errors and bootstrap properties computed here with NumPy.
"""
import importlib.util
import io
import math
import os
import sys
import tempfile
import unittest
import warnings
from unittest import mock

import numpy as np

from particleShear.analysis.periods import t_critical

HAVE_MPL = importlib.util.find_spec("matplotlib") is not None



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


def write_table(folder, runs):
    """Write ``folder/results.csv`` with the real header; ``runs`` are dicts of the columns they set
    (moduli, status, parameters); every other parameter column holds its default."""
    from particleShear.sweep.spec import sweep_parameter_defaults
    from particleShear.sweep.table import row_line, table_columns
    columns = table_columns()
    defaults = sweep_parameter_defaults()
    with open(os.path.join(folder, "results.csv"), "w", newline="", encoding="utf-8") as fh:
        fh.write(row_line({c: c for c in columns}, columns))
        for k, run in enumerate(runs):
            row = {**defaults, "run_id": k, "status": "ok", "spawn_key": [k], **run}
            fh.write(row_line(row, columns))


def moduli(rng):
    gp, gpp, gpi, gppi = rng.uniform(50, 500, 4)
    return {"Gp_surface": gp, "Gpp_surface": gpp, "Gp_internal": gpi, "Gpp_internal": gppi}


def write_sweep_csv(folder):
    """3 amplitudes × 3 seeds × 4 groups (crosslinked μ=0.01 and 0.1, uncrosslinked, bulk control),
    plus one failed row with absurd moduli that must not count.  Returns the table of expected values."""
    rng = np.random.default_rng(5)
    groups = [("crosslinked", 0.01, True, 5), ("crosslinked", 0.1, True, 5), ("uncrosslinked", 0.01, False, 0),
              ("bulk control", 0.01, True, 0)]
    expected = {}
    runs = []
    for name, mu, links, cl in groups:
        for A in (0.01, 0.1, 1.0):
            vals = []
            for _ in range(3):
                m = moduli(rng)
                vals.append((m["Gp_surface"], m["Gpp_surface"], m["Gp_internal"], m["Gpp_internal"]))
                runs.append(dict(m, theAmplitude=A, theMu=mu, do_permanent_links=links, cut_lines=cl))
            expected[(name, mu, A)] = np.array(vals)
    runs.append(dict(status="error", error="SimulationInstabilityError: diverged", Gp_surface=1e12, Gpp_surface=1e12,
                     Gp_internal=1e12, Gpp_internal=1e12, theAmplitude=0.1, theMu=0.01, do_permanent_links=True,
                     cut_lines=5))
    write_table(folder, runs)
    return expected


def panel_axes(fig):
    """The data panels of a sweep figure (the last axes holds the legend)."""
    return fig.axes[:-1]


def containers(ax):
    return {c.get_label(): c for c in ax.containers}


def bar_ends(cont):
    """(low, high) of each error bar of an errorbar container."""
    segs = cont.lines[2][0].get_segments()
    return np.array([s[0][1] for s in segs]), np.array([s[1][1] for s in segs])


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
        np.testing.assert_array_equal(lines["surface (plate forces)"].get_ydata(), res.series["stress_surface"])
        np.testing.assert_array_equal(lines["internal (stress tensor)"].get_ydata(), res.series["stress_internal"])
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
    AMPS = (0.01, 0.1, 1.0)

    def check_figure(self, fig, expected, estimator):
        axes = panel_axes(fig)
        # one panel per material, crosslinked first; μ by colour inside the crosslinked panel
        self.assertEqual([ax.get_title().split("\n")[0] for ax in axes], ["crosslinked", "uncrosslinked", "bulk control"])
        col = {"surface": (0, 1), "internal": (2, 3)}[estimator]
        for ax in axes:
            self.assertEqual(ax.get_xscale(), "log")
            self.assertEqual(ax.get_yscale(), "log")
            self.assertEqual(ax.get_xlabel(), "strain amplitude A (–)")
            self.assertIn("(Pa)", ax.get_ylabel())
            self.assertIn(estimator, ax.get_ylabel())
            self.assertIn("n = 3 seed(s) per point", ax.get_title())
        for (name, mu) in {(k[0], k[1]) for k in expected}:
            ax = axes[["crosslinked", "uncrosslinked", "bulk control"].index(name)]
            for which, c in (("G′", col[0]), ("G″", col[1])):
                cont = containers(ax)[f"{which} μ={mu:g}"]
                data_line = cont.lines[0]
                # drawn side by side with the other μ (plot.dodge_factors): one factor, well within the gap
                ratio = np.asarray(data_line.get_xdata(), float) / np.array(self.AMPS)
                np.testing.assert_allclose(ratio, ratio[0], rtol=1e-12)
                self.assertLess(abs(math.log10(ratio[0])), 0.1)
                seeds = [expected[(name, mu, A)][:, c] for A in self.AMPS]
                np.testing.assert_allclose(data_line.get_ydata(), [v.mean() for v in seeds], rtol=1e-12)
                # a bootstrap mean of resampled seeds lies between the smallest and largest seed; the
                # Student widening moves its log from the log of the mean by at most √(3/2)·t₂/z times, so the
                # interval lies in mean·(extreme/mean)^that factor, is positive, and holds the mean
                low, high = bar_ends(cont)
                cut = low <= ax.get_ylim()[0] * (1 + 1e-12)    # an end below the panel's edge, drawn cut there
                mean = np.array([v.mean() for v in seeds])
                self.assertTrue(all((v > 0).all() for v in seeds))
                widen = math.sqrt(1.5) * t_critical(2, 0.05) / 1.959963984540054
                lo_bound = mean * (np.array([v.min() for v in seeds]) / mean) ** widen
                hi_bound = mean * (np.array([v.max() for v in seeds]) / mean) ** widen
                self.assertTrue(np.all(cut | (low >= lo_bound * (1 - 1e-12))))
                self.assertTrue(np.all(high <= hi_bound * (1 + 1e-12)))
                self.assertTrue(np.all(low > 0))
                self.assertTrue(np.all((low <= data_line.get_ydata()) & (data_line.get_ydata() <= high)))
        legend = fig.axes[-1].get_legend()
        self.assertIn("95 % bootstrap interval", legend.get_title().get_text())
        self.assertEqual(len(fig.axes[-1].lines) + len(fig.axes[-1].containers), 0)   # the legend axes holds no data

    def test_groups_means_and_files(self):
        from particleShear.plot import plot_sweep
        with tempfile.TemporaryDirectory() as d:
            expected = write_sweep_csv(d)
            fig = plot_sweep(d, n_boot=400)
            for name in ("G_vs_amplitude.png", "G_vs_amplitude.pdf"):
                self.assertGreater(os.path.getsize(os.path.join(d, name)), 1000)
            self.check_figure(fig, expected, "surface")
            fig = plot_sweep(os.path.join(d, "results.csv"), estimator="internal", path=False, n_boot=400)
            self.check_figure(fig, expected, "internal")

    def test_bootstrap_interval_of_three_seeds_is_their_range(self):
        # resampling 3 seeds, the mean of a resample is the smallest seed with probability 1/27 = 3.7 %
        # > 2.5 %: with 20000 resamples (741 ± 27 such draws, 500 needed) both 95 % ends are the seeds'
        # minimum and maximum exactly (before the Student widening).  The plotted interval is sweep_summary's.
        from particleShear.analysis.sweep import sweep_summary
        from particleShear.plot import plot_sweep
        rng = np.random.default_rng(11)
        runs, A, gp, gpp = [], [], [], []
        for amp in (0.05, 0.2):
            for _ in range(3):
                m = moduli(rng)
                runs.append(dict(m, theAmplitude=amp))
                A.append(amp)
                gp.append(m["Gp_surface"])
                gpp.append(m["Gpp_surface"])
        with tempfile.TemporaryDirectory() as d:
            write_table(d, runs)
            fig = plot_sweep(d, path=False, n_boot=20000, bootstrap_seed=3)
        conts = containers(panel_axes(fig)[0])
        ref = sweep_summary(A, gp, gpp, n_boot=20000, rng=3)
        for label, values, ci in (("G′ μ=0.01", gp, ref.Gp_ci), ("G″ μ=0.01", gpp, ref.Gpp_ci)):
            v = np.array(values).reshape(2, 3)
            low, high = bar_ends(conts[label])
            # the percentile ends are the seeds' extremes, widened from the mean by √(3/2)·t₂/z (Student width) on
            # the log scale: mean·(extreme/mean)^w, positive however far the widening reaches
            mean = v.mean(axis=1)
            self.assertTrue((v > 0).all())
            widen = math.sqrt(1.5) * t_critical(2, 0.05) / 1.959963984540054
            np.testing.assert_allclose(low, mean * (v.min(axis=1) / mean) ** widen, rtol=1e-12)
            np.testing.assert_allclose(high, mean * (v.max(axis=1) / mean) ** widen, rtol=1e-12)
            self.assertTrue((low > 0).all())
            np.testing.assert_allclose(np.c_[low, high], ci, rtol=1e-12)

    def frequency_runs(self, amplitudes=(0.1,), seeds=3, extra=None):
        rng = np.random.default_rng(2)
        runs, expected = [], {}
        for amp in amplitudes:
            for f in (0.02, 0.05, 0.1):
                vals = [moduli(rng) for _ in range(seeds)]
                runs += [dict(m, theAmplitude=amp, relative_frequency=f, **(extra or {})) for m in vals]
                expected[(amp, f)] = np.array([m["Gp_surface"] for m in vals])
        return runs, expected

    def test_frequency_sweep_plots_frequency_and_does_not_pool(self):
        from particleShear.plot import plot_sweep
        runs, expected = self.frequency_runs()
        with tempfile.TemporaryDirectory() as d:
            write_table(d, runs)
            with warnings.catch_warnings():
                warnings.simplefilter("error")          # 3 seeds, positive means: nothing to warn about
                fig = plot_sweep(d)
            self.assertTrue(os.path.isfile(os.path.join(d, "G_vs_frequency.png")))
            self.assertFalse(os.path.exists(os.path.join(d, "G_vs_amplitude.png")))
        ax, = panel_axes(fig)
        self.assertEqual(ax.get_xlabel(), "relative frequency f·τ (–)")
        cont = containers(ax)["G′ μ=0.01"]
        np.testing.assert_allclose(cont.lines[0].get_xdata(), [0.02, 0.05, 0.1])
        means = np.array([expected[(0.1, f)].mean() for f in (0.02, 0.05, 0.1)])
        se = np.array([expected[(0.1, f)].std(ddof=1) / math.sqrt(3) for f in (0.02, 0.05, 0.1)])
        np.testing.assert_allclose(cont.lines[0].get_ydata(), means, rtol=1e-12)
        low, high = bar_ends(cont)
        # mean ± se in float64: the ends carry rounding of ~ε·mean, far below 1e-9·se
        np.testing.assert_allclose(low, means - se, rtol=1e-9)
        np.testing.assert_allclose(high, means + se, rtol=1e-9)
        self.assertIn("standard error", fig.axes[-1].get_legend().get_title().get_text())

    def test_amplitude_axis_on_a_frequency_sweep_splits_by_frequency(self):
        from particleShear.plot import plot_sweep
        runs, expected = self.frequency_runs()
        with tempfile.TemporaryDirectory() as d:
            write_table(d, runs)
            fig = plot_sweep(d, path=False, x="amplitude")
        axes = panel_axes(fig)
        self.assertEqual([ax.get_title().split("\n")[0] for ax in axes],
                         [f"crosslinked, relative_frequency = {f:g}" for f in (0.02, 0.05, 0.1)])
        for ax, f in zip(axes, (0.02, 0.05, 0.1)):
            ydata = containers(ax)["G′ μ=0.01"].lines[0].get_ydata()
            np.testing.assert_allclose(ydata, [expected[(0.1, f)].mean()], rtol=1e-12)
        # one amplitude per curve: no bootstrap summary, standard errors, and the legend says why
        title = fig.axes[-1].get_legend().get_title().get_text()
        self.assertIn("standard error", title)
        self.assertIn(">= 2 amplitudes", title)

    def test_third_varying_parameter_splits_panels_or_is_refused_by_name(self):
        from particleShear.plot import plot_sweep
        from particleShear.run.cli import main
        runs = []
        for n in (30, 60):
            r, _ = self.frequency_runs(amplitudes=(0.05, 0.2), extra={"N": n})
            runs += r
        with tempfile.TemporaryDirectory() as d:
            write_table(d, runs)
            # amplitude and frequency both vary: the amplitude is the x-axis, frequency and N split panels
            fig = plot_sweep(d, path=False, n_boot=200)
            titles = [ax.get_title().split("\n")[0] for ax in panel_axes(fig)]
            self.assertEqual(len(titles), 6)
            self.assertIn("crosslinked, N = 30, relative_frequency = 0.02", titles)
            self.assertIn("crosslinked, N = 60, relative_frequency = 0.1", titles)
            self.assertIn("N, relative_frequency", fig.get_suptitle())
            with self.assertRaisesRegex(ValueError, r"\['N', 'relative_frequency'\] vary"):
                plot_sweep(d, path=False, split=False)
            with self.assertRaisesRegex(ValueError, r"6 panels .*'N', 'relative_frequency'.*max_panels=4"):
                plot_sweep(d, path=False, max_panels=4)
            err = io.StringIO()
            with mock.patch("sys.stderr", err):
                self.assertEqual(main(["plot", d, "--x", "frequency", "--no-split"]), 2)
            self.assertIn("['theAmplitude', 'N']", err.getvalue())

    def test_nonpositive_means_are_marked_and_reported(self):
        from particleShear.plot import plot_sweep
        rng = np.random.default_rng(4)
        runs = []
        for amp in (0.05, 0.2, 0.8):
            for gp in ((-40.0, -20.0, 5.0) if amp == 0.8 else rng.uniform(50, 500, 3)):
                runs.append(dict(moduli(rng), Gp_surface=gp, theAmplitude=amp, do_permanent_links=False))
        with tempfile.TemporaryDirectory() as d:
            write_table(d, runs)
            with self.assertWarnsRegex(UserWarning, r"<= 0 .*uncrosslinked μ=0.01: G′ = -18.3 Pa at A = 0.8"):
                fig = plot_sweep(d, path=False, n_boot=200)
        ax, = panel_axes(fig)
        ydata = containers(ax)["G′ μ=0.01"].lines[0].get_ydata()
        self.assertTrue(np.isnan(ydata[2]) and np.all(ydata[:2] > 0))   # not drawn on the log axis ...
        marks = [ln for ln in ax.lines if ln.get_gid() == "nonpositive"]
        self.assertEqual(len(marks), 1)                                   # ... but marked there
        np.testing.assert_allclose(marks[0].get_xdata(), [0.8])
        np.testing.assert_allclose(marks[0].get_ydata(), [0.0])          # axes fraction 0: the lower edge
        note = [t for t in fig.axes[-1].texts if t.get_gid() == "note"]
        self.assertIn("G′ = -18.3 Pa at A = 0.8", note[0].get_text())

    def test_fewer_than_three_seeds_warns(self):
        from particleShear.plot import plot_sweep
        runs, _ = self.frequency_runs(seeds=2)
        with tempfile.TemporaryDirectory() as d:
            write_table(d, runs)
            with self.assertWarnsRegex(UserWarning, "fewer than 3 seeds at 3 of 3 point"):
                fig = plot_sweep(d, path=False)
        self.assertIn("n = 2 seed(s) per point", panel_axes(fig)[0].get_title())

    def test_seed_counts_that_differ_are_written_beside_the_points(self):
        from particleShear.plot import plot_sweep
        runs, _ = self.frequency_runs(seeds=3)
        with tempfile.TemporaryDirectory() as d:
            write_table(d, runs[:-1])                     # the last frequency has 2 seeds
            with self.assertWarnsRegex(UserWarning, "fewer than 3 seeds at 1 of 3"):
                fig = plot_sweep(d, path=False)
        ax, = panel_axes(fig)
        self.assertIn("n = 2–3 seeds per point", ax.get_title())
        self.assertEqual(sorted(t.get_text() for t in ax.texts), ["n=2", "n=3", "n=3"])

    def test_cli_plot_subcommand(self):
        from particleShear.run.cli import main
        with tempfile.TemporaryDirectory() as d:
            write_sweep_csv(d)
            with mock.patch("sys.stdout"):
                self.assertEqual(main(["plot", d, "--estimator", "internal"]), 0)
            self.assertTrue(os.path.isfile(os.path.join(d, "G_vs_amplitude.pdf")))
            err = io.StringIO()
            with mock.patch("sys.stderr", err):
                self.assertEqual(main(["plot", os.path.join(d, "nothing_here")]), 2)
                self.assertEqual(main(["plot", d, "--x", "amplitud"]), 2)
                with self.assertRaises(SystemExit):
                    main(["plot", d, "--estimator", "bogus"])
            # the names the user typed (DIR, --x), never plot_sweep's (folder_or_csv, x)
            lines = err.getvalue().splitlines()
            self.assertTrue(lines[0].startswith("particleShear plot: DIR '"), lines[0])
            self.assertTrue(lines[1].startswith("particleShear plot: DIR '"), lines[1])
            self.assertIn(": --x='amplitud' is invalid", lines[1])
            self.assertNotIn("folder_or_csv", err.getvalue())
        runs, _ = self.frequency_runs(seeds=2)
        with tempfile.TemporaryDirectory() as d:
            write_table(d, runs)
            out, err = io.StringIO(), io.StringIO()
            with mock.patch("sys.stdout", out), mock.patch("sys.stderr", err):
                self.assertEqual(main(["plot", d]), 0)
            self.assertIn("G_vs_frequency.png", out.getvalue())
            self.assertTrue(os.path.isfile(os.path.join(d, "G_vs_frequency.pdf")))
            self.assertIn("warning: plot_sweep: fewer than 3 seeds", err.getvalue())

    def test_bad_estimator_and_x_are_named(self):
        from particleShear.plot import plot_sweep
        with self.assertRaisesRegex(ValueError, "estimator='tensor'"):
            plot_sweep(".", estimator="tensor")
        with tempfile.TemporaryDirectory() as d:
            write_sweep_csv(d)
            for bad in ("amplitud", "do_permanent_links", "integrator"):
                with self.assertRaisesRegex(ValueError, f"x='{bad}' is invalid: .*allowed 'theAmplitude'"):
                    plot_sweep(d, path=False, x=bad)
            with self.assertRaisesRegex(ValueError, "n_boot=0 is out of range"):
                plot_sweep(d, path=False, n_boot=0)


if __name__ == "__main__":
    unittest.main()
