"""RepTate and pyRheo files written from MeasuredTest and from simulation results.

RepTate itself is not installable here (Qt, NumPy >= 2.4), so its files are checked against the rules of
``RepTate.core.FileType.TXTColumnFile`` by a small parser written here: first line ``param=value;…``, then the
column names the application declares, then rows of whitespace-separated numbers (latin-1 text).
"""
import math
import os
import tempfile
import unittest

import numpy as np

from particleShear.experiment import MeasuredTest
from particleShear.experiment import writers
from particleShear.run.result import SimulationResult

_DECLARED = {"osc": ["w", "G'", "G''"], "gt": ["t", "Gt"], "creep": ["t", "strain"],
             "shear": ["t", "sigma_xy", "N1", "gdot"], "laos": ["time", "gamma", "sigma"]}
_REAL = "/work/shared/data/rheometer/reptate"


def parse_reptate(text, ext):
    """Parse by RepTate's rules; return (parameters, columns {name: array})."""
    text.encode("latin-1")                                   # RepTate opens files as latin-1
    lines = text.splitlines()
    params = {}
    for item in lines[0].split(";"):
        if item.strip():
            k, v = item.split("=")
            params[k] = v
    names = lines[1].split()
    assert names == _DECLARED[ext], names
    rows = [[float(v) for v in ln.split()] for ln in lines[2:] if ln.split()]
    assert all(len(r) == len(names) for r in rows)
    data = np.array(rows, float).reshape(-1, len(names))
    return params, {n: data[:, i] for i, n in enumerate(names)}


def _close(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    both_nan = np.isnan(a) & np.isnan(b)
    return bool(np.all(both_nan | (np.abs(a - b) <= 1e-12 * np.abs(b))))


class TestRepTate(unittest.TestCase):
    rng = np.random.default_rng(1)

    def _values(self, n):
        return self.rng.lognormal(0.0, 3.0, n)

    def test_frequency_sweep_osc(self):
        w, gp, gpp = np.sort(self._values(7)), self._values(7), self._values(7)
        t = MeasuredTest("frequency_sweep", {"angular_frequency": w, "Gp": gp, "Gpp": gpp},
                         {"label": "mu=0.3; crosslinked", "sample": "gel α"}, "simulated")
        ext, text = writers.reptate_text(t)
        self.assertEqual(ext, "osc")
        params, cols = parse_reptate(text, ext)
        self.assertEqual(params["origin"], "simulated")
        self.assertTrue(_close(cols["w"], w) and _close(cols["G'"], gp) and _close(cols["G''"], gpp))

    def test_relaxation_creep_laos_shear(self):
        t = np.cumsum(self._values(9))
        cases = [
            (MeasuredTest("relaxation", {"time": t, "G": self._values(9)}, {"gamma": 0.05}), "gt", {"gamma": 0.05}),
            (MeasuredTest("creep", {"time": t, "strain": self._values(9)}, {"stress": 12.5}), "creep",
             {"stress": 12.5}),
            (MeasuredTest("laos", {"time": t, "strain": self._values(9), "stress": -self._values(9)},
                          {"omega": 0.3, "gamma": 3.16}), "laos", {"omega": 0.3, "gamma": 3.16}),
            (MeasuredTest("flow_curve", {"time": t, "shear_rate": np.full(9, 0.01), "stress": self._values(9)}),
             "shear", {"gdot": 0.01}),
        ]
        for test, want_ext, want_params in cases:
            with self.subTest(kind=test.kind):
                ext, text = writers.reptate_text(test)
                self.assertEqual(ext, want_ext)
                params, cols = parse_reptate(text, ext)
                for k, v in want_params.items():
                    self.assertEqual(float(params[k]), v)
                names = _DECLARED[ext]
                for name, col in zip(names, writers.REPTATE_TYPES[test.kind][2]):
                    if col in test:
                        self.assertTrue(_close(cols[name], test[col]), (name, cols[name], test[col]))
                    else:
                        self.assertTrue(np.all(np.isnan(cols[name])))

    def test_refusals(self):
        sweep = MeasuredTest("amplitude_sweep", {"strain_amplitude": [0.01, 0.1], "Gp": [1, 2], "Gpp": [1, 2]})
        with self.assertRaisesRegex(ValueError, "test.kind='amplitude_sweep'"):
            writers.reptate_text(sweep)
        with self.assertRaisesRegex(ValueError, r"meta\['stress'\]"):
            writers.reptate_text(MeasuredTest("creep", {"time": [1, 2], "strain": [0.1, 0.2]}))
        with self.assertRaisesRegex(ValueError, r"meta\['omega'\]"):
            writers.reptate_text(MeasuredTest("laos", {"time": [1, 2], "strain": [0, 1], "stress": [0, 1]}))
        with self.assertRaisesRegex(ValueError, "test.kind='laos'"):
            writers.pyrheo_text(MeasuredTest("laos", {"time": [1, 2], "strain": [0, 1], "stress": [0, 1]}))

    def test_parser_reads_the_real_files(self):
        """The rules this file checks are those of RepTate's own example files (header names aside)."""
        path = os.path.join(_REAL, "CPyCL-omega00p30-gam03p1600.laos")
        if not os.path.exists(path):
            self.skipTest("no shared RepTate examples here")
        with open(path, encoding="latin-1") as fh:
            lines = fh.read().splitlines()
        self.assertTrue(lines[0].startswith("omega=0.3;gamma=3.16;"))
        self.assertTrue(all(all(_isnum(v) for v in ln.split()) for ln in lines[2:] if ln.split()))

    def test_write_is_atomic_and_sets_the_extension(self):
        t = MeasuredTest("relaxation", {"time": [1.0, 2.0], "G": [3.0, 2.5]})
        with tempfile.TemporaryDirectory() as d:
            p = writers.write_reptate(t, os.path.join(d, "sub", "run.txt"))
            self.assertTrue(p.endswith("run.gt"))
            self.assertEqual(sorted(os.listdir(os.path.join(d, "sub"))), ["run.gt"])


def _isnum(v):
    try:
        float(v)
        return True
    except ValueError:
        return False


class TestPyRheo(unittest.TestCase):
    def test_exact_headers_and_values(self):
        rng = np.random.default_rng(2)
        x, y, z = (rng.lognormal(0, 2, 5) for _ in range(3))
        cases = [
            (MeasuredTest("frequency_sweep", {"angular_frequency": x, "Gp": y, "Gpp": z}),
             "Angular Frequency\tStorage Modulus\tLoss Modulus", [x, y, z]),
            (MeasuredTest("relaxation", {"time": x, "G": y}), "Time\tRelaxation Modulus", [x, y]),
            (MeasuredTest("creep", {"time": x, "strain": y}, {"stress": 4.0}), "Time\tCreep Compliance", [x, y / 4.0]),
            (MeasuredTest("flow_curve", {"shear_rate": x, "stress": y}), "Shear Rate\tViscosity", [x, y / x]),
        ]
        for test, header, want in cases:
            with self.subTest(kind=test.kind):
                lines = writers.pyrheo_text(test).splitlines()
                self.assertEqual(lines[0], header)
                data = np.array([[float(v) for v in ln.split("\t")] for ln in lines[1:]])
                for i, w in enumerate(want):
                    self.assertTrue(_close(data[:, i], w))


def _table(folder, rows, protocols=False):
    from particleShear.sweep.spec import sweep_parameter_defaults
    from particleShear.sweep.table import table_columns, write_table
    params = sweep_parameter_defaults(protocols=protocols)
    full = []
    for i, r in enumerate(rows):
        row = dict(params, run_id=f"{i:012x}", status="ok", error="")
        row.update(r)
        full.append(row)
    os.makedirs(folder, exist_ok=True)
    write_table(os.path.join(folder, "results.csv"), full, table_columns(list(params)))


class TestFromSimulation(unittest.TestCase):
    def test_frequency_sweep_folder_to_osc(self):
        with tempfile.TemporaryDirectory() as d:
            rows = []
            for mu in (0.1, 0.5):
                for rep in range(2):
                    for rf in (0.01, 0.03, 0.1):
                        rows.append(dict(theMu=mu, relative_frequency=rf, frequency_Hz=rf * 7.0, repetition=rep,
                                         Gp_surface=100 * rf + mu + rep, Gpp_surface=10 * rf + mu,
                                         Gp_internal=1.0, Gpp_internal=1.0))
            _table(d, rows)
            tests, notes = writers.tests_from_sweep(d)
            self.assertEqual([t.kind for t in tests], ["frequency_sweep"] * 4)
            t = tests[0]
            self.assertEqual(t.origin, "simulated")
            self.assertTrue(_close(t["angular_frequency"], 2 * math.pi * 7.0 * np.array([0.01, 0.03, 0.1])))
            from particleShear.run.cli import main
            out = os.path.join(d, "out")
            self.assertEqual(main(["export", d, "--format", "reptate", "--out", out]), 0)
            files = sorted(os.listdir(out))
            self.assertEqual(len(files), 4)
            self.assertTrue(all(f.endswith(".osc") for f in files))
            with open(os.path.join(out, files[0]), encoding="latin-1") as fh:
                params, cols = parse_reptate(fh.read(), "osc")
            self.assertEqual(float(params["theMu"]), 0.1)
            self.assertTrue(_close(cols["G'"], [100 * rf + 0.1 for rf in (0.01, 0.03, 0.1)]))
            self.assertEqual(main(["export", d, "--format", "pyrheo", "--out", out + "2"]), 0)
            with open(os.path.join(out + "2", sorted(os.listdir(out + "2"))[0])) as fh:
                self.assertEqual(fh.readline(), "Angular Frequency\tStorage Modulus\tLoss Modulus\n")

    def test_steady_rows_to_flow_curve(self):
        with tempfile.TemporaryDirectory() as d:
            rows = [dict(protocol="steady", relative_rate=r, strain_rate=r * 3.0, stress_surface=2.0 + r,
                         viscosity_surface=(2.0 + r) / (r * 3.0), N1=0.5, repetition=0) for r in (0.001, 0.01, 0.1)]
            _table(d, rows, protocols=True)
            tests, _ = writers.tests_from_sweep(d)
            flow = [t for t in tests if t.kind == "flow_curve"]
            self.assertEqual(len(flow), 1)
            lines = writers.pyrheo_text(flow[0]).splitlines()
            self.assertEqual(lines[0], "Shear Rate\tViscosity")
            self.assertEqual(len(lines), 4)
            written, notes = writers.export(d, "reptate", os.path.join(d, "o"))
            self.assertEqual(written, [])
            self.assertIn("flow_curve (steady)", " ".join(notes))

    def test_simulation_result_to_laos(self):
        t = np.linspace(0, 2, 50)
        res = SimulationResult(G_surface=(1.0, 0.5), G_internal=(1.0, 0.5), stress_surface=(0.1, 0.05),
                               stress_internal=(0.1, 0.05), parameters={"theAmplitude": 0.2, "theMu": 0.3}, f=0.5,
                               series={"t": t, "strain": 0.2 * np.sin(np.pi * t), "strain_rate": t,
                                       "stress_surface": np.cos(np.pi * t), "stress_internal": t})
        (test,) = writers.tests_from_result(res)
        ext, text = writers.reptate_text(test)
        params, cols = parse_reptate(text, "laos")
        self.assertEqual(float(params["omega"]), 2 * math.pi * 0.5)
        self.assertEqual(float(params["gamma"]), 0.2)
        self.assertTrue(_close(cols["sigma"], np.cos(np.pi * t)))

    def test_bad_input(self):
        with self.assertRaisesRegex(ValueError, "format='xlsx'"):
            writers.export(".", "xlsx")
        with self.assertRaisesRegex(ValueError, "estimator='plate'"):
            writers.tests_from_sweep(".", "plate")


if __name__ == "__main__":
    unittest.main()
