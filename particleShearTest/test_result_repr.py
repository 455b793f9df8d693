"""The notebook face of a run: ``repr(SimulationResult)`` and its HTML table.

The documented content (G′, G″ of both estimators with their standard errors where finite, N,
A, μ, seed, run id) is checked against the result's own attributes; the parameter dict must
not be dumped; every text in the HTML is escaped.
"""
import dataclasses
import re
import unittest

import numpy as np

from particleShear.run.api import SimulationResult
from particleShearTest.test_plot import synthetic_result


def noisy_result(P=4.0, noise=2.0, run_id="0123456789ab"):
    """An ideal viscoelastic solid plus white noise on the stresses: a finite, non-zero standard error."""
    res = synthetic_result(P=P)
    rng = np.random.default_rng(1)
    for key in ("stress_surface", "stress_internal"):
        res.series[key] = res.series[key] + rng.normal(0, noise, res.series[key].shape)
    res.parameters.update(N=40, Young_modulus_spheres=8000, relative_viscosity=0.1)
    res.seed, res.spawn_key, res.run_id = 7, (2,), run_id
    return res


def numbers_after(label, text):
    """(value, se or None) of the first ``label = value [± se]`` in ``text``."""
    m = re.search(re.escape(label) + r" = ([-+0-9.e]+)(?: ± ([-+0-9.e]+))?", text)
    return float(m.group(1)), (float(m.group(2)) if m.group(2) else None)


class TestRepr(unittest.TestCase):
    def test_short_repr_names_moduli_errors_and_run(self):
        res = noisy_result()
        text = repr(res)
        self.assertLessEqual(len(text.splitlines()), 4)
        for fragment in ("N=40", "A=0.2", "μ=0.01", "seed=7", "0123456789ab"):
            self.assertIn(fragment, text)
        surface, internal = (line for line in text.splitlines() if "G′" in line)
        self.assertIn("surface", surface)
        self.assertIn("internal", internal)
        for line, G, se in ((surface, res.G_surface, res.G_surface_se), (internal, res.G_internal, res.G_internal_se)):
            for label, k in (("G′", 0), ("G″", 1)):
                value, err = numbers_after(label, line)
                self.assertAlmostEqual(value / G[k], 1, delta=5e-4)       # 4 significant digits
                self.assertTrue(np.isfinite(se[k]) and se[k] > 0)
                self.assertAlmostEqual(err / se[k], 1, delta=0.05)        # 2 significant digits

    def test_no_parameter_dict(self):
        text = repr(noisy_result())
        self.assertNotIn("Young_modulus_spheres", text)
        self.assertNotIn("parameters", text)
        self.assertNotIn("{", text)
        self.assertLess(len(text), 400)

    def test_no_error_bar_without_periods(self):
        res = noisy_result()
        res.series = {}               # a result rebuilt without its series: standard errors are NaN
        text = repr(res)
        self.assertNotIn("±", text)
        value, err = numbers_after("G′", text)
        self.assertAlmostEqual(value / res.G_surface[0], 1, delta=5e-4)
        self.assertIsNone(err)

    def test_dataclass_behaviour_kept(self):
        a, b = synthetic_result(), synthetic_result()
        a.series = b.series = {}
        self.assertEqual(a, b)
        self.assertNotEqual(a, dataclasses.replace(b, G_surface=(1.0, 2.0)))
        self.assertEqual(dataclasses.asdict(a)["G_surface"], a.G_surface)


class TestHtmlRepr(unittest.TestCase):
    def test_table_with_both_estimators(self):
        res = noisy_result()
        h = res._repr_html_()
        self.assertTrue(h.startswith("<table>") and h.rstrip().endswith("</table>"))
        # header + surface + internal, then the verdict and one row per failed or unjudged check
        self.assertEqual(h.count("<tr>"), 3 + len(res._verdict_lines()))
        self.assertIn("verdict: ", h)
        for fragment in ("surface", "internal", "G′ (Pa)", "G″ (Pa)", "0123456789ab", "±"):
            self.assertIn(fragment, h)
        self.assertNotIn("Young_modulus_spheres", h)

    def test_text_is_escaped(self):
        res = noisy_result(run_id="<b>&x</b>")
        res.parameters["theMu"] = "<script>"
        h = res._repr_html_()
        self.assertNotIn("<b>", h)
        self.assertNotIn("<script>", h)
        self.assertIn("&lt;b&gt;&amp;x&lt;/b&gt;", h)
        self.assertIn("&lt;script&gt;", h)


if __name__ == "__main__":
    unittest.main()


class TestRheometerRepr(unittest.TestCase):
    """``repr`` of a protocol run's SimulationResult and its HTML: every summary number with its standard error and the
    unit of its results-table column, the run's identity; no records dumped; the HTML escaped."""

    @classmethod
    def setUpClass(cls):
        from particleShear import doParticleShearSimulation
        small = dict(N=30, cut_lines=0, relative_frequency=0.2, seed=2, return_result=True, verbose=False,
                     doDrawing=False, plotStress=False)
        cls.creep = doParticleShearSimulation(**small, protocol="creep", creep_stress=20.0, hold_time=5.0)
        cls.sweep = doParticleShearSimulation(**small, protocol="amplitude_sweep", sweep_amplitudes=[0.05, 0.1])

    def test_summary_numbers_units_and_identity(self):
        text = repr(self.creep)
        self.assertTrue(text.startswith("SimulationResult(protocol=creep, N=30"))
        self.assertIn(f"run_id={self.creep.run_id}", text)
        s = self.creep.summary
        m = re.search(r"creep_rate: ([-+0-9.e]+) ± ([-+0-9.e]+) 1/s", text)
        self.assertIsNotNone(m, text)
        self.assertAlmostEqual(float(m.group(1)), s["creep_rate"], delta=abs(s["creep_rate"]) * 1e-3)
        self.assertAlmostEqual(float(m.group(2)), s["creep_rate_se"], delta=abs(s["creep_rate_se"]) * 0.05)
        self.assertRegex(text, r"creep_viscosity: [-+0-9.einf]+ Pa·s")
        self.assertNotIn("array(", text)
        self.assertLess(len(text.splitlines()), 20)

    def test_sweep_has_a_line_per_step_and_estimator(self):
        text = repr(self.sweep)
        lines = [ln for ln in text.splitlines() if ln.startswith("  A = ")]
        self.assertEqual(len(lines), 4)
        g = self.sweep.steps[1]["Gp_surface"]
        value, _ = numbers_after("G′", lines[2])
        self.assertAlmostEqual(value, g, delta=abs(g) * 1e-3)

    def test_html_is_escaped(self):
        self.creep.run_id, keep = "<b>x</b>", self.creep.run_id
        try:
            html = self.creep._repr_html_()
        finally:
            self.creep.run_id = keep
        self.assertIn("&lt;b&gt;x&lt;/b&gt;", html)
        self.assertNotIn("<b>", html)
        self.assertIn("<td>1/s</td>", html)


class TestOneResultInterface(unittest.TestCase):
    """An oscillatory result answers what a protocol result answers (protocol, curves, steps, rows), so
    the sweep's tasks, the CLI and the writers never ask which type they hold."""

    def test_oscillatory_result_is_one_row_of_its_moduli(self):
        res = noisy_result()
        self.assertEqual(res.protocol, "oscillatory")
        self.assertEqual((res.curves, res.steps), ({}, []))
        rows = res.rows()
        self.assertEqual(len(rows), 1)
        # the row holds the measured moduli (the demodulated stresses of the series) and the run's f
        row = rows[0]
        self.assertEqual((row["Gp_surface"], row["Gpp_surface"]), tuple(float(g) for g in res.G_surface))
        self.assertAlmostEqual(row["omega"], 2 * np.pi * res.f, places=12)

    def test_no_module_branches_on_the_result_type(self):
        import ast
        import pathlib
        import particleShear
        names = {"G_internal", "to_dict", "steps", "rows", "curves"}
        found = []
        for path in pathlib.Path(particleShear.__file__).parent.rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if (isinstance(node, ast.Call) and getattr(node.func, "id", None) == "hasattr"
                        and len(node.args) == 2 and isinstance(node.args[1], ast.Constant)
                        and node.args[1].value in names and getattr(node.args[0], "id", "") in ("res", "result")):
                    found.append(f"{path.name}:{node.lineno}")
        self.assertEqual(found, [])
