"""The one-file promise of a contact law (issue 45), shown: docs/design.md "Adding a contact law"
holds, as one python block, the complete file of a law the package does not ship, ``power``.

The test copies the package into a temporary folder, saves that block (read from docs/design.md)
as ``<copy>/particleShear/engine/contact_laws/power.py`` — no other file of the copy is edited —
and, in a subprocess with the copy first on ``sys.path``, checks that ``contact_law="power"`` and
``power_exponent=`` work in doParticleShearSimulation (N = 30, a short run), run_batch, a SPEC
with a ``[grid]`` over ``power_exponent`` (a 2-run sweep) and the command line (``--contact-law
power --power-exponent 2``; ``--help`` shows its unit and range), and that the results schema has
its column with its unit.  The law's value is checked against F = −k·d0·(δ/d0)^p written out
(1e-13 relative: a few rounded operations).
"""
import filecmp
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unittest

import particleShear

PACKAGE = pathlib.Path(particleShear.__file__).resolve().parent
DESIGN = PACKAGE.parent / "docs" / "design.md"

CHECK = textwrap.dedent(r'''
    import io, json, math, os, sys, warnings, contextlib
    warnings.simplefilter("ignore")
    import particleShear
    assert particleShear.__file__.startswith(sys.argv[1]), particleShear.__file__
    from particleShear import doParticleShearSimulation
    from particleShear.engine.contact_laws import LAWS, MODULES
    from particleShear.parameters import BY_NAME, EXTRA
    from particleShear.run.batch import run_batch
    from particleShear.run.cli import main
    from particleShear.sweep import run_sweep
    from particleShear.sweep.schema import column_spec
    from particleShear.simulation.provenance import identity_parameters
    from particleShear.parameters import defaults
    out = {}
    out["choices"] = list(BY_NAME["contact_law"].choices)
    out["extra"] = list(EXTRA)
    law = LAWS["power"]
    d, d0, k, p = 100.0, 120.0, 2.0, 2.0
    out["value"] = [float(law.function(d, d0, 50.0, 70.0, k, 1.0, p)), -k * d0 * ((d0 - d) / d0) ** p]
    out["beyond"] = float(law.function(130.0, d0, 60.0, 60.0, k, 1.0, p))
    quick = dict(N=30, periods=1, pre_periods=0, post_periods=0, relative_frequency=0.2, doDrawing=False,
                 plotStress=False, verbose=False, seed=3)
    a = doParticleShearSimulation(**quick, contact_law="power", power_exponent=2.0, return_result=True)
    b = doParticleShearSimulation(**quick, contact_law="power", return_result=True)
    lin = doParticleShearSimulation(**quick, return_result=True)
    out["G"] = [list(a.G), list(b.G), list(lin.G)]
    out["ids"] = [a.run_id, b.run_id, lin.run_id]
    batch = run_batch([dict(quick, contact_law="power", power_exponent=2.0), dict(quick, contact_law="power")])
    out["batch"] = [list(r.G) for r in batch]
    try:
        doParticleShearSimulation(**quick, contact_law="power", power_exponent=3.5)
    except ValueError as e:
        out["bad"] = str(e)
    out["identity"] = ["power_exponent" in identity_parameters(dict(defaults(), contact_law=c)) for c in ("power", "linear")]
    fixed = {k: v for k, v in quick.items() if k not in ("verbose", "seed")}
    spec = {"parameters": dict(fixed, contact_law="power"), "grid": {"power_exponent": [1.5, 2.0]},
            "seeds": {"root": 5, "repetitions": 1}}
    rows = run_sweep(spec, os.path.join(sys.argv[2], "sweep"), workers=1, progress=False)
    out["sweep"] = [[r["power_exponent"], r["status"], r["Gp_surface"]] for r in rows]
    out["schema"] = column_spec("power_exponent")
    for argv in (["--contact-law", "power", "--power-exponent", "2", "--N", "30", "--periods", "1", "--pre-periods",
                  "0", "--post-periods", "0", "--relative-frequency", "0.2", "--seed", "3", "--json", "--quiet"],
                 ["--help"]):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            try:
                rc = main(argv)
            except SystemExit as e:
                rc = e.code
        out["cli" if argv[0] != "--help" else "help"] = [rc, buf.getvalue()]
    print("RESULT" + json.dumps(out))
''')


def design_block():
    """The one python block of docs/design.md's "Adding a contact law" section."""
    text = DESIGN.read_text(encoding="utf-8")
    section = text[text.index("## Adding a contact law"):]
    section = section[:section.index("\n## ", 3)]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1, f"{len(blocks)} python blocks in 'Adding a contact law'"
    return blocks[0]


def tree(root):
    return sorted(str(p.relative_to(root)) for p in root.rglob("*.py"))


class TestOneFileLaw(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import json
        cls.tmp = pathlib.Path(tempfile.mkdtemp(prefix="ps_plugin_"))
        copy = cls.tmp / "copy"
        shutil.copytree(PACKAGE, copy / "particleShear", ignore=shutil.ignore_patterns("__pycache__"))
        cls.law_file = copy / "particleShear" / "engine" / "contact_laws" / "power.py"
        assert not cls.law_file.exists(), "the package ships no power law"
        cls.law_file.write_text(design_block(), encoding="utf-8")      # the one step
        cls.copy = copy
        # NumPy in the copy: Numba keys its cache by the source files' folder, so the copy's compiled
        # loops would be compiled anew (≈ 50 s of the suite); what is added by one file does not
        # depend on the backend, and the compiled backend is tested on the package itself
        env = dict(os.environ, PYTHONPATH=str(copy), PYTHONDONTWRITEBYTECODE="1", PARTICLESHEAR_BACKEND="numpy")
        proc = subprocess.run([sys.executable, "-c", CHECK, str(copy), str(cls.tmp)], capture_output=True,
                              text=True, env=env, cwd=str(cls.tmp), timeout=900)
        cls.proc = proc
        line = [s for s in proc.stdout.splitlines() if s.startswith("RESULT")]
        cls.out = json.loads(line[-1][6:]) if line else None

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, True)

    def setUp(self):
        self.assertIsNotNone(self.out, self.proc.stderr[-3000:])

    def test_one_file_added_nothing_else_edited(self):
        """Files touched to add ``power``: 1 (the law's file), 0 edits elsewhere."""
        added = sorted(set(tree(self.copy / "particleShear")) - set(tree(PACKAGE)))
        self.assertEqual(added, ["engine/contact_laws/power.py"])
        changed = [p for p in tree(PACKAGE)
                   if not filecmp.cmp(PACKAGE / p, self.copy / "particleShear" / p, shallow=False)]
        self.assertEqual(changed, [])

    def test_law_is_known_with_its_parameter(self):
        self.assertIn("power", self.out["choices"])
        self.assertIn("power_exponent", self.out["extra"])
        got, ref = self.out["value"]
        self.assertLess(got, 0)
        self.assertLessEqual(abs(got - ref), 1e-13 * abs(ref))
        self.assertEqual(self.out["beyond"], 0.0)

    def test_doParticleShearSimulation_and_run_batch(self):
        a, b, lin = self.out["G"]
        self.assertTrue(all(map(lambda g: g == g, a + b)))
        self.assertNotEqual(a, b)                    # power_exponent reaches the law
        self.assertNotEqual(b, lin)
        self.assertEqual(self.out["batch"], [a, b])  # a batch of two is its single runs, bit for bit
        self.assertEqual(len(set(self.out["ids"])), 3)
        self.assertEqual(self.out["identity"], [True, False])
        self.assertIn("power_exponent=3.5 is out of range: allowed 1 < value <= 3", self.out["bad"])

    def test_spec_grid_over_the_parameter(self):
        rows = self.out["sweep"]
        self.assertEqual(sorted(r[0] for r in rows), [1.5, 2.0])
        self.assertEqual({r[1] for r in rows}, {"ok"})
        self.assertNotEqual(rows[0][2], rows[1][2])

    def test_results_schema_column(self):
        self.assertEqual(self.out["schema"]["unit"], "1")
        self.assertIn("Exponent p of the power law", self.out["schema"]["description"])

    def test_command_line(self):
        import json
        rc, text = self.out["cli"]
        self.assertEqual(rc, 0)
        row = json.loads(text)
        self.assertEqual((row["contact_law"], row["power_exponent"]), ("power", 2.0))
        self.assertEqual([row["Gp_surface"], row["Gpp_surface"]], self.out["G"][0])
        rc, text = self.out["help"]
        flat = " ".join(text.split())
        self.assertIn("--contact-law {linear,plateau,hertz,power}", flat)
        self.assertIn("--power-exponent FLOAT", flat)
        self.assertIn("unit: dimensionless; allowed 1 < value <= 3", flat)


if __name__ == "__main__":
    unittest.main()
