"""Sweeps under faults: killed drivers and workers, edited SPECs, racing processes, damaged tables
and files, huge SPECs.

Every wait is for an event (a row in the table, a line on a pipe, a process gone), bounded by a
generous deadline that only a broken implementation reaches; nothing depends on the machine's speed.
Runs are tiny (N = 30, relative_frequency = 0.5: ≈ 0.25 s each).
"""
import concurrent.futures
import csv
import functools
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from unittest import mock

import numpy as np

from particleShearTest.sweep_copies import CopiesOfOneSweep
from particleShear import doParticleShearSimulationSeries
from particleShear.run.validation import RunParameters
from particleShear.sweep import Sweep, expand_runs, parse_spec, run_sweep
from particleShear.sweep.cli import main as sweep_main
from particleShear.sweep.locks import FolderBusyError
from particleShear.sweep.record import RECORD_NAME
from particleShear.sweep.schema import typed_row

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TINY = dict(N=30, relative_frequency=0.5, pre_periods=0.5, periods=1, post_periods=0.5, doDrawing=False,
            plotStress=False, saveData=True)
SPEC = {"parameters": dict(TINY), "grid": {"theAmplitude": [0.2, 0.1]},
        "zip": [{"do_permanent_links": [True, False], "cut_lines": [2, 0]}], "seeds": {"root": 7, "repetitions": 1}}
#: a longer sweep for the kill tests: 12 runs, so that it is still running when the first row appears
LONG = dict(SPEC, seeds={"root": 7, "repetitions": 3})
DEADLINE_S = 120
VOLATILE = ("wall_time_s", "output_path")


def _stable(rows):
    """Rows without the volatile columns; NaN (a measure that is not defined) as the text "nan", so that
    equal rows compare equal (typed rows: ``nan != nan``)."""
    return [{k: ("nan" if isinstance(v, float) and v != v else v) for k, v in r.items() if k not in VOLATILE}
            for r in rows]


def _rows(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _wait_for(predicate, what):
    deadline = time.monotonic() + DEADLINE_S
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(0.02)
    raise AssertionError(f"timed out waiting for {what}")


def _children(pid):
    """PIDs of the live processes whose parent is ``pid`` (Linux /proc)."""
    out = []
    for e in os.listdir("/proc"):
        if not e.isdigit():
            continue
        try:
            with open(f"/proc/{e}/stat") as fh:
                stat = fh.read()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()
        if int(fields[1]) == pid and fields[0] != "Z":
            out.append(int(e))
    return out


def _alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as fh:
            stat = fh.read()
    except OSError:
        return False
    return stat[stat.rindex(")") + 2:].split()[0] != "Z"


def _write_spec(folder, doc, name="spec.json"):
    path = os.path.join(folder, name)
    with open(path, "w") as fh:
        json.dump(doc, fh)
    return path


def _cli(args, **kw):
    env = dict(os.environ, PYTHONPATH=REPO)
    return subprocess.Popen([sys.executable, "-m", "particleShear", "sweep", *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


@unittest.skipUnless(sys.platform.startswith("linux"), "reads /proc")
class TestKilledDriver(unittest.TestCase):
    """SIGKILL or SIGTERM of the driving process ends its workers and frees the folder."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="ps_faults_")
        self.spec = _write_spec(self.tmp, LONG)
        self.out = os.path.join(self.tmp, "out")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def _start_and_wait_for_a_row(self):
        proc = _cli([self.spec, "--out", self.out, "--workers", "2", "--quiet"])
        table = os.path.join(self.out, "results.csv")
        _wait_for(lambda: proc.poll() is not None or (os.path.exists(table) and len(_rows(table)) >= 1),
                  "the first row")
        self.assertIsNone(proc.poll(), "the sweep ended before it could be killed")
        workers = _children(proc.pid)
        self.assertTrue(workers, "no worker processes found")
        return proc, workers

    def _resume_is_complete(self):
        rows = run_sweep(self.spec, self.out, workers=2, progress=False)
        self.assertEqual(len(rows), 12)
        self.assertTrue(all(r["status"] == "ok" for r in rows))
        self.assertFalse(os.path.exists(os.path.join(self.out, "results.csv.lock")))
        self.assertFalse(os.path.exists(os.path.join(self.out, "runs")))
        self.assertEqual(len([e for e in os.listdir(self.out) if e.endswith(".txt")]), 12)

    def test_sigkill_of_the_driver_ends_its_workers(self):
        proc, workers = self._start_and_wait_for_a_row()
        os.kill(proc.pid, signal.SIGKILL)          # the driver only, not its process group
        proc.communicate(timeout=DEADLINE_S)
        _wait_for(lambda: not any(_alive(w) for w in workers), "the orphaned workers to exit")
        self._resume_is_complete()

    def test_sigterm_stops_at_once_with_status_143(self):
        proc, workers = self._start_and_wait_for_a_row()
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=DEADLINE_S)
        self.assertEqual(proc.returncode, 143, err)
        self.assertIn("terminated;", err)
        self.assertNotIn("Traceback", err)
        _wait_for(lambda: not any(_alive(w) for w in workers), "the workers to exit")
        self._resume_is_complete()


@unittest.skipUnless(sys.platform.startswith("linux"), "reads /proc")
class TestSigtermStopsRunningRuns(unittest.TestCase):
    def test_sigterm_kills_the_running_runs_instead_of_waiting_for_them(self):
        """Runs of many seconds each: after SIGTERM none may finish (a row would be appended)."""
        with tempfile.TemporaryDirectory() as d:
            spec = _write_spec(d, dict(SPEC, parameters=dict(TINY, periods=400), grid={"theAmplitude": [0.2]},
                                       zip=[], seeds={"root": 1, "repetitions": 3}))
            out = os.path.join(d, "out")
            proc = _cli([spec, "--out", out, "--workers", "2", "--quiet"])
            runs = os.path.join(out, "runs")

            def started():         # the run folders in the driver's scratch folder: the runs that started
                found = set()
                try:
                    for o in os.listdir(runs):
                        if os.path.isdir(os.path.join(runs, o)):
                            found |= {e for e in os.listdir(os.path.join(runs, o)) if not e.startswith(".")}
                except OSError:
                    pass
                return found

            _wait_for(lambda: proc.poll() is not None or len(started()) >= 2, "two running runs")
            before = started()
            workers = _children(proc.pid)
            proc.send_signal(signal.SIGTERM)
            after = set()
            while proc.poll() is None:        # a run takes many seconds: a run started now is seen
                after |= started()
                time.sleep(0.02)
            _, err = proc.communicate(timeout=DEADLINE_S)
            self.assertEqual(proc.returncode, 143, err)
            self.assertLessEqual(after, before, "a queued run started after SIGTERM")
            self.assertFalse(os.path.exists(os.path.join(out, "results.csv")) and _rows(os.path.join(out, "results.csv")),
                             "a run finished after SIGTERM: the workers were not stopped")
            _wait_for(lambda: not any(_alive(w) for w in workers), "the workers to exit")


class TestLockAndExitStatus(unittest.TestCase):
    def test_live_lock_refuses_with_status_3_dead_lock_is_taken_over(self):
        with tempfile.TemporaryDirectory() as d:
            spec = _write_spec(d, dict(SPEC, grid={"theAmplitude": [0.2]}, zip=[]))
            out = os.path.join(d, "out")
            os.makedirs(out)
            lock = os.path.join(out, "results.csv.lock")
            with open(lock, "w") as fh:          # a lock file left by a dead sweep: nobody holds it
                fh.write("pid 999999@elsewhere\n")
            self.assertEqual(len(run_sweep(spec, out, workers=1, progress=False)), 1)
            self.assertFalse(os.path.exists(lock))
            holder = subprocess.Popen(
                [sys.executable, "-c", "import fcntl, os, sys; fd = os.open(sys.argv[1], os.O_RDWR | os.O_CREAT); "
                 "os.write(fd, b'pid holder@test'); fcntl.lockf(fd, fcntl.LOCK_EX); print('locked', flush=True); "
                 "sys.stdin.read()", lock], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
            try:
                self.assertEqual(holder.stdout.readline().strip(), "locked")
                err = io.StringIO()
                with mock.patch.object(sys, "stderr", err):
                    self.assertEqual(sweep_main([spec, "--out", out, "--retry-failed"]), 3)
                self.assertIn("holder@test", err.getvalue())
                with self.assertRaises(FolderBusyError):
                    run_sweep(spec, out, progress=False)
            finally:
                holder.communicate("")


@unittest.skipUnless(hasattr(os, "fork"), "needs fork (the patched run reaches the workers through it)")
class TestKilledWorker(unittest.TestCase):
    def test_a_killed_worker_fails_its_run_and_the_sweep_goes_on(self):
        import multiprocessing
        if multiprocessing.get_start_method() != "fork":
            self.skipTest("the default start method is not fork")
        from particleShear.run import api
        real = api.measure_run          # what the worker measures a sweep's run with

        @functools.wraps(real)
        def oom(run):     # what the out-of-memory killer does to the worker of this run
            if run["theAmplitude"] == 0.1 and not run["do_permanent_links"]:
                os.kill(os.getpid(), signal.SIGKILL)
            return real(run)

        with tempfile.TemporaryDirectory() as d, mock.patch.object(api, "measure_run", oom):
            rows = run_sweep(SPEC, d, workers=2, progress=False)
        self.assertEqual([r["status"] for r in rows], ["ok", "ok", "ok", "failed"])
        self.assertIn("killed by SIGKILL", rows[3]["error"])
        self.assertEqual(rows[3]["error"].split(":")[0], "WorkerDied")


class TestStartMethods(unittest.TestCase):
    def test_forkserver_and_spawn_workers_run_and_watch_their_driver(self):
        import multiprocessing
        from particleShear.sweep import runner
        one = dict(SPEC, grid={"theAmplitude": [0.2]}, zip=[])
        for method in ("forkserver", "spawn"):
            if method not in multiprocessing.get_all_start_methods():
                continue
            with self.subTest(method=method), tempfile.TemporaryDirectory() as d, \
                    mock.patch.object(runner, "pool_context", lambda _: multiprocessing.get_context(method)):
                rows = run_sweep(one, d, workers=1, progress=False)
                self.assertEqual([r["status"] for r in rows], ["ok"], rows[0]["error"])

    def test_isolated_jobs_under_spawn(self):
        """The isolation after a worker died works with spawned processes (a CUDA sweep's start method)."""
        import multiprocessing
        from particleShear.sweep import pool
        from particleShear.sweep import run_identity
        runs = expand_runs(parse_spec(dict(SPEC, parameters=dict(TINY, saveData=False), grid={"theAmplitude": [0.2]},
                                           zip=[])))
        task = {"run_id": run_identity(runs[0].parameters, 7, (0,)), "index": 0, "parameters": runs[0].parameters,
                "seed_entropy": 7, "spawn_key": (0,), "out_dir": "", "keep_series": False}
        (job, outcomes), = list(pool.isolated([[task]], multiprocessing.get_context("spawn")))
        self.assertEqual(outcomes[0][0]["status"], "ok", outcomes[0][0]["error"])


class TestInterruptInTheCallersLoop(unittest.TestCase):
    @unittest.skipUnless(hasattr(os, "fork"), "needs the default pool")
    def test_ctrl_c_in_the_loop_body_lets_the_running_runs_finish(self):
        with tempfile.TemporaryDirectory() as d:
            sweep = Sweep(SPEC, d)
            seen = []
            with self.assertRaises(KeyboardInterrupt):
                for outcome in sweep.as_completed(workers=2, progress=False):
                    seen.append(outcome.row["run_id"])
                    raise KeyboardInterrupt     # as if Ctrl-C came while the caller handles the first outcome
            rows = _rows(os.path.join(d, "results.csv"))
            self.assertEqual(len(seen), 1)
            self.assertGreaterEqual(len(rows), 2, "the run that was running with the first was killed, not finished")
            self.assertTrue(all(r["status"] == "ok" for r in rows))
            self.assertEqual(len([e for e in os.listdir(d) if e.endswith(".txt")]), len(rows))


class TestSameRun(unittest.TestCase):
    def test_a_number_spelled_otherwise_and_numpy_inputs_are_the_same_run(self):
        with tempfile.TemporaryDirectory() as d:
            base = dict(SPEC, grid={"theAmplitude": [0.2]}, zip=[])
            run_sweep(base, d, workers=1, progress=False)
            respelled = dict(base, parameters=dict(TINY, periods=1.0, N=30.0))
            self.assertEqual(Sweep(respelled, d).pending(), [])
            kw = dict(TINY, cut_lines=0, mu=[0.01], N_repetitions=1, seed=3, max_workers=1, doDrawing=False)
            first = doParticleShearSimulationSeries(root_folder=d, amplitudes=[0.2], **kw)
            with mock.patch("particleShear.sweep.tasks.execute_run", side_effect=AssertionError("ran again")), \
                    concurrent.futures.ThreadPoolExecutor(1) as ex:
                again = doParticleShearSimulationSeries(root_folder=d, amplitudes=np.array([0.2]), executor=ex,
                                                        **dict(kw, plotStress=True))
            self.assertEqual(again[0].G_surface, first[0].G_surface)
            with open(os.path.join(d, "results.csv"), encoding="utf-8") as fh:
                self.assertNotIn("np.float64", fh.read())

    def test_control_characters_in_an_error_keep_the_row_one_line(self):
        from particleShear.run import api
        real = api.measure_run          # what the worker measures a sweep's run with

        @functools.wraps(real)
        def odd(run):
            if run["theAmplitude"] == 0.1:
                raise RuntimeError("line\rbreak\x0bvt\u2028ls\x85nel\nnl")
            return real(run)

        with tempfile.TemporaryDirectory() as d, mock.patch.object(api, "measure_run", odd), \
                concurrent.futures.ThreadPoolExecutor(2) as ex:
            run_sweep(SPEC, d, executor=ex, progress=False)
            rows = Sweep(SPEC, d).rows()
            self.assertEqual(len(rows), 4)
            self.assertEqual(rows[2]["error"], "RuntimeError: line break vt ls nel nl")
            with open(os.path.join(d, "results.csv"), encoding="utf-8") as fh:
                self.assertEqual(len(fh.read().split("\n")), 6)       # header, 4 rows, final newline
            self.assertFalse(os.path.exists(os.path.join(d, "results.csv.rejected")))
            self.assertEqual(list(Sweep(SPEC, d).as_completed(workers=1, progress=False)), [])


class TestScratchOwners(unittest.TestCase):
    def test_a_second_owner_in_one_process_keeps_the_first(self):
        from particleShear.sweep.locks import ScratchOwner
        with tempfile.TemporaryDirectory() as d:
            a = ScratchOwner(d)
            os.makedirs(os.path.join(a.path, "abc"))
            b = ScratchOwner(d)
            self.assertTrue(os.path.isdir(os.path.join(a.path, "abc")))
            b.close()
            self.assertTrue(os.path.isdir(a.path))
            a.close()
            self.assertFalse(os.path.exists(os.path.join(d, "runs")))


class TestExternalProcessPool(unittest.TestCase):
    @unittest.skipUnless(hasattr(os, "fork"), "needs fork (the patched run reaches the workers through it)")
    def test_a_broken_pool_of_the_caller_fails_its_runs_and_stops_clearly(self):
        import multiprocessing
        from particleShear.run import api
        real = api.measure_run          # what the worker measures a sweep's run with

        @functools.wraps(real)
        def oom(run):
            if run["theAmplitude"] == 0.1:
                os.kill(os.getpid(), signal.SIGKILL)
            return real(run)

        with tempfile.TemporaryDirectory() as d, mock.patch.object(api, "measure_run", oom), \
                concurrent.futures.ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as ex:
            with self.assertRaisesRegex(RuntimeError, "process pool is broken"):
                run_sweep(dict(SPEC, zip=[]), d, executor=ex, progress=False)
            rows = _rows(os.path.join(d, "results.csv"))
            self.assertEqual(rows[0]["status"], "ok")
            self.assertIn("BrokenProcessPool", rows[1]["error"])


class TestOneFolderOneSpec(unittest.TestCase):
    def test_changed_spec_is_refused_naming_the_change_and_extend_adds_only_new_runs(self):
        base = dict(SPEC, grid={"theAmplitude": [0.2]}, zip=[])
        with tempfile.TemporaryDirectory() as d:
            first = run_sweep(base, d, workers=1, progress=False)
            self.assertTrue(os.path.isfile(os.path.join(d, RECORD_NAME)))
            edited = dict(base, parameters=dict(TINY, N=32))
            with self.assertRaisesRegex(ValueError, r"parameters\.N: 30 -> 32.*--extend"):
                Sweep(edited, d)
            spec = _write_spec(d, edited, "edited.json")
            err = io.StringIO()
            with mock.patch.object(sys, "stderr", err):
                self.assertEqual(sweep_main([spec, "--out", d, "--dry-run"]), 2)
            self.assertIn("parameters.N", err.getvalue())
            self.assertEqual(len(_rows(os.path.join(d, "results.csv"))), 1)     # nothing ran, nothing added
            # extend: a new grid value and a repetition more; the recorded run is kept, not run again
            grown = dict(base, grid={"theAmplitude": [0.2, 0.1]}, seeds={"root": 7, "repetitions": 2})
            ran = [o.row for o in Sweep(grown, d, extend=True).as_completed(workers=1, progress=False)]
            self.assertEqual(len(ran), 3)
            self.assertNotIn(first[0]["run_id"], [r["run_id"] for r in ran])
            rows = Sweep(grown, d, extend=True).rows()
            self.assertEqual(len(rows), 4)
            self.assertEqual(_stable(rows[:1]), _stable(first))
            self.assertEqual(sorted(r["spawn_key"][0] for r in rows), [0, 1, 2, 3])   # distinct seeds
            # the extended folder resumes with the grown SPEC, and refuses the original one without --extend
            self.assertEqual(list(Sweep(grown, d).as_completed(workers=1, progress=False)), [])
            with self.assertRaisesRegex(ValueError, "another SPEC"):
                Sweep(base, d)


class TestVerifiedResume(CopiesOfOneSweep, unittest.TestCase):
    SPEC = SPEC

    def _resume(self, out):
        err = io.StringIO()
        ran = [o.row["run_id"] for o in Sweep(SPEC, out).as_completed(workers=1, stream=err)]
        return ran, err.getvalue()

    def test_copied_folder_with_a_deleted_file_runs_that_run_again(self):
        out = self._copy("deleted")
        victim = self.rows[1]
        os.remove(os.path.join(out, victim["output_path"]))
        ran, said = self._resume(out)
        self.assertEqual(ran, [victim["run_id"]])
        self.assertIn(f"run {victim['run_id']} runs again: its file", said)
        self.assertEqual(_stable(Sweep(SPEC, out).rows()), _stable(self.rows))
        self.assertEqual(len(_rows(os.path.join(out, "results.csv"))), 4)       # the stale row replaced

    def test_a_row_that_does_not_parse_runs_again(self):
        out = self._copy("abc")
        path = os.path.join(out, "results.csv")
        rows = _rows(path)
        rows[2]["Gp_surface"] = "abc"
        with open(path, "w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]), lineterminator="\n")
            w.writeheader()
            w.writerows(rows)
        ran, said = self._resume(out)
        self.assertEqual(ran, [rows[2]["run_id"]])
        self.assertIn("Gp_surface='abc' is not a number", said)
        self.assertEqual(_stable(Sweep(SPEC, out).rows()), _stable(self.rows))

    def test_bom_is_repaired_and_missing_column_refused_before_any_work(self):
        out = self._copy("bom")
        path = os.path.join(out, "results.csv")
        with open(path, "rb") as fh:
            data = fh.read()
        with open(path, "wb") as fh:
            fh.write(b"\xef\xbb\xbf" + data)
        ran, said = self._resume(out)
        self.assertEqual(ran, [])
        self.assertIn("byte-order mark", said)
        with open(path, "rb") as fh:
            self.assertEqual(fh.read(), data)
        # a missing column: refused before any run (nothing executes, the table is untouched)
        rows = _rows(path)
        os.remove(os.path.join(out, rows[0]["output_path"]))       # so that there would be work
        with open(path, "w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, fieldnames=[c for c in rows[0] if c != "theMu"], extrasaction="ignore",
                               lineterminator="\n")
            w.writeheader()
            w.writerows(rows)
        with open(path, "rb") as fh:
            before = fh.read()
        with mock.patch("particleShear.sweep.tasks.execute_run", side_effect=AssertionError("ran")), \
                concurrent.futures.ThreadPoolExecutor(1) as ex:
            with self.assertRaisesRegex(ValueError, r"missing \['theMu'\]"):
                run_sweep(SPEC, out, executor=ex, progress=False)
        with open(path, "rb") as fh:
            self.assertEqual(fh.read(), before)

    def test_lines_that_are_not_rows_are_moved_aside(self):
        out = self._copy("torn")
        path = os.path.join(out, "results.csv")
        with open(path, "a", encoding="utf-8") as fh:
            fh.write("not,a,row\n")
        ran, said = self._resume(out)
        self.assertEqual(ran, [])
        with open(path + ".rejected", encoding="utf-8") as fh:
            self.assertEqual(fh.read(), "not,a,row\n")
        self.assertEqual(len(_rows(path)), 4)

    def test_merge_prefers_ok_rows_and_keeps_tables_it_did_not_merge(self):
        out = self._copy("merge")
        path = os.path.join(out, "results.csv")
        rows = _rows(path)
        failed = dict(rows[0], status="failed", error="RuntimeError: x", Gp_surface="", Gpp_surface="",
                      Gp_internal="", Gpp_internal="", output_path="")
        task = os.path.join(out, "results.task-0000-of-0002.csv")
        foreign = os.path.join(out, "results.task-0001-of-0002.csv")
        for p, content in ((path, [failed] + rows[1:]), (task, [rows[0]]), (foreign, [dict(rows[1], run_id="0" * 12)])):
            with open(p, "w", newline="", encoding="utf-8") as fh:
                w = csv.DictWriter(fh, fieldnames=list(rows[0]), lineterminator="\n")
                w.writeheader()
                w.writerows(content)
        sweep = Sweep(SPEC, out)
        self.assertEqual(sweep.merge(), (4, 0))
        merged = [typed_row(r) for r in _rows(path)]
        self.assertEqual([r["status"] for r in merged], ["ok"] * 4)
        self.assertEqual(_stable(merged), _stable(self.rows))
        self.assertFalse(os.path.exists(task))
        self.assertTrue(os.path.exists(foreign))
        self.assertEqual([t for t, _ in sweep.kept_tables], [foreign])


class TestConcurrentProcesses(unittest.TestCase):
    def test_plain_sweep_and_task_run_on_one_folder(self):
        with tempfile.TemporaryDirectory() as d:
            spec = _write_spec(d, SPEC)
            out = os.path.join(d, "out")
            procs = [_cli([spec, "--out", out, "--workers", "1", "--quiet"]),
                     _cli([spec, "--out", out, "--workers", "1", "--quiet", "--task-index", "0", "--task-count", "1"])]
            for p in procs:
                _, err = p.communicate(timeout=DEADLINE_S)
                self.assertEqual(p.returncode, 0, err)
            with mock.patch.object(sys, "stdout", io.StringIO()):
                self.assertEqual(sweep_main([spec, "--out", out, "--merge"]), 0)
            rows = _rows(os.path.join(out, "results.csv"))
            self.assertEqual(sorted(r["run_id"] for r in rows), sorted(r.run_id for r in expand_runs(parse_spec(SPEC))))
            self.assertTrue(all(r["status"] == "ok" for r in rows))
            self.assertEqual(sorted(e for e in os.listdir(out) if e.endswith(".csv")), ["results.csv"])
            self.assertFalse(os.path.exists(os.path.join(out, "runs")))
            self.assertEqual(len([e for e in os.listdir(out) if e.endswith(".txt")]), 4)


class TestBoundedAndChecked(unittest.TestCase):
    def test_a_ten_million_run_spec_is_sized_without_enumerating_its_runs(self):
        doc = dict(SPEC, grid={"theAmplitude": [0.05 * (i + 1) for i in range(10)]}, zip=[],
                   seeds={"root": 1, "repetitions": 10 ** 6})
        calls = []
        from particleShear.simulation import provenance
        real = provenance.run_identity

        def counted(*a, **k):
            calls.append(1)
            return real(*a, **k)

        with tempfile.TemporaryDirectory() as d:
            spec = _write_spec(d, doc)
            out = io.StringIO()
            with mock.patch.object(provenance, "run_identity", counted), mock.patch.object(sys, "stdout", out):
                self.assertEqual(sweep_main([spec, "--out", os.path.join(d, "o"), "--dry-run", "--no-calibrate"]), 0)
            self.assertIn("10000000 runs", out.getvalue())
            self.assertLess(len(calls), 10)
            self.assertFalse(os.path.exists(os.path.join(d, "o")))
            spec = _write_spec(d, dict(doc, seeds={"root": 1, "repetitions": 10 ** 400}), "huge.json")
            err = io.StringIO()
            with mock.patch.object(sys, "stderr", err):
                self.assertEqual(sweep_main([spec, "--out", os.path.join(d, "o"), "--dry-run"]), 2)
            self.assertIn("seeds.repetitions=10**400 is invalid", err.getvalue())
            with self.assertRaisesRegex(ValueError, "parameter points"):
                parse_spec(dict(doc, grid={"theAmplitude": [0.1] * 200, "theMu": [0.1] * 200}))

    def test_workers_are_capped_at_the_pending_runs(self):
        from particleShear.sweep import pool
        seen = []
        real = pool.new_pool

        def recording(workers, mp_context=None):
            seen.append(workers)
            return real(workers, mp_context)

        with tempfile.TemporaryDirectory() as d, mock.patch.object(pool, "new_pool", recording):
            run_sweep(dict(SPEC, grid={"theAmplitude": [0.2]}, zip=[]), d, workers=8, progress=False)
        self.assertEqual(seen, [1])

    def test_targets_are_checked_before_any_work(self):
        with tempfile.TemporaryDirectory() as d:
            spec = _write_spec(d, SPEC)
            for args, flag in (([spec, "--out", os.path.join(d, "o"), "--scheduler", "not an address"], "--scheduler"),
                               ([spec, "--out", os.path.join(d, "none"), "--merge"], "--merge"),
                               ([spec, "--out", d, "--merge"], "no results table")):
                err = io.StringIO()
                with mock.patch.object(sys, "stderr", err):
                    self.assertEqual(sweep_main(args), 2, err.getvalue())
                self.assertIn(flag, err.getvalue())
            self.assertFalse(os.path.exists(os.path.join(d, "o")))

    def test_a_write_failure_is_a_failed_row_with_its_error(self):
        from particleShear.run import api
        real = api.measure_run          # what the worker measures a sweep's run with

        @functools.wraps(real)
        def full_disk(run):
            res = real(RunParameters(dict(run, saveData=False), run.run_id, run.seed_sequence, run.generator,
                                     run.cost))
            res.write_error = OSError(28, "No space left on device")
            return res

        with tempfile.TemporaryDirectory() as d, mock.patch.object(api, "measure_run", full_disk), \
                concurrent.futures.ThreadPoolExecutor(1) as ex:
            rows = run_sweep(dict(SPEC, grid={"theAmplitude": [0.2]}, zip=[]), d, executor=ex, progress=False)
            self.assertEqual(rows[0]["status"], "failed")
            self.assertEqual(rows[0]["error"], "write failed: OSError: [Errno 28] No space left on device")
            self.assertIsInstance(rows[0]["Gp_surface"], float)  # the computed moduli are kept
            spec = _write_spec(d, dict(SPEC, grid={"theAmplitude": [0.2]}, zip=[]))
            with mock.patch.object(sys, "stdout", io.StringIO()):
                self.assertEqual(sweep_main([spec, "--out", d, "--quiet"]), 1)    # non-zero: a row failed


if __name__ == "__main__":
    unittest.main()
