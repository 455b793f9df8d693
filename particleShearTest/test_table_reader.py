"""One table reader for ``load_results``, ``analyse``, ``plot`` and the sweep.

Real files throughout: a sweep folder is made once by a real ``run_sweep`` over a stand-in
simulation (instant, deterministic rows: 3 amplitudes × 2 friction coefficients, one seed), then
each test copies it and damages its ``results.csv`` as a killed sweep, an editor or an attacker
would: a torn last line cut inside ``theMu`` ("0.01" → "0.0"), a cell of 200,000 characters, a
duplicate row, random bytes, a formula in a float column.  Every reader must agree: the torn line
is no row and no group, the formula is refused naming file, line and column, the huge cell is
read, the duplicate counts once (with a note), random bytes give an error naming the file, and the
sweep resumes over the same folder without running anything.
"""
import concurrent.futures
import contextlib
import functools
import io
import os
import random
import shutil
import tempfile
import unittest
import warnings
from unittest import mock

import numpy as np

from particleShear.analysis.cli import analyse_folder
from particleShear.analysis.cli import main as analyse_main
from particleShear.plot import read_sweep_table
from particleShear.run import api
from particleShear.run.api import SimulationResult
from particleShear.sweep import Sweep, load_results, run_sweep
from particleShear.sweep.reader import escape_cell, read_table, unescape_cell
from particleShear.sweep.table import REJECTED_SUFFIX, append_row, read_rows, row_line, write_table

TINY = dict(N=12, cut_lines=2, relative_frequency=0.25, pre_periods=0.5, periods=3, post_periods=0.5,
            doDrawing=False, plotStress=False)
SPEC = {"parameters": dict(TINY), "grid": {"theAmplitude": [0.1, 0.2, 0.3], "theMu": [0.01, 0.1]},
        "seeds": {"root": 5, "repetitions": 1}}


@functools.wraps(api.doParticleShearSimulation)          # the signature the SPEC is checked against
def _fake_simulation(**kw):
    """Instant stand-in of doParticleShearSimulation: moduli that encode the amplitude and μ."""
    ss, A, mu = kw["seed"], kw["theAmplitude"], kw["theMu"]
    return SimulationResult(G_surface=(1000 * A + mu, 10.0 + mu), G_internal=(900 * A, 9.0),
                            stress_surface=(0.0, 0.0), stress_internal=(0.0, 0.0), parameters=dict(kw),
                            seed=ss.entropy, spawn_key=tuple(ss.spawn_key), f=100.0, dt=1e-4, N_steps=500)


def _fake_run(run):
    """Instant stand-in of the worker's measurement (``api.measure_run``) of a sweep's checked run."""
    return _fake_simulation(**run)


def _resume(out):
    """Resume the sweep over ``out`` (nothing should run); the run ids run and what was said."""
    err = io.StringIO()
    with mock.patch.object(api, "measure_run", _fake_run), \
            concurrent.futures.ThreadPoolExecutor(1) as ex:
        ran = [o.row["run_id"] for o in Sweep(SPEC, out).as_completed(executor=ex, stream=err)]
    return ran, err.getvalue()


class TestOneReader(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="ps_reader_")
        cls.out = os.path.join(cls.tmp, "sweep")
        with mock.patch.object(api, "measure_run", _fake_run), \
                concurrent.futures.ThreadPoolExecutor(1) as ex:
            cls.rows = run_sweep(SPEC, cls.out, executor=ex, progress=False)
        with open(os.path.join(cls.out, "results.csv"), "rb") as fh:
            cls.data = fh.read()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def _copy(self, name):
        d = os.path.join(self.tmp, name)
        shutil.copytree(self.out, d)
        return d, os.path.join(d, "results.csv")

    def _lines(self):
        return self.data.decode("utf-8").splitlines(True)

    def _analyse(self, d):
        return analyse_folder(d, n_boot=20, seed=1, figure=False)

    # -- torn lines ---------------------------------------------------------------------------
    def test_a_torn_last_line_cut_inside_theMu_is_no_row_and_no_group(self):
        d, path = self._copy("torn")
        lines = self._lines()
        header = next(iter(read_rows(path))).keys()
        victim = dict(read_rows(path)[0], run_id="f" * 12)
        line = row_line(victim, list(header))
        cut = line.index(",0.1,0.01,True,") + len(",0.1,0.0")          # "0.01" -> "0.0", mid-cell
        self.assertEqual(victim["theMu"], "0.01")
        with open(path, "ab") as fh:
            fh.write(line[:cut].encode("utf-8"))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            table = load_results(d, as_frame=False)
        self.assertEqual(len(table), len(lines) - 1)
        self.assertTrue(any("torn last line" in str(w.message) and path in str(w.message) for w in caught))
        self.assertEqual(sorted({r["theMu"] for r in table}), [0.01, 0.1])
        result = self._analyse(d)
        self.assertEqual(len(result["rows"]), 2)                       # μ = 0.01 and 0.1: no group of "0.0"
        self.assertTrue(any("torn last line" in n for n in result["notes"]))
        rows = read_sweep_table(d)
        self.assertEqual(len(rows), len(lines) - 1)
        self.assertEqual({r["theMu"] for r in rows}, {"0.01", "0.1"})
        ran, said = _resume(d)
        self.assertEqual(ran, [])
        self.assertIn("torn last line", said)
        with open(path, "rb") as fh:
            self.assertEqual(fh.read(), self.data)                     # cut back to the rows
        with open(path + REJECTED_SUFFIX, "rb") as fh:
            self.assertEqual(fh.read(), line[:cut].encode("utf-8") + b"\n")   # set aside, not lost

    def test_a_last_line_with_every_field_but_no_newline_is_torn(self):
        d, path = self._copy("torn_full")
        last = self._lines()[-1]
        with open(path, "wb") as fh:
            fh.write(self.data + last.rstrip("\n")[:-1].encode("utf-8"))   # all fields, the last cut
        table = read_table(path)
        self.assertEqual(len(table), len(self._lines()) - 1)
        self.assertEqual(table.set_aside, [(len(self._lines()) + 1, "torn: no final newline")])

    # -- invalid values -------------------------------------------------------------------------
    def test_a_formula_in_a_float_column_is_refused_naming_file_line_and_column(self):
        d, path = self._copy("formula")
        rows = read_rows(path)
        rows[2]["theMu"] = '=HYPERLINK("http://example.com","x")'
        write_table(path, rows, list(rows[0]))
        with open(path, encoding="utf-8") as fh:
            self.assertIn('"\'=HYPERLINK(', fh.read())                # written escaped
        for read in (load_results, read_sweep_table, self._analyse):
            with self.subTest(read=read.__name__):
                with self.assertRaisesRegex(ValueError, rf"{path!r}, line 4: column theMu='=HYPERLINK.*is not of type "
                                                        r"float"):
                    read(d)
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            self.assertEqual(analyse_main([d]), 2)
        self.assertEqual(len(err.getvalue().strip().splitlines()), 1)
        self.assertIn("line 4: column theMu", err.getvalue())
        self.assertFalse(os.path.exists(os.path.join(d, "analysis.csv.new")))

    def test_formula_like_text_is_escaped_when_written_and_unescaped_when_read(self):
        for text, written in (("=1+2", "'=1+2"), ("+x", "'+x"), ("-abc", "'-abc"), ("@SUM(A1)", "'@SUM(A1)"),
                              ("'quoted", "''quoted"), ("-0.5", "-0.5"), ("-inf", "-inf"), ("+1e3", "+1e3"),
                              ("plain", "plain"), ("", "")):
            with self.subTest(text=text):
                self.assertEqual(escape_cell(text), written)
                self.assertEqual(unescape_cell(written), text)
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "t.csv")
            cols = ["run_id", "status", "error", "Gp_surface"]
            write_table(path, [{"run_id": "a" * 12, "status": "failed", "error": "=cmd|' /C calc'!A0",
                                "Gp_surface": -1.5}], cols)
            with open(path, encoding="utf-8") as fh:
                self.assertEqual(fh.read().splitlines()[1], "aaaaaaaaaaaa,failed,'=cmd|' /C calc'!A0,-1.5")
            row = read_table(path).typed_rows()[0]
            self.assertEqual((row["error"], row["Gp_surface"]), ("=cmd|' /C calc'!A0", -1.5))

    def test_analysis_csv_escapes_formula_cells(self):
        d, path = self._copy("analysis_escape")
        self._analyse(d)
        with open(os.path.join(d, "analysis.csv"), encoding="utf-8") as fh:
            for cell in (c for line in fh for c in line.rstrip("\n").split(",")):
                if cell and cell[0] in "=+-@":
                    float(cell)                                     # only numbers start so

    # -- huge cells -------------------------------------------------------------------------------
    def test_a_cell_beyond_the_csv_module_limit_is_read_everywhere(self):
        d, path = self._copy("huge")
        rows = read_rows(path)
        huge = dict(rows[0], run_id="e" * 12, status="failed", error="RuntimeError: " + "x" * 200_000,
                    Gp_surface="", Gpp_surface="", Gp_internal="", Gpp_internal="")
        append_row(path, dict(huge), list(rows[0]))
        table = load_results(d, as_frame=False)
        self.assertEqual(len(table[-1]["error"]), 200_014)
        self.assertEqual(len(read_sweep_table(d)), len(rows) + 1)
        self.assertEqual(len(self._analyse(d)["rows"]), 2)
        ran, said = _resume(d)
        self.assertEqual(ran, [])
        self.assertEqual(len(load_results(d, as_frame=False)), len(rows) + 1)   # kept: a row of no run of the SPEC

    def test_a_ten_thousand_value_list_cell_is_a_list(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "results.csv")
            amplitudes = [0.1 + 1.2345678e-5 * k for k in range(10_000)]
            write_table(path, [{"run_id": "b" * 12, "status": "ok", "sweep_amplitudes": amplitudes}],
                        ["run_id", "status", "sweep_amplitudes"])
            self.assertGreater(os.path.getsize(path), 131_072)
            self.assertEqual(load_results(path, as_frame=False)[0]["sweep_amplitudes"], amplitudes)

    # -- duplicates ---------------------------------------------------------------------------------
    def test_a_duplicate_row_counts_once_with_a_note(self):
        d, path = self._copy("duplicate")
        lines = self._lines()
        with open(path, "a", encoding="utf-8") as fh:
            fh.write(lines[2])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            self.assertEqual(len(load_results(d, as_frame=False)), len(lines) - 1)
        self.assertTrue(any("duplicate" in str(w.message) for w in caught))
        result = self._analyse(d)
        self.assertEqual([r["n_runs"] for r in result["rows"]], [3, 3])     # 3 amplitudes each, not 4
        self.assertTrue(any("duplicate" in n for n in result["notes"]))
        self.assertEqual(len(read_sweep_table(d)), len(lines) - 1)
        ran, said = _resume(d)
        self.assertEqual(ran, [])
        self.assertIn("duplicate row", said)
        with open(path, "rb") as fh:
            self.assertEqual(fh.read(), self.data)
        with open(path + REJECTED_SUFFIX, encoding="utf-8") as fh:
            self.assertEqual(fh.read(), lines[2])

    def test_an_ok_row_wins_over_a_failed_duplicate(self):
        d, path = self._copy("duplicate_failed")
        rows = read_rows(path)
        failed = dict(rows[0], status="failed", error="RuntimeError: x", Gp_surface="", Gpp_surface="")
        write_table(path, [failed] + list(rows), list(rows[0]))
        table = read_table(path)
        self.assertEqual(len(table), len(rows))
        self.assertEqual(table.rows()[0]["status"], "ok")
        self.assertEqual(table.duplicates, [(2, 3)])

    # -- random bytes -----------------------------------------------------------------------------
    def test_random_bytes_give_an_error_naming_the_file(self):
        d, path = self._copy("random")
        with open(path, "wb") as fh:
            fh.write(random.Random(43).randbytes(8192))
        for read in (load_results, read_sweep_table, self._analyse):
            with self.subTest(read=read.__name__):
                with self.assertRaises(ValueError) as cm:
                    read(d)
                self.assertIn(repr(path), str(cm.exception))
        with self.assertRaises(ValueError) as cm:
            _resume(d)
        self.assertIn(path, str(cm.exception))

    # -- typed columns and appends ------------------------------------------------------------
    def test_columns_are_typed_arrays_and_rows_round_trip_byte_for_byte(self):
        path = os.path.join(self.out, "results.csv")
        table = read_table(path)
        self.assertEqual(table.column("Gp_surface").dtype, np.float64)
        self.assertEqual(table.column("N").dtype, np.int64)
        self.assertEqual([r["run_id"] for r in table.typed_rows()], [r["run_id"] for r in self.rows])
        lines = self._lines()
        for i, row in enumerate(table.rows()):
            self.assertEqual(row_line(row, table.columns), lines[i + 1])

    def test_a_checked_append_only_writes(self):
        d, path = self._copy("append")
        rows = read_rows(path)
        extra = dict(rows[0], run_id="d" * 12)
        real_open = open

        def no_read(file, mode="r", *a, **kw):
            if os.fspath(file) == path:
                raise AssertionError(f"the table was opened: {mode}")
            return real_open(file, mode, *a, **kw)

        with mock.patch("builtins.open", no_read):
            append_row(path, dict(extra), list(rows[0]), checked=True)
        with open(path, "rb") as fh:
            self.assertEqual(fh.read(), self.data + row_line(extra, list(rows[0])).encode("utf-8"))


if __name__ == "__main__":
    unittest.main()
