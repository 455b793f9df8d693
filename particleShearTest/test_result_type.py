"""One result type (issue 46, item 3): every protocol's run returns a ``SimulationResult`` with the
same interface, ``RheometerResult`` is a deprecated name that still builds one (and unpickles 2.x
results), and no module of the package branches on the type of a result."""
import ast
import os
import pickle
import unittest
import warnings

import particleShear
from particleShear import SimulationResult, doParticleShearSimulation
from particleShear.protocols import PROTOCOLS
from particleShear.run.rheometer import RheometerResult

SMALL = dict(N=30, cut_lines=0, relative_frequency=0.2, seed=2, return_result=True, verbose=False, doDrawing=False,
             plotStress=False)
#: the shortest run of each shipped protocol
RUNS = {"oscillatory": dict(pre_periods=0.2, periods=1, post_periods=0),
        "steady": dict(total_strain=0.1, relative_rate=0.05),
        "relaxation": dict(hold_time=3.0),
        "creep": dict(creep_stress=20.0, hold_time=3.0),
        "amplitude_sweep": dict(sweep_amplitudes=[0.05, 0.1], pre_periods=0.2, periods=1, post_periods=0),
        "frequency_sweep": dict(sweep_frequencies=[0.2, 0.4], pre_periods=0.2, periods=1, post_periods=0)}
#: names a result is known by in the package
RESULT_TYPES = {"SimulationResult", "RheometerResult"}
#: the names a variable holding a result has in the package
RESULT_NAMES = {"result", "res"}


class TestEveryProtocolReturnsTheOneType(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cls.results = {name: doParticleShearSimulation(**SMALL, protocol=name, **kw) for name, kw in RUNS.items()}

    def test_every_shipped_protocol_is_covered(self):
        self.assertEqual(set(RUNS), set(PROTOCOLS))

    def test_one_type_one_interface(self):
        for name, res in self.results.items():
            with self.subTest(protocol=name):
                self.assertIs(type(res), SimulationResult)
                self.assertEqual(res.protocol, name)
                rows = res.rows()
                self.assertTrue(rows and all(row["run_id"] == res.run_id for row in rows))
                self.assertIsInstance(res.summary, dict)
                self.assertIsInstance(res.curves, dict)
                self.assertIsInstance(res.steps, list)
                self.assertIsInstance(res.values, list)
                self.assertIn(res.verdict.split(":")[0] if res.verdict else None, ("ok", "flagged", None))
                self.assertTrue(repr(res).startswith("SimulationResult("))
                self.assertIn("<table>", res._repr_html_())

    def test_values_are_what_the_call_returns(self):
        for name, kw in (("oscillatory", RUNS["oscillatory"]), ("creep", RUNS["creep"])):
            with self.subTest(protocol=name), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                plain = doParticleShearSimulation(**dict(SMALL, return_result=False), protocol=name, **kw)
            self.assertEqual(plain, self.results[name].values)
        self.assertEqual(self.results["oscillatory"].G, self.results["oscillatory"].values)
        with self.assertRaises(AttributeError):
            self.results["creep"].G    # noqa: B018 - a creep run has no G′, G″ of its own

    def test_rows_rebuild_the_result(self):
        for name in ("oscillatory", "creep", "amplitude_sweep"):
            res = self.results[name]
            with self.subTest(protocol=name):
                back = SimulationResult.from_rows(res.rows(), res.parameters, res.seed, res.spawn_key)
                self.assertIs(type(back), SimulationResult)
                self.assertEqual(back.protocol, name)
                self.assertEqual(back.values, res.values)
                self.assertEqual(back.verdict, res.verdict)

    def test_the_deprecated_name_builds_the_one_type(self):
        res = self.results["creep"]
        with self.assertWarns(DeprecationWarning):
            old = RheometerResult(res.protocol, res.parameters, res.seed, res.spawn_key, res.run_id, res.tau, res.dt,
                                  res.series, res.summary, res.curves, res.steps, res.timings)
        self.assertIs(type(old), SimulationResult)
        self.assertEqual(old.rows(), res.rows())
        self.assertEqual(repr(old), repr(res))

    def test_pickles_of_the_two_old_types_load(self):
        """A 2.x pickle holds the fields of its own type only: the others take their defaults."""
        creep, osc = self.results["creep"], self.results["oscillatory"]
        for res, cls, lacking in ((creep, RheometerResult, ("G_surface", "G_internal", "f", "microstructure",
                                                            "repetition", "_measures")),
                                  (osc, SimulationResult, ("protocol", "tau", "summary", "curves", "steps"))):
            with self.subTest(type=cls.__name__):
                old = cls.__new__(cls)
                old.__dict__.update({k: v for k, v in vars(res).items() if k not in lacking})
                back = pickle.loads(pickle.dumps(old))
                self.assertEqual(back.protocol, res.protocol)
                self.assertEqual(back.rows()[0]["run_id"], res.run_id)
                self.assertEqual(back.values, res.values)


class TestNoBranchOnTheResultType(unittest.TestCase):
    """No module of the package asks which type of result it holds: no ``isinstance``/``issubclass``
    of a result type, no ``type(result)`` comparison, no ``hasattr(result, ...)``."""

    @staticmethod
    def _names(node):
        if isinstance(node, ast.Tuple):
            return {n for el in node.elts for n in TestNoBranchOnTheResultType._names(el)}
        if isinstance(node, ast.Name):
            return {node.id}
        if isinstance(node, ast.Attribute):
            return {node.attr}
        return set()

    def test_no_branch(self):
        root = os.path.dirname(particleShear.__file__)
        found = []
        for folder, _, files in os.walk(root):
            for fname in files:
                if not fname.endswith(".py"):
                    continue
                path = os.path.join(folder, fname)
                with open(path, encoding="utf-8") as fh:
                    tree = ast.parse(fh.read(), path)
                for node in ast.walk(tree):
                    if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)):
                        continue
                    where = f"{os.path.relpath(path, root)}:{node.lineno}"
                    fn, args = node.func.id, node.args
                    if fn in ("isinstance", "issubclass") and len(args) == 2 and self._names(args[1]) & RESULT_TYPES:
                        found.append(f"{where}: {fn} of a result type")
                    elif fn == "hasattr" and args and self._names(args[0]) & RESULT_NAMES:
                        found.append(f"{where}: hasattr of a result")
                    elif fn == "type" and args and self._names(args[0]) & RESULT_NAMES:
                        parent_is_name = False   # type(result).__name__ in a message is not a branch
                        for other in ast.walk(tree):
                            if isinstance(other, ast.Attribute) and other.value is node and other.attr == "__name__":
                                parent_is_name = True
                        if not parent_is_name:
                            found.append(f"{where}: type() of a result")
        self.assertEqual(found, [])


if __name__ == "__main__":
    unittest.main()
