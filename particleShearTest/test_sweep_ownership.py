"""A sweep touches only what it made, and resume verifies every kept run.

* scratch: ``DIR/runs`` may hold the user's folders and files, old ones included (mtimes set in
  the past with ``os.utime``), folders of dead sweeps, and symbolic links; a sweep removes only the
  marked scratch folders of dead sweeps, names what it leaves alone, and follows no link;
* links: a symbolic link at ``DIR/runs``, a table, a lock, the record, the schema, the Parquet copy
  or a run file is never written or deleted through (refused before any work, or — for a run
  file — not trusted: the run runs again and its new file replaces the link, not its target);
* resume: a kept run without sidecar runs again (said); a file copied from another run is refused
  with or without its sidecar; a duplicated row counts once and is set aside.

Real processes (the CLI, a killed scratch owner) and real files throughout; scenes are tiny
(N = 30, one period: ≈ 0.3 s a run).
"""
import csv
import io
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import unittest

from particleShear.sweep import Sweep, run_sweep
from particleShearTest.sweep_copies import CopiesOfOneSweep
from particleShear.sweep.locks import SCRATCH_MARKER, ScratchOwner, foreign_entries, remove_dead_scratch

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TINY = dict(N=30, relative_frequency=0.5, pre_periods=0.5, periods=1, post_periods=0.5, doDrawing=False,
            plotStress=False, saveData=True)
SPEC = {"parameters": dict(TINY), "grid": {"theAmplitude": [0.2, 0.1]},
        "zip": [{"do_permanent_links": [True, False], "cut_lines": [2, 0]}], "seeds": {"root": 7, "repetitions": 1}}
ONE = dict(SPEC, grid={"theAmplitude": [0.2]}, zip=[])
TWO_HOURS_AGO = time.time() - 7200
ENV = dict(os.environ, PYTHONPATH=REPO)


def _cli(*args):
    """Run ``particleShear sweep ARGS`` to its end; ``(rc, what it printed)`` (stdout and stderr together)."""
    p = subprocess.run([sys.executable, "-m", "particleShear", "sweep", *args, "--workers", "1"], env=ENV,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=300)
    return p.returncode, p.stdout


def _write_spec(folder, doc):
    path = os.path.join(folder, "spec.json")
    with open(path, "w") as fh:
        json.dump(doc, fh)
    return path


def _rows(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _old(*paths):
    for p in paths:
        os.utime(p, (TWO_HOURS_AGO, TWO_HOURS_AGO), follow_symlinks=not os.path.islink(p))


def _read(path):
    with open(path, "rb") as fh:
        return fh.read()


def _tree(path):
    """``{relative path: bytes or 'dir' or 'link -> target'}`` of everything under ``path`` (links not followed)."""
    out = {}
    for root, dirs, files in os.walk(path):
        for n in dirs + files:
            p = os.path.join(root, n)
            rel = os.path.relpath(p, path)
            out[rel] = f"link -> {os.readlink(p)}" if os.path.islink(p) else "dir" if os.path.isdir(p) else _read(p)
    return out


def _dead_owner(out_dir):
    """A scratch folder of a sweep process that died (a real process, killed before it could clean up)."""
    code = ("import os, sys; from particleShear.sweep.locks import ScratchOwner; o = ScratchOwner(sys.argv[1]); "
            "os.makedirs(os.path.join(o.path, 'abc123')); open(os.path.join(o.path, 'abc123', 'x.txt'), 'w').write('x'); "
            "print(os.path.basename(o.path), flush=True); os._exit(0)")
    p = subprocess.run([sys.executable, "-c", code, out_dir], env=ENV, stdout=subprocess.PIPE, text=True, check=True)
    return p.stdout.strip()


class TestScratchIsTheSweeps(unittest.TestCase):
    """Why 1: ``mkdir -p D/runs/mine && echo x > D/runs/mine/notes.txt && touch -d '2 hours ago' D/runs/mine``."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="ps_own_")
        self.spec = _write_spec(self.tmp, ONE)
        self.out = os.path.join(self.tmp, "D")
        self.runs = os.path.join(self.out, "runs")
        self.outside = os.path.join(self.tmp, "outside")
        os.makedirs(os.path.join(self.outside, "sub"))
        with open(os.path.join(self.outside, "sub", "data.txt"), "w") as fh:
            fh.write("precious\n")
        with open(os.path.join(self.outside, "file.txt"), "w") as fh:
            fh.write("precious\n")
        _old(os.path.join(self.outside, "sub"), self.outside)

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def test_user_entries_under_runs_are_kept_and_named_dead_scratch_is_removed(self):
        os.makedirs(os.path.join(self.runs, "mine"))
        with open(os.path.join(self.runs, "mine", "notes.txt"), "w") as fh:
            fh.write("x\n")
        os.makedirs(os.path.join(self.runs, "host-1-deadbeef", "abc"))     # an older layout / a look-alike
        with open(os.path.join(self.runs, "host-1-deadbeef.lock"), "w"):
            pass                                                            # an empty lock nobody holds
        os.makedirs(os.path.join(self.runs, "copied"))                     # a marker copied from another folder
        with open(os.path.join(self.runs, "copied", SCRATCH_MARKER), "w") as fh:
            fh.write(json.dumps({"format": "particleShear sweep scratch 1", "owner": "elsewhere"}) + "\n")
        with open(os.path.join(self.runs, "stray.txt"), "w") as fh:
            fh.write("y\n")
        os.symlink(os.path.join(self.outside, "sub"), os.path.join(self.runs, "link"))
        os.symlink(os.path.join(self.outside, "file.txt"), os.path.join(self.runs, "linked.lock"))
        dead = _dead_owner(self.out)
        self.assertTrue(os.path.isfile(os.path.join(self.runs, dead, SCRATCH_MARKER)))
        _old(*[os.path.join(r, n) for r, ds, fs in os.walk(self.runs) for n in ds + fs], self.runs)
        user = {k: v for k, v in _tree(self.runs).items() if not k.startswith(dead)}
        outside = _tree(self.outside)
        rc, err = _cli(self.spec, "--out", self.out)
        self.assertEqual(rc, 0, err)
        self.assertEqual(_tree(self.runs), user)                # every user entry as it was, links included
        self.assertEqual(_tree(self.outside), outside)
        self.assertFalse(os.path.lexists(os.path.join(self.runs, dead)))   # the dead sweep's scratch is gone
        self.assertFalse(os.path.lexists(os.path.join(self.runs, dead + ".lock")))
        said = [line for line in err.splitlines() if "left alone in" in line]
        self.assertEqual(len(said), 1, err)
        for name in ("mine", "host-1-deadbeef", "copied", "stray.txt", "link", "linked.lock"):
            self.assertIn(repr(name), said[0])
        self.assertEqual(len(_rows(os.path.join(self.out, "results.csv"))), 1)

    def test_symlinked_runs_folder_is_refused_and_its_target_untouched(self):
        os.makedirs(self.out)
        os.symlink(self.outside, self.runs)
        before = _tree(self.outside)
        rc, err = _cli(self.spec, "--out", self.out)
        self.assertEqual(rc, 2, err)
        lines = [line for line in err.splitlines() if line.startswith("particleShear sweep:")]
        self.assertEqual(len(lines), 1, err)
        self.assertIn(self.runs, lines[0])
        self.assertIn("symbolic link", lines[0])
        self.assertEqual(_tree(self.outside), before)
        self.assertFalse(os.path.exists(os.path.join(self.out, "results.csv")))
        # the library refuses the same, and a bare scratch owner too
        with self.assertRaisesRegex(ValueError, re.escape(self.runs) + ".*symbolic link"):
            run_sweep(ONE, self.out, progress=False)
        with self.assertRaisesRegex(ValueError, "symbolic link"):
            ScratchOwner(self.out)
        self.assertEqual(remove_dead_scratch(self.runs), [])
        self.assertEqual(_tree(self.outside), before)

    def test_a_file_at_runs_is_refused(self):
        os.makedirs(self.out)
        with open(self.runs, "w") as fh:
            fh.write("mine\n")
        with self.assertRaisesRegex(ValueError, re.escape(self.runs) + " is not a folder"):
            run_sweep(ONE, self.out, progress=False)
        self.assertEqual(_read(self.runs), b"mine\n")

    def test_symlinks_where_a_sweep_writes_are_refused_before_any_work(self):
        names = ("results.csv", "results.csv.lock", "results.csv.rejected", "sweep.json.lock", "results.schema.json",
                 "results.parquet", ".results.parquet.part", "results.task-0000-of-0002.csv",
                 "results.task-0001-of-0002.csv.lock")
        target = os.path.join(self.outside, "file.txt")
        for name in names:
            with self.subTest(name=name):
                out = os.path.join(self.tmp, "L_" + name.strip("."))
                os.makedirs(out)
                link = os.path.join(out, name)
                os.symlink(target, link)
                task = dict(task_index=1, task_count=2) if name.startswith("results.task-0001") else {}
                with self.assertRaisesRegex(ValueError, re.escape(link) + r" is a symbolic link \(to "):
                    run_sweep(ONE, out, progress=False, **task)
                self.assertEqual(_read(target), b"precious\n")
                self.assertTrue(os.path.islink(link))
                self.assertFalse(os.path.exists(os.path.join(out, "runs")))
                if name.startswith("results.task") and name.endswith(".csv"):
                    with self.assertRaisesRegex(ValueError, "symbolic link"):
                        Sweep(ONE, out).merge()
        # the record: read through the link only, refused as not a record, never replaced
        out = os.path.join(self.tmp, "L_record")
        os.makedirs(out)
        os.symlink(target, os.path.join(out, "sweep.json"))
        with self.assertRaisesRegex(ValueError, re.escape(os.path.join(out, "sweep.json"))):
            run_sweep(ONE, out, progress=False)
        self.assertEqual(_read(target), b"precious\n")
        # the CLI: one line, status 2
        out = os.path.join(self.tmp, "L_cli")
        os.makedirs(out)
        os.symlink(target, os.path.join(out, "results.csv"))
        rc, err = _cli(self.spec, "--out", out)
        self.assertEqual(rc, 2, err)
        self.assertEqual(len([x for x in err.splitlines() if x.startswith("particleShear sweep:")]), 1, err)
        self.assertIn(os.path.join(out, "results.csv"), err)
        self.assertEqual(_read(target), b"precious\n")

    def test_scratch_owner_marks_its_folder_and_cleans_a_death_at_any_point(self):
        os.makedirs(self.runs)
        dead = _dead_owner(self.out)                  # died with work in its folder
        crash = socket.gethostname() + "-2-00000000"   # died between its lock and its marker: empty folder
        os.makedirs(os.path.join(self.runs, crash))
        with open(os.path.join(self.runs, crash + ".lock"), "w") as fh:
            fh.write(json.dumps({"format": "particleShear sweep scratch 1", "owner": crash}) + "\n")
        os.makedirs(os.path.join(self.runs, "h-3-00000000"))     # the same, but the folder is not empty: not ours
        with open(os.path.join(self.runs, "h-3-00000000", "notes.txt"), "w") as fh:
            fh.write("x\n")
        with open(os.path.join(self.runs, "h-3-00000000.lock"), "w") as fh:
            fh.write(json.dumps({"format": "particleShear sweep scratch 1", "owner": "h-3-00000000"}) + "\n")
        self.assertEqual(foreign_entries(self.runs), ["h-3-00000000"])
        live = ScratchOwner(self.out)
        try:
            with open(os.path.join(live.path, SCRATCH_MARKER)) as fh:
                self.assertEqual(json.load(fh)["owner"], os.path.basename(live.path))
            for name in (dead, crash):
                self.assertFalse(os.path.lexists(os.path.join(self.runs, name)))
                self.assertFalse(os.path.lexists(os.path.join(self.runs, name + ".lock")))
            self.assertTrue(os.path.isfile(os.path.join(self.runs, "h-3-00000000", "notes.txt")))
            _old(live.path)
            self.assertEqual(remove_dead_scratch(self.runs), [])     # a live owner is never removed
            self.assertTrue(os.path.isdir(live.path))
        finally:
            live.close()
        self.assertFalse(os.path.lexists(live.path))
        self.assertEqual(sorted(os.listdir(self.runs)), ["h-3-00000000", "h-3-00000000.lock"])


class TestSymlinkedRunFiles(unittest.TestCase):
    def test_a_run_file_or_sidecar_that_is_a_link_is_not_trusted_and_its_target_not_written(self):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "D")
            rows = run_sweep(dict(SPEC, zip=[]), out, workers=1, progress=False)
            outside = os.path.join(d, "outside")
            os.makedirs(outside)
            a, b = rows
            fa = os.path.join(out, a["output_path"])
            sb = os.path.join(out, os.path.splitext(b["output_path"])[0] + ".json")
            links = {}
            for p in (fa, sb):                              # the same bytes, moved outside and linked back
                q = os.path.join(outside, os.path.basename(p))
                shutil.move(p, q)
                os.symlink(q, p)
                links[p] = _read(q)
            err = io.StringIO()
            ran = sorted(o.row["run_id"] for o in Sweep(dict(SPEC, zip=[]), out).as_completed(workers=1, stream=err))
            self.assertEqual(ran, sorted([a["run_id"], b["run_id"]]))
            self.assertIn(f"run {a['run_id']} runs again: {os.path.basename(fa)} is a symbolic link", err.getvalue())
            self.assertIn(f"run {b['run_id']} runs again: {os.path.basename(sb)} is a symbolic link", err.getvalue())
            for p, data in links.items():
                self.assertFalse(os.path.islink(p))                              # replaced by the run's own file
                self.assertEqual(_read(os.path.join(outside, os.path.basename(p))), data)   # target untouched
            self.assertEqual(len(_rows(os.path.join(out, "results.csv"))), 2)


class TestResumeVerifiesEveryRun(CopiesOfOneSweep, unittest.TestCase):
    """Why 3: copy run A's ``.txt`` over run B's and delete B's ``.json``."""
    SPEC = SPEC

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.spec = _write_spec(cls.tmp, SPEC)

    def _files(self, out, row):
        txt = os.path.join(out, row["output_path"])
        return txt, os.path.splitext(txt)[0] + ".json"

    def _header_run_id(self, path):
        with open(path, encoding="utf-8") as fh:
            return re.search(r"\n\tRun id: (\S+)\n", fh.read(4096)).group(1)

    def test_a_copied_file_without_its_sidecar_runs_again_through_the_cli(self):
        out = self._copy("swap")
        a, b = self.rows[0], self.rows[1]
        shutil.copyfile(self._files(out, a)[0], self._files(out, b)[0])
        os.remove(self._files(out, b)[1])
        rc, err = _cli(self.spec, "--out", out)
        self.assertEqual(rc, 0, err)
        self.assertIn(f"run {b['run_id']} runs again:", err)
        self.assertRegex(err, rf"run {b['run_id']} runs again: [^\n]*(no sidecar|run {a['run_id']})")
        self.assertIn("4 runs in this share, 3 already finished", err)
        self.assertIn("4 of 4 runs finished", err)
        rows = _rows(os.path.join(out, "results.csv"))
        self.assertEqual(len(rows), 4)
        for row in rows:                                      # every row's file is its own run's
            self.assertEqual(self._header_run_id(os.path.join(out, row["output_path"])), row["run_id"])
            self.assertTrue(os.path.isfile(self._files(out, row)[1]))

    def test_a_missing_sidecar_alone_runs_again_and_says_so(self):
        out = self._copy("noside")
        b = self.rows[2]
        os.remove(self._files(out, b)[1])
        err = io.StringIO()
        ran = [o.row["run_id"] for o in Sweep(SPEC, out).as_completed(workers=1, stream=err)]
        self.assertEqual(ran, [b["run_id"]])
        self.assertIn(f"run {b['run_id']} runs again: its file {os.path.basename(b['output_path'])} has no sidecar",
                      err.getvalue())

    def test_a_file_of_another_run_is_refused_with_a_sidecar_that_fits_it(self):
        out = self._copy("header")
        a, b = self.rows[0], self.rows[3]
        fa, _ = self._files(out, a)
        fb, sb = self._files(out, b)
        shutil.copyfile(fa, fb)
        with open(sb, encoding="utf-8") as fh:             # B's own sidecar, its size made to fit A's file
            side = json.load(fh)
        side["size_bytes"] = os.path.getsize(fb)
        side.pop("sha256", None)
        with open(sb, "w", encoding="utf-8") as fh:
            json.dump(side, fh)
        err = io.StringIO()
        ran = [o.row["run_id"] for o in Sweep(SPEC, out).as_completed(workers=1, stream=err)]
        self.assertEqual(ran, [b["run_id"]])
        self.assertIn(f"is the file of run {a['run_id']} (its header says)", err.getvalue())
        self.assertEqual(self._header_run_id(fb), b["run_id"])
        # A's file with A's sidecar copied over B's: the sidecar names A
        shutil.copyfile(fa, fb)
        shutil.copyfile(self._files(out, a)[1], sb)
        err = io.StringIO()
        ran = [o.row["run_id"] for o in Sweep(SPEC, out).as_completed(workers=1, stream=err)]
        self.assertEqual(ran, [b["run_id"]])
        self.assertIn(f"is the file of run {a['run_id']}", err.getvalue())

    def test_an_npz_file_of_another_run_is_refused_by_its_embedded_header(self):
        spec = dict(SPEC, parameters=dict(TINY, output_format="npz"), grid={"theAmplitude": [0.2, 0.1]}, zip=[])
        out = os.path.join(self.tmp, "npz")
        a, b = run_sweep(spec, out, workers=1, progress=False)
        fb = os.path.join(out, b["output_path"])
        shutil.copyfile(os.path.join(out, a["output_path"]), fb)
        os.remove(os.path.splitext(fb)[0] + ".json")
        from particleShear.simulation.formats import run_file_identity
        self.assertEqual(run_file_identity(fb)["run_id"], a["run_id"])
        err = io.StringIO()
        ran = [o.row["run_id"] for o in Sweep(spec, out).as_completed(workers=1, stream=err)]
        self.assertEqual(ran, [b["run_id"]])
        self.assertIn(f"is the file of run {a['run_id']} (its header says)", err.getvalue())
        self.assertEqual(run_file_identity(fb), {"run_id": b["run_id"], "seed_entropy": "7", "spawn_key": "[1]"})

    def test_a_duplicated_row_counts_once_and_is_set_aside(self):
        out = self._copy("dup")
        path = os.path.join(out, "results.csv")
        with open(path, encoding="utf-8", newline="") as fh:
            lines = fh.readlines()
        with open(path, "w", encoding="utf-8", newline="") as fh:
            fh.writelines(lines + [lines[2]])                 # run 2's row twice
        rc, err = _cli(self.spec, "--out", out)
        self.assertEqual(rc, 0, err)
        self.assertIn("4 runs in this share, 4 already finished", err)
        self.assertIn("moved 1 duplicate row(s)", err)
        self.assertIn("4 of 4 runs finished", err)
        with open(path, encoding="utf-8", newline="") as fh:
            self.assertEqual(fh.readlines(), lines)
        with open(path + ".rejected", encoding="utf-8", newline="") as fh:
            self.assertEqual(fh.read(), lines[2])
        self.assertEqual(len(Sweep(SPEC, out).rows()), 4)


if __name__ == "__main__":
    unittest.main()
