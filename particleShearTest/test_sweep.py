"""Sweeps: SPEC parsing and validation, run identity, results table, resume after a
SIGKILL, failed runs as rows, Dask and job-array execution equal to the local one, the series on
the sweep machinery.

Runs are tiny (N = 30, relative_frequency = 0.5: 112 steps per period, 2 periods in all), so a
run takes ≈ 0.25 s; the reference 4-run sweep is computed once per class.
"""
import concurrent.futures
import csv
import functools
import io
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from unittest import mock

import numpy as np

from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries, read_run
from particleShear.sweep import Sweep, expand_runs, load_spec, parse_spec, run_identity, run_sweep
from particleShear.sweep.cli import main as sweep_main
from particleShear.sweep.cost import run_steps
from particleShear.sweep.schema import typed_row
from particleShear.sweep.table import RESULT_COLUMNS

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TINY = dict(N=30, relative_frequency=0.5, pre_periods=0.5, periods=1, post_periods=0.5, doDrawing=False,
            plotStress=False, saveData=True)
SPEC = {"parameters": dict(TINY), "grid": {"theAmplitude": [0.2, 0.1]},
        "zip": [{"do_permanent_links": [True, False], "cut_lines": [2, 0]}], "seeds": {"root": 7, "repetitions": 1}}
TOML = """\
[parameters]
N = 30
relative_frequency = 0.5
pre_periods = 0.5
periods = 1
post_periods = 0.5
doDrawing = false
plotStress = false
saveData = true
[grid]
theAmplitude = [0.2, 0.1]
[[zip]]
do_permanent_links = [true, false]
cut_lines = [2, 0]
[seeds]
root = 7
repetitions = 1
"""
#: columns that legitimately differ between two executions of the same run
VOLATILE = ("wall_time_s", "output_path")


def _stable(rows, volatile=VOLATILE):
    """Rows without the ``volatile`` columns; NaN (a measure that is not defined) as the text "nan", so
    that equal rows compare equal (typed rows: ``nan != nan``)."""
    return [{k: ("nan" if isinstance(v, float) and v != v else v) for k, v in r.items() if k not in volatile}
            for r in rows]


def _lines(path):
    with open(path) as fh:
        return fh.read().splitlines()


def _txt(folder):
    return sorted(e for e in os.listdir(folder) if e.endswith(".txt"))


def _leftovers(folder):
    out = []
    for root, dirs, files in os.walk(folder):
        out += [os.path.join(root, f) for f in files if f.endswith(".part")]
    return out


class TestSpec(unittest.TestCase):
    def _err(self, doc, *words):
        with self.assertRaises((ValueError, TypeError)) as cm:
            expand_runs(parse_spec(doc))
        for w in words:
            self.assertIn(w, str(cm.exception))

    def test_errors_name_the_key(self):
        self._err({"seeds": {"root": 1}, "gird": {}}, "gird")
        self._err({"seeds": {"root": 1}, "grid": {"theAmplitud": [0.1]}}, "grid.theAmplitud")
        self._err({"seeds": {"root": 1}, "grid": {"theAmplitude": [0.1, -0.2]}}, "theAmplitude", "-0.2")
        self._err({"seeds": {"root": 1}, "grid": {"theAmplitude": 0.1}}, "grid.theAmplitude", "list")
        self._err({"seeds": {"root": 1}, "parameters": {"N": 1}}, "N=1")
        self._err({"seeds": {"root": 1}, "parameters": {"root_folder": "x"}}, "root_folder")
        self._err({"seeds": {"root": 1}, "parameters": {"N": 30}, "grid": {"N": [20]}}, "N", "twice")
        self._err({"seeds": {"root": 1}, "zip": [{"theMu": [0.1, 0.2], "N": [30]}]}, "zip[0]", "equal")
        self._err({"grid": {"theMu": [0.1]}}, "[seeds]")
        self._err({"seeds": {"root": -3}}, "seeds.root")
        self._err({"seeds": {"root": 1, "repetitions": 0}}, "seeds.repetitions")
        self._err({"seeds": {"root": 1, "reps": 2}}, "seeds.reps")
        self._err({"seeds": {"root": 1}, "parameters": {"integrator": "rk4"}}, "integrator")

    def test_toml_and_json_give_the_same_runs(self):
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "s.toml"), "w") as fh:
                fh.write(TOML)
            with open(os.path.join(d, "s.json"), "w") as fh:
                json.dump(SPEC, fh)
            a, b = expand_runs(load_spec(os.path.join(d, "s.toml"))), expand_runs(load_spec(os.path.join(d, "s.json")))
            with self.assertRaises(ValueError):
                load_spec(os.path.join(d, "s.yaml"))
        self.assertEqual([r.run_id for r in a], [r.run_id for r in b])
        self.assertEqual(len(a), 4)
        # the grid key varies slowest, the zip group fastest
        self.assertEqual([(r.parameters["theAmplitude"], r.parameters["do_permanent_links"],
                           r.parameters["cut_lines"]) for r in a],
                         [(0.2, True, 2), (0.2, False, 0), (0.1, True, 2), (0.1, False, 0)])

    def test_seeds_are_the_spawned_children_of_the_root(self):
        runs = expand_runs(parse_spec(dict(SPEC, seeds={"root": 11, "repetitions": 3})))
        children = np.random.SeedSequence(11).spawn(len(runs))
        for r, c in zip(runs, children):
            self.assertEqual((r.seed_entropy, r.spawn_key), (c.entropy, c.spawn_key))
        self.assertEqual(len({r.run_id for r in runs}), 12)
        # more repetitions keep the ids of the earlier runs
        fewer = expand_runs(parse_spec(dict(SPEC, seeds={"root": 11, "repetitions": 2})))
        self.assertEqual([r.run_id for r in fewer], [r.run_id for r in runs[:8]])

    def test_identity(self):
        p = {"N": 30, "theMu": 0.1, "saveData": True}
        rid = run_identity(p, 5, (1,))
        self.assertRegex(rid, r"^[0-9a-f]{12}$")
        self.assertEqual(rid, run_identity({"saveData": True, "theMu": 0.1, "N": 30.0, "root_folder": "/x"}, 5, [1]))
        self.assertNotEqual(rid, run_identity(p, 5, (2,)))
        self.assertNotEqual(rid, run_identity(p, 6, (1,)))
        self.assertNotEqual(rid, run_identity(dict(p, theMu=0.1000001), 5, (1,)))
        self.assertNotEqual(rid, run_identity(dict(p, saveData=1), 5, (1,)))

    def test_step_count_matches_a_run(self):
        """The cost model's step count is the number of steps a run actually takes."""
        runs = expand_runs(parse_spec(SPEC))
        r = doParticleShearSimulation(**dict(runs[1].parameters, saveData=False, seed=1, verbose=False,
                                             return_result=True))
        self.assertEqual(run_steps(runs[1].parameters), r.N_steps)


class TestSweep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="ps_sweep_")
        cls.ref = os.path.join(cls.tmp, "ref")
        cls.rows = run_sweep(SPEC, cls.ref, workers=2, progress=False)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_table_and_files(self):
        runs = expand_runs(parse_spec(SPEC))
        with open(os.path.join(self.ref, "results.csv"), newline="") as fh:
            table = list(csv.reader(fh))
        self.assertEqual(tuple(table[0][:len(RESULT_COLUMNS)]), RESULT_COLUMNS)
        self.assertEqual(table[0][-5:], ["seed_entropy", "spawn_key", "package_version", "wall_time_s",
                                         "output_path"])
        self.assertEqual(len(table), 5)
        self.assertEqual([r["run_id"] for r in self.rows], [r.run_id for r in runs])
        self.assertTrue(all(r["status"] == "ok" and r["error"] == "" for r in self.rows))
        names = _txt(self.ref)
        self.assertEqual(len(names), 4)                       # one text file per run, nothing else
        for r in self.rows:
            self.assertEqual(os.path.dirname(r["output_path"]), "")     # relative to the sweep folder
            self.assertTrue(os.path.isfile(os.path.join(self.ref, r["output_path"])))
            with open(os.path.join(self.ref, r["output_path"][:-len(".txt")] + ".json"), encoding="utf-8") as fh:
                self.assertEqual(json.load(fh)["file"], r["output_path"])   # the sidecar names the published file
            self.assertEqual(read_run(os.path.join(self.ref, r["output_path"]))["t"].size, run_steps(
                dict(runs[0].parameters)))
            self.assertTrue(os.path.basename(r["output_path"]).endswith("_nr_" + r["run_id"] + ".txt"))
            self.assertTrue(os.path.basename(r["output_path"]).startswith(
                "dermal_filler0.01_f_" if r["do_permanent_links"] else "dermal_filler_uncrosslinked0.01_f_"))
        self.assertEqual(_leftovers(self.ref), [])
        self.assertFalse(os.path.exists(os.path.join(self.ref, "runs")))
        try:
            import pyarrow.parquet as pq
        except ImportError:  # pragma: no cover - optional extra
            return
        pt = pq.read_table(os.path.join(self.ref, "results.parquet")).to_pydict()
        # the same table as the CSV; floats round-trip through their repr, flags are Arrow booleans
        self.assertEqual(dict(zip(pt["run_id"], pt["Gp_surface"])),
                         {r["run_id"]: float(r["Gp_surface"]) for r in self.rows})
        self.assertEqual(dict(zip(pt["run_id"], pt["do_permanent_links"])),
                         {r["run_id"]: r["do_permanent_links"] for r in self.rows})

    def test_file_header_names_the_row_id(self):
        """The run id in a file's provenance header is the id of its row and of its file name."""
        for r in self.rows:
            with open(os.path.join(self.ref, r["output_path"]), encoding="utf-8") as fh:
                head = fh.read(20000)
            ids = re.findall(r"^\tRun id: (\S+)$", head, flags=re.M)
            self.assertEqual(ids, [r["run_id"]])

    def test_row_is_the_run(self):
        """A row holds the moduli of the same run done directly with the same seed, and equals to_dict()."""
        run = expand_runs(parse_spec(SPEC))[3]
        res = doParticleShearSimulation(**dict(run.parameters, saveData=False, verbose=False, return_result=True,
                                               seed=np.random.SeedSequence(7).spawn(4)[3]))
        row = self.rows[3]
        self.assertEqual(float(row["Gp_surface"]), res.G_surface[0])
        self.assertEqual(float(row["Gpp_internal"]), res.G_internal[1])
        res.parameters.update(saveData=True)
        d = res.to_dict()
        self.assertEqual(list(d)[:len(RESULT_COLUMNS)], list(RESULT_COLUMNS))
        self.assertEqual(d["run_id"], row["run_id"])
        self.assertEqual(d["spawn_key"], [3])

    def test_rerun_skips_all(self):
        before = {n: os.stat(os.path.join(self.ref, n)).st_mtime_ns for n in _txt(self.ref)}
        with open(os.path.join(self.ref, "results.csv"), "rb") as fh:
            table = fh.read()
        done = list(Sweep(SPEC, self.ref).as_completed(workers=1, progress=False))
        self.assertEqual(done, [])
        with open(os.path.join(self.ref, "results.csv"), "rb") as fh:
            self.assertEqual(fh.read(), table)
        self.assertEqual({n: os.stat(os.path.join(self.ref, n)).st_mtime_ns for n in _txt(self.ref)}, before)

    def test_sigkill_then_resume(self):
        out = os.path.join(self.tmp, "killed")
        spec_path = os.path.join(self.tmp, "spec.toml")
        with open(spec_path, "w") as fh:
            fh.write(TOML)
        env = dict(os.environ, PYTHONPATH=REPO)
        proc = subprocess.Popen([sys.executable, "-m", "particleShear", "sweep", spec_path, "--out", out,
                                 "--workers", "1", "--quiet"], env=env, start_new_session=True,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        table = os.path.join(out, "results.csv")
        try:
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline and proc.poll() is None:   # kill after the first row
                if os.path.exists(table) and len(_lines(table)) >= 2:
                    break
                time.sleep(0.01)
        finally:
            os.killpg(proc.pid, signal.SIGKILL)   # the whole job, as a scheduler kills it
            proc.wait(timeout=30)
        n_before = len(_lines(table)) - 1
        self.assertLess(n_before, 4, "the sweep finished before it was killed: nothing to resume")
        rows = run_sweep(spec_path, out, workers=1, progress=False)
        self.assertEqual(_stable(rows), _stable(self.rows))
        self.assertEqual(_txt(out), _txt(self.ref))
        self.assertEqual(len(_lines(table)), 5)        # no duplicate row
        self.assertEqual(_leftovers(out), [])
        for name in _txt(out):                                          # same numbers in every file
            a, b = _lines(os.path.join(out, name)), _lines(os.path.join(self.ref, name))
            self.assertEqual(a[-100:], b[-100:])

    def test_failed_run_is_a_row(self):
        from particleShear.run import api
        real = api.measure_run          # what the worker measures a sweep's run with

        @functools.wraps(real)
        def flaky(run):
            if run["theAmplitude"] == 0.1 and not run["do_permanent_links"]:
                raise FloatingPointError("simulated node failure")
            return real(run)

        out = os.path.join(self.tmp, "failing")
        with mock.patch.object(api, "measure_run", flaky), \
                concurrent.futures.ThreadPoolExecutor(2) as ex:
            rows = run_sweep(SPEC, out, executor=ex, progress=False)
        self.assertEqual([r["status"] for r in rows], ["ok", "ok", "ok", "failed"])
        self.assertEqual(rows[3]["error"], "FloatingPointError: simulated node failure")
        self.assertIsNone(rows[3]["Gp_surface"])                 # empty in the table: no modulus
        self.assertEqual(_stable(rows[:3]), _stable(self.rows[:3]))
        self.assertEqual(len(_txt(out)), 3)
        # failed rows count as finished; --retry-failed runs them again and replaces the row
        self.assertEqual(Sweep(SPEC, out).pending(), [])
        rows = run_sweep(SPEC, out, workers=1, retry_failed=True, progress=False)
        self.assertEqual(_stable(rows), _stable(self.rows))
        self.assertEqual(len(_lines(os.path.join(out, "results.csv"))), 5)

    def test_dask_local_cluster_equals_local(self):
        from dask.distributed import Client, LocalCluster
        out = os.path.join(self.tmp, "dask")
        with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster, \
                Client(cluster) as client:
            rows = run_sweep(SPEC, out, executor=client.get_executor(), progress=False)
        self.assertEqual(_stable(rows), _stable(self.rows))
        self.assertEqual(_txt(out), _txt(self.ref))
        for name in _txt(out):                                          # every per-step value
            self.assertEqual(_lines(os.path.join(out, name))[-100:], _lines(os.path.join(self.ref, name))[-100:])

    def test_batched_sweep_equals_unbatched(self):
        """--batch-size: the runs of one schedule measured as replicas of one batch give the same rows and files."""
        out = os.path.join(self.tmp, "batched")
        rows = run_sweep(SPEC, out, workers=1, progress=False, batch_size=4)
        self.assertEqual(_stable(rows), _stable(self.rows))
        self.assertEqual(_txt(out), _txt(self.ref))
        for name in _txt(out):
            self.assertEqual(_lines(os.path.join(out, name))[-100:], _lines(os.path.join(self.ref, name))[-100:])
        self.assertEqual(_leftovers(out), [])
        self.assertEqual(_stable(run_sweep(SPEC, out, workers=1, progress=False, batch_size=4), volatile=()),
                         _stable(rows, volatile=()))   # resumes: nothing to run
        with self.assertRaisesRegex(ValueError, "--batch-size"):
            run_sweep(SPEC, out, progress=False, batch_size=0)

    def test_task_array_and_merge(self):
        out = os.path.join(self.tmp, "array")
        shares = []
        for i in range(3):
            shares.append(run_sweep(SPEC, out, task_index=i, task_count=3, workers=1, progress=False))
        self.assertEqual(sorted(len(Sweep(SPEC, out, task_index=i, task_count=3).my_runs()) for i in range(3)),
                         [1, 1, 2])
        err = io.StringIO()
        with mock.patch.object(sys, "stdout", err):
            self.assertEqual(sweep_main([os.path.join(self.tmp, "x.json"), "--out", out, "--merge"]), 2)  # no SPEC
        spec_path = os.path.join(self.tmp, "arr.json")
        with open(spec_path, "w") as fh:
            json.dump(SPEC, fh)
        with mock.patch.object(sys, "stdout", io.StringIO()):
            self.assertEqual(sweep_main([spec_path, "--out", out, "--merge"]), 0)
        self.assertEqual(sorted(e for e in os.listdir(out) if e.endswith(".csv")), ["results.csv"])
        with open(os.path.join(out, "results.csv"), newline="") as fh:
            merged = [typed_row(r) for r in csv.DictReader(fh)]
        self.assertEqual(_stable(merged), _stable(self.rows))

    def test_cli_dry_run_and_bad_input(self):
        spec_path = os.path.join(self.tmp, "dry.json")
        with open(spec_path, "w") as fh:
            json.dump(dict(SPEC, seeds={"root": 7, "repetitions": 6}), fh)
        out = io.StringIO()
        with mock.patch.object(sys, "stdout", out):
            self.assertEqual(sweep_main([spec_path, "--out", os.path.join(self.tmp, "dry"), "--dry-run", "--no-calibrate"]), 0)
        self.assertIn("24 runs, 5,352 protocol steps", out.getvalue())     # 24 × 223 steps
        self.assertFalse(os.path.exists(os.path.join(self.tmp, "dry")))
        err = io.StringIO()
        with mock.patch.object(sys, "stderr", err):
            self.assertEqual(sweep_main([spec_path, "--out", self.tmp, "--workers", "0"]), 2)
        self.assertIn("--workers", err.getvalue())


class TestSeriesOnSweep(unittest.TestCase):
    def test_series_resumes_in_root_folder(self):
        kw = dict(TINY, cut_lines=2, amplitudes=[0.2], mu=[0.01], N_repetitions=2, seed=3)
        with tempfile.TemporaryDirectory() as d, concurrent.futures.ThreadPoolExecutor(2) as ex:
            first = doParticleShearSimulationSeries(root_folder=d, executor=ex, **kw)
            names = _txt(d)
            with mock.patch("particleShear.sweep.tasks.execute_run", side_effect=AssertionError("ran again")):
                again = doParticleShearSimulationSeries(root_folder=d, executor=ex, **kw)
            self.assertEqual(_txt(d), names)
        self.assertEqual(len(names), 2)
        self.assertEqual([r.G_surface for r in again], [r.G_surface for r in first])
        self.assertEqual([r.spawn_key for r in first], [(0,), (1,)])


if __name__ == "__main__":
    unittest.main()
