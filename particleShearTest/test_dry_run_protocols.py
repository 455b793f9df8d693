"""Bounded, honest dry runs of protocol SPECs (docs/sweeps.md, "Projected cost"):
the calibration shortens every protocol and stops at its wall-clock budget, the projection counts each
protocol's own steps, an interrupted sweep names its table only when it exists, and the final line
counts runs and rows apart.

Real processes where the fault is one: the dry run of a long creep SPEC is a subprocess (its timeout
is a hang guard only), the budget is enforced on real calibration runs in a child process.
"""
import contextlib
import io
import json
import multiprocessing
import os
import subprocess
import sys
import tempfile
import unittest
import warnings
from unittest import mock

from particleShear.run.batch import _signature_defaults
from particleShear.run.validation import validate_run
from particleShear.sweep import calibration as C
from particleShear.sweep.cost import estimate_point_cost, run_bytes, run_steps

_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

CREEP = dict(N=20, protocol="creep", creep_stress=50.0, hold_time=1e7)


def _point(**kw):
    return dict(_signature_defaults(), **kw)


class TestProtocolSteps(unittest.TestCase):
    def test_projection_counts_the_protocols_own_steps(self):
        p = _point(**CREEP)
        self.assertEqual(run_steps(p), 560_000_000)       # hold_time / dt, not the oscillation's 13,439
        self.assertEqual(run_steps(_point(N=20)), 13_439)
        c = estimate_point_cost([p], [3])
        self.assertEqual(c["steps"], 3 * 560_000_000)
        self.assertEqual(run_bytes(dict(p, saveData=True)), 4000 + 110 * 560_000_000)
        q = _point(N=20, protocol="frequency_sweep", sweep_frequencies=[0.25, 0.1])
        one = [run_steps(dict(q, protocol="oscillatory", relative_frequency=f)) for f in (0.25, 0.1)]
        self.assertEqual(run_steps(q), sum(one))        # every step of the sweep, each its own oscillation

    def test_calibration_shortens_every_protocol(self):
        cases = [CREEP, dict(N=20, protocol="steady", relative_rate=0.001, total_strain=1000.0),
                 dict(N=20, protocol="relaxation", hold_time=1e6, ramp_time=2.0),
                 dict(N=20, protocol="frequency_sweep", sweep_frequencies=[0.25, 0.2, 0.1, 0.05], periods=500),
                 dict(N=20, protocol="amplitude_sweep", sweep_amplitudes=[0.05, 0.1, 0.2], periods=500),
                 dict(N=20, periods=500)]
        for kw in cases:
            with self.subTest(protocol=kw.get("protocol", "oscillatory")):
                p = _point(**kw)
                for target in (100, 400):
                    short = C._shortened(p, target, "")
                    n = run_steps(short)
                    self.assertGreater(n, 0)
                    self.assertLessEqual(n, 1.1 * target + (112 if kw.get("protocol") == "relaxation" else 0))
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        validate_run(dict(short, root_folder=""))   # a valid run

    def test_calibration_key_names_the_protocol(self):
        p = _point(N=20)
        self.assertNotEqual(C.calibration_key(p, 400, 4, host="h", version="v"),
                            C.calibration_key(dict(p, protocol="creep"), 400, 4, host="h", version="v"))


class TestBudget(unittest.TestCase):
    def test_fake_clock_stops_before_passing_the_budget(self):
        clock = [0.0]

        def run(kw):
            clock[0] += 0.4

        def batch(kws):
            clock[0] += 0.4 * len(kws)

        cal = C.measure_calibration(_point(**CREEP), repeats=3, replicas=4, timer=lambda: clock[0], run=run,
                                    batch=batch, budget_s=1.0)
        self.assertFalse(cal["complete"])
        self.assertIn("budget", cal["stopped"])
        self.assertEqual(len(cal["per_step_s"]), 1)      # the first pair only: the batch would pass 1 s
        self.assertIsNone(cal["batch_s"])
        self.assertLessEqual(clock[0], 1.0)
        c = C.project_cost([_point(**CREEP)], [2], cal, workers=1, batch_size=2, schedule=lambda p: 0)
        self.assertGreater(c["wall_s"], 0)

    def test_real_calibration_is_ended_at_its_budget(self):
        # a budget of 10 ms is shorter than any run (its constitution alone is hundreds of steps on
        # 60 spheres): the child process is ended when the budget runs out, and nothing measured is
        # no calibration, not a guess
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = C.measure_calibration(_point(N=60, relative_frequency=0.25), budget_s=0.01)
        self.assertIsNone(cal)
        self.assertEqual(multiprocessing.active_children(), [])

    def test_budget_argument_checked(self):
        with self.assertRaises(ValueError) as cm:
            C.measure_calibration(_point(N=20), budget_s=0, run=lambda kw: None, batch=lambda kws: None)
        self.assertIn("budget_s", str(cm.exception))


def _write(d, name, doc):
    path = os.path.join(d, name)
    with open(path, "w") as fh:
        json.dump(doc, fh)
    return path


class TestCli(unittest.TestCase):
    def test_dry_run_of_a_long_creep_spec_finishes_and_counts_its_steps(self):
        # 1.12e7 steps per run (hours each; its record, 0.83 GiB, within the memory of a CI machine)
        spec = {"parameters": dict(N=20, protocol="creep", creep_stress=50.0, hold_time=2e5),
                "grid": {"theMu": [0.01, 0.1]}, "seeds": {"root": 1, "repetitions": 2}}
        with tempfile.TemporaryDirectory() as d:
            path = _write(d, "creep.json", spec)
            env = dict(os.environ, PYTHONPATH=_ROOT, PARTICLESHEAR_CACHE_DIR=d)
            out = subprocess.run([sys.executable, "-m", "particleShear", "sweep", path, "--out",
                                  os.path.join(d, "o"), "--dry-run", "--workers", "1"],
                                 capture_output=True, text=True, timeout=170, env=env)   # hang guard only
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertFalse(os.path.exists(os.path.join(d, "o")))
        self.assertIn(f"4 runs, {4 * 11_200_000:,} protocol steps", out.stdout)
        self.assertIn("protocol creep", out.stdout)
        self.assertIn("calibrated here", out.stdout)

    def test_no_calibration_within_the_budget_is_said(self):
        from particleShear.sweep.cli import main
        spec = {"parameters": dict(N=20, protocol="creep", creep_stress=50.0, hold_time=100.0),
                "seeds": {"root": 1, "repetitions": 1}}
        with tempfile.TemporaryDirectory() as d:
            path = _write(d, "c.json", spec)
            out = io.StringIO()
            with mock.patch.object(C, "measure_calibration", return_value=None), \
                    mock.patch.dict(os.environ, {"PARTICLESHEAR_CACHE_DIR": d}), contextlib.redirect_stdout(out):
                self.assertEqual(main([path, "--out", os.path.join(d, "o"), "--dry-run"]), 0)
        self.assertIn("calibration stopped", out.getvalue())
        self.assertNotIn("calibrated here", out.getvalue())
        out = io.StringIO()
        with tempfile.TemporaryDirectory() as d:
            path = _write(d, "c.json", spec)
            with mock.patch.object(C, "measure_calibration", side_effect=RuntimeError("a calibration run failed: X")), \
                    mock.patch.dict(os.environ, {"PARTICLESHEAR_CACHE_DIR": d}), contextlib.redirect_stdout(out):
                self.assertEqual(main([path, "--out", os.path.join(d, "o"), "--dry-run"]), 0)
        self.assertIn("calibration failed", out.getvalue())

    def test_interrupted_sweep_names_its_table_only_when_it_exists(self):
        from particleShear.sweep.cli import main
        from particleShear.sweep.runner import Sweep
        spec = {"parameters": dict(N=20, protocol="creep", creep_stress=50.0, hold_time=100.0),
                "seeds": {"root": 1, "repetitions": 1}}
        with tempfile.TemporaryDirectory() as d:
            path = _write(d, "c.json", spec)
            out_dir = os.path.join(d, "o")

            def interrupted(self, **kw):
                raise KeyboardInterrupt
                yield   # pragma: no cover

            for has_table in (False, True):
                if has_table:
                    os.makedirs(out_dir, exist_ok=True)
                    open(os.path.join(out_dir, "results.csv"), "w").close()
                err = io.StringIO()
                with mock.patch.object(Sweep, "as_completed", interrupted), contextlib.redirect_stderr(err), \
                        contextlib.redirect_stdout(io.StringIO()):
                    self.assertEqual(main([path, "--out", out_dir, "--quiet", "--workers", "1"]), 130)
                if has_table:
                    self.assertIn("results.csv are kept", err.getvalue())
                else:
                    self.assertIn("no table written", err.getvalue())
                    self.assertNotIn("are kept", err.getvalue())
                    self.assertFalse(os.path.exists(out_dir))

    def test_final_line_counts_runs_and_rows(self):
        spec = {"parameters": dict(N=20, protocol="amplitude_sweep", sweep_amplitudes=[0.05, 0.1], periods=1,
                                   relative_frequency=0.25),
                "seeds": {"root": 1, "repetitions": 2}}
        with tempfile.TemporaryDirectory() as d:
            path = _write(d, "a.json", spec)
            env = dict(os.environ, PYTHONPATH=_ROOT, PARTICLESHEAR_CACHE_DIR=d)
            out = subprocess.run([sys.executable, "-m", "particleShear", "sweep", path, "--out",
                                  os.path.join(d, "o"), "--workers", "1", "--quiet"],
                                 capture_output=True, text=True, timeout=300, env=env)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("2 of 2 runs finished (0 failed), 4 rows", out.stdout)


if __name__ == "__main__":
    unittest.main()
