"""One measurement driver (issue 46 item 3): every protocol's runs are measured by
:func:`particleShear.simulation.driver.measure_sessions`, checked on the source and the registry.

- exactly one function of the package constitutes the replicas of a measurement (``_constitute``)
  and exactly one pre-equilibrates them (``pre_equilibrated``): the driver;
- every registered protocol has its part in the driver (``PARTS`` of its ``loop``), so the choice
  of a protocol's loop is data of the registry;
- :mod:`particleShear.run.measurement` names no protocol (no branch on a protocol's name) and calls
  the driver once; the two drivers of before are deprecated names of ``measure``.
"""
import ast
import pathlib
import unittest
import warnings
from unittest import mock

from particleShear.protocols import LOOPS, PROTOCOLS
from particleShear.run import measurement
from particleShear.simulation import driver

PACKAGE = pathlib.Path(driver.__file__).resolve().parent.parent


def _callers(name):
    """``{"module.function"}`` of the package's functions that call ``name`` (a bare or attribute call)."""
    found = set()
    for path in PACKAGE.rglob("*.py"):
        module = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        tree = ast.parse(path.read_text(encoding="utf-8"))

        def visit(node, where):
            for child in ast.iter_child_nodes(node):
                here = where
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    here = f"{where}.{child.name}" if where != module else f"{module}.{child.name}"
                if isinstance(child, ast.Call):
                    f = child.func
                    called = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else None
                    if called == name:
                        found.add(here)
                visit(child, here)
        visit(tree, module)
    return found


class TestOneDriver(unittest.TestCase):
    def test_one_function_constitutes_and_pre_equilibrates(self):
        one = {"particleShear.simulation.driver.measure_sessions"}
        self.assertEqual(_callers("_constitute"), one)
        self.assertEqual(_callers("pre_equilibrated"), one)

    def test_one_function_calls_the_driver_in_the_run_layer(self):
        callers = {c for c in _callers("measure_sessions") if c.startswith("particleShear.run.")}
        self.assertEqual(callers, {"particleShear.run.measurement.measure"})

    def test_every_protocol_has_its_part(self):
        self.assertEqual(set(driver.PARTS), set(LOOPS))
        for name, spec in PROTOCOLS.items():
            with self.subTest(protocol=name):
                self.assertIn(spec.loop, driver.PARTS)
        self.assertEqual(PROTOCOLS["oscillatory"].loop, "oscillation")
        self.assertEqual({PROTOCOLS[n].loop for n in ("steady", "relaxation", "creep")}, {"record"})
        self.assertEqual({PROTOCOLS[n].loop for n in ("amplitude_sweep", "frequency_sweep")}, {"segments"})

    def test_measure_names_no_protocol(self):
        tree = ast.parse(pathlib.Path(measurement.__file__).read_text(encoding="utf-8"))
        names = {node.value for node in ast.walk(tree) if isinstance(node, ast.Constant) and isinstance(node.value, str)}
        self.assertEqual(names & set(PROTOCOLS), set())
        self.assertNotIn("PROTOCOLS", {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)})

    def test_old_drivers_are_deprecated_names_of_measure(self):
        for name in ("measure_batch", "measure_rheometer"):
            with self.subTest(name=name), mock.patch.object(measurement, "measure", return_value=["r"]) as m:
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    self.assertEqual(getattr(measurement, name)(["run"]), ["r"])
                m.assert_called_once_with(["run"])
                self.assertTrue(any(issubclass(w.category, DeprecationWarning) for w in caught))


if __name__ == "__main__":
    unittest.main()


class _Tripwire:
    """Stands for an ensemble after its hand-over: any read fails the test (a write is let through,
    e.g. ``_close_windows`` clearing a renderer)."""

    def __getattr__(self, name):
        raise AssertionError(f"the measurement read the ensemble's {name!r} after the hand-over")


#: a small batch of two protocols' kinds of replica (frictional only; crosslinked and cut)
_QUICK = dict(N=20, relative_frequency=0.2, pre_periods=0.5, periods=1, post_periods=0.5, doDrawing=False,
              plotStress=False, verbose=False)
_BATCH = [dict(_QUICK, seed=1, theAmplitude=0.2, theMu=0.01, do_permanent_links=False, cut_lines=0),
          dict(_QUICK, seed=2, theAmplitude=0.3, theMu=0.05, do_permanent_links=True, cut_lines=2)]


class TestMeasurementReadsNoEnsemble(unittest.TestCase):
    """Issue 46 item 1: after the hand-over (``RunSession.hand_over``) the measurement works on the
    sessions' states; the ensemble is replaced by a tripwire there, and every replica's moduli and
    stress series must be the same numbers as those of the run that kept its ensemble (the state
    holds everything a measurement needs, generator included)."""

    @staticmethod
    def _tripped(original):
        def hand_over(run):
            original(run)
            run.sim.theEnsemble = _Tripwire()
            if run.exp is not None:
                run.exp.theEnsemble = _Tripwire()
        return hand_over

    def _both(self, call):
        from particleShear.simulation.oscillatory import RunSession
        kept = call()
        with mock.patch.object(RunSession, "hand_over", self._tripped(RunSession.hand_over)):
            tripped = call()
        return kept, tripped

    def test_oscillatory_batch(self):
        from particleShear import run_batch
        kept, tripped = self._both(lambda: run_batch(_BATCH))
        for a, b in zip(kept, tripped):
            self.assertEqual((a.G_surface, a.G_internal, a.removed_fraction), (b.G_surface, b.G_internal, b.removed_fraction))
            self.assertEqual(a.series["stress_surface"].tolist(), b.series["stress_surface"].tolist())

    def test_recording_protocol(self):
        from particleShear import doParticleShearSimulation
        kw = dict(_BATCH[1], protocol="relaxation", ramp_time=2.0, hold_time=5.0, return_result=True)
        kept, tripped = self._both(lambda: doParticleShearSimulation(**kw))
        self.assertEqual(kept.summary, tripped.summary)
        self.assertEqual(sorted(kept.series), sorted(tripped.series))
        for name in kept.series:
            self.assertEqual(kept.series[name].tolist(), tripped.series[name].tolist(), name)
