"""``analyse`` and ``plot`` on every folder a sweep writes, bounded, and published as one set.

Synthetic ``results.csv`` tables with the real header (``table_columns``, ``row_line``) stand for
one-packing sweeps (step rows: ``theAmplitude`` is the first amplitude, ``sweep_amplitude`` the
step's), mixed-protocol tables and steady/relaxation/creep folders; one tiny real mixed-protocol
sweep checks what the sweep writes.  Concurrency and Ctrl-C use real processes.
"""
import contextlib
import csv
import importlib.util
import io
import json
import os
import signal
import stat
import subprocess
import sys
import tempfile
import time
import unittest

from particleShear.run.cli import main
from particleShear.sweep.spec import sweep_parameter_defaults
from particleShear.sweep.table import row_line, table_columns

HAVE_MPL = importlib.util.find_spec("matplotlib") is not None
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
AMPS = [0.01, 0.03, 0.1, 0.3]
FREQS = [0.1, 0.2, 0.4]


def model(A, ac=0.1, f=1.0):
    x = A / ac
    return 1000.0 * f / (1 + x * x), 500.0 * f * x / (1 + x * x)


def moduli(gp, gpp):
    return dict(Gp_surface=gp, Gpp_surface=gpp, Gp_internal=gp, Gpp_internal=gpp)


def write_table(folder, rows):
    """results.csv with protocol columns: every row a dict of overrides of the defaults."""
    params = list(sweep_parameter_defaults(protocols=True))
    cols = table_columns(params)
    base = sweep_parameter_defaults(protocols=True)
    with open(os.path.join(folder, "results.csv"), "w", newline="", encoding="utf-8") as fh:
        fh.write(row_line({c: c for c in cols}, cols))
        for k, r in enumerate(rows):
            fh.write(row_line(dict(base, status="ok", error="", seed_entropy=1, spawn_key=[k], wall_time_s=1.0,
                                   **r), cols))


def amplitude_sweep_rows(seeds=3, protocol_cell="amplitude_sweep"):
    return [dict(run_id=f"a{s}", protocol=protocol_cell, sweep_amplitudes=AMPS, theAmplitude=AMPS[0],
                 sweep_position=i, sweep_amplitude=A, **moduli(*model(A))) for s in range(seeds)
            for i, A in enumerate(AMPS)]


def frequency_sweep_rows(seeds=3):
    return [dict(run_id=f"f{s}", protocol="frequency_sweep", sweep_frequencies=FREQS, relative_frequency=FREQS[0],
                 theAmplitude=0.05, sweep_position=i, sweep_relative_frequency=f, **moduli(*model(0.05, f=f)))
            for s in range(seeds) for i, f in enumerate(FREQS)]


def oscillatory_rows(amps=(0.01, 0.1), seeds=2, mu=None, cell=""):
    return [dict(run_id=f"o{A}-{s}-{mu}", protocol=cell, theAmplitude=A, **({"theMu": mu} if mu else {}),
                 **moduli(*model(A, ac=0.2))) for A in amps for s in range(seeds)]


def run(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, out.getvalue(), err.getvalue()


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def env():
    e = dict(os.environ)
    e["PYTHONPATH"] = ROOT + os.pathsep + e.get("PYTHONPATH", "")
    return e


def analyse_process(folder, *extra):
    return subprocess.Popen([sys.executable, "-m", "particleShear", "analyse", folder, *extra], env=env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


class OnePackingSweeps(unittest.TestCase):
    """Why case 2: step rows are runs at their own amplitude or frequency; protocols split groups."""

    def test_amplitude_sweep_folder_has_its_amplitudes(self):
        with tempfile.TemporaryDirectory() as d:
            write_table(d, amplitude_sweep_rows())
            rc, out, err = run(["analyse", d, "--seed", "1", "--n-boot", "50", "--no-figure"])
            self.assertEqual(rc, 0, err)
            rows = read_csv(os.path.join(d, "analysis.csv"))
            self.assertEqual(len(rows), 1)
            self.assertEqual((rows[0]["n_runs"], rows[0]["n_amplitudes"]), ("12", "4"))
            self.assertEqual((float(rows[0]["amplitude_min"]), float(rows[0]["amplitude_max"])), (0.01, 0.3))
            self.assertAlmostEqual(float(rows[0]["plateau"]), model(0.01)[0], delta=1e-6)
            self.assertNotIn("amplitude only", rows[0]["note"])

    def test_plot_of_an_amplitude_sweep_has_one_point_per_amplitude(self):
        from particleShear.plot import read_sweep_table
        from particleShear.sweep_plot import sweep_panels
        with tempfile.TemporaryDirectory() as d:
            write_table(d, amplitude_sweep_rows())
            table = sweep_panels(read_sweep_table(d), n_boot=20)
            self.assertEqual(table["x"], "theAmplitude")
            (panel,) = table["panels"]
            (curve,) = panel["curves"]
            self.assertEqual(list(curve["x"]), AMPS)
            self.assertEqual(list(curve["n"]), [3] * 4)

    def test_frequency_sweep_folder_keeps_its_frequencies_apart(self):
        from particleShear.plot import read_sweep_table
        from particleShear.sweep_plot import sweep_panels
        with tempfile.TemporaryDirectory() as d:
            write_table(d, frequency_sweep_rows())
            table = sweep_panels(read_sweep_table(d))
            self.assertEqual(table["x"], "relative_frequency")
            (curve,) = table["panels"][0]["curves"]
            self.assertEqual(list(curve["x"]), FREQS)
            self.assertEqual([round(v, 9) for v in curve["Gp"]], [round(model(0.05, f=f)[0], 9) for f in FREQS])
            rc, _, err = run(["analyse", d, "--seed", "1", "--n-boot", "20", "--no-figure"])
            self.assertEqual(rc, 0, err)
            rows = read_csv(os.path.join(d, "analysis.csv"))
            self.assertEqual([float(r["relative_frequency"]) for r in rows], FREQS)
            self.assertEqual([r["n_runs"] for r in rows], ["3"] * 3)
            self.assertIn("particleShear plot DIR draws G′, G″ against the frequency", rows[0]["note"])

    def test_mixed_protocols_split_groups(self):
        with tempfile.TemporaryDirectory() as d:
            # 4 oscillatory rows (an empty protocol cell, as older sweeps wrote) + 12 amplitude-sweep steps
            write_table(d, oscillatory_rows() + amplitude_sweep_rows())
            rc, out, err = run(["analyse", d, "--seed", "1", "--n-boot", "20", "--no-figure"])
            self.assertEqual(rc, 0, err)
            rows = read_csv(os.path.join(d, "analysis.csv"))
            self.assertEqual(sorted(r["protocol"] for r in rows), ["amplitude_sweep", "oscillatory"])
            by = {r["protocol"]: r for r in rows}
            self.assertEqual((by["oscillatory"]["n_runs"], by["oscillatory"]["n_amplitudes"]), ("4", "2"))
            self.assertEqual((by["amplitude_sweep"]["n_runs"], by["amplitude_sweep"]["n_amplitudes"]), ("12", "4"))
            self.assertNotIn("all runs", out)
            self.assertTrue(all(len(r["group"]) < 200 for r in rows))   # the list of amplitudes is cut in labels

    def test_oscillatory_stream_is_that_of_a_table_without_protocols(self):
        with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b:
            write_table(a, oscillatory_rows(amps=AMPS, seeds=3, cell="oscillatory"))
            cols = table_columns()
            base = sweep_parameter_defaults()
            with open(os.path.join(b, "results.csv"), "w", newline="", encoding="utf-8") as fh:
                fh.write(row_line({c: c for c in cols}, cols))
                for r in oscillatory_rows(amps=AMPS, seeds=3):
                    r = {k: v for k, v in r.items() if k != "protocol"}
                    fh.write(row_line(dict(base, status="ok", **r), cols))
            for d in (a, b):
                self.assertEqual(run(["analyse", d, "--seed", "4", "--n-boot", "30", "--no-figure"])[0], 0)
            ra, rb = read_csv(os.path.join(a, "analysis.csv"))[0], read_csv(os.path.join(b, "analysis.csv"))[0]
            self.assertEqual(ra["plateau_ci_low"], rb["plateau_ci_low"])

    def test_steady_relaxation_and_creep_are_summarised(self):
        with tempfile.TemporaryDirectory() as d:
            rows = []
            for s in range(2):
                for rate in (0.01, 0.02, 0.04, 0.08):
                    g = rate * 10.0
                    rows.append(dict(run_id=f"s{rate}-{s}", protocol="steady", relative_rate=rate, repetition=s,
                                     strain_rate=g, stress_surface=3.0 + 2.0 * g ** 0.5 * (1 + 0.01 * s),
                                     stress_internal=1.0))
                rows.append(dict(run_id=f"r{s}", protocol="relaxation", repetition=s, hold_time=5.0,
                                 G_plateau_surface=100.0 + s, G_plateau_internal=1.0, residual_stress=0.5))
                rows.append(dict(run_id=f"c{s}", protocol="creep", repetition=s, creep_stress=20.0,
                                 creep_rate=1e-3 * (1 + s), creep_viscosity=2e4, strain_plateau=0.1,
                                 residual_stress=0.2))
            write_table(d, rows)
            rc, out, err = run(["analyse", d, "--seed", "2", "--n-boot", "40"])
            self.assertEqual(rc, 0, err)
            self.assertFalse(os.path.exists(os.path.join(d, "analysis.csv")))   # no moduli: no empty table
            table = read_csv(os.path.join(d, "analysis_protocols.csv"))
            got = {(r["protocol"], r["quantity"]): r for r in table}
            self.assertAlmostEqual(float(got["relaxation", "G_plateau_surface"]["value"]), 100.5)
            self.assertEqual(got["relaxation", "G_plateau_surface"]["n_runs"], "2")
            self.assertAlmostEqual(float(got["creep", "creep_rate"]["value"]), 1.5e-3)
            self.assertLessEqual(float(got["creep", "creep_rate"]["ci_low"]), 1.5e-3)
            sy = got["steady", "sigma_y"]
            self.assertEqual((sy["n_runs"], sy["n_rates"]), ("8", "4"))
            self.assertAlmostEqual(float(sy["value"]), 3.0, delta=0.1)
            self.assertAlmostEqual(float(got["steady", "n"]["value"]), 0.5, delta=0.05)
            self.assertEqual({r["flag"] for r in table}, {"ok"})        # a proper fit, positive moduli
            with open(os.path.join(d, "analysis_protocols.schema.json"), encoding="utf-8") as fh:
                self.assertEqual(list(json.load(fh)["columns"]), list(table[0]))
            self.assertIn("no oscillatory runs or sweep steps", err)

    def test_degenerate_flow_curve_fit_is_flagged(self):
        # a stress that grows as the rate cubed: the Herschel-Bulkley fit puts n on its bound 2 — flagged, with why
        with tempfile.TemporaryDirectory() as d:
            rows = [dict(run_id=f"s{rate}-{s}", protocol="steady", relative_rate=rate, repetition=s,
                         strain_rate=rate * 10, stress_surface=1.0 + (rate * 10) ** 3 * (1 + 0.01 * s),
                         stress_internal=1.0) for s in range(2) for rate in (0.01, 0.02, 0.04, 0.08, 0.16)]
            write_table(d, rows)
            rc, out, err = run(["analyse", d, "--n-boot", "40"])
            self.assertEqual(rc, 0, err)
            table = read_csv(os.path.join(d, "analysis_protocols.csv"))
            self.assertEqual({r["flag"] for r in table}, {"degenerate_fit"})
            self.assertIn("on its upper bound 2", table[0]["note"])
            self.assertIn("degenerate_fit", out)
            self.assertIn("degenerate Herschel-Bulkley fit", out)


class RealMixedSweep(unittest.TestCase):
    """A tiny real sweep of two protocols: the oscillatory row says ``oscillatory``."""

    def test_oscillatory_row_of_a_mixed_table_names_its_protocol(self):
        from particleShear.sweep import run_sweep
        spec = {"parameters": dict(N=20, cut_lines=0, relative_frequency=0.25, pre_periods=0.2, periods=3,
                                   post_periods=0, doDrawing=False, plotStress=False, theAmplitude=0.05,
                                   sweep_amplitudes=[0.05, 0.1]),
                "grid": {"protocol": ["oscillatory", "amplitude_sweep"]}, "seeds": {"root": 3, "repetitions": 1}}
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "mixed")
            run_sweep(spec, out, workers=1, progress=False)
            table = read_csv(os.path.join(out, "results.csv"))
            self.assertEqual(sorted(r["protocol"] for r in table), ["amplitude_sweep"] * 2 + ["oscillatory"])
            rc, _, err = run(["analyse", out, "--seed", "1", "--n-boot", "20", "--no-figure"])
            self.assertEqual(rc, 0, err)
            rows = read_csv(os.path.join(out, "analysis.csv"))
            self.assertEqual(sorted(r["protocol"] for r in rows), ["amplitude_sweep", "oscillatory"])


class Bounds(unittest.TestCase):
    """Why case 7: n_boot bounded, the figure capped or skipped."""

    def test_n_boot_bounded_before_any_work(self):
        from particleShear.analysis.cli import analyse_folder
        from particleShear.analysis.sweep import N_BOOT_MAX, sweep_summary
        with tempfile.TemporaryDirectory() as d:
            write_table(d, amplitude_sweep_rows())
            rc, out, err = run(["analyse", d, "--n-boot", "1000000000"])
            self.assertEqual(rc, 2)
            self.assertEqual(err.count("\n"), 1, err)
            self.assertIn("--n-boot='1000000000' is out of range: allowed an integer >= 1 and <= 100000 (n_boot)", err)
            with self.assertRaisesRegex(ValueError, r"n_boot=1000000000 is out of range: allowed an integer >= 1 and "
                                                    r"<= 100000 \(CLI --n-boot\)"):
                analyse_folder(d, n_boot=10 ** 9)
            with self.assertRaisesRegex(ValueError, r"n_boot=100001 .*<= 100000 \(CLI --n-boot\)"):
                sweep_summary(AMPS, [1, 2, 3, 4], [1, 2, 3, 4], n_boot=N_BOOT_MAX + 1)
            self.assertFalse(any(n.startswith("analysis") for n in os.listdir(d)))

    @unittest.skipUnless(HAVE_MPL, "matplotlib not installed (extra [plot])")
    def test_figure_capped_and_the_rest_named(self):
        with tempfile.TemporaryDirectory() as d:
            rows = []
            for k in range(60):
                rows += oscillatory_rows(amps=(0.01, 0.1), seeds=1, mu=0.01 * (k + 1), cell="oscillatory")
            write_table(d, rows)
            rc, out, err = run(["analyse", d, "--seed", "1", "--n-boot", "5"])
            self.assertEqual(rc, 0, err)
            self.assertEqual(len(read_csv(os.path.join(d, "analysis.csv"))), 60)
            self.assertIn("figure: the first 24 of 60 groups drawn; not drawn: theMu=0.25", err)
            self.assertIn("… and", err)            # the names are cut to one short line
            self.assertTrue(os.path.isfile(os.path.join(d, "analysis.png")))

    def test_no_figure_writes_none_and_removes_an_earlier_one(self):
        with tempfile.TemporaryDirectory() as d:
            write_table(d, amplitude_sweep_rows())
            for name in ("analysis.png", "analysis.pdf"):
                with open(os.path.join(d, name), "wb") as fh:
                    fh.write(b"old")
            rc, out, err = run(["analyse", d, "--n-boot", "5", "--no-figure"])
            self.assertEqual(rc, 0, err)
            self.assertFalse(os.path.exists(os.path.join(d, "analysis.png")))
            self.assertIn("removed analysis.png, analysis.pdf of an earlier analysis", err)


class OutputSet(unittest.TestCase):
    """Why case 8: unwritable targets refused first, one set on disk, concurrency and Ctrl-C."""

    def check_refused(self, d, pattern):
        rc, out, err = run(["analyse", d, "--n-boot", "5"])
        self.assertEqual(rc, 2, err)
        self.assertEqual(err.count("\n"), 1, err)
        self.assertRegex(err, pattern)
        self.assertNotIn("Traceback", err)

    def test_directory_at_an_output_is_refused_before_the_bootstrap(self):
        import particleShear.analysis.sweep as sweep_module
        with tempfile.TemporaryDirectory() as d:
            write_table(d, amplitude_sweep_rows())
            for name in ("analysis.csv", "analysis.png"):
                os.mkdir(os.path.join(d, name))
                calls = []
                original = sweep_module.sweep_summary
                sweep_module.sweep_summary = lambda *a, **k: calls.append(1) or original(*a, **k)
                try:
                    self.check_refused(d, rf"{name}' is a directory")
                finally:
                    sweep_module.sweep_summary = original
                self.assertEqual(calls, [])
                os.rmdir(os.path.join(d, name))
            self.assertEqual([n for n in os.listdir(d) if n.startswith(".analysis")], [])

    def test_read_only_output_is_not_replaced(self):
        with tempfile.TemporaryDirectory() as d:
            write_table(d, amplitude_sweep_rows())
            path = os.path.join(d, "analysis.csv")
            with open(path, "w", encoding="utf-8") as fh:
                fh.write("mine\n")
            os.chmod(path, stat.S_IRUSR | stat.S_IRGRP)
            try:
                self.check_refused(d, r"analysis\.csv' is read-only: not replaced")
                with open(path, encoding="utf-8") as fh:
                    self.assertEqual(fh.read(), "mine\n")
            finally:
                os.chmod(path, stat.S_IRUSR | stat.S_IWUSR)

    @unittest.skipIf(hasattr(os, "geteuid") and os.geteuid() == 0, "root writes into read-only folders")
    def test_unwritable_folder_is_refused(self):
        with tempfile.TemporaryDirectory() as d:
            write_table(d, amplitude_sweep_rows())
            os.chmod(d, stat.S_IRUSR | stat.S_IXUSR)
            try:
                self.check_refused(d, r"DIR=.* is invalid: the folder is not writable")
            finally:
                os.chmod(d, stat.S_IRWXU)

    @unittest.skipUnless(HAVE_MPL, "matplotlib not installed (extra [plot])")
    def test_two_concurrent_analyses_both_finish_and_one_set_is_on_disk(self):
        with tempfile.TemporaryDirectory() as d:
            write_table(d, oscillatory_rows(amps=AMPS, seeds=3, mu=0.1, cell="oscillatory")
                        + oscillatory_rows(amps=AMPS, seeds=3, mu=0.2, cell="oscillatory"))
            procs = [analyse_process(d, "--seed", str(k), "--n-boot", "300") for k in (1, 2)]
            results = [p.communicate(timeout=300) for p in procs]
            for p, (out, err) in zip(procs, results):
                self.assertEqual(p.returncode, 0, err)
                self.assertNotIn("Traceback", err)
            with open(os.path.join(d, "analysis.schema.json"), encoding="utf-8") as fh:
                schema = json.load(fh)
            seed = schema["settings"]["bootstrap_seed"]
            self.assertEqual({r["bootstrap_seed"] for r in read_csv(os.path.join(d, "analysis.csv"))}, {str(seed)})
            for name in ("analysis.png", "analysis.pdf"):
                with open(os.path.join(d, name), "rb") as fh:
                    self.assertIn(schema["generation"].encode(), fh.read(), name)
            self.assertEqual([n for n in os.listdir(d) if n.startswith(".")], [])   # no temporaries left

    def test_ctrl_c_leaves_the_old_set_and_no_traceback(self):
        with tempfile.TemporaryDirectory() as d:
            rows = []
            for k in range(12):
                rows += oscillatory_rows(amps=AMPS, seeds=3, mu=0.01 * (k + 1), cell="oscillatory")
            write_table(d, rows)
            rc, _, err = run(["analyse", d, "--seed", "1", "--n-boot", "5", "--no-figure"])
            self.assertEqual(rc, 0, err)
            with open(os.path.join(d, "analysis.csv"), "rb") as fh:
                old_csv = fh.read()
            with open(os.path.join(d, "analysis.schema.json"), "rb") as fh:
                old_schema = fh.read()
            p = analyse_process(d, "--seed", "2", "--n-boot", "100000")
            deadline = time.monotonic() + 120
            # the event: the staging folder exists (the folder was checked, the bootstrap starts)
            while not any(n.startswith(".analysis.") and n.endswith(".part") for n in os.listdir(d)):
                self.assertIsNone(p.poll(), "the analysis ended before it staged anything")
                self.assertLess(time.monotonic(), deadline)
                time.sleep(0.01)
            p.send_signal(signal.SIGINT)
            out, err = p.communicate(timeout=120)
            self.assertNotIn("Traceback", err)
            with open(os.path.join(d, "analysis.csv"), "rb") as fh:
                new_csv = fh.read()
            with open(os.path.join(d, "analysis.schema.json"), "rb") as fh:
                new_schema = fh.read()
            if p.returncode == 130 and "nothing written" in err:
                self.assertEqual((new_csv, new_schema), (old_csv, old_schema))
            else:    # it published whole before the signal was taken
                self.assertIn(p.returncode, (0, 130), err)
                self.assertNotEqual(new_csv, old_csv)
                self.assertEqual(json.loads(new_schema)["settings"]["bootstrap_seed"], 2)
            self.assertEqual(len(err.strip().splitlines()), 1, err)
            self.assertEqual([n for n in os.listdir(d) if n.startswith(".")], [])


if __name__ == "__main__":
    unittest.main()
