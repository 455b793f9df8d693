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
