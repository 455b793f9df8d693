"""The parameter table (particleShear.parameters) is the one source of the run parameters.

The signature and the docstring of doParticleShearSimulation are checked against the table (order,
names, defaults, keyword-only options, types, choices, ranges), and what is derived from it is
checked to be the table's: validation limits, command-line flags, results columns and units, run
identity, batch classes, the protocols' parameters.
"""
import ast
import inspect
import math
import pathlib
import re
import unittest

from particleShear import parameters as P
from particleShear.run.api import doParticleShearSimulation
from particleShear.run.cli import parameter_docs

PACKAGE = pathlib.Path(P.__file__).resolve().parent


class TestSignatureAndDocstring(unittest.TestCase):
    def test_signature_is_the_table(self):
        sig = inspect.signature(doParticleShearSimulation)
        named = [n for n, par in sig.parameters.items() if par.kind is not par.VAR_KEYWORD]
        self.assertEqual(named, [p.name for p in P.SIGNATURE])
        # the contact laws' other parameters: the table's ``extra`` ones, after the signature's
        self.assertEqual(list(P.PARAMETERS), list(P.SIGNATURE) + [P.BY_NAME[n] for n in P.EXTRA])
        self.assertIn("hertz_scale", P.EXTRA)
        for p in P.SIGNATURE:
            par = sig.parameters[p.name]
            with self.subTest(name=p.name):
                self.assertEqual(par.default, p.default)
                self.assertEqual(type(par.default), type(p.default))
                self.assertEqual(par.kind is par.KEYWORD_ONLY, p.keyword_only)
        # 1.0.2's positional parameters come first, in its order
        self.assertEqual([p.keyword_only for p in P.PARAMETERS],
                         sorted(p.keyword_only for p in P.PARAMETERS))

    def test_docstring_documents_the_table(self):
        docs = parameter_docs(doParticleShearSimulation)
        self.assertEqual([n for n in docs if n in P.BY_NAME], [p.name for p in P.SIGNATURE])
        for p in P.SIGNATURE:
            type_text, text = docs[p.name]
            with self.subTest(name=p.name):
                self.assertIn("default", type_text)
                if p.choices:
                    self.assertTrue(type_text.startswith("{"))
                    shown = tuple(re.findall(r'"([^"]*)"', type_text[:type_text.index("}")]))
                    self.assertEqual(shown, p.choices)
                elif p.kind in ("float", "int", "bool"):
                    self.assertTrue(type_text.startswith(p.kind), type_text)
                if p.has_range:
                    self.assertIn("allowed " + p.range_text(), " ".join(text.split()))
                self.assertTrue(p.doc)
                # the table's line is the docstring's first sentence (the schema and --help show it)
                self.assertEqual(" ".join(text.split()).split(" ")[:3], p.doc.split(" ")[:3])


class TestDerived(unittest.TestCase):
    def test_table_is_consistent(self):
        self.assertEqual(len(P.BY_NAME), len(P.PARAMETERS))
        for p in P.PARAMETERS:
            with self.subTest(name=p.name):
                self.assertIn(p.kind, P.KINDS)
                self.assertIn(p.base_role, P.ROLES)
                if p.has_range:
                    self.assertIn(p.kind, ("float", "int"))
                    lo = -math.inf if p.low is None else p.low
                    hi = math.inf if p.high is None else p.high
                    self.assertLess(lo, hi)
                    self.assertTrue(lo <= p.default <= hi and p.default != (p.low if p.low_open else None))
                if p.choices:
                    self.assertIn(p.default, p.choices)
                for name in p.role_names:          # a law's or a protocol's parameters name real ones
                    selector = "contact_law" if p.base_role == "law" else "protocol"
                    self.assertIn(name, P.BY_NAME[selector].choices)

    def test_choices_are_the_implementations(self):
        from particleShear.engine.laws import LAWS
        from particleShear.engine.step import BatchEngine
        from particleShear.run.batch import BACKENDS
        from particleShear.simulation.formats import OUTPUT_FORMATS
        self.assertEqual(P.BY_NAME["integrator"].choices, tuple(BatchEngine.INTEGRATORS))
        self.assertEqual(P.BY_NAME["backend"].choices, tuple(BACKENDS))
        self.assertEqual(P.BY_NAME["output_format"].choices, tuple(OUTPUT_FORMATS))
        from particleShear.engine.contact_laws import MODULES
        self.assertEqual(P.BY_NAME["contact_law"].choices, tuple(MODULES))     # the laws of the laws folder
        self.assertEqual(P.BY_NAME["contact_law"].choices[:3], ("linear", "plateau", "hertz"))
        for law in P.BY_NAME["contact_law"].choices:       # each law's parameters are the table's
            self.assertEqual(tuple(LAWS[law].parameters or ()), P.law_parameters(law))

    def test_validation_limits_are_the_table(self):
        from particleShear.run.validation import validate_run
        for p in P.PARAMETERS:
            if not p.has_range:
                continue
            for edge, is_open, step in ((p.low, p.low_open, -1), (p.high, p.high_open, +1)):
                if edge is None:
                    continue
                with self.subTest(name=p.name, edge=edge):
                    outside = edge + step * max(abs(edge), 1e-300) * 1e-9 if not is_open else edge
                    with self.assertRaisesRegex(ValueError, re.escape(f"allowed {p.range_text()}")):
                        validate_run({p.name: outside, "N": 20})

    def test_schema_units_and_descriptions_come_from_the_table(self):
        from particleShear.sweep.schema import column_spec
        from particleShear.sweep.spec import sweep_parameter_defaults
        for name in sweep_parameter_defaults(protocols=True):
            p = P.BY_NAME[name]
            spec = column_spec(name)
            with self.subTest(name=name):
                self.assertIn(p.doc, spec["description"])
                if p.kind in ("float", "float_list"):
                    self.assertEqual(spec["unit"], p.unit)
                self.assertEqual(spec["nullable"], p.nullable)

    def test_cli_flags_come_from_the_table(self):
        from particleShear.run.cli import NOT_FLAGS, build_parser
        actions = {a.dest: a for a in build_parser()._actions}
        for p in P.PARAMETERS:
            if p.name in NOT_FLAGS:
                continue
            with self.subTest(name=p.name):
                self.assertIn(p.name, actions)
                if p.choices:
                    self.assertIn("{" + ",".join(p.choices) + "}", actions[p.name].metavar)
                if p.has_range:
                    self.assertIn(p.range_text(), actions[p.name].help)

    def test_batch_classes_and_identity(self):
        from particleShear.run.batch import PER_REPLICA_PARAMETERS, SCHEDULE_PARAMETERS
        from particleShear.simulation.provenance import identity_parameters
        self.assertEqual(set(SCHEDULE_PARAMETERS), {p.name for p in P.PARAMETERS if p.batch == "schedule"})
        self.assertEqual(set(PER_REPLICA_PARAMETERS), {p.name for p in P.PARAMETERS if p.batch == "replica"})
        full = P.defaults()
        # an oscillatory run of the linear law: no law or protocol parameter, no display/call one
        ids = identity_parameters(full)
        for p in P.PARAMETERS:
            with self.subTest(name=p.name):
                hashed = p.base_role in ("model", "numerics", "output") and not p.role_names
                self.assertEqual(p.name in ids, hashed)
        creep = identity_parameters(dict(full, protocol="creep", creep_stress=10.0))
        self.assertEqual({n for n in creep if P.BY_NAME[n].base_role == "protocol"},
                         {"protocol"} | set(P.protocol_parameters("creep")))
        plateau = identity_parameters(dict(full, contact_law="plateau"))
        self.assertTrue(set(P.law_parameters("plateau")) | {"contact_law"} <= set(plateau))

    def test_no_module_reads_the_signature_or_parses_the_docstring(self):
        """The table is read; the signature and the docstring of doParticleShearSimulation are not."""
        for path in PACKAGE.rglob("*.py"):
            tree = ast.parse(path.read_text(encoding="utf-8"))
            for node in ast.walk(tree):
                if isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Name) \
                        and node.args[0].id == "doParticleShearSimulation":
                    fn = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
                    with self.subTest(path=path.name, line=node.lineno):
                        self.assertNotIn(fn, ("signature", "parameter_docs", "getdoc"))


if __name__ == "__main__":
    unittest.main()


FIXTURE = pathlib.Path(__file__).resolve().parent / "fixtures"


class TestFolderOf200(unittest.TestCase):
    """A sweep folder written by 2.0.0 (fixtures/sweep_2_0_0, its SPEC beside it) resumes: nothing
    runs again, its run ids are those this code computes, and columns it lacks — a parameter whose
    default changes no run id, a result column — are added (the parameter at its default)."""

    def setUp(self):
        import json
        import shutil
        import tempfile
        self.tmp = tempfile.mkdtemp(prefix="ps_fixture_")
        self.addCleanup(shutil.rmtree, self.tmp, True)
        self.folder = pathlib.Path(self.tmp) / "sweep"
        shutil.copytree(FIXTURE / "sweep_2_0_0", self.folder)
        self.spec = json.loads((FIXTURE / "sweep_2_0_0.spec.json").read_text(encoding="utf-8"))

    def rows(self):
        import csv
        with open(self.folder / "results.csv", newline="", encoding="utf-8") as fh:
            return list(csv.DictReader(fh))

    def test_run_ids_are_this_codes(self):
        from particleShear.sweep.spec import expand_runs, parse_spec
        ids = sorted(r.run_id for r in expand_runs(parse_spec(self.spec)))
        self.assertEqual(ids, sorted(r["run_id"] for r in self.rows()))

    def test_resumes_without_running_and_adds_missing_columns(self):
        import csv
        import warnings
        from particleShear.sweep import run_sweep
        before = self.rows()
        header = list(before[0])
        dropped = ["plateau_slope", "verdict"]            # a law parameter (not the run's law), a result
        kept = [c for c in header if c not in dropped]
        with open(self.folder / "results.csv", "w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, kept, lineterminator="\n", extrasaction="ignore")
            w.writeheader()
            w.writerows(before)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rows = run_sweep(self.spec, str(self.folder), workers=1, progress=False)
        after = self.rows()
        # the parameters of laws added since 2.0.0 (hertz_scale) are added as columns at their defaults
        self.assertEqual([c for c in after[0] if c not in P.EXTRA], header)
        self.assertEqual(set(after[0]) - set(header), set(P.EXTRA))
        self.assertEqual(len(after), len(before))                 # nothing ran again
        self.assertEqual(sorted(r["run_id"] for r in rows), sorted(r["run_id"] for r in before))
        for a, b in zip(after, before):
            self.assertEqual({c: a[c] for c in kept}, {c: b[c] for c in kept})
            self.assertEqual(a["plateau_slope"], repr(P.BY_NAME["plateau_slope"].default))
            self.assertEqual(a["verdict"], "")
            for name in P.EXTRA:
                self.assertEqual(a[name], repr(P.BY_NAME[name].default))
