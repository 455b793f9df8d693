"""Typed, self-describing results tables: ``load_results``, ``results.schema.json``, the
typed Parquet copy, typed ``run_sweep`` rows, the run columns (repetition, frequency, ω, dt, steps),
rows in SPEC order after a sweep whose runs finished in reverse order, and no lock or scratch file
left behind.

The real sweep is tiny (N = 12, 2 particles, relative_frequency = 0.25, 3 periods: ≈ 900 steps, about
a second a run): 2 amplitudes × 2 repetitions, run once per class on an executor that runs the jobs in
reverse SPEC order, one at a time (the next starts when the sweep has recorded the previous), so the
completion order is reversed whatever the machine's speed.  The ordering of extended folders uses a
stand-in simulation (instant, deterministic rows).
"""
import concurrent.futures
import csv
import functools
import io
import math
import os
import shutil
import sys
import tempfile
import threading
import unittest
from unittest import mock

import numpy as np

from particleShear import doParticleShearSimulation
from particleShear.run import api
from particleShear.run.api import SimulationResult
from particleShear.sweep import Sweep, expand_runs, load_results, parse_spec, run_sweep
from particleShear.sweep.cli import main as sweep_main
from particleShear.sweep.schema import COLUMN_TYPES, SCHEMA_NAME, read_schema, typed_row
from particleShear.sweep.table import read_rows, write_table

try:
    import pandas as pd
except ImportError:  # pragma: no cover - optional
    pd = None
try:
    import pyarrow.parquet as pq
except ImportError:  # pragma: no cover - optional
    pq = None

TINY = dict(N=12, cut_lines=2, relative_frequency=0.25, pre_periods=0.5, periods=3, post_periods=0.5,
            doDrawing=False, plotStress=False)
SPEC = {"parameters": dict(TINY), "grid": {"theAmplitude": [0.1, 0.2]}, "seeds": {"root": 11, "repetitions": 2}}
DEADLINE_S = 300


class ReverseExecutor(concurrent.futures.Executor):
    """Holds the jobs until ``n`` are submitted, then runs them in this order reversed, one at a time.

    The next job starts only when the sweep has recorded the previous one (:meth:`progress`, the
    sweep's progress callback, is called after its row is appended), so the rows reach the table in
    reverse SPEC order — an event-driven order, independent of the speed of the machine.
    """

    def __init__(self, n):
        self.n, self.jobs, self.completed = n, [], []
        self._recorded = threading.Semaphore(0)

    def submit(self, fn, /, *args, **kwargs):
        fut = concurrent.futures.Future()
        self.jobs.append((fut, fn, args, kwargs))
        if len(self.jobs) == self.n:
            threading.Thread(target=self._drain, daemon=True).start()
        return fut

    def _drain(self):
        for fut, fn, args, kwargs in reversed(self.jobs):
            try:
                fut.set_result(fn(*args, **kwargs))
            except BaseException as exc:  # noqa: BLE001 - handed to the sweep, as an executor does
                fut.set_exception(exc)
            if not self._recorded.acquire(timeout=DEADLINE_S):
                return

    def progress(self, outcome):
        """The sweep's progress callback: note the run, let the next job start."""
        self.completed.append(outcome.run.index)
        self._recorded.release()


def _fake_simulation(**kw):
    """Instant stand-in of doParticleShearSimulation: a result whose moduli encode the amplitude."""
    ss = kw["seed"]
    A = kw["theAmplitude"]
    return SimulationResult(G_surface=(1000 * A, 10.0), G_internal=(900 * A, 9.0), stress_surface=(0.0, 0.0),
                            stress_internal=(0.0, 0.0), parameters=dict(kw), seed=ss.entropy,
                            spawn_key=tuple(ss.spawn_key), f=100.0, dt=1e-4, N_steps=500)


def _fake_run(run):
    """Instant stand-in of the worker's measurement (``api.measure_run``) of a sweep's checked run."""
    return _fake_simulation(**run)


def _leftovers(folder):
    """Lock files, temporary files and scratch folders under ``folder``."""
    out = []
    for root, dirs, files in os.walk(folder):
        out += [os.path.join(root, d) for d in dirs if d == "runs"]
        out += [os.path.join(root, f) for f in files if f.endswith((".lock", ".part"))]
    return out


class TestTypedTables(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="ps_typed_")
        cls.out = os.path.join(cls.tmp, "sweep")
        cls.runs = expand_runs(parse_spec(SPEC))
        cls.executor = ReverseExecutor(len(cls.runs))
        cls.rows = run_sweep(SPEC, cls.out, executor=cls.executor, progress=cls.executor.progress)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def _header(self):
        with open(os.path.join(self.out, "results.csv"), newline="", encoding="utf-8") as fh:
            return next(csv.reader(fh))

    # -- order and leftovers ----------------------------------------------------------------------
    def test_rows_in_spec_order_after_reverse_completion(self):
        self.assertEqual(self.executor.completed, [3, 2, 1, 0])            # the runs finished in reverse
        ids = [r["run_id"] for r in read_rows(os.path.join(self.out, "results.csv"))]
        self.assertEqual(ids, [r.run_id for r in self.runs])               # the table is in SPEC order
        self.assertEqual([r["run_id"] for r in self.rows], ids)

    def test_no_lock_or_scratch_left(self):
        self.assertEqual(_leftovers(self.out), [])
        self.assertEqual(sorted(os.listdir(self.out)), sorted(["results.csv", SCHEMA_NAME, "sweep.json"]
                                                              + (["results.parquet"] if pq else [])))

    def test_cli_leaves_no_lock_or_scratch(self):
        d = os.path.join(self.tmp, "cli")
        spec_path = os.path.join(self.tmp, "one.toml")
        with open(spec_path, "w", encoding="utf-8") as fh:
            fh.write("[parameters]\nN = 12\ncut_lines = 2\nrelative_frequency = 0.25\npre_periods = 0.5\n"
                     "periods = 3\npost_periods = 0.5\ndoDrawing = false\nplotStress = false\nsaveData = true\n"
                     "[grid]\ntheAmplitude = [0.1]\n[seeds]\nroot = 11\n")
        with mock.patch.object(sys, "stderr", io.StringIO()):
            self.assertEqual(sweep_main([spec_path, "--out", d, "--workers", "1", "--quiet"]), 0)
        self.assertEqual(_leftovers(d), [])
        self.assertTrue(os.path.isfile(os.path.join(d, SCHEMA_NAME)))

    def test_an_unsorted_table_is_sorted_by_the_next_sweep(self):
        """A killed sweep may leave completion order; the next sweep (nothing to run) sorts, losing no row."""
        d = os.path.join(self.tmp, "unsorted")
        shutil.copytree(self.out, d)
        path = os.path.join(d, "results.csv")
        rows = read_rows(path)
        write_table(path, rows[::-1], self._header())
        self.assertEqual(run_sweep(SPEC, d, workers=1, progress=False)[0]["run_id"], self.runs[0].run_id)
        self.assertEqual(read_rows(path), rows)                              # every row, text unchanged
        self.assertEqual(Sweep(SPEC, d).pending(), [])                       # and the sweep still resumes

    def test_extended_folder_puts_other_segments_after(self):
        """An extended folder's table: the newest SPEC's runs in its order (a recorded run of it where it
        is in that SPEC), then the rows of the older segment that the new SPEC does not have."""
        base = dict(SPEC, grid={"theAmplitude": [0.1, 0.3]}, seeds={"root": 11, "repetitions": 1})
        grown = dict(SPEC, grid={"theAmplitude": [0.2, 0.1]}, seeds={"root": 11, "repetitions": 1})
        d = os.path.join(self.tmp, "extended")
        fake = mock.patch.object(api, "measure_run", _fake_run)   # the runs, not the checks
        sweep = Sweep(base, d)
        with fake, concurrent.futures.ThreadPoolExecutor(1) as ex:
            first = sweep.run(executor=ex, progress=False)                 # A = 0.1, then 0.3
        sweep = Sweep(grown, d, extend=True)
        with fake, concurrent.futures.ThreadPoolExecutor(1) as ex:
            rows = sweep.run(executor=ex, progress=False)                  # runs A = 0.2 only
        table = [typed_row(r) for r in read_rows(os.path.join(d, "results.csv"))]
        self.assertEqual([r["theAmplitude"] for r in table], [0.2, 0.1, 0.3])
        self.assertEqual([r["run_id"] for r in table[1:]], [first[0]["run_id"], first[1]["run_id"]])
        self.assertEqual(len(rows), 3)                                      # no row lost
        self.assertEqual(_leftovers(d), [])

    # -- types ------------------------------------------------------------------------------------
    def test_run_sweep_rows_are_typed(self):
        for row in self.rows:
            for name in ("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal", "frequency_Hz", "omega", "dt",
                         "theAmplitude", "wall_time_s"):
                self.assertIs(type(row[name]), float, name)
            for name in ("N", "cut_lines", "repetition", "N_steps", "seed_entropy"):
                self.assertIs(type(row[name]), int, name)
            for name in ("do_permanent_links", "doDrawing", "saveData"):
                self.assertIs(type(row[name]), bool, name)
            self.assertIn(row["steady_state"], (True, False, None))
            self.assertEqual(row["spawn_key"], [self.runs[[r.run_id for r in self.runs].index(row["run_id"])].index])
            self.assertIsInstance(row["run_id"], str)

    def test_repetition_and_spawn_key(self):
        """Run k = repetition · n_points + point has spawn key [k] (docs/sweeps.md): the repetition column
        is the run's repetition, the spawn key's last element divided by the number of points."""
        n_points = len(SPEC["grid"]["theAmplitude"])
        for row, run in zip(self.rows, self.runs):
            self.assertEqual(row["repetition"], run.repetition)
            self.assertEqual(row["repetition"], row["spawn_key"][-1] // n_points)
        self.assertEqual(sorted(r["repetition"] for r in self.rows), [0, 0, 1, 1])

    def test_time_scales_match_the_run(self):
        """omega is 2π·frequency_Hz exactly; frequency, dt and N_steps are those of the same run done directly."""
        run = self.runs[2]
        res = doParticleShearSimulation(**dict(run.parameters, verbose=False, return_result=True,
                                               seed=np.random.SeedSequence(run.seed_entropy,
                                                                           spawn_key=run.spawn_key)))
        row = self.rows[2]
        self.assertEqual(row["run_id"], res.run_id)
        self.assertEqual(row["frequency_Hz"], res.f)
        self.assertEqual(row["dt"], res.dt)
        self.assertEqual(row["N_steps"], res.N_steps)
        self.assertEqual(row["Gp_surface"], res.G_surface[0])
        for r in self.rows:
            self.assertEqual(r["omega"], 2 * math.pi * r["frequency_Hz"])
        d = res.to_dict()
        self.assertEqual(d["omega"], 2 * math.pi * res.f)
        self.assertEqual((d["frequency_Hz"], d["dt"], d["N_steps"], d["repetition"]), (res.f, res.dt, res.N_steps, 0))
        self.assertEqual(list(d), self._header())                     # to_dict is a row, in table order
        if pd is not None:
            s = res.to_dataframe()
            self.assertEqual(list(s.index), list(d))
            self.assertEqual(s["N_steps"], res.N_steps)
            self.assertEqual(s.name, res.run_id)

    def test_schema_describes_every_column(self):
        schema = read_schema(os.path.join(self.out, SCHEMA_NAME))
        cols = schema["columns"]
        self.assertEqual([c["name"] for c in cols], self._header())
        for c in cols:
            self.assertIn(c["type"], COLUMN_TYPES)
            self.assertTrue(c["description"], c["name"])
        by = {c["name"]: c for c in cols}
        self.assertEqual({n: by[n]["unit"] for n in ("Gp_surface", "Gpp_internal_se", "frequency_Hz", "omega", "dt",
                                                        "wall_time_s", "Young_modulus_spheres")},
                         {"Gp_surface": "Pa", "Gpp_internal_se": "Pa", "frequency_Hz": "Hz", "omega": "rad/s",
                          "dt": "s", "wall_time_s": "s", "Young_modulus_spheres": "Pa"})
        self.assertEqual({n: by[n]["type"] for n in ("Gp_surface", "N", "N_steps", "steady_state", "run_id",
                                                        "spawn_key", "seed_entropy", "theAmplitude")},
                         {"Gp_surface": "float", "N": "int", "N_steps": "int", "steady_state": "bool",
                          "run_id": "string", "spawn_key": "int_list", "seed_entropy": "bigint",
                          "theAmplitude": "float"})
        # a parameter's type is the one its docstring declares (int, float, bool or a string choice)
        import inspect
        import re
        doc = inspect.getdoc(doParticleShearSimulation)
        for name, kind in re.findall(r"^(\w+) : (\w+|\{)", doc, flags=re.M):
            if name in by:
                want = {"int": "int", "float": "float", "bool": "bool", "str": "string", "{": "string"}[kind]
                self.assertEqual(by[name]["type"], want, name)

    @unittest.skipIf(pd is None, "pandas is not installed")
    def test_load_results_dtypes(self):
        df = load_results(self.out)
        self.assertEqual(list(df.columns), self._header())
        self.assertEqual(len(df), 4)
        for name in ("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal", "Gp_surface_se", "frequency_Hz",
                     "omega", "dt", "theAmplitude", "density", "wall_time_s"):
            self.assertEqual(df[name].dtype, np.float64, name)
        for name in ("N", "cut_lines", "repetition"):
            self.assertEqual(df[name].dtype, np.int64, name)
        self.assertEqual(str(df["N_steps"].dtype), "Int64")                # nullable: empty for a failed run
        self.assertEqual(str(df["steady_state"].dtype), "boolean")         # True / False / <NA>
        for name in ("do_permanent_links", "saveData", "doDrawing"):
            self.assertEqual(df[name].dtype, np.bool_, name)
        for name in ("run_id", "status", "backend", "output_path"):
            self.assertTrue(pd.api.types.is_string_dtype(df[name]), name)
        self.assertEqual(list(df["run_id"]), [r.run_id for r in self.runs])
        self.assertTrue((df["omega"] == 2 * np.pi * df["frequency_Hz"]).all())
        self.assertEqual(list(df["Gp_surface"]), [r["Gp_surface"] for r in self.rows])
        self.assertEqual(list(df["spawn_key"]), [[r.index] for r in self.runs])

    def test_load_results_without_pandas(self):
        with mock.patch.dict(sys.modules, {"pandas": None}):
            rows = load_results(self.out)
        self.assertIsInstance(rows, list)
        self.assertEqual(rows, load_results(os.path.join(self.out, "results.csv"), as_frame=False))
        self.assertEqual([r["run_id"] for r in rows], [r["run_id"] for r in self.rows])
        self.assertEqual([(r["N"], r["N_steps"], r["Gp_surface"]) for r in rows],
                         [(r["N"], r["N_steps"], r["Gp_surface"]) for r in self.rows])
        with self.assertRaisesRegex(ValueError, "as_frame='yes' is invalid"):
            load_results(self.out, as_frame="yes")
        # a DataFrame asked for without pandas: an ImportError naming the extra, before the table is read
        with mock.patch.dict(sys.modules, {"pandas": None}):
            with self.assertRaisesRegex(ImportError, r"as_frame=True\) needs pandas: pip install .*particleShear\[tables\]"):
                load_results(self.out, as_frame=True)
            with self.assertRaisesRegex(ImportError, r"particleShear\[tables\]"):
                load_results(os.path.join(self.tmp, "nowhere"), as_frame=True)     # checked before the folder
        with self.assertRaisesRegex(ValueError, "no results table"):
            load_results(os.path.join(self.tmp, "nowhere"))

    @unittest.skipIf(pq is None, "pyarrow is not installed")
    def test_parquet_carries_the_schema(self):
        import pyarrow as pa
        table = pq.read_table(os.path.join(self.out, "results.parquet"))
        schema = read_schema(os.path.join(self.out, SCHEMA_NAME))
        self.assertEqual(table.column_names, [c["name"] for c in schema["columns"]])
        want = {"float": pa.float64(), "int": pa.int64(), "bool": pa.bool_(), "string": pa.string(),
                "bigint": pa.string(), "int_list": pa.list_(pa.int64())}
        for c in schema["columns"]:
            field = table.schema.field(c["name"])
            self.assertEqual(field.type, want[c["type"]], c["name"])
            self.assertEqual(field.metadata[b"unit"].decode(), c["unit"])
            self.assertEqual(field.metadata[b"description"].decode(), c["description"])
        data = table.to_pydict()
        self.assertEqual(data["run_id"], [r["run_id"] for r in self.rows])
        self.assertEqual(data["N_steps"], [r["N_steps"] for r in self.rows])
        self.assertEqual(data["spawn_key"], [r["spawn_key"] for r in self.rows])
        self.assertEqual(data["Gp_surface"], [r["Gp_surface"] for r in self.rows])

    def test_failed_row_has_empty_run_columns(self):
        real = api.measure_run          # what the worker measures a sweep's run with

        @functools.wraps(real)
        def fail_small(run):
            if run["theAmplitude"] == 0.1:
                raise FloatingPointError("simulated failure")
            return real(run)

        d = os.path.join(self.tmp, "failed")
        spec = dict(SPEC, seeds={"root": 11, "repetitions": 1})
        with mock.patch.object(api, "measure_run", fail_small), \
                concurrent.futures.ThreadPoolExecutor(1) as ex:
            rows = run_sweep(spec, d, executor=ex, progress=False)
        self.assertEqual([r["status"] for r in rows], ["failed", "ok"])
        bad = rows[0]
        self.assertEqual(bad["repetition"], 0)
        for name in ("Gp_surface", "frequency_Hz", "omega", "dt", "N_steps"):
            self.assertIsNone(bad[name], name)
        self.assertEqual(rows[1]["omega"], 2 * math.pi * rows[1]["frequency_Hz"])
        if pd is not None:
            df = load_results(d)
            self.assertTrue(np.isnan(df["frequency_Hz"][0]))
            self.assertTrue(pd.isna(df["N_steps"][0]))
            self.assertEqual(int(df["N_steps"][1]), rows[1]["N_steps"])
            self.assertEqual(df["Gp_surface"].dtype, np.float64)

    def test_a_cell_of_the_wrong_type_is_refused(self):
        d = os.path.join(self.tmp, "bad_cell")
        shutil.copytree(self.out, d)
        path = os.path.join(d, "results.csv")
        rows = read_rows(path)
        rows[1]["N_steps"] = "many"
        write_table(path, rows, self._header())
        with self.assertRaisesRegex(ValueError, r"line 3: column N_steps='many' is not of type int"):
            load_results(d)
        self.assertEqual(typed_row({"N_steps": "895", "steady_state": ""}), {"N_steps": 895, "steady_state": None})


if __name__ == "__main__":
    unittest.main()
