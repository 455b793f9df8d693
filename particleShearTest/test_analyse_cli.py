"""``python -m particleShear analyse DIR`` (particleShear.analysis.cli) on synthetic and real sweep folders.

The synthetic folder holds a ``results.csv`` with the real header (``table_columns()``, ``row_line``):
two friction coefficients theMu × 5 amplitudes × 3 seeds of the model G′ = G₀/(1+x²),
G″ = rG₀x/(1+x²), x = A/A_c, with A_c differing between the groups and identical seeds, so every
interval collapses to its point and the flow point is exactly A_c/r (log G′ − log G″ is linear in
log A), plus rows that must not count (status failed, ok with a non-finite modulus).
"""
import contextlib
import csv
import importlib.util
import io
import json
import math
import os
import tempfile
import unittest

from particleShear.analysis.sweep import CHARACTERISTICS
from particleShear.run.cli import main
from particleShear.sweep.spec import sweep_parameter_defaults
from particleShear.sweep.table import row_line, table_columns

HAVE_MPL = importlib.util.find_spec("matplotlib") is not None
G0, R = 1000.0, 0.5
GROUPS = {0.01: 0.05, 0.1: 0.2}          # theMu → A_c
AMPLITUDES = (0.01, 0.03, 0.1, 0.3, 1.0)


def model(A, ac):
    x = A / ac
    return G0 / (1 + x * x), R * G0 * x / (1 + x * x)


def write_results(folder, groups=GROUPS, amplitudes=AMPLITUDES, seeds=3, extra=True):
    cols = table_columns()
    base = dict(sweep_parameter_defaults())
    with open(os.path.join(folder, "results.csv"), "w", newline="", encoding="utf-8") as fh:
        fh.write(row_line({c: c for c in cols}, cols))
        k = 0
        for mu, ac in groups.items():
            for A in amplitudes:
                for _ in range(seeds):
                    gp, gpp = model(A, ac)
                    fh.write(row_line(dict(base, theAmplitude=A, theMu=mu, run_id=f"r{k:04d}", status="ok",
                                           error="", Gp_surface=gp, Gpp_surface=gpp, Gp_internal=2 * gp,
                                           Gpp_internal=2 * gpp, seed_entropy=7, spawn_key=[k]), cols))
                    k += 1
        if extra:
            fh.write(row_line(dict(base, theAmplitude=0.1, theMu=0.01, run_id="failed", status="failed",
                                   error="boom"), cols))
            fh.write(row_line(dict(base, theAmplitude=0.1, theMu=0.01, run_id="nan", status="ok", error="",
                                   Gp_surface=math.nan, Gpp_surface=1.0, Gp_internal=1.0, Gpp_internal=1.0), cols))


def run(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, out.getvalue(), err.getvalue()


def read_analysis(folder):
    with open(os.path.join(folder, "analysis.csv"), newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


class Synthetic(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.dir = cls.tmp.name
        write_results(cls.dir)
        cls.rc, cls.out, cls.err = run(["analyse", cls.dir, "--seed", "3", "--n-boot", "200"])

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_exit_status_and_messages(self):
        self.assertEqual(self.rc, 0, self.err)
        self.assertIn("left out 1 row(s) with status ok", self.err)   # the NaN row is said, not dropped silently
        self.assertIn("theMu=0.01", self.out)
        self.assertIn("wrote " + os.path.join(self.dir, "analysis.csv"), self.out)

    def test_one_row_per_group_with_every_characteristic(self):
        rows = read_analysis(self.dir)
        self.assertEqual([r["theMu"] for r in rows], ["0.01", "0.1"])
        self.assertEqual([r["group"] for r in rows], ["theMu=0.01", "theMu=0.1"])
        for r in rows:
            self.assertEqual(int(r["n_runs"]), len(AMPLITUDES) * 3)      # failed and NaN rows do not count
            self.assertEqual(int(r["n_amplitudes"]), len(AMPLITUDES))
            self.assertEqual(r["estimator"], "surface")
            for name in CHARACTERISTICS:
                for suffix in ("", "_ci_low", "_ci_high", "_defined"):
                    self.assertIn(name + suffix, r)
        header = list(rows[0])
        self.assertNotIn("theAmplitude", header)
        self.assertNotIn("cut_lines", header)                # the same in every group: not a column

    def test_values_are_the_model_truths(self):
        for r in read_analysis(self.dir):
            ac = GROUPS[float(r["theMu"])]
            self.assertAlmostEqual(float(r["flow_point"]) / (ac / R), 1, delta=1e-12)
            self.assertAlmostEqual(float(r["plateau"]), model(AMPLITUDES[0], ac)[0], delta=1e-9)
            for name in ("plateau", "flow_point"):              # identical seeds: intervals collapse
                self.assertAlmostEqual(float(r[name + "_ci_low"]), float(r[name]), delta=1e-9 * float(r[name]))
                self.assertAlmostEqual(float(r[name + "_ci_high"]), float(r[name]), delta=1e-9 * float(r[name]))
                self.assertEqual(float(r[name + "_defined"]), 1.0)

    def test_schema_describes_every_column(self):
        with open(os.path.join(self.dir, "analysis.schema.json"), encoding="utf-8") as fh:
            schema = json.load(fh)
        header = list(read_analysis(self.dir)[0])
        self.assertEqual(list(schema["columns"]), header)
        for col, spec in schema["columns"].items():
            self.assertIn(spec["type"], ("str", "int", "float"), col)
            self.assertIn("unit", spec)
            self.assertTrue(spec["description"], col)
        self.assertEqual(schema["columns"]["plateau"]["unit"], "Pa")
        self.assertEqual(schema["columns"]["flow_point"]["unit"], "1")

    @unittest.skipUnless(HAVE_MPL, "matplotlib not installed (extra [plot])")
    def test_figure_files(self):
        for ext in (".png", ".pdf"):
            path = os.path.join(self.dir, "analysis" + ext)
            self.assertTrue(os.path.isfile(path) and os.path.getsize(path) > 1000, path)
        with open(os.path.join(self.dir, "analysis.png"), "rb") as fh:
            self.assertEqual(fh.read(8), b"\x89PNG\r\n\x1a\n")

    def test_json_and_estimator_and_reproducible(self):
        with tempfile.TemporaryDirectory() as d:                 # own folder: analysis.csv is rewritten
            write_results(d)
            rc, out, err = run(["analyse", d, "--json", "--estimator", "internal", "--seed", "3", "--n-boot", "50"])
            self.assertEqual(rc, 0, err)
            rows = json.loads(out)                                # stdout is the JSON and nothing else
            self.assertEqual(len(rows), 2)
            self.assertEqual(rows[0]["estimator"], "internal")
            self.assertEqual(rows[0]["n_runs"], len(AMPLITUDES) * 3 + 1)   # the row with a NaN surface G′ counts
            self.assertEqual(list(rows[0]), list(read_analysis(d)[0]))
            again = json.loads(run(["analyze", d, "--json", "--estimator", "internal", "--seed", "3",
                                    "--n-boot", "50"])[1])
            self.assertEqual(rows, again)

    def test_non_positive_means_are_said(self):
        with tempfile.TemporaryDirectory() as d:
            cols = table_columns()
            base = dict(sweep_parameter_defaults())
            with open(os.path.join(d, "results.csv"), "w", newline="", encoding="utf-8") as fh:
                fh.write(row_line({c: c for c in cols}, cols))
                fh.writelines(row_line(dict(base, theAmplitude=A, run_id=f"r{k}", status="ok", Gp_surface=gp,
                                           Gpp_surface=gpp, Gp_internal=gp, Gpp_internal=gpp), cols) for k, (A, gp, gpp) in enumerate([(0.01, 100.0, 10.0), (0.03, 90.0, 20.0), (0.1, 60.0, 30.0), (1.0, -5.0, 40.0)] * 2))
            rc, out, err = run(["analyse", d, "--seed", "0", "--n-boot", "20"])
            self.assertEqual(rc, 0, err)
            row = read_analysis(d)[0]
            self.assertEqual(row["group"], "all runs")
            self.assertIn("mean G′ <= 0 at amplitude(s) [1]", row["note"])
            self.assertEqual(row["flow_point"], "")            # no log across a negative mean: empty = undefined
            self.assertEqual(row["flow_point_flag"], "undefined")
            self.assertEqual((row["flow_point_ci_low"], row["flow_point_ci_high"]), ("", ""))   # none without a value
            self.assertIn("mean G′ <= 0", out)

    def write_rows(self, d, points):
        cols = table_columns()
        base = dict(sweep_parameter_defaults())
        with open(os.path.join(d, "results.csv"), "w", newline="", encoding="utf-8") as fh:
            fh.write(row_line({c: c for c in cols}, cols))
            fh.writelines(row_line(dict(base, theAmplitude=A, run_id=f"r{k}", status="ok", Gp_surface=gp,
                                        Gpp_surface=gpp, Gp_internal=gp, Gpp_internal=gpp), cols)
                          for k, (A, gp, gpp) in enumerate(points))

    def test_censored_flow_point_is_a_bound(self):
        # G′ > G″ at every amplitude up to 0.2: the flow point lies beyond 0.2 — '> 0.2', no interval, a flag
        with tempfile.TemporaryDirectory() as d:
            self.write_rows(d, [(A, 100.0 * f, 10.0 * f) for A in (0.01, 0.03, 0.1, 0.2) for f in (0.9, 1.0, 1.1)])
            rc, out, err = run(["analyse", d, "--n-boot", "50", "--no-figure"])
            self.assertEqual(rc, 0, err)
            row = read_analysis(d)[0]
            self.assertEqual((float(row["flow_point"]), row["flow_point_flag"]), (0.2, "lower_bound"))
            self.assertEqual((row["flow_point_ci_low"], row["flow_point_ci_high"]), ("", ""))
            self.assertIn("> 0.2", out)
            self.assertNotIn("0.2 [0.2, 0.2]", out)
            with open(os.path.join(d, "analysis.schema.json"), encoding="utf-8") as fh:
                self.assertEqual(json.load(fh)["columns"]["flow_point_flag"]["type"], "str")

    def test_fewer_than_four_amplitudes_refuse_the_points(self):
        with tempfile.TemporaryDirectory() as d:
            self.write_rows(d, [(A, 100.0 / A * f, 10.0 * f) for A in (0.01, 1.0) for f in (0.9, 1.1)])
            rc, out, err = run(["analyse", d, "--n-boot", "50", "--no-figure"])
            self.assertEqual(rc, 0, err)
            row = read_analysis(d)[0]
            self.assertIn("2 amplitudes: the characteristic points", row["note"])
            self.assertIn("need >= 4", out)
            for name in CHARACTERISTICS:
                if name != "plateau":
                    self.assertEqual((row[name], row[name + "_flag"]), ("", "too_few_amplitudes"), name)
            self.assertEqual(row["plateau_flag"], "ok")
            self.assertTrue(0 <= float(row["plateau_ci_low"]) <= float(row["plateau"]) <= float(row["plateau_ci_high"]))

    def test_same_call_same_numbers_with_the_default_seed(self):
        from particleShear.analysis.sweep import DEFAULT_SEED
        from particleShear.plot import plot_sweep
        import inspect
        with tempfile.TemporaryDirectory() as d:
            self.write_rows(d, [(A, 100.0 / (1 + A) * f, 30.0 * A * f) for A in (0.01, 0.1, 0.3, 1.0, 3.0)
                                for f in (0.8, 1.0, 1.3)])
            first = run(["analyse", d, "--n-boot", "100", "--no-figure"])
            one = read_analysis(d)
            second = run(["analyse", d, "--n-boot", "100", "--no-figure"])
            self.assertEqual(first[1], second[1])              # the same printed numbers
            self.assertEqual(one, read_analysis(d))
            self.assertEqual(one[0]["bootstrap_seed"], str(DEFAULT_SEED))   # recorded
            self.assertIn(f"seed {DEFAULT_SEED}", first[1])
            other = run(["analyse", d, "--n-boot", "100", "--no-figure", "--seed", "5"])
            self.assertNotEqual(one[0]["plateau_ci_low"], read_analysis(d)[0]["plateau_ci_low"])   # --seed overrides
            self.assertIn("seed 5", other[1])
        self.assertEqual(inspect.signature(plot_sweep).parameters["bootstrap_seed"].default, DEFAULT_SEED)


class BadInput(unittest.TestCase):

    def check(self, argv, pattern):
        rc, out, err = run(argv)
        self.assertEqual(rc, 2)
        self.assertEqual(len(err.strip().splitlines()), 1, err)
        self.assertRegex(err, pattern)
        self.assertEqual(out, "")

    def test_exit_2_with_one_line(self):
        with tempfile.TemporaryDirectory() as d:
            self.check(["analyse", d], r"^particleShear analyse: DIR '.*' is invalid: no results\.csv")
            write_results(d, groups={}, extra=True)
            self.check(["analyse", d], r"no rows with status 'ok'")
            write_results(d)
            self.check(["analyse", d, "--n-boot", "0"], r"--n-boot='0' is out of range: allowed an integer >= 1")
            self.check(["analyse", d, "--n-boot", "1.5"], r"--n-boot='1.5' is invalid")
            self.check(["analyse", d, "--confidence", "1"], r"--confidence='1' is out of range: allowed a number in")
            self.check(["analyse", d, "--confidence", "x"], r"--confidence='x' is invalid")
            self.check(["analyse", d, "--seed", "-1"], r"--seed='-1' is out of range")
            self.check(["analyse", d, "--estimator", "both"], r"invalid choice: 'both'")
            self.check(["analyse"], r"required: DIR")
            self.assertFalse(os.path.exists(os.path.join(d, "analysis.csv")))

    def test_unknown_command_names_analyse(self):
        rc, _, err = run(["nope"])
        self.assertEqual(rc, 2)
        self.assertIn("analyse", err)


class RealSweep(unittest.TestCase):
    """One tiny real sweep end to end: N = 20 particles, 2 amplitudes × 2 seeds, 3 short periods."""

    SPEC = """
[parameters]
N = 20
relative_frequency = 0.25
pre_periods = 0.5
periods = 3
post_periods = 0.5
doDrawing = false
plotStress = false
[grid]
theAmplitude = [0.05, 0.2]
[seeds]
root = 7
repetitions = 2
"""

    def test_sweep_then_analyse(self):
        with tempfile.TemporaryDirectory() as d:
            spec = os.path.join(d, "tiny.toml")
            with open(spec, "w", encoding="utf-8") as fh:
                fh.write(self.SPEC)
            out = os.path.join(d, "out")
            rc, _, err = run(["sweep", spec, "--out", out, "--workers", "1", "--quiet"])
            self.assertEqual(rc, 0, err)
            with open(os.path.join(out, "results.csv"), newline="", encoding="utf-8") as fh:
                table = list(csv.DictReader(fh))
            self.assertEqual(len(table), 4)
            for row in table:   # 3 periods measure 2: a standard error, no steady-state verdict
                self.assertGreater(float(row["Gp_surface_se"]), 0)
                self.assertEqual(row["steady_state"], "")
                self.assertGreaterEqual(float(row["I3_I1_surface"]), 0)
            rc, stdout, err = run(["analyse", out, "--seed", "1", "--n-boot", "100", "--json"])
            self.assertEqual(rc, 0, err)
            rows = json.loads(stdout)
            self.assertEqual(len(rows), 1)
            self.assertEqual(rows[0]["n_runs"], 4)
            self.assertEqual(rows[0]["n_amplitudes"], 2)
            self.assertTrue(math.isfinite(rows[0]["plateau"]))
            self.assertTrue(os.path.isfile(os.path.join(out, "analysis.csv")))


if __name__ == "__main__":
    unittest.main()
