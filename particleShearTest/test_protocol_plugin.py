"""The one-file promise of a protocol (issues 45 and 46), shown: docs/design.md "Adding a protocol"
holds, as one python block, the complete file of a protocol the package does not ship, ``ramp``
(a linear strain-rate ramp from 0 to ``ramp_rate_max``/τ over ``ramp_duration``·τ).

The test copies the package into a temporary folder, saves that block (read from docs/design.md)
as ``<copy>/particleShear/protocols/ramp.py`` — no other file of the copy is edited — and, in a
subprocess with the copy first on ``sys.path``, checks that ``protocol="ramp"`` and its
parameters work in doParticleShearSimulation (N = 20, a short ramp), run_batch, a SPEC with a
``[grid]`` over ``ramp_rate_max`` (a 2-run sweep) and the command line (``--protocol ramp
--ramp-rate-max …``; ``--help`` shows unit and range), and that the results schema has its
columns with their units.

Physics: step i runs at the rate of its midpoint, a·(i + ½)·dt with a = γ̇_max/t_ramp, so the
strain at each step's start is exactly ½·a·t² (t = i·dt): the recorded strain must equal it to the
rounding of the ~1,000 additions of the strain and of the clock (1e-10 of the final strain; the
observed error is ~5e-14).  The rate of the last step is γ̇_max·(1 − dt/(2 t_ramp)) at most, and
the shear stress the positive rate adds to the packing's residual stress is positive (the
reported τ = −σ_xy has the sign of the strain rate in a sheared solid, as for ``steady``).
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
    import numpy as np
    import particleShear
    assert particleShear.__file__.startswith(sys.argv[1]), particleShear.__file__
    from particleShear import doParticleShearSimulation
    from particleShear.protocols import PROTOCOLS
    from particleShear.parameters import BY_NAME, EXTRA, defaults
    from particleShear.run.batch import run_batch
    from particleShear.run.cli import main
    from particleShear.sweep import run_sweep
    from particleShear.sweep.schema import column_spec
    from particleShear.simulation.provenance import identity_parameters
    out = {}
    out["choices"] = list(BY_NAME["protocol"].choices)
    out["extra"] = list(EXTRA)
    quick = dict(N=20, doDrawing=False, plotStress=False, verbose=False, seed=3, protocol="ramp", ramp_duration=20.0)
    r = doParticleShearSimulation(**quick, ramp_rate_max=0.05, return_result=True)
    s = r.series
    t, gam = s["t"], s["strain"] - s["strain"][0]
    a = 0.05 / r.tau / (20.0 * r.tau)
    out["strain"] = [float(np.max(np.abs(gam - 0.5 * a * t ** 2))), float(gam[-1]), float(0.5 * a * t[-1] ** 2)]
    out["rate"] = [float(s["strain_rate"][0] * r.tau), float(s["strain_rate"][-1] * r.tau), float(np.min(np.diff(s["strain_rate"])))]
    n = len(t)
    out["stress"] = [float(s["stress_surface"][0]), float(np.mean(s["stress_surface"][-n // 10:]))]
    out["values"] = list(r.values)
    out["summary"] = [r.summary["ramp_stress_end"], r.summary["ramp_viscosity_end"], r.tau]
    out["plain"] = doParticleShearSimulation(**quick, ramp_rate_max=0.05)
    slower = doParticleShearSimulation(**quick, ramp_rate_max=0.02, return_result=True)
    out["ids"] = [r.run_id, slower.run_id]
    batch = run_batch([dict(quick, ramp_rate_max=0.05), dict(quick, ramp_rate_max=0.02)])
    out["batch"] = [list(b.values) for b in batch] + [list(r.values), list(slower.values)]
    for bad in (dict(ramp_rate_max=-1.0), dict(ramp_rate_max=50.0)):
        try:
            doParticleShearSimulation(**quick, **bad)
        except ValueError as e:
            out.setdefault("bad", []).append(str(e))
    out["identity"] = ["ramp_rate_max" in identity_parameters(dict(defaults(), protocol=p)) for p in ("ramp", "steady")]
    fixed = {k: v for k, v in quick.items() if k not in ("verbose", "seed")}
    spec = {"parameters": fixed, "grid": {"ramp_rate_max": [0.02, 0.05]}, "seeds": {"root": 5, "repetitions": 1}}
    rows = run_sweep(spec, os.path.join(sys.argv[2], "sweep"), workers=1, progress=False)
    out["sweep"] = [[row["ramp_rate_max"], row["status"], row["ramp_stress_end"]] for row in rows]
    out["schema"] = [column_spec("ramp_stress_end"), column_spec("ramp_viscosity_end"), column_spec("ramp_rate_max")]
    for argv in (["--protocol", "ramp", "--ramp-rate-max", "0.05", "--ramp-duration", "20", "--N", "20", "--seed", "3",
                  "--json", "--quiet"], ["--help"]):
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
    """The one python block of docs/design.md's "Adding a protocol" section."""
    text = DESIGN.read_text(encoding="utf-8")
    section = text[text.index("## Adding a protocol"):]
    section = section[:section.index("\n## ", 3)]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1, f"{len(blocks)} python blocks in 'Adding a protocol'"
    return blocks[0]


def tree(root):
    return sorted(str(p.relative_to(root)) for p in root.rglob("*.py"))


class TestOneFileProtocol(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import json
        cls.tmp = pathlib.Path(tempfile.mkdtemp(prefix="ps_protocol_"))
        copy = cls.tmp / "copy"
        shutil.copytree(PACKAGE, copy / "particleShear", ignore=shutil.ignore_patterns("__pycache__"))
        cls.protocol_file = copy / "particleShear" / "protocols" / "ramp.py"
        assert not cls.protocol_file.exists(), "the package ships no ramp protocol"
        cls.protocol_file.write_text(design_block(), encoding="utf-8")      # the one step
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
        """Files touched to add ``ramp``: 1 (the protocol's file), 0 edits elsewhere."""
        added = sorted(set(tree(self.copy / "particleShear")) - set(tree(PACKAGE)))
        self.assertEqual(added, ["protocols/ramp.py"])
        changed = [p for p in tree(PACKAGE)
                   if not filecmp.cmp(PACKAGE / p, self.copy / "particleShear" / p, shallow=False)]
        self.assertEqual(changed, [])

    def test_protocol_is_known_with_its_parameters(self):
        self.assertEqual(self.out["choices"][-1], "ramp")
        self.assertIn("ramp_rate_max", self.out["extra"])
        self.assertIn("ramp_duration", self.out["extra"])

    def test_strain_is_half_a_t_squared(self):
        """γ(t) − γ(0) = ½·(γ̇_max/t_ramp)·t² at every step's start (module docstring)."""
        err, last, expected = self.out["strain"]
        self.assertGreater(last, 0)
        self.assertLessEqual(err, 1e-10 * expected)

    def test_rate_ramps_from_zero_to_the_maximum(self):
        first, last, min_increment = self.out["rate"]
        self.assertGreater(first, 0)
        self.assertLess(first, 0.05 * 1e-2)               # half a step of a ~1,000-step ramp
        self.assertLessEqual(last, 0.05)
        self.assertGreater(last, 0.05 * (1 - 1e-2))
        self.assertGreater(min_increment, 0)               # strictly increasing

    def test_stress_follows_the_positive_rate(self):
        start, end = self.out["stress"]
        self.assertGreater(end - start, 0)
        stress_end, viscosity_end, tau = self.out["summary"]
        self.assertEqual(stress_end, end)
        self.assertAlmostEqual(viscosity_end, stress_end / (0.05 / tau), delta=1e-12 * abs(viscosity_end))
        self.assertEqual(self.out["values"], [stress_end, viscosity_end])
        self.assertEqual(self.out["plain"], self.out["values"])

    def test_run_batch_and_identity(self):
        a, b, single_a, single_b = self.out["batch"]
        self.assertEqual([a, b], [single_a, single_b])     # a batch of two is its single runs, bit for bit
        self.assertNotEqual(a, b)                          # ramp_rate_max reaches the schedule
        self.assertEqual(len(set(self.out["ids"])), 2)
        self.assertEqual(self.out["identity"], [True, False])
        low, high = self.out["bad"]
        self.assertIn("ramp_rate_max=-1.0 is out of range: allowed 0 < value <= 1000", low)
        self.assertIn("ramp_rate_max=50.0 is out of range: allowed ramp_rate_max <=", high)

    def test_spec_grid_over_the_parameter(self):
        rows = self.out["sweep"]
        self.assertEqual(sorted(r[0] for r in rows), [0.02, 0.05])
        self.assertEqual({r[1] for r in rows}, {"ok"})
        self.assertNotEqual(rows[0][2], rows[1][2])

    def test_results_schema_columns(self):
        stress, viscosity, rate = self.out["schema"]
        self.assertEqual((stress["unit"], viscosity["unit"], rate["unit"]), ("Pa", "Pa·s", "1"))
        self.assertIn("empty unless protocol is 'ramp'", stress["description"])

    def test_command_line(self):
        import json
        rc, text = self.out["cli"]
        self.assertEqual(rc, 0)
        row = json.loads(text)
        self.assertEqual((row["protocol"], row["ramp_rate_max"]), ("ramp", 0.05))
        self.assertEqual([row["ramp_stress_end"], row["ramp_viscosity_end"]], self.out["values"])
        rc, text = self.out["help"]
        flat = " ".join(text.split())
        self.assertIn("amplitude_sweep,frequency_sweep,ramp}", flat)
        self.assertIn("--ramp-rate-max FLOAT", flat)
        self.assertIn("unit: dimensionless; allowed 0 < value <= 1000", flat)
        self.assertIn("unit: τ; allowed 0 < value <= 1e+09", flat)


if __name__ == "__main__":
    unittest.main()
