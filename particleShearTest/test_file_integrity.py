"""Files say whether they are complete: the sidecar's integrity fields, read_run/verify_run, full disks.

Faults are real where that is possible: a full disk is an OS-level file size limit
(``RLIMIT_FSIZE`` with ``SIGXFSZ`` ignored, so writes past the limit fail with ``EFBIG``) in a
subprocess; damaged files are real files cut or with flipped bits.
"""
import errno
import hashlib
import importlib.util
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
import zipfile
from unittest import mock

import numpy as np

from particleShear import doParticleShearSimulation, read_run, verify_run
from particleShear.simulation import formats, output
from particleShear.simulation.formats import RunFileError
from particleShear.simulation.output import AtomicOutputFile, sidecar_path

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HAVE_PYARROW = importlib.util.find_spec("pyarrow") is not None
FORMATS = ("text", "text.gz", "npz") + (("parquet",) if HAVE_PYARROW else ())
#: a small fast run (447 protocol steps, ~1.5 s)
SMALL = dict(N=30, cut_lines=0, do_permanent_links=False, relative_frequency=0.25, pre_periods=0.5, periods=1,
             post_periods=0.5, doDrawing=False, plotStress=False, saveData=True, seed=1, return_result=True,
             verbose=False)
try:
    import resource
    import signal
    HAVE_RLIMIT = hasattr(resource, "RLIMIT_FSIZE") and hasattr(signal, "SIGXFSZ")
except ImportError:  # pragma: no cover - Windows
    HAVE_RLIMIT = False

#: the run of SMALL in a subprocess whose files may grow to LIMIT bytes only (a disk that fills up)
_FULL_DISK_SCRIPT = """
import json, resource, signal, sys
from particleShear import doParticleShearSimulation
from particleShear.simulation import formats
folder, fmt, limit, tensors, strict = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4] == "1", sys.argv[5] == "1"
if fmt == "parquet":
    formats._pyarrow()  # imported before the limit (nothing but the run's output is written after it)
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG instead of killing
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
r = doParticleShearSimulation(root_folder=folder, output_format=fmt, saveStressTensorData=tensors, strict_io=strict,
                              **json.loads(sys.argv[6]))
e = r.write_error
print(json.dumps({"errno": getattr(e, "errno", None), "error": repr(e), "output_path": r.output_path,
                  "G": list(r.G_surface) + list(r.G_internal), "info_error": repr(r.write_error)}))
"""

#: an AtomicOutputFile whose buffered data cannot be flushed (file size limit): abort() must not raise
_ABORT_SCRIPT = """
import os, resource, signal, sys
from particleShear.simulation.output import AtomicOutputFile
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (1000, 1000))
out = AtomicOutputFile(os.path.join(sys.argv[1], "x_nr_1.npz"))
out.write(b"x" * 4000)          # stays in the 8 kB buffer: nothing has failed yet
try:
    out.flush()
except OSError as exc:
    print("flush", exc.errno)
out.abort()                     # closes the file, whose close flushes again: must not raise
print("aborted", sorted(os.listdir(sys.argv[1])))
"""


def _child_env():
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""),
               PYTHONDONTWRITEBYTECODE="1")
    env.pop("DISPLAY", None)
    return env


class Fixture(unittest.TestCase):
    """Complete runs of SMALL in every format (with and without the tensor table), written once."""

    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.runs = {}
        for fmt in FORMATS:
            cls.runs[fmt, True] = doParticleShearSimulation(cls.dir.name, output_format=fmt, **SMALL)
        for fmt in ("text", "text.gz"):
            cls.runs[fmt, False] = doParticleShearSimulation(cls.dir.name, output_format=fmt,
                                                             saveStressTensorData=False, **SMALL)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)

    def copy(self, fmt, tensors=True, sidecar=True):
        """A private copy of the run's file (and its sidecar) to damage."""
        src = self.runs[fmt, tensors].output_path
        dst = os.path.join(self.tmp.name, os.path.basename(src))
        shutil.copyfile(src, dst)
        for side in (sidecar_path(dst), dst + ".json"):  # from an earlier subtest
            if os.path.exists(side):
                os.remove(side)
        if sidecar:
            shutil.copyfile(sidecar_path(src), sidecar_path(dst))
        return dst

    def assertRejected(self, path, *words, check=read_run):
        """``check(path)`` raises one RunFileError (a ValueError) naming the file and saying ``words``."""
        with self.assertRaises(ValueError) as cm:
            check(path)
        self.assertIsInstance(cm.exception, RunFileError)
        message = str(cm.exception)
        self.assertTrue(message.startswith(path + ": "), message)
        for w in words:
            self.assertIn(w, message)
        return message


def _write(path, data):
    with open(path, "wb") as fh:
        fh.write(data)


def _read(path):
    with open(path, "rb") as fh:
        return fh.read()


class TestSidecar(Fixture):
    def test_fields_describe_the_complete_file(self):
        for (fmt, tensors), r in self.runs.items():
            with self.subTest(fmt=fmt, tensors=tensors):
                side = sidecar_path(r.output_path)
                self.assertEqual(side, r.output_path[: -len(formats.FORMAT_SUFFIXES[fmt])] + ".json")
                self.assertFalse(os.path.exists(r.output_path + ".json"))
                with open(side, encoding="utf-8") as fh:
                    meta = json.load(fh)
                data = _read(r.output_path)
                self.assertEqual(meta["size_bytes"], len(data))
                self.assertEqual(meta["sha256"], hashlib.sha256(data).hexdigest())
                # the text formats write no table without the tensor columns; npz/parquet always the six scalars
                self.assertEqual(meta["n_rows"], r.N_steps if tensors else 0)
                self.assertEqual(meta["output_format"], fmt)
                self.assertEqual(meta["run_id"], r.run_id)

    def test_binary_formats_embed_n_rows(self):
        r = self.runs["npz", True]
        with np.load(r.output_path) as z:
            self.assertEqual(json.loads(str(z["header"]))["metadata"]["n_rows"], r.N_steps)
        if HAVE_PYARROW:
            import pyarrow.parquet as pq
            r = self.runs["parquet", True]
            kv = pq.ParquetFile(r.output_path).metadata.metadata
            self.assertEqual(json.loads(kv[b"particleShear"])["metadata"]["n_rows"], r.N_steps)

    def test_formats_never_share_a_number(self):
        # the sidecar x_nr_k.json is shared by the formats' names: each run takes its own number
        stems = [output.run_file_stem(r.output_path) for r in self.runs.values()]
        self.assertEqual(len(set(stems)), len(stems))
        names = sorted(os.listdir(self.dir.name))
        self.assertEqual(len(names), 2 * len(self.runs))  # each file and its sidecar, nothing else
        self.assertFalse([n for n in names if n.startswith(".")], names)

    def test_old_sidecar_name_is_read(self):
        path = self.copy("text")
        os.rename(sidecar_path(path), path + ".json")
        self.assertEqual(read_run(path).metadata["run_id"], self.runs["text", True].run_id)
        self.assertEqual(verify_run(path)["size_bytes"], os.path.getsize(path))

    def test_sidecar_of_another_format_is_not_used(self):
        path = self.copy("text", sidecar=False)
        shutil.copyfile(sidecar_path(self.runs["npz", True].output_path), sidecar_path(path))
        self.assertEqual(read_run(path).metadata, {})  # not this file's: its size and hash are not checked
        self.assertEqual(verify_run(path), {})

    def test_sidecar_name_of_every_format(self):
        for suffix in formats.FORMAT_SUFFIXES.values():
            self.assertEqual(sidecar_path(os.path.join("d", "x_nr_1" + suffix)), os.path.join("d", "x_nr_1.json"))
        with self.assertRaises(ValueError):
            sidecar_path("x.csv")


class TestReadRunVerifies(Fixture):
    def test_complete_files_read_back(self):
        for (fmt, tensors), r in self.runs.items():
            with self.subTest(fmt=fmt, tensors=tensors):
                self.assertEqual(verify_run(r.output_path)["n_rows"], r.N_steps if tensors else 0)
                data = read_run(r.output_path)
                np.testing.assert_array_equal(data.series["t"] if tensors or fmt not in ("text", "text.gz")
                                              else r.series["t"], r.series["t"])

    def test_complete_files_without_sidecar_read_back(self):
        # structure alone (header blocks, the header's step count) accepts a complete file
        for (fmt, tensors), r in self.runs.items():
            with self.subTest(fmt=fmt, tensors=tensors):
                path = self.copy(fmt, tensors, sidecar=False)
                self.assertEqual(verify_run(path), {})
                self.assertEqual(len(read_run(path).get("t", ())), r.N_steps if tensors else 0)

    def test_header_records_the_step_count(self):
        r = self.runs["text", True]
        self.assertEqual(formats._header_steps(read_run(r.output_path).header), r.N_steps)

    def test_empty_file(self):
        for fmt in FORMATS:
            for sidecar in (True, False):
                with self.subTest(fmt=fmt, sidecar=sidecar):
                    path = self.copy(fmt, sidecar=sidecar)
                    _write(path, b"")
                    self.assertRejected(path, "empty")
                    self.assertRejected(path, "empty", check=verify_run)

    def test_missing_file(self):
        path = os.path.join(self.tmp.name, "x_nr_1.npz")
        self.assertRejected(path, "does not exist")
        self.assertRejected(path, "does not exist", check=verify_run)

    def _rows_start(self, text):
        return text.index("\n", text.index("\nindex\t") + 1)  # the newline before row 0

    def test_text_cut_at_a_row_boundary(self):
        r = self.runs["text", True]
        text = _read(r.output_path)
        cut = text[: text.rindex(b"\n", 0, len(text) // 2)]  # complete rows only
        for sidecar in (True, False):
            with self.subTest(sidecar=sidecar):
                path = self.copy("text", sidecar=sidecar)
                _write(path, cut)
                if sidecar:
                    self.assertRejected(path, "incomplete", "records " + str(len(text)), check=verify_run)
                    self.assertRejected(path, "incomplete")
                else:
                    rows = cut.count(b"\n") - text.count(b"\n") + r.N_steps
                    self.assertRejected(path, f"has {rows} rows", f"header records {r.N_steps}")

    def test_text_cut_inside_a_row(self):
        text = _read(self.runs["text", True].output_path)
        cut = text[: text.rindex(b"\t", 0, len(text) // 2)]  # ends inside a row
        for sidecar in (True, False):
            with self.subTest(sidecar=sidecar):
                path = self.copy("text", sidecar=sidecar)
                _write(path, cut)
                self.assertRejected(path, "incomplete")
                self.assertRejected(path, "incomplete", check=verify_run)

    def test_header_only_text(self):
        # the header and the column names, no rows: fewer rows than recorded
        r = self.runs["text", True]
        text = _read(r.output_path).decode("utf-8")
        for sidecar in (True, False):
            with self.subTest(sidecar=sidecar):
                path = self.copy("text", sidecar=sidecar)
                _write(path, text[: self._rows_start(text)].encode("utf-8"))
                self.assertRejected(path, "has 0 rows" if not sidecar else "incomplete")
                if not sidecar:
                    self.assertRejected(path, f"header records {r.N_steps}")

    def test_foreign_txt(self):
        path = os.path.join(self.tmp.name, "measurements.txt")
        _write(path, b"time\tstress\n0.0\t1.5\n0.1\t1.7\n")
        self.assertRejected(path, "not a particleShear run file")
        self.assertRejected(path, "not a particleShear run file", check=verify_run)
        _write(path, b"\xff\xfe binary \x00\x01")  # not even UTF-8
        self.assertRejected(path, "not a particleShear run file")

    def test_flipped_bits_with_sidecar(self):
        # the SHA-256 of the sidecar covers every byte
        for fmt in FORMATS:
            size = os.path.getsize(self.runs[fmt, True].output_path)
            for pos in (0, size // 20, size // 2, size - size // 20, size - 1):
                with self.subTest(fmt=fmt, pos=pos):
                    path = self.copy(fmt)
                    data = bytearray(_read(path))
                    data[pos] ^= 0x10
                    _write(path, bytes(data))
                    self.assertRejected(path, "SHA-256")

    def test_flipped_bits_without_sidecar_npz(self):
        # the CRC-32 of the npz member (zipfile.BadZipFile) is reported as a RunFileError
        path = self.copy("npz", sidecar=False)
        with zipfile.ZipFile(path) as zf:
            info = zf.getinfo("t.npy")
        data = bytearray(_read(path))
        data[info.header_offset + 30 + len(info.filename) + 200] ^= 0x01  # inside the member's data
        _write(path, bytes(data))
        self.assertRejected(path, "CRC")

    @unittest.skipUnless(HAVE_PYARROW, "pyarrow not installed (extra [parquet])")
    def test_flipped_bits_without_sidecar_parquet(self):
        # the Parquet page checksums catch it (pyarrow reads the damaged page silently without them)
        import pyarrow.parquet as pq
        path = self.copy("parquet", sidecar=False)
        chunk = pq.ParquetFile(path).metadata.row_group(0).column(3)
        data = bytearray(_read(path))
        data[chunk.data_page_offset + chunk.total_compressed_size - 10] ^= 0x01
        _write(path, bytes(data))
        self.assertRejected(path, "CRC checksum")

    def test_flipped_bits_without_sidecar_text_gz(self):
        path = self.copy("text.gz", sidecar=False)
        data = bytearray(_read(path))
        data[len(data) // 2] ^= 0x01
        _write(path, bytes(data))
        self.assertRejected(path, "damaged or unreadable")

    def test_missing_npz_members(self):
        src = self.copy("npz", sidecar=False)
        for drop in ("stress_measured_at_surface.npy", "stress_tensor_overall_11.npy", "header.npy"):
            with self.subTest(drop=drop):
                path = os.path.join(self.tmp.name, "cut_nr_1.npz")
                with zipfile.ZipFile(src) as zin, zipfile.ZipFile(path, "w") as zout:
                    for name in zin.namelist():
                        if name != drop:
                            zout.writestr(name, zin.read(name))
                self.assertRejected(path, "missing", drop[: -len(".npy")])

    @unittest.skipUnless(HAVE_PYARROW, "pyarrow not installed (extra [parquet])")
    def test_missing_parquet_column(self):
        import pyarrow.parquet as pq
        src = self.copy("parquet", sidecar=False)
        path = os.path.join(self.tmp.name, "cut_nr_1.parquet")
        pq.write_table(pq.read_table(src).drop_columns(["strain_rate"]), path)
        self.assertRejected(path, "missing", "strain_rate")
        self.assertRejected(path, "missing", "strain_rate", check=verify_run)

    def test_no_raw_exception_escapes(self):
        # cuts and flipped bits all over each file: read_run raises RunFileError (or, for a flipped
        # bit without sidecar outside the container's checksums, reads), never EOFError, BadZipFile …
        for fmt in FORMATS:
            size = os.path.getsize(self.runs[fmt, True].output_path)
            for sidecar in (True, False):
                for pos in np.linspace(1, size - 40, 17).astype(int):
                    with self.subTest(fmt=fmt, sidecar=sidecar, cut=pos):
                        path = self.copy(fmt, sidecar=sidecar)
                        _write(path, _read(path)[:pos])
                        self.assertRejected(path)  # cut anywhere but inside the last number: detected
                    with self.subTest(fmt=fmt, sidecar=sidecar, flip=pos):
                        path = self.copy(fmt, sidecar=sidecar)
                        data = bytearray(_read(path))
                        data[pos] ^= 0x55
                        _write(path, bytes(data))
                        if sidecar:
                            self.assertRejected(path)
                        else:  # not every byte is under a container checksum (a digit of plain text,
                            try:  # Parquet's leading magic and statistics, zip/gzip time stamps)
                                read_run(path)
                            except RunFileError:
                                pass


class TestVerifyRun(Fixture):
    def test_truncated_files(self):
        for fmt in FORMATS:
            for sidecar in (True, False):
                if fmt == "text.gz" and not sidecar:
                    continue  # only decompressing the whole file finds the cut (read_run does)
                with self.subTest(fmt=fmt, sidecar=sidecar):
                    path = self.copy(fmt, sidecar=sidecar)
                    data = _read(path)
                    # the last 400 bytes: inside the last row of a text file (~700 bytes a row); a cut
                    # inside its last number would leave a valid-looking file, only the sidecar tells
                    _write(path, data[: len(data) - 400])
                    self.assertRejected(path, check=verify_run)
                    self.assertRejected(path)

    def test_no_full_hash(self):
        # cheap: the resume calls it for every finished row; only read_run hashes the file
        path = self.copy("text")
        with mock.patch.object(formats.hashlib, "sha256", side_effect=AssertionError("hashed")):
            self.assertEqual(verify_run(path)["size_bytes"], os.path.getsize(path))


class TestDurableCommit(unittest.TestCase):
    def test_fsync_before_rename(self):
        events = []
        real_fsync, real_replace = os.fsync, os.replace
        with tempfile.TemporaryDirectory() as d:
            out = AtomicOutputFile(os.path.join(d, "x_nr_1.txt"))
            out.write("data")
            out.add_companion("json", b"{}", os.path.join(d, "x_nr_1.json"))
            with mock.patch.object(output.os, "fsync", side_effect=lambda fd: (events.append("fsync"),
                                                                               real_fsync(fd))), \
                    mock.patch.object(output.os, "replace", side_effect=lambda a, b: (events.append(
                        os.path.basename(b)), real_replace(a, b))):
                out.commit()
            self.assertEqual(events[:3], ["fsync", "x_nr_1.json", "x_nr_1.txt"])  # file synced, sidecar first
            self.assertEqual(sorted(os.listdir(d)), ["x_nr_1.json", "x_nr_1.txt"])

    def test_failed_rename_removes_the_companion(self):
        # the sidecar never exists without its file
        with tempfile.TemporaryDirectory() as d:
            out = AtomicOutputFile(os.path.join(d, "x_nr_1.txt"))
            out.write("data")
            out.add_companion("json", b"{}", os.path.join(d, "x_nr_1.json"))
            os.remove(out.tmp_path)  # the file's rename fails (ENOENT)
            with self.assertRaises(FileNotFoundError):
                out.commit()
            out.abort()
            self.assertEqual(os.listdir(d), [])


@unittest.skipUnless(HAVE_RLIMIT, "needs RLIMIT_FSIZE and SIGXFSZ (POSIX)")
class TestFullDisk(Fixture):
    """A disk that fills up while the output is written, as an OS-level file size limit."""

    def run_full(self, fmt, limit, tensors=True, strict=False):
        folder = tempfile.mkdtemp(dir=self.tmp.name)
        kwargs = {k: v for k, v in SMALL.items() if k != "verbose"}
        proc = subprocess.run([sys.executable, "-c", _FULL_DISK_SCRIPT, folder, fmt, str(limit),
                               "1" if tensors else "0", "1" if strict else "0", json.dumps(kwargs)],
                              env=_child_env(), capture_output=True, text=True, timeout=300)
        return proc, folder

    def check_kept(self, fmt, limit, tensors=True):
        proc, folder = self.run_full(fmt, limit, tensors)
        self.assertEqual(proc.returncode, 0, proc.stderr)  # returned, did not raise
        out = json.loads(proc.stdout.strip().splitlines()[-1])
        self.assertEqual(out["errno"], errno.EFBIG, out["error"])
        self.assertIsNone(out["output_path"])
        ref = self.runs[fmt, tensors]
        for got, want in zip(out["G"], list(ref.G_surface) + list(ref.G_internal)):
            self.assertTrue(math.isfinite(got))
            # the same deterministic run (seed 1) in another process: the same moduli
            self.assertTrue(math.isclose(got, want, rel_tol=1e-12), (got, want))
        self.assertEqual(os.listdir(folder), [])  # no file, no sidecar, no .part

    def test_fault_in_the_data(self):
        for fmt in FORMATS:
            size = os.path.getsize(self.runs[fmt, True].output_path)
            with self.subTest(fmt=fmt, limit=size // 2):
                self.check_kept(fmt, size // 2)  # half of the file: the fault hits the table

    def test_fault_in_the_sidecar(self):
        # text.gz without the table is smaller than its sidecar: the file is complete, the sidecar is not
        r = self.runs["text.gz", False]
        size, side = os.path.getsize(r.output_path), os.path.getsize(sidecar_path(r.output_path))
        self.assertLess(size, side)
        self.check_kept("text.gz", (size + side) // 2, tensors=False)

    def test_strict_io_raises(self):
        size = os.path.getsize(self.runs["npz", True].output_path)
        proc, folder = self.run_full("npz", size // 2, strict=True)
        self.assertNotEqual(proc.returncode, 0)
        self.assertIn("OSError: [Errno 27] File too large", proc.stderr)
        self.assertEqual(os.listdir(folder), [])

    def test_abort_after_a_failed_flush(self):
        proc = subprocess.run([sys.executable, "-c", _ABORT_SCRIPT, self.tmp.name], env=_child_env(),
                              capture_output=True, text=True, timeout=120)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertEqual(proc.stdout.split("\n")[:2], [f"flush {errno.EFBIG}", "aborted []"])


if __name__ == "__main__":
    unittest.main()
