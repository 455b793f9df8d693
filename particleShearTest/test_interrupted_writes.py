"""A protocol run's file is complete or absent when the process is interrupted while writing it.

Ctrl-C (SIGINT) or SIGTERM that arrives while a protocol file (creep, relaxation, steady, the
sweeps) is being written must leave no hidden ``.<name>.part`` file and no sidecar, and the CLI
says "no file written" with 130 (SIGINT) or 143 (SIGTERM) — as for the oscillatory files
(docs/output.md).  The signals are real: a child process sends them to itself from inside the
writer, after the first bytes of the table are written, so the interruption lands in the write.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

_SCRIPT = r"""
import json, os, signal, sys
import particleShear.run.rheometer_files as rheometer_files
from particleShear.run.cli import main

real = rheometer_files.write_columns      # patched where the protocol writer looks it up
state = {}

def interrupted(fh, fmt, *args, **kw):
    fh.write(b"first bytes of the table\n")
    fh.flush()
    os.kill(os.getpid(), state["signal"])      # delivered now: the write is under way
    return real(fh, fmt, *args, **kw)

rheometer_files.write_columns = interrupted
out = {}
for fmt in sys.argv[2].split(","):
    for name in ("SIGINT", "SIGTERM"):
        folder = os.path.join(sys.argv[1], fmt + "_" + name)
        os.mkdir(folder)
        state["signal"] = getattr(signal, name)
        rc = main(["--N", "30", "--cut-lines", "0", "--protocol", "creep", "--creep-stress", "20",
                   "--hold-time", "5", "--relative-frequency", "0.2", "--no-do-drawing", "--no-plot-stress",
                   "--no-progress", "--save", folder + "/", "--output-format", fmt])
        out[fmt + " " + name] = [rc, sorted(os.listdir(folder))]
print(json.dumps(out))
"""

FORMATS = ["text", "text.gz", "npz"]
try:
    import pyarrow  # noqa: F401
    FORMATS.append("parquet")
except ImportError:
    pass


class TestProtocolWriteInterrupted(unittest.TestCase):
    def test_complete_or_absent_under_sigint_and_sigterm(self):
        env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
        env.pop("DISPLAY", None)
        with tempfile.TemporaryDirectory() as d:
            proc = subprocess.run([sys.executable, "-c", _SCRIPT, d, ",".join(FORMATS)], env=env,
                                  capture_output=True, text=True, timeout=600)
            self.assertEqual(proc.returncode, 0, proc.stderr[-2000:])
            seen = json.loads(proc.stdout.strip().splitlines()[-1])
        self.assertEqual(len(seen), 2 * len(FORMATS))
        for case, (rc, files) in seen.items():
            with self.subTest(case=case):
                self.assertEqual(rc, 143 if case.endswith("SIGTERM") else 130)
                self.assertEqual(files, [], "an interrupted write left files behind")
        self.assertEqual(proc.stderr.count("no file written"), 2 * len(FORMATS))
        self.assertEqual(proc.stderr.count("terminated (SIGTERM)"), len(FORMATS))
        self.assertNotIn("Traceback", proc.stderr)


if __name__ == "__main__":
    unittest.main()
