"""Every ```python block of README.md and docs/*.md runs as pasted, headless, in order.

One test class per document (``TestSnippets_README_md``, ``TestSnippets_docs_sweeps_md`` …).

Each document's blocks are pasted in the order they appear into ONE fresh empty folder, each by a
fresh interpreter (so every block carries its own imports, and a block may use the files an
earlier block of the same document made, as a reader following the page would), without a
display, with warnings turned into errors (a block that warns fails), with a generous time limit.
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


def documents():
    """README.md, then docs/*.md in name order (those that exist)."""
    return [d for d in [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md")) if d.exists()]


def document_blocks_from_text(text):
    """The code of every ```python block of a Markdown text, in order."""
    return [m.group(1) for m in _FENCE.finditer(text)]


def document_blocks(doc):
    """The code of every ```python block of ``doc``, in document order."""
    return document_blocks_from_text(pathlib.Path(doc).read_text(encoding="utf-8"))


def snippet_blocks():
    """(document name, index, code) of every ```python block of README.md and docs/*.md."""
    return [(doc.relative_to(ROOT).as_posix(), k, code)
            for doc in documents() for k, code in enumerate(document_blocks(doc))]


def _headless_env():
    env = dict(os.environ)
    env.pop("DISPLAY", None)
    env.pop("WAYLAND_DISPLAY", None)
    env["MPLBACKEND"] = "Agg"
    env["PYTHONWARNINGS"] = "error"          # every warning is an error, in worker processes too
    # the package as this test sees it (installed, or the source tree on sys.path)
    import particleShear
    env["PYTHONPATH"] = os.pathsep.join([str(pathlib.Path(particleShear.__file__).resolve().parent.parent)]
                                        + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    return env


def run_block(code, folder, env):
    """Run one block as pasted into ``folder`` by a fresh interpreter, warnings as errors."""
    return subprocess.run([sys.executable, "-W", "error", "-c", code], cwd=folder, env=env, capture_output=True,
                          text=True, timeout=900, stdin=subprocess.DEVNULL)


class TestHarness(unittest.TestCase):
    """The harness itself: blocks share their folder, and a block that warns fails."""

    def test_blocks_share_one_folder_and_warnings_fail(self):
        env = _headless_env()
        with tempfile.TemporaryDirectory() as folder:
            self.assertEqual(run_block("open('made_by_block_0.txt', 'w').write('x')", folder, env).returncode, 0)
            self.assertEqual(run_block("assert open('made_by_block_0.txt').read() == 'x'", folder, env).returncode, 0)
            self.assertNotEqual(run_block("import warnings; warnings.warn('w', UserWarning)", folder, env).returncode, 0)
        blocks = document_blocks_from_text("text\n```python\nprint(1)\n```\n```bash\nls\n```\n```python\nprint(2)\n```\n")
        self.assertEqual(blocks, ["print(1)\n", "print(2)\n"])


@unittest.skipUnless((ROOT / "README.md").exists(), "documents not shipped with this installation")
class TestDocumentSnippets(unittest.TestCase):
    def test_blocks_found(self):
        self.assertGreater(len(document_blocks(ROOT / "README.md")), 0, "README.md has no python block")


class DocumentRun:
    """The blocks of one document run in order in one folder (a mixin: one TestCase class per
    document, so a parallel run (pytest-xdist, ``--dist loadscope``) spreads the documents)."""

    document = None     # path relative to the checkout, e.g. "docs/sweeps.md"

    def test_blocks_run_in_order_in_one_folder(self):
        env = _headless_env()
        name = self.document
        blocks = document_blocks(ROOT / name)
        with tempfile.TemporaryDirectory() as folder:
            for k, code in enumerate(blocks):
                with self.subTest(document=name, block=k):
                    proc = run_block(code, folder, env)
                    self.assertEqual(proc.returncode, 0,
                                     f"{name} block {k} (pasted after blocks 0..{k - 1} in the same folder) "
                                     f"failed:\n{code}\n--- stderr ---\n{proc.stderr[-3000:]}")
                    self.assertNotIn("Warning", proc.stderr, f"{name} block {k} warned:\n{proc.stderr[-3000:]}")


def _test_class_name(name):
    """``docs/sweeps.md`` → ``TestSnippets_docs_sweeps_md``."""
    return "TestSnippets_" + re.sub(r"\W", "_", name)


for _doc in documents():
    if document_blocks(_doc):
        _name = _doc.relative_to(ROOT).as_posix()
        globals()[_test_class_name(_name)] = type(_test_class_name(_name), (DocumentRun, unittest.TestCase),
                                                  {"document": _name, "__module__": __name__,
                                                   "__doc__": f"The python blocks of {_name} run as pasted, in order."})


if __name__ == "__main__":
    unittest.main()
