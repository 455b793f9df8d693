"""Output layer: provenance in the header, output formats and read_run, files complete or absent.

The header checks port the regular expressions of the downstream R package particleShearEvaluation
(docs/output.md, "Downstream compatibility"): a number it reads must be the number the run used.
"""
import errno
import importlib.util
import io
import json
import math
import os
import queue
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import tracemalloc
import unittest
from unittest import mock

import numpy as np

import particleShear
from particleShear import doParticleShearSimulation, read_run
from particleShear.simulation import formats, output
from particleShear.simulation.experiment import OscillatoryShearExperiment
from particleShear.simulation.provenance import header_number, run_identity

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
QUICK = dict(N=20, do_permanent_links=False, cut_lines=0, relative_frequency=0.2, pre_periods=0.5, periods=1,
             post_periods=0.5, doDrawing=False, plotStress=False, verbose=False)
CUT = dict(QUICK, N=30, do_permanent_links=True, cut_lines=3)

# the header patterns of particleShearEvaluation (R), first 100 lines, first match wins
_NUM = r"([0-9]*\.?[0-9]*)"
_GNUM = r"(-?[0-9]*\.?[0-9]*)"
R_PATTERNS = {
    "N": r"N=([0-9]*) spheres", "packing": r"nominal packing density = " + _NUM,
    "E": r"Young modulus of the individual spheres = " + _NUM + " Pa", "mu": r"Friction coefficient = " + _NUM,
    "links": r"do_permanent_links=([a-zA-Z]*),", "cut_lines": r"cut_lines=([0-9]*),",
    "amplitude": r"amplitude=" + _NUM + ",", "pre": r"baseline_pre_periods = ([0-9]*)",
    "post": r"baseline_post_periods = ([0-9]*)", "periods": r"runSimulation\(periods=([0-9]*),",
    "rts": r"relative_transversal_link_strength=" + _NUM + "[,)]", "rv": r"relative_viscosity=" + _NUM,
    "damping": r"Damping factor = " + _NUM, "Gp": r"G'=" + _GNUM, "Gpp": r"G''=" + _GNUM,
    "Gp_s": r"G'\(by surface force\)=" + _GNUM, "Gpp_s": r"G''\(by surface force\)=" + _GNUM,
    "rf": r"relative_frequency=" + _NUM, "f": r"Frequency = " + _NUM + "Hz",
    "angle": r"avoid_horizontal_angle_degree=" + _NUM, "stress": r"Stress = ([0-9eE.+\-]*)Pa",
    "irc": r"interface_reenforcement_central=" + _NUM, "irt": r"interface_reenforcement_tangential=" + _NUM,
    "keep": r"keep_viscosity_coefficients_constant=([a-zA-Z]*)", "ctb": r"cut_top_bottom=([a-zA-Z]*)",
    "tri": r"doCutByTriangulation=([a-zA-Z]*)", "rlf": r"remove_link_fraction=" + _NUM,
    "removed": r"Actual fraction of randomly removed non-essential permanent bonds = " + _NUM,
}


def r_header(text):
    head = "\n".join(text.split("\n")[:100])
    out = {}
    for key, pat in R_PATTERNS.items():
        m = re.search(pat, head)
        out[key] = m.group(1) if m else None
    return out


def read_text(path):
    with open(path, encoding="utf-8", newline="") as fh:
        return fh.read()


def run(folder, **kw):
    args = dict(CUT, seed=5, saveData=True, return_result=True)
    args.update(kw)
    return doParticleShearSimulation(folder, **args)


class TestProvenanceHeader(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        d = cls.dir.name
        cls.small_mu = run(d, theMu=1e-5, time_step_factor=0.5, correct_drift_sign=True)
        cls.small_mu_text = read_text(cls.small_mu.output_path)
        cls.plain = run(d, theMu=0.01)
        cls.plain_text = read_text(cls.plain.output_path)
        cls.ref = run(d, theMu=0.01, reference_header=True)
        cls.ref_text = read_text(cls.ref.output_path)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def test_small_mu_reads_back_with_the_r_patterns(self):
        h = r_header(self.small_mu_text)
        self.assertEqual(float(h["mu"]), 1e-5)  # '1e-05' would be read as 1
        # every number the patterns read is the run's own value
        self.assertEqual(float(h["Gp"]), self.small_mu.G_internal[0])
        self.assertEqual(float(h["Gpp_s"]), self.small_mu.G_surface[1])
        self.assertEqual(float(h["f"]), self.small_mu.f)
        self.assertEqual(float(h["damping"]), self.small_mu.damping_factor)
        self.assertNotIn("e-05", self.small_mu_text.split("Detailed stress tensor data")[0].replace(
            os.path.basename(self.small_mu.output_path), ""))
        self.assertIn("mu=0.00001,", self.small_mu_text)
        self.assertIn("\nFriction coefficient mu = 0.00001\n", self.small_mu_text)

    def test_provenance_lines(self):
        r, text = self.small_mu, self.small_mu_text
        self.assertIn("\n\tRun id: " + r.run_id + "\n", text)
        self.assertIn("\n\tSeed entropy: 5\n\tSeed spawn key: []\n", text)
        self.assertIn("\n\tparticleShear version: " + particleShear.__version__ + "\n", text)
        self.assertIn("\n\tTime step factor: 0.5\n\tIntegrator: euler\n\tCorrect drift sign: True\n", text)

    def test_new_lines_do_not_change_what_r_reads(self):
        # same run with the reference header (no provenance lines): every pattern reads the same
        self.assertEqual(r_header(self.plain_text), r_header(self.ref_text))
        # and the provenance lines alone match no pattern
        lines = self.plain_text.split("\n")
        k = next(i for i, line in enumerate(lines) if line.startswith("\tFriction coefficient = "))
        block = "\n".join(lines[k + 1: k + 8])  # the seven provenance lines
        self.assertTrue(block.startswith("\tparticleShear version: ") and "Correct drift sign" in block, block)
        for key, pat in R_PATTERNS.items():
            self.assertIsNone(re.search(pat, block), key)

    def test_reference_header_has_no_provenance(self):
        self.assertNotIn("Run id", self.ref_text)
        self.assertEqual(self.ref_text.replace(self.ref.output_path, "X").split("\n")[:4],
                         self.plain_text.replace(self.plain.output_path, "X").split("\n")[:4])
        self.assertIn("\tFriction coefficient = 0.01\n\n\n\nFunction call : \n", self.ref_text)

    def test_reference_header_keeps_exponent_notation(self):
        with tempfile.TemporaryDirectory() as d:
            r = run(d, theMu=1e-5, reference_header=True)
            self.assertIn("\tFriction coefficient = 1e-05\n", read_text(r.output_path))

    def test_sidecar_has_every_input(self):
        r = self.small_mu
        with open(output.sidecar_path(r.output_path), encoding="utf-8") as fh:
            meta = json.load(fh)
        self.assertEqual(meta["run_id"], r.run_id)
        self.assertEqual(meta["seed_entropy"], 5)
        self.assertEqual(meta["parameters"]["theMu"], 1e-5)
        self.assertEqual(meta["parameters"]["time_step_factor"], 0.5)
        self.assertEqual(set(meta["parameters"]), set(r.parameters))
        for key in ("return_result", "verbose", "progress", "correct_drift_sign", "reference_header", "renderer",
                    "time_step_factor", "integrator", "stability_guard", "output_format", "strict_io"):
            self.assertIn(key, r.parameters)
        self.assertIs(r.parameters["correct_drift_sign"], True)

    def test_run_identity(self):
        p = dict(self.plain.parameters)
        a = run_identity(p, 5, ())
        self.assertRegex(a, r"^[0-9a-f]{12}$")
        self.assertEqual(a, self.plain.run_id)
        self.assertEqual(a, run_identity(dict(reversed(list(p.items()))), 5, ()))  # order-free
        self.assertEqual(a, run_identity(dict(p, root_folder="/elsewhere", verbose=True), 5, ()))
        self.assertNotEqual(a, run_identity(p, 6, ()))
        self.assertNotEqual(a, run_identity(p, 5, (1,)))
        self.assertNotEqual(a, run_identity(dict(p, theMu=0.02), 5, ()))
        self.assertNotEqual(a, self.ref.run_id)  # reference_header changes what is written

    def test_header_number_round_trip(self):
        for x in (1e-5, 2.5231325220201602e-05, 1e-300, 1.5e16, 123.456, 0.1, -3e-7, 8000, 0.0):
            text = header_number(x)
            self.assertNotIn("e", text)
            self.assertEqual(float(text), x)
        self.assertEqual(header_number(0.1), "0.1")
        self.assertEqual(header_number(8000), "8000")
        self.assertEqual(header_number(True), "True")


class TestFormats(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def check_round_trip(self, fmt, tensors=True):
        r = run(self.dir.name, output_format=fmt, saveStressTensorData=tensors)
        self.assertTrue(r.output_path.endswith(formats.FORMAT_SUFFIXES[fmt]))
        self.assertTrue(os.path.exists(output.sidecar_path(r.output_path)))
        self.assertFalse(os.path.exists(r.output_path + ".json"))  # the old name, which ".txt" matches
        data = read_run(r.output_path)
        self.assertEqual(data.metadata["run_id"], r.run_id)
        self.assertTrue(data.header.startswith("Dermal filler Ensemble: \n"))
        self.assertTrue(data.header.endswith("Detailed stress tensor data"))
        self.assertEqual(float(r_header(data.header)["Gp"]), r.G_internal[0])
        for key in ("t", "strain", "strain_rate", "stress_surface", "stress_internal"):
            self.assertEqual(len(r.series[key]), r.N_steps)
        if fmt in ("text", "text.gz") and not tensors:
            self.assertEqual(len(data), 0)  # the reference writes no table
            return r, data
        s = data.series
        for key in ("t", "strain", "strain_rate", "stress_surface", "stress_internal"):
            np.testing.assert_array_equal(s[key], r.series[key], err_msg=fmt + " " + key)
        np.testing.assert_array_equal(data["index"], np.arange(r.N_steps))
        if tensors:
            self.assertEqual(len(data), 42)
            np.testing.assert_array_equal(s["tensors"], r.series["tensors"])
        else:
            self.assertEqual(len(data), 6)
        df = data.to_dataframe()
        self.assertEqual(df.shape, (r.N_steps, len(data)))
        return r, data

    def test_text(self):
        r, data = self.check_round_trip("text")
        self.assertEqual(read_text(r.output_path)[: len(data.header)], data.header)

    def test_text_gz(self):
        r, _ = self.check_round_trip("text.gz")
        import gzip
        with gzip.open(r.output_path, "rt", encoding="utf-8", newline="") as fh:
            text = fh.read()
        self.assertFalse(text.endswith("\n"))
        self.assertIn("\nindex\tt\tstrain\t", text)

    def test_npz(self):
        self.check_round_trip("npz")

    def test_npz_without_tensors_keeps_base_series(self):
        self.check_round_trip("npz", tensors=False)

    def test_text_without_tensors_keeps_base_series(self):
        self.check_round_trip("text", tensors=False)

    @unittest.skipUnless(importlib.util.find_spec("pyarrow"), "pyarrow not installed (extra [parquet])")
    def test_parquet(self):
        self.check_round_trip("parquet")

    def test_parquet_without_pyarrow_names_the_extra(self):
        with mock.patch.dict(sys.modules, {"pyarrow": None, "pyarrow.parquet": None}):
            with self.assertRaises(ImportError) as cm:
                doParticleShearSimulation(self.dir.name, saveData=True, output_format="parquet", **QUICK)
        self.assertIn("particleShear[parquet]", str(cm.exception))

    def test_bad_format(self):
        with mock.patch("particleShear.run.sessions.Simulation_interlocking_rheology") as sim:
            with self.assertRaises(ValueError) as cm:
                doParticleShearSimulation(self.dir.name, saveData=True, output_format="csv", **QUICK)
            sim.assert_not_called()
        self.assertIn("output_format='csv'", str(cm.exception))
        with self.assertRaises(ValueError):
            read_run(os.path.join(self.dir.name, "x.csv"))


class TestStreaming(unittest.TestCase):
    @staticmethod
    def peak_while_writing(fmt, n):
        """(peak traced bytes, bytes written) for writing a synthetic n-step table in ``fmt``."""
        rng = np.random.default_rng(0)
        scalars = rng.standard_normal((n, 5))  # full-precision values: ~800 bytes of text per row
        tensors = rng.standard_normal((n, 9, 2, 2))
        with tempfile.TemporaryFile() as fh:
            tracemalloc.start()
            try:
                formats.write_run(fh, fmt, "header", scalars, tensors, {})
                _, peak = tracemalloc.get_traced_memory()
            finally:
                tracemalloc.stop()
            return peak, fh.tell()

    def test_writer_memory_is_bounded(self):
        # the writers hold one chunk of rows (text) or one column (npz) at a time: the peak does not
        # grow with the table and stays far below its size (the old writer built the whole text)
        small, _ = self.peak_while_writing("text", 3 * output.CHUNK_ROWS)
        big, size = self.peak_while_writing("text", 12 * output.CHUNK_ROWS)
        self.assertGreater(size, 9e6)
        self.assertLess(big, 1.3 * small + 0.5e6, f"text writer peak {small / 1e6:.1f} → {big / 1e6:.1f} MB")
        self.assertLess(big, size / 2)
        peak, size = self.peak_while_writing("npz", 30_000)
        self.assertGreater(size, 10e6)
        self.assertLess(peak, 2e6, f"npz writer peak {peak / 1e6:.1f} MB")  # one column is 0.24 MB

    def test_one_text_writer_round_trips_exactly(self):
        # output.iter_text_rows writes both the 42-column table and the protocol tables: every value
        # reads back bit for bit (floats with repr precision, ±inf, nan, −0.0, subnormals; integers
        # as integers), whatever the chunk size and wherever a chunk ends
        rng = np.random.default_rng(3)
        n = 2 * 7 + 3
        vals = rng.standard_normal((n, 3)) * 10.0 ** rng.integers(-300, 300, (n, 3))
        vals[0] = (np.inf, -np.inf, np.nan)
        vals[1] = (-0.0, 5e-324, 1e-310)
        ints = rng.integers(-2 ** 62, 2 ** 62, n)
        texts = {c: "".join(output.iter_text_rows(["a", "b", "c", "i"], (vals[:, 0], vals[:, 1:], ints[:, None]),
                                                   chunk_rows=c)) for c in (1, 7, 1024)}
        self.assertEqual(len(set(texts.values())), 1)
        lines = texts[7].split("\n")
        self.assertEqual(lines[0], "")
        self.assertEqual(lines[1], "a\tb\tc\ti")
        self.assertEqual(len(lines), n + 2)
        rows = [line.split("\t") for line in lines[2:]]
        back = np.array([[float(v) for v in row[:3]] for row in rows])
        np.testing.assert_array_equal(back.view(np.int64)[1:], vals.view(np.int64)[1:])   # bit patterns
        self.assertTrue(np.isnan(back[0, 2]) and back[0, 0] == np.inf and back[0, 1] == -np.inf)
        self.assertEqual([int(row[3]) for row in rows], ints.tolist())
        self.assertTrue(all("." not in row[3] and "e" not in row[3] for row in rows))


def _wait_for(predicate, timeout_s):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.05)
    return False


_KILL_SCRIPT = """
import sys
from particleShear import doParticleShearSimulation
doParticleShearSimulation(sys.argv[1], N=60, do_permanent_links=False, cut_lines=0, relative_frequency=0.025,
                          pre_periods=2, periods=30, post_periods=1, seed=1, saveData=True, saveOutputImages=True,
                          imageFileType="png", renderer="pillow", doDrawing=True, plotStress=False,
                          verbose=False)
"""


class TestFilesCompleteOrAbsent(unittest.TestCase):
    def _start(self, folder, extra_args=None, code=None):
        env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
        env.pop("DISPLAY", None)
        cmd = [sys.executable, "-c", code, folder] if code else [sys.executable, "-m", "particleShear"] + extra_args
        return subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def test_sigkill_then_new_run(self):
        with tempfile.TemporaryDirectory() as d:
            proc = self._start(d, code=_KILL_SCRIPT)
            try:
                def image_started():
                    names = os.listdir(d)
                    img = [n for n in names if n.endswith(".part.images")]
                    return bool(img) and len(os.listdir(os.path.join(d, img[0]))) > 0
                self.assertTrue(_wait_for(image_started, 90), "the run did not start writing images")
            finally:
                proc.send_signal(signal.SIGKILL)
                proc.communicate(timeout=30)
            left = sorted(os.listdir(d))
            self.assertTrue(any(n.endswith(".part") for n in left), left)  # what a killed run leaves
            self.assertTrue(any(n.endswith(".part.images") for n in left), left)
            r = run(d, **QUICK)
            names = sorted(os.listdir(d))
            base = os.path.basename(r.output_path)
            self.assertTrue(base.endswith("_nr_1.txt"), base)  # the stale reservation took no number
            self.assertEqual(names, [base[: -len(".txt")] + ".json", base])
            self.assertEqual(len(read_run(r.output_path)["t"]), r.N_steps)  # complete

    def test_live_reservation_is_respected(self):
        with tempfile.TemporaryDirectory() as d:
            stem = os.path.join(d, "run_nr_")
            live = output.reserve_numbered_path(stem)
            try:
                self.assertEqual(output.remove_stale_parts(d), [])
                second = output.reserve_numbered_path(stem)
                self.assertTrue(second.path.endswith("run_nr_2.txt"))
                second.abort()
                self.assertTrue(os.path.exists(live.tmp_path))
            finally:
                live.abort()
            self.assertEqual(os.listdir(d), [])

    def test_failed_write_keeps_the_result(self):
        with tempfile.TemporaryDirectory() as d:
            full = OSError(errno.ENOSPC, "No space left on device")
            doParticleShearSimulation.last_result = None
            with mock.patch.object(OscillatoryShearExperiment, "write_output_information_to_file",
                                   side_effect=full):
                r = run(d, **QUICK)
            self.assertIs(r.write_error, full)
            self.assertIs(doParticleShearSimulation.last_result, r)
            self.assertTrue(all(math.isfinite(g) for g in r.G_surface + r.G_internal))
            self.assertIsNone(r.output_path)
            self.assertEqual(os.listdir(d), [])  # nothing partial
            with mock.patch.object(OscillatoryShearExperiment, "write_output_information_to_file",
                                   side_effect=full):
                with self.assertRaises(OSError):
                    run(d, strict_io=True, **QUICK)
            self.assertIs(doParticleShearSimulation.last_result.write_error, full)
            self.assertEqual(os.listdir(d), [])

    def test_folder_removed_during_the_run(self):
        # a real failure, no mock: the output folder disappears while the run computes
        with tempfile.TemporaryDirectory() as top:
            d = os.path.join(top, "out")
            os.mkdir(d)

            def progress(phase, step, total, elapsed):
                if phase == "protocol" and os.path.isdir(d):
                    shutil.rmtree(d)
            r = run(d, progress=progress, **QUICK)
            self.assertIsInstance(r.write_error, OSError)
            self.assertTrue(all(math.isfinite(g) for g in r.G_surface + r.G_internal))
            self.assertEqual(len(r.series["t"]), r.N_steps)
            self.assertEqual(os.listdir(top), [])

    def test_failed_write_in_a_binary_format(self):
        with tempfile.TemporaryDirectory() as d:
            with mock.patch("particleShear.simulation.oscillatory.write_run",
                            side_effect=OSError(errno.EIO, "I/O error")):
                r = run(d, output_format="npz", **QUICK)
            self.assertIsInstance(r.write_error, OSError)
            self.assertTrue(math.isfinite(r.G_surface[0]))
            self.assertEqual(os.listdir(d), [])

    def test_cli_reports_a_failed_write(self):
        from particleShear.run import cli
        with tempfile.TemporaryDirectory() as d:
            err = io.StringIO()
            with mock.patch.object(OscillatoryShearExperiment, "write_output_information_to_file",
                                   side_effect=OSError(errno.ENOSPC, "No space left on device")), \
                    mock.patch("sys.stderr", err), mock.patch("sys.stdout", io.StringIO()):
                rc = cli.main(["--save", d, "--N", "20", "--cut-lines", "0", "--no-permanent-links",
                               "--relative-frequency", "0.2", "--pre-periods", "0.5", "--periods", "1",
                               "--post-periods", "0.5", "--quiet", "--seed", "1"])
            self.assertEqual(rc, 1)
            self.assertIn("No space left on device", err.getvalue())
            self.assertEqual(os.listdir(d), [])

    def test_unwritable_folder_refused_before_any_work(self):
        with tempfile.TemporaryDirectory() as d:
            with mock.patch("particleShear.simulation.oscillatory.probe_writable",
                            side_effect=PermissionError(errno.EACCES, "Permission denied")), \
                    mock.patch("particleShear.simulation.simulations.Simulation_interlocking_rheology.initEnsemble"
                               ) as build:
                with self.assertRaises(ValueError) as cm:
                    run(d, **QUICK)
                build.assert_not_called()
            self.assertIn("root_folder=", str(cm.exception))
            self.assertIn("writable", str(cm.exception))

    def test_interrupt_api(self):
        with tempfile.TemporaryDirectory() as d:
            def progress(phase, step, total, elapsed):
                if phase == "protocol" and step >= 10:
                    raise KeyboardInterrupt
            with self.assertRaises(KeyboardInterrupt) as cm:
                run(d, progress=progress, saveOutputImages=True, imageFileType="png", renderer="pillow",
                    **dict(QUICK, doDrawing=True))
            phase, step, total = cm.exception.position
            self.assertEqual(phase, "protocol")
            self.assertGreaterEqual(step, 10)
            self.assertLess(step, total)
            self.assertEqual(os.listdir(d), [])  # no partial file, no image folder

    def test_interrupt_cli(self):
        # event-driven: SIGINT is sent when the progress line of the protocol's first step appears
        # on stderr; the protocol (60 periods, 148k steps, ~90 s on a 2-core host) cannot finish
        # between that line and the signal being handled (the next Python instruction)
        with tempfile.TemporaryDirectory() as d:
            proc = self._start(d, ["--save", d, "--N", "60", "--no-permanent-links", "--cut-lines", "0",
                                   "--periods", "60", "--seed", "1"])
            lines = queue.Queue()
            reader = threading.Thread(target=lambda: [lines.put(line) for line in proc.stderr] + [lines.put(None)],
                                      daemon=True)
            reader.start()
            seen = []
            try:
                while True:
                    line = lines.get(timeout=120)  # a safety bound only: the wait ends with the line
                    if line is None or line.startswith("[protocol] step 1/"):
                        break
                    seen.append(line)
                self.assertIsNotNone(line, "the run ended before its protocol started: " + "".join(seen))
                self.assertTrue(any(n.endswith(".part") for n in os.listdir(d)))  # reserved, not yet written
                proc.send_signal(signal.SIGINT)
                proc.wait(timeout=60)
                reader.join(timeout=60)
            finally:
                if proc.poll() is None:
                    proc.kill()
                    proc.wait()
                proc.stdout.close()
                proc.stderr.close()
            rest = []
            while not lines.empty():
                item = lines.get()
                if item is not None:
                    rest.append(item)
            err = "".join(seen + rest)
            self.assertEqual(proc.returncode, 130, err)
            self.assertNotIn("Traceback", err)
            messages = [line for line in err.splitlines() if line.strip() and not line.startswith("[")]
            self.assertEqual(len(messages), 1, err)  # progress lines aside, one message
            self.assertRegex(messages[0], r"^particleShear: interrupted at step \d+ of \d+ "
                                          r"\(protocol\); no file written$")
            self.assertEqual(os.listdir(d), [])


if __name__ == "__main__":
    unittest.main()
