"""Every ```python block of README.md and docs/*.md runs as pasted, headless, on its own.

Each block is executed in a fresh empty folder by a fresh interpreter (so it must carry its own
imports and create its own folders), without a display, with a generous time limit.
"""
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parent.parent
_FENCE = re.compile(r"^```python[^\n]*\n(.*?)^```", re.S | re.M)


def snippet_blocks():
    """(document name, index, code) of every ```python block of README.md and docs/*.md."""
    docs = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
    out = []
    for doc in docs:
        if doc.exists():
            for k, m in enumerate(_FENCE.finditer(doc.read_text(encoding="utf-8"))):
                out.append((doc.relative_to(ROOT).as_posix(), k, m.group(1)))
    return out


def _headless_env():
    env = dict(os.environ)
    env.pop("DISPLAY", None)
    env.pop("WAYLAND_DISPLAY", None)
    env["MPLBACKEND"] = "Agg"
    # the package as this test sees it (installed, or the source tree on sys.path)
    import particleShear
    env["PYTHONPATH"] = os.pathsep.join([str(pathlib.Path(particleShear.__file__).resolve().parent.parent)]
                                        + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    return env


@unittest.skipUnless((ROOT / "README.md").exists(), "documents not shipped with this installation")
class TestDocumentSnippets(unittest.TestCase):
    def test_blocks_found(self):
        self.assertGreater(len(snippet_blocks()), 0, "README.md has no python block")

    def test_every_block_runs_as_pasted(self):
        env = _headless_env()
        for doc, k, code in snippet_blocks():
            with self.subTest(document=doc, block=k), tempfile.TemporaryDirectory() as folder:
                proc = subprocess.run([sys.executable, "-c", code], cwd=folder, env=env, capture_output=True,
                                      text=True, timeout=600, stdin=subprocess.DEVNULL)
                self.assertEqual(proc.returncode, 0,
                                 f"{doc} block {k} failed:\n{code}\n--- stderr ---\n{proc.stderr[-3000:]}")


if __name__ == "__main__":
    unittest.main()
