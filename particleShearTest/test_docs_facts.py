"""The reference pages (README.md, docs/*.md) state current facts: no dates or session history, and
every run id they quote is one the code produces for the documented inputs.

CHANGELOG.md is the place for history and is not checked.  Run ids are a hash of a run's
parameters and seed (``particleShear.simulation.provenance.run_identity``), so the ids a SPEC
produces are computed from the SPEC alone (``expand_runs(load_spec(...))``), without running a
simulation.
"""
import glob
import inspect
import os
import re
import unittest
import warnings

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAGES = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))

_MONTHS = ("January|February|March|April|May|June|July|August|September|October|November|December|"
           "Jan|Feb|Mar|Apr|Jun|Jul|Aug|Sep|Sept|Oct|Nov|Dec")
#: what a lab notebook says and a reference page does not: (pattern, what it is)
FORBIDDEN = [
    (re.compile(r"\b20\d\d-\d\d-\d\d\b"), "an ISO date"),
    (re.compile(rf"\b(?:{_MONTHS})\.? (?:\d{{1,2}}(?:st|nd|rd|th)?,? )?20\d\d\b"), "a month and year"),
    (re.compile(r"\b\d{1,2} (?:" + _MONTHS + r") 20\d\d\b"), "a date"),
    (re.compile(r"\b(?:morning|afternoon|evening|tonight|yesterday|today)\b", re.I), "a time of day"),
    (re.compile(r"\bUTC\b"), "a clock time"),
    (re.compile(r"\b(?:slow|fast) spell\b|\bprevious (?:writer|day|session)\b", re.I), "session history"),
    (re.compile(r"^\s*\d+\.\s+Done:", re.M), "a to-do list"),
]

#: a quoted run id: 12 lower-case hex digits, not part of a longer hex string or a decimal number
RUN_ID = re.compile(r"(?<![0-9a-fA-F.])[0-9a-f]{12}(?![0-9a-fA-F])")
#: SPEC files a page names
SPEC_NAME = re.compile(r"examples/[\w./-]+\.(?:toml|json)")


def _text(path):
    with open(path, encoding="utf-8") as fh:
        return fh.read()


def _spec_ids(spec_path):
    from particleShear.sweep import expand_runs, load_spec
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # the specs' own measurement warnings (short protocols)
        return {r.run_id for r in expand_runs(load_spec(spec_path))}


def _single_run_ids():
    """Ids of the single runs the pages quote: ``doParticleShearSimulation(seed=s)`` with the defaults."""
    from particleShear import doParticleShearSimulation
    from particleShear.simulation.provenance import run_identity
    defaults = {k: v.default for k, v in inspect.signature(doParticleShearSimulation).parameters.items()
                if v.default is not inspect.Parameter.empty}
    return {run_identity(defaults, seed, ()) for seed in range(10)}


def quoted_run_ids(text):
    """The 12-hex run ids quoted in ``text`` (decimal fractions and longer hex strings excluded).

    Parameters
    ----------
    text : str

    Returns
    -------
    list of str
    """
    return [m.group(0) for m in RUN_ID.finditer(text) if re.search("[a-f]", m.group(0))]


class TestDocsFacts(unittest.TestCase):
    def test_pages_exist(self):
        self.assertIn(os.path.join(ROOT, "docs", "reporting.md"), PAGES)
        self.assertIn("docs/reporting.md", _text(os.path.join(ROOT, "README.md")))

    def test_no_dates_or_history(self):
        found = []
        for path in PAGES:
            for n, line in enumerate(_text(path).splitlines(), 1):
                for pattern, what in FORBIDDEN:
                    m = pattern.search(line)
                    if m:
                        found.append(f"{os.path.relpath(path, ROOT)}:{n}: {what} {m.group(0)!r}")
        self.assertEqual(found, [], "history belongs in CHANGELOG.md")

    def test_detector_catches_the_notebook_phrases(self):
        for bad in ("(2026-12-02, morning)", "00:10 UTC", "Afternoon of the run", "on a slow spell of the host",
                    "The previous writer built it", "1. Done: the guard", "December 2026", "2 Dec 2026"):
            self.assertTrue(any(p.search(bad) for p, _ in FORBIDDEN), bad)
        for fine in ("walltime=08:00:00", "N = 2024 spheres", "seed 2021", "relative_frequency=0.25"):
            self.assertFalse(any(p.search(fine) for p, _ in FORBIDDEN), fine)

    def test_run_id_pattern(self):
        self.assertEqual(quoted_run_ids("1297.783793606958 and ecc45e5689df, 89efadd, f=3963.327297606011"),
                         ["ecc45e5689df"])

    def test_quoted_run_ids_are_produced_by_the_documented_inputs(self):
        singles = None
        for path in PAGES:
            text = _text(path)
            ids = quoted_run_ids(text)
            if not ids:
                continue
            produced = set()
            for spec in sorted(set(SPEC_NAME.findall(text))):
                spec_path = os.path.join(ROOT, spec)
                if os.path.isfile(spec_path) and os.path.getsize(spec_path) < 100_000:
                    produced |= _spec_ids(spec_path)
            if singles is None:
                singles = _single_run_ids()
            stale = sorted(set(ids) - produced - singles)
            self.assertEqual(stale, [], f"{os.path.relpath(path, ROOT)} quotes run ids that neither a SPEC it "
                                        "names nor a default run with seed 0-9 produces")

    def test_small_campaign_ids_are_in_sweeps_md(self):
        # the page's table excerpt is of examples/paper_campaign_small.toml: each quoted id is one of its 36 runs
        text = _text(os.path.join(ROOT, "docs", "sweeps.md"))
        ids = _spec_ids(os.path.join(ROOT, "examples", "paper_campaign_small.toml"))
        self.assertEqual(len(ids), 36)
        self.assertGreaterEqual(len(set(quoted_run_ids(text)) & ids), 1)


if __name__ == "__main__":
    unittest.main()


class TestCitation(unittest.TestCase):
    """CITATION.cff names the version this code is, and the README points to it."""

    def test_version_and_readme(self):
        from particleShear import __version__
        with open(os.path.join(ROOT, "CITATION.cff"), encoding="utf-8") as fh:
            text = fh.read()
        self.assertIn("cff-version: 1.2.0", text)
        top = [line for line in text.splitlines() if line.startswith("version:")]
        self.assertEqual(top, [f"version: {__version__}"])
        with open(os.path.join(ROOT, "pyproject.toml"), encoding="utf-8") as fh:
            self.assertIn(f'version = "{__version__}"', fh.read())
        with open(PAGES[0], encoding="utf-8") as fh:
            readme = fh.read()
        self.assertIn("## How to cite", readme)
        self.assertIn("CITATION.cff", readme)
