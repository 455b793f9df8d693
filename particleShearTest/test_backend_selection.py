"""Backend selection (docs/backends.md): ``backend="auto"`` by default (Numba where importable, else
NumPy, unless the environment variable ``PARTICLESHEAR_BACKEND`` says otherwise), the backend recorded by a run, and one run identity for the backends
that give NumPy's bits.

Numba is optional: the checks that need it are skipped without it, and a subprocess in which
``import numba`` fails (``sys.modules['numba'] = None``) shows what a NumPy-only install does.
"""
import os
import subprocess
import sys
import unittest
import warnings
from unittest import mock

import numpy as np

from particleShear import doParticleShearSimulation
from particleShear.engine import xp as xpmod
from particleShear.parameters import defaults
from particleShear.run.batch import run_batch
from particleShear.simulation.provenance import run_identity, same_input

HAVE_NUMBA = xpmod.numba_importable()

#: a short run (N = 30, one period): what matters is equality between backends, not the moduli
SMALL = dict(N=30, cut_lines=0, relative_frequency=0.2, pre_periods=0.2, periods=1, post_periods=0,
             doDrawing=False, plotStress=False, verbose=False, seed=1)


def _run(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # one period: no error bars (MeasurementWarning)
        return doParticleShearSimulation(return_result=True, **dict(SMALL, **kw))


def _environment(value):
    """The environment with ``PARTICLESHEAR_BACKEND`` set to ``value`` (removed for None)."""
    env = {k: v for k, v in os.environ.items() if k != xpmod.BACKEND_ENV}
    if value is not None:
        env[xpmod.BACKEND_ENV] = value
    return mock.patch.dict(os.environ, env, clear=True)


class TestResolver(unittest.TestCase):
    def test_auto_is_numba_where_importable_unless_the_environment_says_otherwise(self):
        with _environment(None):
            self.assertEqual(xpmod.AUTO_DEFAULT, "auto")
            want = "numba" if HAVE_NUMBA else "numpy"
            self.assertEqual(xpmod.resolve_backend("auto"), want)
            self.assertEqual(xpmod.resolve_backend(None), want)
            self.assertEqual(xpmod.get_backend().name, want)
            for name in ("numpy", "numba", "cupy"):     # an explicit name is returned as it is
                self.assertEqual(xpmod.resolve_backend(name), name)

    def test_environment_sets_what_auto_stands_for(self):
        for value in ("numpy", "auto") + (("numba",) if HAVE_NUMBA else ()):
            with self.subTest(value=value), _environment(value):
                want = value if value != "auto" else ("numba" if HAVE_NUMBA else "numpy")
                self.assertEqual(xpmod.resolve_backend("auto"), want)
                self.assertEqual(xpmod.resolve_backend("numpy"), "numpy")     # an explicit choice wins

    def test_bad_environment_value_is_refused_before_any_work(self):
        calls = []
        with _environment("gpu"):
            for call in (lambda: xpmod.resolve_backend("auto"),
                         lambda: _run(progress=lambda *a: calls.append(a)),
                         lambda: run_batch([dict(SMALL, progress=lambda *a: calls.append(a))])):
                with self.assertRaises(ValueError) as caught:
                    call()
                text = str(caught.exception)
                self.assertIn("PARTICLESHEAR_BACKEND='gpu'", text)
                for name in xpmod.backend_names():
                    self.assertIn(repr(name), text)
        self.assertEqual(calls, [], "no phase of a run began")

    def test_identity_of_backends(self):
        """numpy, numba and auto are one run; cupy (equal only to rounding) is a run of its own."""
        base = dict(SMALL, theAmplitude=0.2)
        ids = {b: run_identity(dict(base, backend=b), 1, ()) for b in ("numpy", "numba", "auto", "cupy")}
        self.assertEqual(ids["numba"], ids["numpy"])
        self.assertEqual(ids["auto"], ids["numpy"])
        self.assertNotEqual(ids["cupy"], ids["numpy"])
        # the default run, seed 1 (entropy 1): one id whichever CPU backend measures it (docs/backends.md)
        for b in ("numpy", "numba", "auto"):
            self.assertEqual(run_identity(dict(defaults(), seed=1, backend=b), 1, ()), "0f296519b842")
        # a results-table cell of the backend used is the input "auto" or "numpy"
        self.assertTrue(same_input("numba", "auto", "backend"))
        self.assertTrue(same_input("numpy", "auto", "backend"))
        self.assertFalse(same_input("cupy", "auto", "backend"))


class TestRecordedBackend(unittest.TestCase):
    def test_run_records_the_backend_used(self):
        with _environment("auto"):
            got = _run()
        used = "numba" if HAVE_NUMBA else "numpy"
        self.assertEqual(got.parameters["backend"], used)
        self.assertEqual(got.rows()[0]["backend"], used)

    def test_environment_chooses_the_backend_of_a_run(self):
        with _environment("numpy"):
            self.assertEqual(_run().parameters["backend"], "numpy")

    @unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
    def test_backends_are_one_run_bit_for_bit(self):
        with _environment("auto"):
            runs = {b: _run(backend=b) for b in ("numpy", "numba", "auto")}
        ref = runs["numpy"]
        self.assertEqual(runs["auto"].parameters["backend"], "numba")
        for b in ("numba", "auto"):
            with self.subTest(backend=b):
                self.assertEqual(runs[b].run_id, ref.run_id)
                for key in ref.series:
                    a, c = np.asarray(ref.series[key]), np.asarray(runs[b].series[key])
                    self.assertEqual(a.tobytes(), c.tobytes(), key)
                self.assertEqual(runs[b].G_surface, ref.G_surface)


class TestWithoutNumba(unittest.TestCase):
    """In a process where ``import numba`` fails: auto is NumPy, an explicit numba is refused."""

    CODE = """
import contextlib, io, sys, warnings
sys.modules['numba'] = None
from particleShear import doParticleShearSimulation
from particleShear.engine import xp
from particleShear.run.cli import main
assert not xp.numba_importable()
print(xp.resolve_backend('auto'))
kw = dict(N=30, cut_lines=0, relative_frequency=0.2, pre_periods=0.2, periods=1, post_periods=0,
          doDrawing=False, plotStress=False, verbose=False, seed=1, return_result=True)
warnings.simplefilter('ignore')
print(doParticleShearSimulation(**kw).parameters['backend'])
try:
    doParticleShearSimulation(backend='numba', **kw)
except ValueError as exc:
    print(exc)
err = io.StringIO()
with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
    code = main(['--backend', 'numba', '--N', '20', '--quiet'])
print(code, err.getvalue().strip().splitlines()[-1])
"""

    def test_auto_is_numpy_and_numba_is_refused(self):
        env = dict(os.environ, **{xpmod.BACKEND_ENV: "auto"})     # auto: Numba where importable
        out = subprocess.run([sys.executable, "-c", self.CODE], capture_output=True, text=True, timeout=300,
                             env=env)
        self.assertEqual(out.returncode, 0, out.stderr)
        lines = out.stdout.strip().splitlines()
        self.assertEqual(lines[0], "numpy")      # resolved
        self.assertEqual(lines[1], "numpy")      # recorded by the run
        self.assertIn("backend='numba' needs Numba", lines[2])
        self.assertIn("particleShear[fast]", lines[2])
        self.assertTrue(lines[3].startswith("2 "), lines[3])      # invalid parameters
        self.assertIn("--backend='numba' needs Numba", lines[3])
        self.assertIn("particleShear[fast]", lines[3])


if __name__ == "__main__":
    unittest.main()


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed")
class TestNumbaThatDoesNotCompile(unittest.TestCase):
    """Numba imports but compiling its loops fails (an unsupported build): a run that asked for
    "auto" warns once and runs NumPy with the same numbers and records "numpy"; one that asked for
    "numba" gets the error."""

    def test_auto_falls_back_and_numba_raises(self):
        code = ("import warnings, particleShear.simulation.driver as d\n"
                "def broken(**kw):\n"
                "    raise RuntimeError('no compiler here')\n"
                "d.compile_kernels = broken\n"
                "from particleShear import doParticleShearSimulation\n"
                "kw = dict(seed=1, N=30, relative_frequency=0.25, periods=1, verbose=False, doDrawing=False,\n"
                "          plotStress=False, return_result=True)\n"
                "try:\n"
                "    doParticleShearSimulation(backend='numba', **kw)\n"
                "    print('numba ran')\n"
                "except RuntimeError as e:\n"
                "    print('numba raised', e)\n"
                "with warnings.catch_warnings(record=True) as w:\n"
                "    warnings.simplefilter('always')\n"
                "    a = doParticleShearSimulation(**kw)\n"
                "print(a.parameters['backend'], sum('compiling its loops failed' in str(x.message) for x in w))\n"
                "b = doParticleShearSimulation(backend='numpy', **kw)\n"
                "print(a.G_surface == b.G_surface, a.run_id == b.run_id)\n")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                             env={k: v for k, v in os.environ.items() if k != xpmod.BACKEND_ENV})
        self.assertEqual(out.returncode, 0, out.stderr)
        lines = out.stdout.strip().splitlines()
        self.assertEqual(lines[0], "numba raised no compiler here")
        self.assertEqual(lines[1], "numpy 1")
        self.assertEqual(lines[2], "True True")
