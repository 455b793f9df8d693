"""Every way to start a run validates it the same way (``particleShear.run.validation.validate_run``).

The paths: ``doParticleShearSimulation``, ``doParticleShearSimulationSeries`` (every run before
any starts), ``run_batch``, a sweep SPEC (``parse_spec`` + ``expand_runs``, whose message carries
the prefix ``point K (...): ``) and the run command line (whose message names the flags).  For a
table of bad values each path refuses with the message of ``validate_run`` and without starting
any work (the functions that build or measure a run are replaced by ones that fail the test).
"""
import contextlib
import io
import json
import os
import sys
import tempfile
import unittest
import warnings
from unittest import mock

import numpy as np

from particleShear.analysis.measures import MeasurementWarning
from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries, run_batch
from particleShear.run import cli
from particleShear.run.validation import MAX_N, show_value, validate_run
from particleShear.sweep import expand_runs, load_spec, parse_spec

BIG = 10 ** 400
#: what sets the lower limit of N at the default packing (one range rule, one message)
N_WHY = (" for packing_fraction=1.5 and bimodal_factor=1.4: the largest spheres must be smaller than a quarter "
         "of the 500 µm cell for each pair to interact through one image only (or a smaller packing_fraction)")

#: a quick run (no crosslinks, 30 spheres, one period; well under a second)
TINY = dict(N=30, cut_lines=0, do_permanent_links=False, relative_frequency=0.25, pre_periods=0.5, periods=1,
            post_periods=0.5, doDrawing=False, plotStress=False)
TINY_ARGV = ["--N", "30", "--cut-lines", "0", "--no-permanent-links", "--relative-frequency", "0.25",
             "--pre-periods", "0.5", "--periods", "1", "--post-periods", "0.5", "--quiet"]

#: (parameter, bad value, its command-line argv or None where the command line cannot express it,
#: other parameters the case needs)
BAD = [
    ("N", "x", None, {}),                                  # wrong type (the CLI's int flag: argparse)
    ("N", 0, ["--N", "0"], {}),
    ("N", BIG, ["--N", str(BIG)], {}),
    ("N", np.int64(MAX_N + 1), ["--N", str(MAX_N + 1)], {}),
    ("theAmplitude", -1.0, ["--amplitude", "-1"], {}),
    ("theAmplitude", BIG, ["--amplitude", str(BIG)], {}),
    ("theAmplitude", "0.2", None, {}),                     # wrong type
    ("cut_lines", BIG, ["--cut-lines", str(BIG)], {}),
    ("cut_lines", BIG, ["--cut-lines", str(BIG)], {"do_permanent_links": True}),
    ("periods", BIG, ["--periods", str(BIG)], {}),
    ("time_step_factor", BIG, ["--time-step-factor", str(BIG)], {}),
    ("seed", BIG, ["--seed", str(BIG)], {}),
    ("seed", -1, ["--seed", "-1"], {}),
    ("output_format", "xml", ["--output-format", "xml"], {}),
    ("saveOutputMovie", True, ["--movie"], {}),            # the movie needs saveOutputImages
    ("strict_io", "yes", None, {}),                        # a boolean flag cannot be "yes"
    ("backend", "nope", ["--backend", "nope"], {}),
    ("integrator", "rk4", ["--integrator", "rk4"], {}),
]


def api_error(kw):
    """(type, message) with which ``doParticleShearSimulation(**kw)`` refuses."""
    try:
        doParticleShearSimulation(**kw)
    except (ValueError, TypeError) as exc:
        return type(exc), str(exc)
    raise AssertionError(f"doParticleShearSimulation accepted {kw}")


def _work(*args, **kwargs):
    raise AssertionError("work started for an invalid run")


@contextlib.contextmanager
def no_work():
    """Fail the test as soon as any path builds, measures or submits a run."""
    with mock.patch("particleShear.run.sessions._build_simulation", _work), \
            mock.patch("particleShear.run.api.measure", _work), \
            mock.patch("particleShear.run.batch.measure", _work), \
            mock.patch("particleShear.sweep.series.run_series", _work):
        yield


def run_main(argv):
    """(exit status, stdout, stderr) of the command line ``main(argv)``, in this process."""
    out, err = io.StringIO(), io.StringIO()
    with mock.patch.object(sys, "stdout", out), mock.patch.object(sys, "stderr", err):
        try:
            rc = cli.main(list(argv))
        except SystemExit as exc:
            rc = exc.code
    return rc, out.getvalue(), err.getvalue()


def series_kwargs(name, value, extra):
    """The series call with ``name=value`` in each run (amplitudes and mu are the series' lists)."""
    kw = dict(TINY, N_repetitions=1, max_workers=1, **extra)
    kw.pop("do_permanent_links", None)   # the series' material runs are crosslinked
    if name == "theAmplitude":
        kw["amplitudes"] = [value]
    else:
        kw[name] = value
    return kw


class TestEveryPathRefusesAlike(unittest.TestCase):
    def test_the_api_refuses_with_the_message_of_validate_run(self):
        for name, value, _, extra in BAD:
            with self.subTest(name=name, value=show_value(value)), no_work():
                kw = dict(TINY, verbose=False, **extra, **{name: value})
                kind, message = api_error(kw)
                with self.assertRaises(kind) as cm:
                    validate_run(kw)
                self.assertEqual(str(cm.exception), message)
                self.assertTrue(message.startswith(f"{name}={show_value(value)} is "), message)
                self.assertNotIn("\n", message)
                self.assertLess(len(message), 400)   # a huge value is abbreviated

    def test_huge_integers_are_out_of_range_naming_the_limits(self):
        self.assertEqual(api_error(dict(TINY, N=BIG))[1],
                         "N=10**400 is out of range: allowed integers 11 <= value <= 1,000,000" + N_WHY)
        self.assertEqual(api_error(dict(TINY, theAmplitude=BIG))[1],
                         "theAmplitude=10**400 is out of range: allowed 0 < value <= 100")
        self.assertEqual(api_error(dict(TINY, cut_lines=BIG))[1],
                         "cut_lines=10**400 is out of range: allowed integers 0 <= value <= 1,000,000")
        self.assertEqual(api_error(dict(TINY, theMu=-BIG))[1], "theMu=-10**400 is out of range: allowed 0 <= value "
                                                               "<= 1e+06")
        kind, message = api_error(dict(TINY, periods=BIG))
        self.assertEqual((kind, message), (ValueError, "periods=10**400 is out of range: allowed 0 < value <= "
                                                       "1.79769e+308"))

    def test_one_range_statement_per_parameter(self):
        # below the cell's minimum, negative, zero or huge: the same rule, the same allowed range
        for n in (5, -5, 0, 10, BIG):
            with self.subTest(N=show_value(n)):
                self.assertEqual(api_error(dict(TINY, N=n))[1], f"N={show_value(n)} is out of range: allowed "
                                 "integers 11 <= value <= 1,000,000" + N_WHY)
        self.assertIsNone(validate_run(dict(TINY, N=11, verbose=False)) and None)   # the lower limit is allowed
        # a looser packing allows fewer spheres: the limit follows, the wording does not change
        self.assertEqual(api_error(dict(TINY, N=1, packing_fraction=0.1))[1],
                         "N=1 is out of range: allowed integers 2 <= value <= 1,000,000")
        # cut_lines: above what N can hold or negative, one statement
        kw = dict(TINY, do_permanent_links=True, doCutByTriangulation=True)
        messages = {api_error(dict(kw, cut_lines=c))[1].split(" is ", 1)[1] for c in (-1, 11, BIG)}
        self.assertEqual(messages, {"out of range: allowed integers 0 <= value <= 10 for N=30: each particle "
                                    "(Voronoi cell) must hold at least 3 spheres (more with a larger N; cut_lines=0: "
                                    "bulk gel)"})

    def test_show_value(self):
        self.assertEqual(show_value(BIG), "10**400")
        self.assertEqual(show_value(-BIG), "-10**400")
        self.assertEqual(show_value(BIG + 1), "100000…(401 digits)")
        self.assertEqual(show_value(123456789 * 10 ** 40), "123456…(49 digits)")
        self.assertEqual(show_value(10 ** 20 - 1), repr(10 ** 20 - 1))   # 20 digits: shown whole
        self.assertEqual(show_value(10 ** 20), "10**20")
        self.assertEqual(show_value(10 ** 5000), "10**5000")           # beyond Python's int-to-text limit
        self.assertEqual(show_value(0.5), "0.5")
        self.assertEqual(show_value(True), "True")

    def test_the_series_refuses_alike_before_any_run(self):
        for name, value, _, extra in BAD:
            with self.subTest(name=name, value=show_value(value)), no_work():
                # the series' first run is crosslinked (its cut_lines limit is the one of linked runs)
                kind, message = api_error(dict(TINY, verbose=False, **dict(extra, do_permanent_links=True),
                                               **{name: value}))
                with self.assertRaises(kind) as cm:
                    doParticleShearSimulationSeries(**series_kwargs(name, value, extra))
                self.assertEqual(str(cm.exception), message)

    def test_a_bad_run_late_in_the_series_stops_it_before_the_first(self):
        with no_work(), self.assertRaises(ValueError) as cm:
            doParticleShearSimulationSeries(**dict(series_kwargs("theAmplitude", 0.2, {}), amplitudes=[0.2, BIG]))
        self.assertEqual(str(cm.exception), api_error(dict(TINY, theAmplitude=BIG))[1])

    def test_run_batch_refuses_alike(self):
        for name, value, _, extra in BAD:
            with self.subTest(name=name, value=show_value(value)), no_work():
                kw = dict(TINY, verbose=False, seed=1, **extra)
                kw[name] = value
                kind, message = api_error(kw)
                with self.assertRaises(kind) as cm:
                    run_batch([dict(TINY, verbose=False, seed=2), kw])   # the second replica is bad
                self.assertEqual(str(cm.exception), message)

    def test_a_sweep_spec_refuses_alike_with_the_point_in_front(self):
        for name, value, _, extra in BAD:
            if name == "seed":   # the sweep sets the seeds itself ([seeds] root)
                continue
            with self.subTest(name=name, value=show_value(value)), no_work():
                value = value.item() if isinstance(value, np.generic) else value   # as TOML/JSON hold it
                kind, message = api_error(dict(TINY, verbose=False, **extra, **{name: value}))
                parameters = dict(TINY, **extra)
                parameters[name] = value
                with self.assertRaises(kind) as cm:
                    expand_runs(parse_spec({"parameters": parameters, "seeds": {"root": 1}}))
                self.assertEqual(str(cm.exception), "point 0 (fixed parameters): " + message)

    def test_a_json_spec_with_a_huge_integer(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "spec.json")
            with open(path, "w") as fh:
                json.dump({"parameters": dict(TINY, N=BIG), "seeds": {"root": 1}}, fh)
            with no_work(), self.assertRaises(ValueError) as cm:
                expand_runs(load_spec(path))
        # the same message as the API's, after the file and the point (issue 43: every error names the file)
        self.assertEqual(str(cm.exception),
                         f"SPEC {path!r}: point 0 (fixed parameters): " + api_error(dict(TINY, N=BIG))[1])

    def test_the_command_line_refuses_alike_naming_the_flags(self):
        for name, value, argv, extra in BAD:
            if argv is None:
                continue
            with self.subTest(argv=[show_value(a) if a == str(BIG) else a for a in argv]), no_work():
                full_argv = TINY_ARGV + (["--do-permanent-links"] if extra.get("do_permanent_links") else []) + argv
                kw = cli.api_kwargs(cli.build_parser().parse_args(full_argv))
                self.assertEqual(kw[name], value)   # the flag's value arrives as the API's
                _, message = api_error(kw)
                rc, out, err = run_main(full_argv)
                self.assertEqual(rc, 2)
                self.assertEqual(out, "")
                expected = cli.cli_message(message, {name: argv[0]})   # the names replaced by the flags
                self.assertEqual(err, f"particleShear: invalid parameter: {expected}\n")
                self.assertIn(argv[0], err)

    def test_cli_flags_in_the_message(self):
        rc, _, err = run_main(TINY_ARGV + ["--N", str(BIG)])
        self.assertEqual((rc, err), (2, "particleShear: invalid parameter: --N=10**400 is out of range: "
                                        "allowed integers 11 <= value <= 1,000,000 for --packing-fraction=1.5 and "
                                        "--bimodal-factor=1.4: the largest spheres must be smaller than a quarter of "
                                        "the 500 µm cell for each pair to interact through one image only (or a "
                                        "smaller --packing-fraction)\n"))


class TestPlotTargetOfTheCommandLine(unittest.TestCase):
    """``--plot FILE`` is checked before the run starts (exit status 2, one line naming --plot)."""

    def refused(self, argv):
        # the tiny run measures under 2 periods: its MeasurementWarning is not what is tested here
        with no_work(), warnings.catch_warnings():
            warnings.filterwarnings("ignore", category=MeasurementWarning)
            rc, out, err = run_main(TINY_ARGV + argv)
        self.assertEqual(rc, 2)
        self.assertEqual(out, "")
        self.assertEqual(err.count("\n"), 1, err)
        self.assertTrue(err.startswith("particleShear: invalid parameter: --plot"), err)
        return err

    def test_suffix(self):
        with tempfile.TemporaryDirectory() as d:
            err = self.refused(["--plot", os.path.join(d, "figure.gif")])
        self.assertIn("allowed extensions ['.eps', '.pdf', '.png', '.svg']", err)

    def test_folder(self):
        with tempfile.TemporaryDirectory() as d:
            err = self.refused(["--plot", os.path.join(d, "missing", "figure.png")])
        self.assertIn("no such directory", err)

    def test_matplotlib(self):
        with tempfile.TemporaryDirectory() as d, mock.patch("particleShear.plot_tools._has_matplotlib", lambda: False):
            err = self.refused(["--plot", os.path.join(d, "figure.png")])
        self.assertIn("pip install 'particleShear[plot]'", err)


class TestSeriesPassesEveryOutputOption(unittest.TestCase):
    """The series accepts, and gives every run, the output options of a single run."""

    def test_npz_strict_io_and_movie(self):
        with tempfile.TemporaryDirectory() as d:
            results = doParticleShearSimulationSeries(
                root_folder=d, N_repetitions=1, max_workers=1, seed=1, saveData=True, output_format="npz",
                strict_io=True, saveOutputImages=True, saveOutputMovie=True,
                **{k: v for k, v in TINY.items() if k != "do_permanent_links"}, do_bulk_control=False)
            self.assertEqual(len(results), 1)
            r = results[0]
            self.assertEqual((r.parameters["output_format"], r.parameters["strict_io"],
                              r.parameters["saveOutputMovie"]), ("npz", True, True))
            self.assertTrue(r.output_path.endswith(".npz"), r.output_path)
            self.assertTrue(os.path.isfile(r.output_path))
            self.assertTrue(os.path.isfile(os.path.join(r.image_folder, "movie.gif")))

    def test_unknown_option(self):
        with no_work(), self.assertRaises(TypeError) as cm:
            doParticleShearSimulationSeries(**series_kwargs("N", 30, {}), return_result=True)
        self.assertIn("return_result=True is invalid for doParticleShearSimulationSeries", str(cm.exception))


if __name__ == "__main__":
    unittest.main()
