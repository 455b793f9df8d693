"""The command line and messages through logging.

The flags are checked against ``inspect.signature(doParticleShearSimulation)`` (every parameter
reachable, its value arriving unchanged at the API), the help against the signature's defaults,
``--json`` against the definition of the result row, and the console text of ``verbose`` against
the logging records that carry it.
"""
import contextlib
import inspect
import io
import json
import logging
import os
import subprocess
import sys
import tempfile
import unittest
from unittest import mock

import particleShear
from particleShear import doParticleShearSimulation
from particleShear.run import cli
from particleShear.run.cli import NOT_FLAGS, api_kwargs, build_parser, flag_name, main, parameter_docs

#: a run of well under a second (no crosslinks, 20 spheres, one period)
TINY = ["--N", "20", "--no-permanent-links", "--cut-lines", "0", "--relative-frequency", "0.2",
        "--pre-periods", "0.5", "--periods", "1", "--post-periods", "0.5", "--seed", "3", "--quiet"]
TINY_KW = dict(N=20, do_permanent_links=False, cut_lines=0, relative_frequency=0.2, pre_periods=0.5, periods=1,
               post_periods=0.5, seed=3, doDrawing=False, plotStress=False)


def run_main(argv):
    """(exit status, stdout, stderr) of ``main(argv)``; argparse's SystemExit is an exit status too."""
    out, err = io.StringIO(), io.StringIO()
    with mock.patch.object(sys, "stdout", out), mock.patch.object(sys, "stderr", err):
        try:
            rc = main(list(argv))
        except SystemExit as exc:
            rc = exc.code
    return rc, out.getvalue(), err.getvalue()


def sample_value(name, cli_type, choices, default):
    """(command-line text, expected Python value) of a legal value different from the default."""
    if choices:
        value = next((c for c in choices if c != default), default)  # a single choice: the default itself
        return value, value
    if cli_type is int:
        return "7", 7
    if cli_type is float:
        return "0.375", 0.375    # exact in binary: the parsed float equals the literal
    if cli_type is cli.float_list:
        return "0.25,0.5", [0.25, 0.5]
    return "some_folder", "some_folder"


class TestFlagsFromTheSignature(unittest.TestCase):
    def setUp(self):
        sig = inspect.signature(doParticleShearSimulation)   # its named keywords (not **law_parameters)
        self.sig = sig.replace(parameters=[p for p in sig.parameters.values() if p.kind is not p.VAR_KEYWORD])
        self.parser = build_parser()
        self.by_dest = {}
        for action in self.parser._actions:
            self.by_dest.setdefault(action.dest, []).append(action)

    def test_every_parameter_has_its_flag(self):
        self.assertEqual(set(NOT_FLAGS), {"return_result"})  # the only exemption, with its reason
        for name in self.sig.parameters:
            if name in NOT_FLAGS:
                continue
            with self.subTest(name=name):
                strings = [s for a in self.by_dest.get(name, []) for s in a.option_strings]
                self.assertIn(flag_name(name), strings)

    def test_derived_names_and_aliases(self):
        self.assertEqual(flag_name("time_step_factor"), "--time-step-factor")
        self.assertEqual(flag_name("relative_frequency"), "--relative-frequency")
        self.assertEqual(flag_name("saveOutputImages"), "--save-output-images")
        self.assertEqual(flag_name("N"), "--N")
        strings = {s for a in self.parser._actions for s in a.option_strings}
        for alias in ("--amplitude", "--mu", "--N", "--cut-lines", "--no-permanent-links", "--young-modulus",
                      "--line-cuts", "--no-tensor-data", "--save", "--images", "--draw", "--seed", "--plot",
                      "--movie", "--output-format", "--quiet", "--verbose", "--correct-drift-sign",
                      "--reference-header", "--json", "--version", "--no-verbose", "--no-stability-guard"):
            self.assertIn(alias, strings)

    def test_value_of_every_flag_reaches_the_api(self):
        """Each flag's value arrives unchanged under its parameter's name (the others keep their defaults)."""
        for name, (strings, cli_type, choices, default) in cli._flags().items():
            with self.subTest(name=name):
                if cli_type is bool:
                    cases = [([flag_name(name)], True), (["--no-" + flag_name(name)[2:]], False)]
                else:
                    text, value = sample_value(name, cli_type, choices, default)
                    cases = [([s, text], value) for s in strings]
                for argv, value in cases:
                    kw = api_kwargs(self.parser.parse_args(argv))
                    if name == "progress":
                        self.assertEqual(kw[name] is not None, value)
                    else:
                        self.assertEqual(kw[name], value, argv)
                    self.assertNotIn("return_result", kw)

    def test_command_line_defaults(self):
        """Without flags: the API defaults, except the headless, quiet settings of the command line."""
        kw = api_kwargs(self.parser.parse_args([]))
        headless = dict(doDrawing=False, plotStress=False, renderer="none", verbose=False, saveData=False,
                        root_folder="", saveOutputImages=False)
        for name, par in self.sig.parameters.items():
            if name in NOT_FLAGS or name == "progress":
                continue
            with self.subTest(name=name):
                self.assertEqual(kw[name], headless.get(name, par.default))
        kw = api_kwargs(self.parser.parse_args(["--save", "d", "--images", "png", "--draw"]))
        self.assertEqual((kw["root_folder"], kw["saveData"], kw["saveOutputImages"], kw["imageFileType"]),
                         ("d", True, True, "png"))
        self.assertEqual((kw["doDrawing"], kw["plotStress"], kw["renderer"]), (True, True, "auto"))
        kw = api_kwargs(self.parser.parse_args(["--save", "d", "--no-save-data"]))   # the explicit flag wins
        self.assertEqual((kw["root_folder"], kw["saveData"]), ("d", False))

    def test_help_shows_every_default_and_the_docstring(self):
        rc, out, _ = run_main(["--help"])
        self.assertEqual(rc, 0)
        text = " ".join(out.split())
        docs = parameter_docs()
        for name, par in self.sig.parameters.items():
            if name in NOT_FLAGS or name in cli._CLI_DEFAULTS:
                continue
            with self.subTest(name=name):
                d = par.default
                shown = f"{d:g}" if isinstance(d, float) else (json.dumps(d) if isinstance(d, str) else str(d))
                self.assertIn(f"[default: {shown}]", text)
                described = cli.cli_message(docs[name][1]).replace("``", "")   # names spelled as flags
                self.assertIn(" ".join(described.split()[:3]), text)          # the docstring's text
        self.assertIn("[default: off unless --draw or --images]", text)    # doDrawing on the command line
        self.assertIn("in Pa", text)                                     # units come with the help
        self.assertIn("kg/m³", text)

    def test_version(self):
        rc, out, _ = run_main(["--version"])
        self.assertEqual(rc, 0)
        self.assertEqual(out.strip(), f"particleShear {particleShear.__version__}")

    def test_bad_values_exit_2_with_one_line_naming_the_flag(self):
        cases = [("--time-step-factor", ["--time-step-factor", "0"]), ("--time-step-factor", ["--time-step-factor", "x"]),
                 ("--amplitude", ["--amplitude", "-1"]), ("--the-amplitude", ["--the-amplitude", "-1"]),
                 ("--integrator", ["--integrator", "rk4"]), ("--cool-factor", ["--cool-factor", "2"]),
                 ("--image-file-type", ["--image-file-type", "gif"]), ("--N", ["--N", "2.5"]),
                 ("--movie", ["--movie"]), ("nowhere", ["nowhere"])]
        for flag, argv in cases:
            with self.subTest(argv=argv):
                rc, out, err = run_main(["--quiet", *argv] if argv[0].startswith("-") else argv)
                self.assertEqual(rc, 2)
                self.assertEqual(err.count("\n"), 1, err)
                self.assertIn(flag, err)
                self.assertNotIn("Traceback", err)
                self.assertEqual(out, "")
                for python_name in ("theAmplitude", "time_step_factor", "cool_factor", "saveOutputMovie"):
                    self.assertNotIn(python_name, err)


class TestApiDocstrings(unittest.TestCase):
    """The docstrings of the run API document every parameter (the CLI help is made of them)."""

    def test_every_parameter_is_documented(self):
        import dataclasses
        from particleShear import SimulationResult, doParticleShearSimulationSeries
        for func in (doParticleShearSimulation, doParticleShearSimulationSeries):
            docs = parameter_docs(func)
            for name in inspect.signature(func).parameters:
                with self.subTest(func=func.__name__, name=name):
                    self.assertIn(name.lstrip("*"), {n.lstrip("*") for n in docs})
                    self.assertTrue(docs.get(name, docs.get("**" + name, ("", "")))[1])   # a description
        docs = parameter_docs(SimulationResult)
        for field in dataclasses.fields(SimulationResult):
            if field.name.startswith("_"):
                continue          # a private cache (``_measures``), not an argument anyone passes
            with self.subTest(field=field.name):
                self.assertTrue(docs[field.name][1])

    def test_types_units_and_defaults(self):
        docs = parameter_docs()
        for name, par in inspect.signature(doParticleShearSimulation).parameters.items():
            if par.kind is par.VAR_KEYWORD:      # **law_parameters: the laws' own (test_parameter_table)
                continue
            with self.subTest(name=name):
                type_text, text = docs[name]
                self.assertIn("default", type_text)               # "float, default 0.2"
                self.assertNotIn("\u00a7", text)                   # no reference to the unpublished spec
        self.assertIn("Pa", docs["Young_modulus_spheres"][1])
        self.assertIn("kg/m³", docs["density"][1])
        self.assertIn("eq. S1-8", docs["Young_modulus_spheres"][1])


class TestRunAndJson(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.rc, cls.out, cls.err = run_main(["--json", *TINY])

    def test_json_is_the_only_stdout_and_holds_the_moduli(self):
        self.assertEqual(self.rc, 0, self.err)
        self.assertEqual(self.out.count("\n"), 1)
        row = json.loads(self.out)
        ref = doParticleShearSimulation(**TINY_KW, verbose=False, return_result=True)
        self.assertEqual((row["Gp_surface"], row["Gpp_surface"]), ref.G_surface)   # same seed, same run
        self.assertEqual((row["Gp_internal"], row["Gpp_internal"]), ref.G_internal)
        self.assertEqual(row["run_id"], ref.to_dict()["run_id"])
        self.assertEqual(row["status"], "ok")

    def test_run_subcommand_equals_the_default(self):
        rc, out, err = run_main(["run", "--json", *TINY])
        self.assertEqual(rc, 0, err)
        a, b = json.loads(out), json.loads(self.out)
        for row in (a, b):
            row.pop("wall_time_s")
        self.assertEqual(a, b)

    def test_verbose_with_json_keeps_stdout_clean(self):
        rc, out, err = run_main(["--json", "--verbose", *TINY])
        self.assertEqual(rc, 0, err)
        json.loads(out)
        self.assertIn("G''(by surface force)", err)   # the messages went to stderr


class TestProtocolJson(unittest.TestCase):
    """``--json`` of a protocol run is one object, as the help says: the row, or a sweep's rows in one object."""

    PROTO = ["--N", "30", "--cut-lines", "0", "--relative-frequency", "0.2", "--seed", "2", "--quiet", "--json"]

    def test_creep_is_its_row(self):
        rc, out, err = run_main([*self.PROTO, "--protocol", "creep", "--creep-stress", "20", "--hold-time", "5"])
        self.assertEqual(rc, 0, err)
        row = json.loads(out)
        self.assertIsInstance(row, dict)
        self.assertEqual((row["protocol"], row["status"]), ("creep", "ok"))

    def test_the_summary_carries_the_schema_units(self):
        argv = [a for a in self.PROTO if a != "--json"]
        rc, out, err = run_main([*argv, "--protocol", "creep", "--creep-stress", "20", "--hold-time", "5"])
        self.assertEqual(rc, 0, err)
        self.assertRegex(out, r"creep_stress = 20 Pa\b")
        self.assertRegex(out, r"creep_rate = [-+0-9.e]+ 1/s\b")
        self.assertRegex(out, r"creep_viscosity = [-+0-9.einf]+ Pa·s")
        self.assertRegex(out, r"strain_plateau = [-+0-9.e]+  ")     # dimensionless: no unit

    def test_a_sweep_is_one_object_with_a_row_per_step(self):
        rc, out, err = run_main([*self.PROTO, "--protocol", "amplitude_sweep", "--sweep-amplitudes", "0.05,0.1"])
        self.assertEqual(rc, 0, err)
        obj = json.loads(out)
        self.assertEqual(obj["protocol"], "amplitude_sweep")
        self.assertEqual([r["sweep_amplitude"] for r in obj["rows"]], [0.05, 0.1])
        self.assertEqual({r["run_id"] for r in obj["rows"]}, {obj["run_id"]})


class TestSaveFolder(unittest.TestCase):
    """``--save DIR`` makes DIR (and its parents) as ``sweep --out`` does, after every other check."""

    def test_a_missing_folder_is_made_and_holds_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            target = os.path.join(d, "new", "runs")
            rc, out, err = run_main([*TINY, "--save", target])
            self.assertEqual(rc, 0, err)
            self.assertEqual(sorted(f.rsplit(".", 1)[1] for f in os.listdir(target)), ["json", "txt"])

    def test_a_refused_run_makes_no_folder(self):
        with tempfile.TemporaryDirectory() as d:
            target = os.path.join(d, "new")
            rc, _, err = run_main([*TINY, "--N", "5", "--save", target])
            self.assertEqual(rc, 2, err)
            self.assertFalse(os.path.exists(target))

    def test_a_folder_that_cannot_be_made_is_one_line(self):
        with tempfile.TemporaryDirectory() as d:
            blocker = os.path.join(d, "a_file")
            open(blocker, "w").close()
            rc, _, err = run_main([*TINY, "--save", os.path.join(blocker, "sub")])
            self.assertEqual(rc, 2)
            self.assertEqual(err.count("\n"), 1, err)
            self.assertIn("--save=", err)
            self.assertIn("cannot be made", err)


class TestMessagesThroughLogging(unittest.TestCase):
    def test_verbose_messages_are_info_records_and_console_text(self):
        out = io.StringIO()
        with self.assertLogs("particleShear", level="INFO") as logs, contextlib.redirect_stdout(out):
            G = doParticleShearSimulation(**TINY_KW, verbose=True)
        messages = [r.getMessage() for r in logs.records]
        self.assertTrue(all(r.levelno == logging.INFO for r in logs.records))
        i = messages.index("G''(by surface force)")
        self.assertEqual(messages[i + 1:i + 3], [str(G[1]), "Pa"])   # the reference's three lines
        self.assertTrue(any(m.startswith("Setting relative frequency: 0.2 f= ") for m in messages))
        self.assertTrue(all(r.name.startswith("particleShear.") for r in logs.records))
        self.assertEqual(out.getvalue().splitlines(), messages)  # the console shows the records' text only

    def test_quiet_run_shows_nothing_and_logs_no_info(self):
        out, err = io.StringIO(), io.StringIO()
        seen = []
        handler = logging.Handler()
        handler.emit = seen.append
        logger = logging.getLogger("particleShear")
        logger.addHandler(handler)
        try:
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                doParticleShearSimulation(**TINY_KW, verbose=False)
        finally:
            logger.removeHandler(handler)
        self.assertEqual(out.getvalue(), "")
        self.assertEqual(err.getvalue(), "")
        self.assertEqual([r for r in seen if r.levelno <= logging.INFO], [])

    def test_console_handler_is_removed_and_level_restored(self):
        logger = logging.getLogger("particleShear")
        before = (list(logger.handlers), logger.level, logger.propagate)
        with contextlib.redirect_stdout(io.StringIO()):
            doParticleShearSimulation(**TINY_KW, verbose=True)
        self.assertEqual((list(logger.handlers), logger.level, logger.propagate), before)
        self.assertTrue(any(isinstance(h, logging.NullHandler) for h in logger.handlers))

    def test_import_errors_are_not_hidden(self):
        """A broken sub-package makes ``import particleShear`` fail instead of silently losing functions."""
        code = ("import sys\nsys.modules['particleShear.run'] = None\n"
                "import particleShear\n")
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [os.getcwd(), os.environ.get("PYTHONPATH")])))
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=env)
        self.assertNotEqual(proc.returncode, 0)
        self.assertRegex(proc.stderr, r"(ModuleNotFound|Import)Error: import of particleShear.run")


if __name__ == "__main__":
    unittest.main()
