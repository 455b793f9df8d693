"""A SPEC's parser and messages are bounded: deep nesting, huge values and huge keys give one line, rc 2.

Every error names the SPEC file; a value is never echoed longer than
``particleShear.checks.MESSAGE_VALUE_LIMIT`` characters (plus the count of those left out); the
closest-name search never compares a name that cannot be close (difflib's time grows with the
product of the lengths).  The files are real files read by the real command in a child process.
"""
import difflib
import json
import os
import subprocess
import sys
import tempfile
import unittest

from particleShear.checks import MESSAGE_VALUE_LIMIT, cut_text, show_value
from particleShear.run.guard import close_names, shorten_values
from particleShear.sweep.spec import MAX_SPEC_DEPTH, load_spec, parse_spec

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SEEDS = {"root": 1}


def _sweep(spec_path, out):
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env.pop("DISPLAY", None)
    return subprocess.run([sys.executable, "-m", "particleShear", "sweep", spec_path, "--out", out, "--dry-run"],
                          env=env, capture_output=True, text=True, timeout=300)


class TestSpecFilesAreBounded(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.dir.cleanup)

    def write(self, name, text):
        path = os.path.join(self.dir.name, name)
        with open(path, "w") as fh:
            fh.write(text)
        return path

    def assertOneLine(self, proc, path, *words):
        self.assertEqual(proc.returncode, 2, proc.stderr[-1500:])
        lines = proc.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, proc.stderr[-1500:])
        self.assertNotIn("Traceback", proc.stderr)
        self.assertIn(repr(path), lines[0])              # the message names the file
        for w in words:
            self.assertIn(w, lines[0])
        return lines[0]

    def test_deep_nesting_json_and_toml(self):
        n = 100_000   # far beyond Python's recursion limit: the parsers themselves would overflow
        js = self.write("deep.json", '{"parameters": {"N": ' + "[" * n + "]" * n + '}, "seeds": {"root": 1}}')
        tm = self.write("deep.toml", "parameters = {N = " + "[" * n + "]" * n + "}\n")
        for path in (js, tm):
            with self.subTest(path=path):
                self.assertOneLine(_sweep(path, os.path.join(self.dir.name, "out")), path, "deeper than")
        self.assertFalse(os.path.exists(os.path.join(self.dir.name, "out")))

    def test_depth_limit_exact(self):
        # a list of steps in [[zip]] is 5 levels deep and legal; one more level than the limit is not
        ok = {"parameters": {"N": 30}, "zip": [{"sweep_amplitudes": [[0.01, 0.02]]}], "seeds": SEEDS}
        self.assertEqual(parse_spec(ok).zips[0]["sweep_amplitudes"], [[0.01, 0.02]])
        deep = 0.1
        for _ in range(MAX_SPEC_DEPTH):
            deep = [deep]
        with self.assertRaisesRegex(ValueError, "deeper than"):
            parse_spec({"parameters": {"N": deep}, "seeds": SEEDS}, source="x.json")

    def test_a_huge_value_is_named_not_echoed(self):
        path = self.write("long.json", json.dumps({"parameters": {"N": 30, "output_format": "x" * 5_000_000},
                                                   "seeds": SEEDS}))
        line = self.assertOneLine(_sweep(path, os.path.join(self.dir.name, "out")), path, "output_format",
                                  "characters")
        self.assertLess(len(line), 600)

    def test_a_huge_key_is_named_not_searched(self):
        path = self.write("key.json", json.dumps({"parameters": {"N" * 5_000_000: 30}, "seeds": SEEDS}))
        line = self.assertOneLine(_sweep(path, os.path.join(self.dir.name, "out")), path,
                                  "is not a parameter", "no parameter name is close")
        self.assertLess(len(line), 800)

    def test_every_error_names_the_file(self):
        for i, doc in enumerate([{"parameters": {"N": "abc"}, "seeds": SEEDS},          # a value (validation)
                                 {"parameters": {"theMuu": 0.1}, "seeds": SEEDS},       # a typo
                                 {"parameters": {"N": 30}},                            # no [seeds]
                                 {"grid": {"theMu": []}, "seeds": SEEDS}]):             # an empty list
            path = self.write(f"bad{i}.json", json.dumps(doc))
            with self.subTest(doc=doc):
                with self.assertRaises((ValueError, TypeError)) as cm:   # TypeError: a value of the wrong type
                    from particleShear.sweep.spec import spec_runs
                    spec_runs(load_spec(path))
                self.assertIn(repr(path), str(cm.exception))


class TestMessageValues(unittest.TestCase):
    def test_cut_text(self):
        short = "x" * MESSAGE_VALUE_LIMIT
        self.assertEqual(cut_text(short), short)
        long = "a" * 1000 + "b" * 1000
        cut = cut_text(long)
        shown = cut.split("…")[0] + cut.split("…")[-1]
        self.assertEqual(len(shown), MESSAGE_VALUE_LIMIT - 30)
        self.assertIn(f"({len(long) - len(shown):,} characters)", cut)
        self.assertTrue(long.startswith(cut.split("…")[0]) and long.endswith(cut.split("…")[-1]))

    def test_show_value_of_a_huge_string_counts_every_character(self):
        v = "y" * 10 ** 6
        s = show_value(v)
        head, _, tail = s.split("…")
        self.assertIn(f"({10 ** 6 - (len(head) - 1) - (len(tail) - 1):,} characters)", s)

    def test_shorten_values_cuts_each_long_value_only(self):
        msg = "amplitudes=" + str([0.5] * 3000) + " is invalid: allowed a list; mu=" + repr("z" * 900)
        out = shorten_values(msg)
        self.assertIn("is invalid: allowed a list; mu='", out)
        self.assertLess(len(out), 2 * MESSAGE_VALUE_LIMIT + 100)
        self.assertEqual(shorten_values("theMu=0.5 is out of range"), "theMu=0.5 is out of range")


class TestCloseNamesBound(unittest.TestCase):
    def test_bound_is_exact(self):
        # difflib's ratio is 2M/(|a|+|b|) <= 2|b|/(|a|+|b|): a name over 7/3 of the longest allowed
        # one cannot reach 0.6, so skipping the search changes no suggestion
        allowed = ["theMu", "N", "theAmplitude"]
        longest = max(len(a.lower()) for a in allowed)
        for n in range(1, 7 * longest // 3 + 6):
            name = ("theamplitude" * 3)[:n]
            ratios = [difflib.SequenceMatcher(None, name, a.lower()).ratio() for a in allowed]
            expected_none = max(ratios) < 0.6 and name not in [a.lower() for a in allowed]
            with self.subTest(n=n):
                self.assertEqual(close_names(name, allowed) == [], expected_none)


if __name__ == "__main__":
    unittest.main()
