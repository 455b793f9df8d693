"""docs/design.md is the map of the code as it is (issue 46): what of it can be checked, checked.

- it is at most 200 lines;
- its layer diagram is :data:`particleShear.layers.LAYERS` (``test_layers.design_layers``);
- every dotted name it gives in backticks, and every dotted name of its run diagram, is a module
  or an attribute of one (names relative to ``particleShear``);
- its registries table lists exactly what the live registries hold;
- every citation of a section of a Markdown page (the page's name, then the section's title in
  quotes) in the package, the tests, the benchmarks, the examples, README.md and docs/ names a
  heading that page has.
"""
import importlib
import json
import os
import pathlib
import re
import subprocess
import sys
import unittest

from particleShear import layers
from particleShearTest.test_layers import design_layers

ROOT = pathlib.Path(__file__).resolve().parent.parent
DESIGN = ROOT / "docs" / "design.md"
MAX_LINES = 200

#: a dotted Python name: identifiers joined by dots (a file name such as results.csv is not one)
DOTTED = re.compile(r"(?<![\w.])[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)+(?!\w)")
FILE_SUFFIXES = (".py", ".md", ".csv", ".json", ".toml", ".txt", ".gz", ".npz", ".parquet", ".png")
#: a citation: a page ``….md`` (optionally in backticks), then a comma or a space (and optionally
#: "section"/"sections"), then one or more quoted titles joined by "and" or commas
CITATION = re.compile(r"([\w./-]*\w\.md)`?(?:,\s*|\s+)(?:sections?\s+)?"
                      r"((?:[\"'][A-Z][^\"'\n]*[\"'](?:\s*(?:,|and)\s*(?=[\"']))?)+)")
TITLE = re.compile(r"[\"']([^\"']+)[\"']")
#: where citations are looked for
SOURCES = ("particleShear", "particleShearTest", "benchmarks", "examples", "docs")


def _text():
    return DESIGN.read_text(encoding="utf-8")


def _fenced(text):
    """``(language, body)`` of every fenced block of a Markdown text."""
    return re.findall(r"^```(\w*)[^\n]*\n(.*?)^```", text, flags=re.S | re.M)


def _prose(text):
    """The text outside fenced blocks."""
    return re.sub(r"^```.*?^```[^\n]*$", "", text, flags=re.S | re.M)


def _section(text, title):
    return text.split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0]


def resolve(name):
    """The object a dotted name relative to ``particleShear`` (or absolute) names.

    Parameters
    ----------
    name : str
        ``module.attribute…``, e.g. ``engine.step.BatchEngine.force_phase``.

    Returns
    -------
    object

    Raises
    ------
    LookupError
        When no prefix of the name is a module whose rest is a chain of attributes.
    """
    for parts in (["particleShear"] + name.split("."), name.split(".")):
        if parts[1:2] == ["particleShear"]:
            continue
        for k in range(len(parts), 0, -1):
            try:
                obj = importlib.import_module(".".join(parts[:k]))
            except ImportError:
                continue
            try:
                for attr in parts[k:]:
                    obj = getattr(obj, attr)
            except AttributeError:
                break
            return obj
    raise LookupError(name)


def backticked_names(text):
    """The dotted names in backticks of the prose (file names excluded)."""
    found = []
    for code in re.findall(r"`([^`\n]+)`", _prose(text)):
        if DOTTED.fullmatch(code) and not code.endswith(FILE_SUFFIXES):
            found.append(code)
    return found


def headings(path):
    """The titles of the Markdown headings of ``path`` (lines in fenced blocks are not headings; a
    title keeps its backticks)."""
    text = _prose(path.read_text(encoding="utf-8"))
    return {m.group(1).strip() for m in re.finditer(r"^#{1,6} (.+)$", text, flags=re.M)}


def citations(text):
    """``(page, title)`` of every citation of a section in ``text``; lines are joined first (a
    comment's ``#`` continuation included), so a title may run over a line break."""
    flat = re.sub(r"\s*\n\s*(?:#+\s+)?", " ", text)
    return [(m.group(1), t) for m in CITATION.finditer(flat) for t in TITLE.findall(m.group(2))]


def names_heading(title, titles):
    """Whether ``title`` names one of ``titles``: equal to it, or its leading words (followed by a
    space, a colon, a comma or a parenthesis: "Verdicts" names "Verdicts (`result.verdict`, …)";
    a title ending in "…" is such a lead)."""
    lead = title.rstrip("… ").rstrip()
    return title in titles or any(re.match(re.escape(lead) + r"[\s:,(]", t) for t in titles)


def page_path(page):
    """The file a cited page names: a path from the checkout's root, else a page of docs/."""
    for candidate in (ROOT / page, ROOT / "docs" / page, ROOT / "docs" / os.path.basename(page)):
        if candidate.is_file():
            return candidate
    return None


def source_files():
    """The Python and Markdown files of :data:`SOURCES` and README.md (this file excluded)."""
    files = [ROOT / "README.md"]
    for folder in SOURCES:
        files += sorted(p for p in (ROOT / folder).rglob("*") if p.suffix in (".py", ".md"))
    return [f for f in files if f.is_file() and f.resolve() != pathlib.Path(__file__).resolve()]


def registry_rows(text):
    """``{registry name: [listed contents]}`` of the registries table of docs/design.md."""
    rows = {}
    for line in _section(text, "Registries").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 4 and cells[1].startswith("`"):
            rows[cells[1].strip("`")] = re.findall(r"`([^`]+)`", cells[3])
    return rows


def live_contents(registry):
    """The names a registry holds: a dict's keys, or the items (their ``name`` where they have one)."""
    return [getattr(v, "name", v) for v in registry] if not isinstance(registry, dict) else list(registry)


@unittest.skipUnless(DESIGN.exists(), "documents not shipped with this installation")
class TestDesignMap(unittest.TestCase):
    def test_at_most_200_lines(self):
        self.assertLessEqual(len(_text().splitlines()), MAX_LINES)

    def test_layer_diagram_is_layers(self):
        self.assertEqual(design_layers(), [(i, name, sorted(names)) for i, (name, names) in
                                           enumerate(layers.LAYERS)][::-1])

    def _assert_resolve(self, names, where):
        missing = []
        for name in names:
            try:
                resolve(name)
            except LookupError:
                missing.append(name)
        self.assertEqual(missing, [], f"names of {where} that are no module or attribute")

    def test_backticked_names_resolve(self):
        names = backticked_names(_text())
        self.assertGreater(len(names), 10)
        self._assert_resolve(names, "docs/design.md in backticks")

    def test_run_diagram_names_resolve(self):
        block = [body for lang, body in _fenced(_section(_text(), "One run")) if lang == "text"]
        self.assertEqual(len(block), 1)
        names = [n for n in DOTTED.findall(block[0]) if not n.endswith(FILE_SUFFIXES)]
        self.assertGreater(len(names), 20)
        self._assert_resolve(names, "the run diagram")

    def test_registries_table_is_the_registries(self):
        """The table against the registries of a fresh process: what the package itself registers
        (other tests register laws or protocols of their own in this process for a while)."""
        rows = registry_rows(_text())
        self.assertGreaterEqual(len(rows), 5)
        code = ("import json; from particleShearTest.test_design_map import _text, live_contents, registry_rows, "
                "resolve; print(json.dumps({n: sorted(map(str, live_contents(resolve(n)))) "
                "for n in registry_rows(_text())}))")
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
        out = subprocess.run([sys.executable, "-c", code], cwd=str(ROOT), env=env, capture_output=True, text=True,
                             timeout=300)
        self.assertEqual(out.returncode, 0, out.stderr[-2000:])
        fresh = json.loads(out.stdout.strip().splitlines()[-1])
        for name, listed in rows.items():
            with self.subTest(registry=name):
                self.assertEqual(len(listed), len(set(listed)))
                self.assertEqual(sorted(map(str, listed)), fresh[name])

    def test_citations_name_headings(self):
        bad, seen = [], 0
        for path in source_files():
            for page, title in citations(path.read_text(encoding="utf-8")):
                seen += 1
                target = page_path(page)
                if target is None or not names_heading(title, headings(target)):
                    bad.append(f"{path.relative_to(ROOT)}: {page}, {title!r}")
        self.assertGreater(seen, 20)
        self.assertEqual(bad, [], "citations of sections that do not exist")


class TestCheckers(unittest.TestCase):
    """The checkers find what they look for."""

    def test_citation_forms(self):
        text = ('(docs/engine.md, "One step") `docs/sweeps.md`, "Where it\n    # runs" design.md "Layers" '
                "x (docs/backends.md, 'One law, two drivers') y docs/engine.md sections \"Runs\" and \"Observers\""
                ' "see docs/output.md", "other" docs/output.md), x docs/output.md ("a quoted line")')
        self.assertEqual(citations(text), [("docs/engine.md", "One step"), ("docs/sweeps.md", "Where it runs"),
                                           ("design.md", "Layers"), ("docs/backends.md", "One law, two drivers"),
                                           ("docs/engine.md", "Runs"), ("docs/engine.md", "Observers")])

    def test_resolve(self):
        self.assertIs(resolve("layers.LAYERS"), layers.LAYERS)
        self.assertIs(resolve("particleShear.layers.LAYERS"), layers.LAYERS)
        for name in ("layers.NO_SUCH_NAME", "no_such_module.x"):
            with self.assertRaises(LookupError):
                resolve(name)

    def test_names_heading(self):
        titles = {"Verdicts (`result.verdict`, …)", "Runs", "Time scales: the model's kHz"}
        for title in ("Verdicts", "Runs", "Time scales", "Time scales: the model's kHz", "Verdicts …"):
            self.assertTrue(names_heading(title, titles), title)
        for title in ("Verdict", "Run", "Time scale", "Scales"):
            self.assertFalse(names_heading(title, titles), title)

    def test_headings_skip_fenced_blocks(self):
        self.assertIn("Layers", headings(DESIGN))
        self.assertNotIn("flow_curve.toml — particleShear sweep flow_curve.toml --out flow",
                         headings(ROOT / "docs" / "protocols.md"))


if __name__ == "__main__":
    unittest.main()
