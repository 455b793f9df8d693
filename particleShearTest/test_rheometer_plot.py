"""Rheometer figures: log axes, plotted points equal the positive inputs, fit curve, dropped note, PNG."""
import importlib.util
import os
import tempfile
import unittest

import numpy as np

HAVE_MPL = importlib.util.find_spec("matplotlib") is not None


class HB:
    sigma_y, K, n = 2.0, 3.0, 0.5

    def stress(self, rate):
        return self.sigma_y + self.K * np.asarray(rate) ** self.n


@unittest.skipUnless(HAVE_MPL, "needs matplotlib")
class FlowCurve(unittest.TestCase):
    def test_points_fit_note_png(self):
        from particleShear.rheometer_plot import plot_flow_curve
        rate = np.array([-1.0, 0.1, 1.0, 10.0])
        stress = HB().stress(np.abs(rate))
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "f.png")
            fig = plot_flow_curve(rate, stress, 0.1 * stress, fit=HB(), path=p)
            self.assertGreater(os.path.getsize(p), 0)
        ax_s, ax_e = fig.axes[:2]
        for ax in (ax_s, ax_e):
            self.assertEqual((ax.get_xscale(), ax.get_yscale()), ("log", "log"))
        x, y = ax_s.lines[0].get_data()
        np.testing.assert_array_equal(x, rate[1:])
        np.testing.assert_array_equal(y, stress[1:])
        np.testing.assert_array_equal(ax_e.lines[0].get_ydata(), stress[1:] / rate[1:])
        fit = [ln for ln in ax_s.lines if ln.get_gid() == "fit"][0]
        np.testing.assert_allclose(fit.get_ydata(), HB().stress(fit.get_xdata()), rtol=1e-15)
        self.assertTrue(any("1 non-positive" in t.get_text() for t in ax_s.texts))

    def test_bad_input_before_drawing(self):
        from particleShear.rheometer_plot import plot_flow_curve
        with self.assertRaisesRegex(ValueError, "stress"):
            plot_flow_curve([1.0, 2.0], [1.0])
        with self.assertRaisesRegex(ValueError, "path"):
            plot_flow_curve([1.0], [1.0], path="x.txt")


@unittest.skipUnless(HAVE_MPL, "needs matplotlib")
class Others(unittest.TestCase):
    def test_creep_relaxation_sweeps(self):
        from particleShear.rheometer_plot import plot_amplitude_sweeps, plot_creep, plot_relaxation
        t = np.array([0.0, 1.0, 2.0])
        ax = plot_creep(t, [1.0, 2.0, 3.0]).axes[0]
        np.testing.assert_array_equal(ax.lines[0].get_xdata(), [1.0, 2.0])
        self.assertTrue(any("1 non-positive" in x.get_text() for x in ax.texts))
        ax = plot_relaxation(t, [3.0, -1.0, 2.0], plateau=(1.0, 0.1)).axes[0]
        self.assertEqual((ax.get_xscale(), ax.get_yscale()), ("log", "linear"))
        ax = plot_amplitude_sweeps({"amplitude": [0.1, 1.0], "Gp": [5.0, 4.0], "Gpp": [1.0, 2.0]}).axes[0]
        self.assertEqual((ax.get_xscale(), ax.get_yscale()), ("log", "log"))
        np.testing.assert_array_equal(ax.lines[0].get_ydata(), [5.0, 4.0])
        with self.assertRaisesRegex(ValueError, "Gpp"):
            plot_amplitude_sweeps({"amplitude": [0.1, 1.0], "Gp": [5.0, 4.0], "Gpp": [1.0]})
