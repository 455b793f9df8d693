"""Figures a paper can use: geometry of the drawn figures, checked on the rendered canvas.

* no text clipped: every visible text artist's window extent lies inside the figure, for sweep
  figures of 1 to 9 panels, the analysis figure and the protocol figures;
* series at the same x are drawn side by side (distinct x, constant factor, within the gap);
* flagged runs (``verdict`` "flagged: …") are marked, never hidden, with a legend entry; a table
  without the column draws as before;
* the analysis figure's point labels do not overlap, and curves of fewer than 4 amplitudes get no
  linear limits or yield;
* titles say what made the figure (N, seeds, estimator, rate, γ₀ or σ₀).
"""
import importlib.util
import os
import sys
import tempfile
import unittest
import warnings

import numpy as np

HAVE_MPL = importlib.util.find_spec("matplotlib") is not None
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # test_plot's synthetic run


def texts_outside(fig, tolerance=1.0):
    """(text, extent) of every visible, non-empty text artist whose window extent leaves the figure."""
    from matplotlib.text import Text
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    box = fig.bbox
    # tick labels are drawn only for the ticks inside the view (Axis._update_ticks) of an axes that is
    # on; the others exist, positioned, but are never drawn
    ticks, drawn = set(), set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                ticks.update((id(tick.label1), id(tick.label2)))
            for tick in (axis._update_ticks() if ax.axison and ax.get_visible() else []):   # axes off: none
                drawn.update((id(tick.label1), id(tick.label2)))
    out = []
    for t in fig.findobj(Text):
        if not t.get_visible() or not t.get_text().strip() or (id(t) in ticks and id(t) not in drawn):
            continue
        e = t.get_window_extent(renderer)
        if (e.x0 < box.x0 - tolerance or e.x1 > box.x1 + tolerance or e.y0 < box.y0 - tolerance
                or e.y1 > box.y1 + tolerance):
            out.append((t.get_text()[:60], tuple(np.round(e.extents, 1))))
    return out


def write_rows(folder, runs, verdict=True):
    """``folder/results.csv`` with the real header (plus ``verdict`` where the schema has none yet)."""
    from particleShear.sweep.spec import sweep_parameter_defaults
    from particleShear.sweep.table import row_line, table_columns
    columns = list(table_columns())
    if verdict and "verdict" not in columns:
        columns.append("verdict")
    if not verdict and "verdict" in columns:
        columns.remove("verdict")
    defaults = sweep_parameter_defaults()
    with open(os.path.join(folder, "results.csv"), "w", newline="", encoding="utf-8") as fh:
        fh.write(row_line({c: c for c in columns}, columns))
        for k, run in enumerate(runs):
            row = {**defaults, "run_id": k, "status": "ok", "spawn_key": [k], "verdict": "ok", **run}
            fh.write(row_line(row, columns))


def sweep_runs(n_panels=1, mus=(0.0, 0.01, 0.1), amplitudes=(0.01, 0.1, 1.0), seeds=3, flag=None):
    """Runs of ``n_panels`` values of N (one panel each) × μ × amplitude × seeds; ``flag(run)`` names a verdict."""
    rng = np.random.default_rng(3)
    runs = []
    for p in range(n_panels):
        for mu in mus:
            for A in amplitudes:
                for k in range(seeds):
                    gp, gpp = rng.uniform(200, 400), rng.uniform(50, 100)
                    run = dict(N=40 + p, theMu=mu, theAmplitude=A, Gp_surface=gp, Gpp_surface=gpp, Gp_internal=gp,
                               Gpp_internal=gpp, seed_index=k)
                    run["verdict"] = flag(run) if flag else "ok"
                    run.pop("seed_index")
                    runs.append(run)
    return runs


@unittest.skipUnless(HAVE_MPL, "matplotlib not installed (extra [plot])")
class TestSweepFigure(unittest.TestCase):
    def figure(self, runs, verdict=True, **kw):
        from particleShear.plot import plot_sweep
        with tempfile.TemporaryDirectory() as d, warnings.catch_warnings():
            warnings.simplefilter("ignore")
            write_rows(d, runs, verdict)
            return plot_sweep(d, path=False, n_boot=50, **kw)

    def test_no_text_leaves_the_figure_from_one_to_nine_panels(self):
        for n in range(1, 10):
            with self.subTest(panels=n):
                fig = self.figure(sweep_runs(n, mus=(0.01, 0.1), amplitudes=(0.01, 0.1), seeds=2))
                self.assertEqual(len(fig.axes) - 1, n)
                self.assertEqual(texts_outside(fig), [])

    def test_series_at_the_same_x_are_side_by_side(self):
        fig = self.figure(sweep_runs(1))
        ax = fig.axes[0]
        xs = {c.get_label(): np.asarray(c.lines[0].get_xdata(), float) for c in ax.containers}
        true = np.array([0.01, 0.1, 1.0])
        factors = {}
        for label, x in xs.items():
            ratio = x / true
            np.testing.assert_allclose(ratio, ratio[0], rtol=1e-12)       # one factor per series
            self.assertLess(abs(np.log10(ratio[0])), 0.5)                  # within half the gap (1 decade)
            factors[label] = ratio[0]
        for mu in ("0", "0.01", "0.1"):
            self.assertEqual(factors[f"G′ μ={mu}"], factors[f"G″ μ={mu}"])  # G′ and G″ of a μ together
        self.assertEqual(len({factors[f"G′ μ={mu}"] for mu in ("0", "0.01", "0.1")}), 3)   # distinct
        self.assertEqual([float(t) for t in ax.get_xticks()], list(true))  # ticks at the measured values

    def test_title_names_what_made_it(self):
        fig = self.figure(sweep_runs(1, seeds=3), estimator="internal")
        title = " ".join(fig._suptitle.get_text().split())
        for part in ("N = 40", "3 seeds per point", "internal estimator", "f·τ = 0.025"):
            self.assertIn(part, title)

    def test_flagged_points_are_marked_never_hidden(self):
        flag = (lambda r: "flagged: linear_response" if r["theAmplitude"] == 1.0 and r["theMu"] == 0.1 else "ok")
        fig = self.figure(sweep_runs(1, flag=flag))
        ax = fig.axes[0]
        rings = [ln for ln in ax.lines if ln.get_gid() == "flagged"]
        self.assertEqual(len(rings), 2)                  # G′ and G″ of μ = 0.1 at A = 1
        for ring in rings:
            self.assertEqual(ring.get_markerfacecolor(), "none")
            self.assertAlmostEqual(float(np.asarray(ring.get_xdata())[0]) / 1.0, 1.0, delta=0.3)
        # the flagged point is still drawn as a mean with its bar
        gp = next(c for c in ax.containers if c.get_label() == "G′ μ=0.1")
        self.assertTrue(np.all(np.isfinite(gp.lines[0].get_ydata())))
        labels = fig.axes[-1].get_legend().get_texts()
        self.assertTrue(any(t.get_text().startswith("flagged (see verdict)") for t in labels))
        # a table without the verdict column (older tables): drawn, no rings, no legend entry
        fig = self.figure(sweep_runs(1), verdict=False)
        self.assertEqual([ln for ln in fig.axes[0].lines if ln.get_gid() == "flagged"], [])

    def test_bars_stay_inside_the_panel(self):
        # one seed far from the others: the interval of G″ reaches below 0; its bar is cut at the
        # panel's lower edge and marked there, never drawn off the axis
        runs = sweep_runs(1, mus=(0.01,))
        for r in runs[::3]:
            r["Gpp_surface"] = 1e-3
        fig = self.figure(runs)
        ax = fig.axes[0]
        low = ax.get_ylim()[0]
        for c in ax.containers:
            for seg in c.lines[2][0].get_segments():
                self.assertGreaterEqual(min(seg[0][1], seg[1][1]), low * (1 - 1e-9))
        self.assertTrue(any(ln.get_gid() == "interval-cut" for ln in ax.lines))


@unittest.skipUnless(HAVE_MPL, "matplotlib not installed (extra [plot])")
class TestAnalysisFigure(unittest.TestCase):
    @staticmethod
    def summary(amplitudes, seeds=4):
        from particleShear.analysis.sweep import sweep_summary
        rng = np.random.default_rng(7)
        A, gp, gpp = [], [], []
        for a in amplitudes:       # a soft glassy response: plateau, softening, crossover near A = 0.3
            for _ in range(seeds):
                A.append(a)
                gp.append(300 / (1 + (a / 0.1) ** 1.5) * rng.uniform(0.95, 1.05))
                gpp.append(60 * (1 + (a / 0.1) ** 0.7) / (1 + (a / 0.5) ** 1.2) * rng.uniform(0.95, 1.05))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return sweep_summary(A, gp, gpp, n_boot=100, rng=0)

    def test_labels_do_not_overlap_and_no_text_leaves_the_figure(self):
        from particleShear.analysis.figure import plot_analysis
        amps = list(np.geomspace(0.001, 3, 14))
        for n in (1, 2, 4):
            with self.subTest(panels=n):
                fig = plot_analysis([(f"group {k}", self.summary(amps), []) for k in range(n)])
                self.assertEqual(texts_outside(fig), [])
                renderer = fig.canvas.get_renderer()
                for ax in fig.axes:
                    boxes = [t.get_window_extent(renderer) for t in ax.texts if t.get_gid() == "mark-label"]
                    self.assertGreaterEqual(len(boxes), 3 if ax.get_visible() and ax.axison else 0)
                    for i, a in enumerate(boxes):
                        for b in boxes[i + 1:]:
                            self.assertFalse(a.overlaps(b), (a, b))

    def test_short_curves_get_no_limits_or_yield(self):
        from particleShear.analysis.figure import plot_analysis
        fig = plot_analysis([("two amplitudes", self.summary([0.01, 1.0]), [])])
        texts = {t.get_text() for t in fig.axes[0].texts}
        for short in ("5 %", "10 %", "yield"):
            self.assertNotIn(short, texts)
        fig = plot_analysis([("fourteen", self.summary(list(np.geomspace(0.001, 3, 14))), [])])
        self.assertIn("flow", {t.get_text() for t in fig.axes[0].texts})

    def test_title_names_what_made_it(self):
        from particleShear.analysis.figure import plot_analysis
        fig = plot_analysis([("g", self.summary([0.01, 0.1, 1.0, 2.0], seeds=3), [])], estimator="internal",
                            made={"N": 40, "relative_frequency": 0.025})
        title = " ".join(fig._suptitle.get_text().split())
        for part in ("N = 40", "3 seeds", "internal estimator", "f·τ = 0.025"):
            self.assertIn(part, title)


@unittest.skipUnless(HAVE_MPL, "matplotlib not installed (extra [plot])")
class TestLaosBox(unittest.TestCase):
    def test_ratios_carry_their_spread_over_periods(self):
        from particleShear.plot import _with_error, plot_result
        from test_plot import synthetic_result
        self.assertEqual(_with_error(0.1234, 0.0123), "0.123 ± 0.012")
        self.assertEqual(_with_error(-0.16, 0.29), "-0.16 ± 0.29")
        self.assertEqual(_with_error(0.1234, None), "0.12 (no error: < 2 periods)")
        fig = plot_result(synthetic_result(P=5, f=2.0))
        text = fig.axes[-1].texts[0].get_text()
        for line in text.splitlines():
            if line.strip().startswith(("S =", "T =")):
                self.assertIn("±", line)            # every S and T with its error over the periods
        self.assertEqual(texts_outside(fig), [])


@unittest.skipUnless(HAVE_MPL, "matplotlib not installed (extra [plot])")
class TestProtocolFigures(unittest.TestCase):
    @staticmethod
    def sweep_result(protocol, **parameters):
        from particleShear.run.result import SimulationResult
        x = "amplitude" if protocol == "amplitude_sweep" else "relative_frequency"
        steps = [{x: v, "Gp_surface": 300.0 - 50 * k, "Gpp_surface": 60.0 + 10 * k, "Gp_surface_se": 5.0,
                  "Gpp_surface_se": 3.0} for k, v in enumerate((0.01, 0.03, 0.1))]
        return SimulationResult.of_protocol(protocol, dict(N=40, theAmplitude=0.1, relative_frequency=0.025,
                                                           **parameters), 7, (), "", None, 0.0, {}, {}, {}, steps, {})

    def test_titles_and_legends_say_what_made_them(self):
        from particleShear.rheometer_plot import plot_rheometer_result
        cases = {"amplitude_sweep": ("amplitude after amplitude", ("N = 40", "1 seed", "surface estimator",
                                                                     "f·τ = 0.025", "seed 7")),
                 "frequency_sweep": ("frequency after frequency", ("N = 40", "1 seed", "surface estimator",
                                                                     "γ₀ = 0.1"))}
        for protocol, (legend, parts) in cases.items():
            with self.subTest(protocol=protocol):
                fig = plot_rheometer_result(self.sweep_result(protocol))
                title = " ".join(fig._suptitle.get_text().split())
                for part in parts:
                    self.assertIn(part, title)
                labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
                self.assertTrue(all(legend in t for t in labels), labels)
                self.assertEqual(texts_outside(fig), [])

    def test_protocol_titles_name_rate_strain_or_stress(self):
        import types
        from particleShear.rheometer_plot import _result_title
        r = types.SimpleNamespace(protocol="creep", seed=None, parameters=dict(N=150, creep_stress=50.0))
        self.assertEqual(_result_title(r), "creep: N = 150, 1 seed, surface estimator, σ₀ = 50 Pa")
        r = types.SimpleNamespace(protocol="steady", seed=3, parameters=dict(N=150, relative_rate=0.01))
        self.assertEqual(_result_title(r), "steady shear: N = 150, 1 seed, surface estimator, γ̇·τ = 0.01 (seed 3)")
        r = types.SimpleNamespace(protocol="relaxation", seed=None, parameters=dict(N=150, theAmplitude=0.01,
                                                                                   ramp_time=1.0))
        self.assertEqual(_result_title(r), "stress relaxation: N = 150, 1 seed, surface estimator, ramp time 1 τ, "
                                           "γ₀ = 0.01")


if __name__ == "__main__":
    unittest.main()
