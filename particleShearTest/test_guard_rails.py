"""Guard-rails for common mistakes: misspelled names get the closest names.

* an unknown keyword of ``doParticleShearSimulation``, the series and ``run_batch`` (and an unknown
  key of a batch's dicts or of a sweep SPEC) raises :class:`UnknownParameterError` — a TypeError
  *and* a ValueError — naming the closest parameters, before any work;
* ``amplitude`` and ``mu`` are documented aliases of ``theAmplitude`` and ``theMu``: the same run
  (bit-equal moduli) and the same run id; both spellings at once are refused;
* no command line takes prefix abbreviations, and an unknown flag names the closest flags;
* a SPEC that is not valid TOML is refused naming the file, the line and the usual fix.
"""
import inspect
import os
import tempfile
import unittest
import warnings
from unittest import mock

from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries, run_batch
from particleShear.run.guard import PARAMETER_ALIASES, UnknownParameterError, close_names
from particleShear.run.validation import validate_run
from particleShear.sweep.spec import expand_runs, load_spec, parse_spec
from particleShearTest.test_cli import run_main

#: a run of about a second: 12 spheres, no cuts, one period at a high relative frequency
TINY = dict(N=12, cut_lines=0, relative_frequency=0.5, pre_periods=0, periods=1, post_periods=0, seed=11,
            doDrawing=False, plotStress=False, verbose=False)


def run_cli(argv):
    """(exit status, stderr) of ``particleShear.run.cli.main(argv)`` (test_cli's runner)."""
    rc, _, err = run_main(argv)
    return rc, err


def quiet(func, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")    # the few-periods MeasurementWarning of the tiny run
        return func(*args, **kwargs)


class TestUnknownKeywords(unittest.TestCase):
    def assert_suggests(self, cm, name, suggestion, documented="docs/parameters.md"):
        exc = cm.exception
        self.assertIsInstance(exc, TypeError)      # what Python itself raises: old handlers still work
        self.assertIsInstance(exc, ValueError)     # what the package raises for a bad parameter
        self.assertEqual(exc.name, name)
        self.assertIn(suggestion, exc.suggestions)
        self.assertIn(repr(name), str(exc))
        self.assertIn(f"did you mean {suggestion}", str(exc))
        self.assertIn(documented, str(exc))

    def test_single_run(self):
        with self.assertRaises(UnknownParameterError) as cm:
            doParticleShearSimulation(theAmplitud=0.1, **TINY)
        self.assert_suggests(cm, "theAmplitud", "theAmplitude")
        # a clear winner stands alone: not "theAmplitude, amplitude or theMu"
        self.assertEqual(cm.exception.suggestions, ("theAmplitude",))
        for wrong, right in (("save_data", "saveData"), ("n", "N"), ("pre_period", "pre_periods"),
                             ("young_modulus", "Young_modulus_spheres")):
            with self.subTest(wrong=wrong), self.assertRaises(UnknownParameterError) as cm:
                doParticleShearSimulation(**{wrong: 1}, **TINY)
            self.assert_suggests(cm, wrong, right)

    def test_old_except_type_error_still_catches_it(self):
        try:
            doParticleShearSimulation(theAmplitud=0.1)
        except TypeError as exc:
            self.assertIn("theAmplitude", str(exc))
        else:
            self.fail("no error")

    def test_series(self):
        # the series takes lists: a single run's names point to them
        for wrong, right in (("theAmplitude", "amplitudes"), ("amplitude", "amplitudes"), ("theMu", "mu"),
                             ("max_worker", "max_workers"), ("stability_gard", "stability_guard")):
            with self.subTest(wrong=wrong), self.assertRaises(UnknownParameterError) as cm:
                doParticleShearSimulationSeries(**{wrong: [0.1]}, N_repetitions=0)
            self.assert_suggests(cm, wrong, right, "doParticleShearSimulationSeries")
        # a known option that the series refuses keeps its own message
        with self.assertRaisesRegex(TypeError, "return_result=True is invalid for doParticleShearSimulationSeries"):
            doParticleShearSimulationSeries(return_result=True, N_repetitions=0)

    def test_run_batch(self):
        with self.assertRaises(UnknownParameterError) as cm:
            run_batch([dict(TINY, theAmplitude=0.1), dict(TINY, theAmplitud=0.1)])
        self.assert_suggests(cm, "theAmplitud", "theAmplitude")
        self.assertIn("list_of_kwargs[1]", str(cm.exception))
        with self.assertRaises(UnknownParameterError) as cm:
            run_batch([dict(TINY)], backnd="numpy")
        self.assert_suggests(cm, "backnd", "backend", "run_batch")

    def test_validate_run_names_the_closest_parameter(self):
        with self.assertRaises(UnknownParameterError) as cm:
            validate_run(dict(TINY, relative_frequncy=0.2))
        self.assertIn("did you mean relative_frequency", str(cm.exception))
        self.assertIn("unknown parameters", str(cm.exception))

    def test_signatures_are_the_functions_own(self):
        # the command line and the docs are generated from the signature: the wrapper must not change it
        for func in (doParticleShearSimulation, doParticleShearSimulationSeries, run_batch):
            with self.subTest(func=func.__name__):
                self.assertEqual(inspect.signature(func), inspect.signature(func.__wrapped__))
                self.assertEqual(func.__doc__, func.__wrapped__.__doc__)
                self.assertNotIn("amplitude", inspect.signature(func).parameters)

    def test_close_names(self):
        self.assertEqual(close_names("theAmplitud", ["theAmplitude", "theMu"]), ["theAmplitude"])
        self.assertEqual(close_names("xyz", ["theAmplitude", "theMu"]), [])
        self.assertEqual(close_names("dodrawing", ["doDrawing", "saveData"]), ["doDrawing"])


class TestAliases(unittest.TestCase):
    def test_documented(self):
        from particleShear.run.cli import parameter_docs
        docs = parameter_docs(doParticleShearSimulation)
        for alias, name in PARAMETER_ALIASES.items():
            self.assertIn(f"Python alias: ``{alias}=``", docs[name][1])
        with open(os.path.join(os.path.dirname(__file__), os.pardir, "docs", "parameters.md"), encoding="utf-8") as f:
            text = f.read()
        self.assertIn("`amplitude`", text)
        self.assertIn("`mu`", text)

    def test_same_run_and_run_id(self):
        a = quiet(doParticleShearSimulation, amplitude=0.1, mu=0.05, return_result=True, **TINY)
        b = quiet(doParticleShearSimulation, theAmplitude=0.1, theMu=0.05, return_result=True, **TINY)
        self.assertEqual(a.run_id, b.run_id)
        self.assertEqual(a.parameters, b.parameters)
        self.assertEqual(a.parameters["theAmplitude"], 0.1)
        self.assertEqual(a.parameters["theMu"], 0.05)
        # bit-equal moduli: the alias is the same call, not a similar one
        self.assertEqual(a.G_surface, b.G_surface)
        self.assertEqual(a.G_internal, b.G_internal)

    def test_batch_dicts_take_the_aliases(self):
        # what the batch measures is the canonical dict (measurement replaced: only the names matter here)
        seen = []
        self.addCleanup(setattr, doParticleShearSimulation, "last_result", doParticleShearSimulation.last_result)
        with mock.patch("particleShear.run.batch.measure", side_effect=lambda runs: seen.extend(runs) or
                        [None] * len(runs)):
            quiet(run_batch, [dict(TINY, amplitude=0.1, mu=0.05), dict(TINY, theAmplitude=0.1, theMu=0.05)])
        self.assertEqual(len(seen), 2)
        self.assertEqual(seen[0], seen[1])
        self.assertNotIn("amplitude", seen[0])
        self.assertEqual((seen[0]["theAmplitude"], seen[0]["theMu"]), (0.1, 0.05))

    def test_both_spellings_are_refused(self):
        for kwargs in (dict(amplitude=0.1, theAmplitude=0.1), dict(mu=0.1, theMu=0.2)):
            with self.subTest(kwargs=kwargs), self.assertRaises(UnknownParameterError) as cm:
                doParticleShearSimulation(**kwargs, **TINY)
            self.assertIn("is an alias of", str(cm.exception))
            self.assertIn("give only one", str(cm.exception))
        with self.assertRaisesRegex(ValueError, "amplitude is an alias of theAmplitude"):
            doParticleShearSimulation("", 0.1, amplitude=0.2)      # theAmplitude given by position
        with self.assertRaisesRegex(ValueError, "mu is an alias of theMu"):
            run_batch([dict(TINY, mu=0.1, theMu=0.1)])


class TestSpecKeys(unittest.TestCase):
    def spec(self, **tables):
        return dict(tables, seeds={"root": 1})

    def test_unknown_keys_suggest(self):
        cases = (({"parameters": {"theAmplitud": 0.1}}, "parameters.theAmplitud", "theAmplitude"),
                 ({"grid": {"relative_frequncy": [0.1]}}, "grid.relative_frequncy", "relative_frequency"),
                 ({"zip": [{"cut_line": [0], "N": [12]}]}, "zip[0].cut_line", "cut_lines"))
        for tables, where, right in cases:
            with self.subTest(where=where), self.assertRaises(UnknownParameterError) as cm:
                parse_spec(self.spec(**tables))
            self.assertIn(where, str(cm.exception))
            self.assertIn(f"did you mean {right}?", str(cm.exception))
            self.assertIn("docs/parameters.md", str(cm.exception))

    def test_aliases_are_the_same_sweep(self):
        a = parse_spec(self.spec(parameters={"N": 12, "cut_lines": 0, "mu": 0.05}, grid={"amplitude": [0.1, 0.2]}))
        b = parse_spec(self.spec(parameters={"N": 12, "cut_lines": 0, "theMu": 0.05},
                                 grid={"theAmplitude": [0.1, 0.2]}))
        self.assertEqual(a.parameters, b.parameters)
        self.assertEqual(a.grid, b.grid)
        self.assertEqual([r.run_id for r in expand_runs(a)], [r.run_id for r in expand_runs(b)])

    def test_alias_and_name_together_are_refused(self):
        with self.assertRaisesRegex(ValueError, r"grid\.theAmplitude is set twice.*amplitude is an alias"):
            parse_spec(self.spec(parameters={"amplitude": 0.1}, grid={"theAmplitude": [0.1]}))


class TestTomlErrors(unittest.TestCase):
    def write(self, text):
        folder = tempfile.mkdtemp()
        self.addCleanup(lambda: __import__("shutil").rmtree(folder, ignore_errors=True))
        path = os.path.join(folder, "spec.toml")
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(text)
        return path, folder

    def test_capitalised_boolean(self):
        path, _ = self.write("[parameters]\nN = 12\ndoDrawing = False\n[seeds]\nroot = 1\n")
        with self.assertRaises(ValueError) as cm:
            load_spec(path)
        text = str(cm.exception)
        self.assertIn(repr(path), text)                       # the file
        self.assertIn("line 3", text)                         # where
        self.assertIn("doDrawing = False", text)              # the line itself
        self.assertIn("write doDrawing = false", text)        # its fix
        self.assertIn("TOML booleans are lowercase true/false; strings need quotes", text)   # the usual fixes

    def test_unquoted_string_and_python_none(self):
        for line, fix in (('imageFileType = png', 'write imageFileType = "png"'),
                          ("root_folder = None", "TOML has no None: leave root_folder out"),
                          ("theAmplitude = .5", "write theAmplitude = 0.5"),
                          ("theMu = (0.1, 0.2)", "lists use square brackets: theMu = [0.1, 0.2]")):
            path, _ = self.write(f"[parameters]\n{line}\n[seeds]\nroot = 1\n")
            with self.subTest(line=line), self.assertRaises(ValueError) as cm:
                load_spec(path)
            self.assertIn(line, str(cm.exception))
            self.assertIn(fix, str(cm.exception))

    def test_through_the_command_line(self):
        path, folder = self.write("[parameters]\nN = 12\ndoDrawing = False\n[seeds]\nroot = 1\n")
        rc, err = run_cli(["sweep", path, "--out", os.path.join(folder, "out"), "--quiet"])
        self.assertEqual(rc, 2)
        self.assertIn(path, err)
        self.assertIn("write doDrawing = false", err)


class TestNoAbbreviations(unittest.TestCase):
    def test_every_parser_refuses_prefixes(self):
        from particleShear.analysis.cli import build_parser as analyse_parser
        from particleShear.plot import build_parser as plot_parser
        from particleShear.run.cli import build_parser as run_parser
        from particleShear.sweep.cli import build_parser as sweep_parser
        for build in (run_parser, sweep_parser, plot_parser, analyse_parser):
            with self.subTest(parser=build.__module__):
                self.assertFalse(build().allow_abbrev)

    def test_run_flags(self):
        for argv, right in ((["--amplitud", "0.1"], "--amplitude"), (["--amplitud=0.1"], "--amplitude"),
                            (["--amp", "0.1"], "--amplitude"), (["--periode", "3"], "--periods"),
                            (["--n", "40"], "--N"), (["--pre_periods", "1"], "--pre-periods")):
            with self.subTest(argv=argv):
                rc, err = run_cli(argv)
                self.assertEqual(rc, 2)
                self.assertIn(f"did you mean {right}", err)
                self.assertIn("particleShear --help lists the flags", err)
        # the full flag still works
        from particleShear.run.cli import build_parser
        self.assertEqual(build_parser().parse_args(["--amplitude", "0.1"]).theAmplitude, 0.1)

    def test_subcommand_flags(self):
        folder = tempfile.mkdtemp()
        self.addCleanup(os.rmdir, folder)
        for argv, right in ((["sweep", "spec.toml", "--out", folder, "--worker", "2"], "--workers"),
                            (["sweep", "spec.toml", "--out", folder, "--dry"], "--dry-run"),
                            (["plot", folder, "--estimat", "internal"], "--estimator"),
                            (["analyse", folder, "--n-bot", "3"], "--n-boot")):
            with self.subTest(argv=argv):
                rc, err = run_cli(argv)
                self.assertEqual(rc, 2)
                self.assertIn(f"did you mean {right}?", err)


if __name__ == "__main__":
    unittest.main()
