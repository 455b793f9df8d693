"""Readers of measured rheometer files (particleShear.experiment.readers) and the analysis on them.

Real RheoCompass and RepTate files are read from ``../shared/data/rheometer`` (or
``$PARTICLESHEAR_RHEOMETER_DATA``, or /work/shared/data/rheometer) when present, checked against an
independent parse; every other fixture is written here from the documented layouts.
"""
import codecs
import glob
import io
import math
import os
import tempfile
import unittest
from contextlib import redirect_stderr, redirect_stdout

import numpy as np

from particleShear.experiment.measured import (amplitude_sweep_summary, analyse_files, creep_summary, flow_curve_fit,
                                               frequency_sweep_table, measured_laos, relaxation_summary)
from particleShear.experiment.readers import read_rheometer

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _data_dir():
    for d in (os.environ.get("PARTICLESHEAR_RHEOMETER_DATA"), os.path.join(REPO, "..", "shared", "data", "rheometer"),
              "/work/shared/data/rheometer"):
        if d and os.path.isdir(os.path.join(d, "rheocompass")):
            return d
    return None


DATA = _data_dir()


def _write(folder, name, text, encoding="utf-8", newline="\n"):
    path = os.path.join(folder, name)
    with open(path, "w", encoding=encoding, newline="") as fh:
        fh.write(text.replace("\n", newline))
    return path


def _independent_rheocompass(path):
    """The intervals of a RheoCompass export by hand: codecs decode, split on CRLF and tabs."""
    with open(path, "rb") as fh:
        raw = fh.read()
    assert raw[:2] == codecs.BOM_UTF16_LE
    lines = codecs.decode(raw[2:], "utf-16-le").split("\r\n")
    blocks, k = [], 0
    while k < len(lines):
        if lines[k].startswith("Interval:"):
            names = lines[k + 1].split("\t")
            units = lines[k + 3].split("\t")
            rows, j = [], k + 4
            while j < len(lines) and lines[j] != "" and not lines[j].startswith("Test:"):
                cells = lines[j].split("\t")
                if any(c.strip() for c in cells):
                    rows.append(cells)
                j += 1
            if rows:
                blocks.append((names, units, rows))
            k = j
        k += 1
    return blocks


@unittest.skipIf(DATA is None, "no ../shared/data/rheometer folder (real exports)")
class RealFiles(unittest.TestCase):

    def test_rheocompass_against_an_independent_parse(self):
        files = sorted(glob.glob(os.path.join(DATA, "rheocompass", "*.csv")))
        self.assertTrue(files)
        for f in files:
            tests = read_rheometer(f)
            blocks = _independent_rheocompass(f)
            self.assertEqual(len(tests), len(blocks), f)
            for t, (names, units, rows) in zip(tests, blocks):
                self.assertEqual(len(t), len(rows), f)
                col = {n: i for i, n in enumerate(names)}
                for r in (0, len(rows) // 2, len(rows) - 1):
                    cells = rows[r]
                    if "Storage Modulus" in col:
                        self.assertEqual(t.kind, "frequency_sweep")
                        self.assertEqual(units[col["Angular Frequency"]], "[rad/s]")
                        self.assertEqual(t["angular_frequency"][r],
                                         float(cells[col["Angular Frequency"]].replace(",", ".")))
                        self.assertEqual(t["Gp"][r], float(cells[col["Storage Modulus"]].replace(",", ".")))
                        self.assertEqual(t["Gpp"][r], float(cells[col["Loss Modulus"]].replace(",", ".")))
                    else:
                        self.assertEqual(t.kind, "relaxation")
                        self.assertEqual(units[col["Shear Strain"]], "[%]")
                        self.assertAlmostEqual(t["strain"][r],
                                               float(cells[col["Shear Strain"]].replace(",", ".")) / 100, places=15)
                        self.assertEqual(t["G"][r], float(cells[col["Relaxation Modulus"]].replace(",", ".")))
                        self.assertEqual(t["time"][r], float(cells[col["Time"]].replace(",", ".")))
                self.assertIn("x0.01", t.meta["units"].get("strain", "x0.01"))

    def test_empty_interval_is_named(self):
        f = os.path.join(DATA, "rheocompass", "cnf_0-3_mc1-2_zn1-2_20c.csv")
        tests = read_rheometer(f)
        self.assertEqual(len(tests), 1)
        self.assertTrue(any("Interval 2" in s for s in tests[0].meta["skipped"]))

    def test_reptate_examples(self):
        kinds = {".creep": "creep", ".laos": "laos", ".gt": "relaxation", ".tts": "frequency_sweep"}
        for f in sorted(glob.glob(os.path.join(DATA, "reptate", "*"))):
            ext = os.path.splitext(f)[1]
            if ext not in kinds:
                continue
            t, = read_rheometer(f)
            self.assertEqual(t.kind, kinds[ext], f)
            with open(f) as fh:
                numeric = [ln.split() for ln in fh.read().splitlines()[1:]
                           if ln.strip() and not ln.startswith("#") and ln.split()[0][0] in "0123456789.-+"]
            self.assertEqual(len(t), len(numeric), f)
            first = [float(x) for x in numeric[0]]
            self.assertEqual(t[{"creep": "time", "laos": "time", "relaxation": "time",
                                "frequency_sweep": "angular_frequency"}[t.kind]][0], first[0])
        laos_file = glob.glob(os.path.join(DATA, "reptate", "*.laos"))[0]
        t, = read_rheometer(laos_file)
        r = measured_laos(t)
        self.assertAlmostEqual(r.omega, 0.3, places=12)
        self.assertAlmostEqual(r.strain_amplitude, 3.16, delta=0.05)    # gamma=3.16 of the header

    def test_analyse_cli_on_a_real_file(self):
        from particleShear.analysis.cli import main
        f = os.path.join(DATA, "rheocompass", "cnf_0-3_mc1-2_zn1-2_10c.csv")
        with tempfile.TemporaryDirectory() as out:
            buf = io.StringIO()
            with redirect_stdout(buf), redirect_stderr(io.StringIO()):
                self.assertEqual(main([f, "--out", out]), 0)
            self.assertIn("Gp_at_omega_min", buf.getvalue())
            self.assertIn("rad/s", buf.getvalue())
            self.assertTrue(os.path.isfile(os.path.join(out, "cnf_0-3_mc1-2_zn1-2_10c_analysis.csv")))


_RHEOCOMPASS = ("Test:\tgel A\nResult:\tAmplitude sweep\nInterval:\t1\n"
                "Point No.\tShear Strain\tStorage Modulus\tLoss Modulus\tAngular Frequency\n\t\t\t\t\n"
                "\t[%]\t[Pa]\t[Pa]\t[rad/s]\n"
                "1\t0,01\t1000,5\t50,25\t10\n2\t0,1\t998\t51\t10\n3\t1\t900\t80\t10\n4\t10\t300\t200\t10\n"
                "5\t100\t20\t60\t10\n\n"
                "Test:\tgel A\nResult:\tAmplitude sweep\nInterval:\t2\n"
                "Point No.\tShear Strain\tStorage Modulus\tLoss Modulus\tAngular Frequency\n\t\t\t\t\n"
                "\t[%]\t[kPa]\t[kPa]\t[rad/s]\n"
                "1\t0,01\t1,0\t0,05\t10\n2\t0,1\t1,0\t0,05\t10\n3\t1\t0,9\t0,08\t10\n4\t10\t0,3\t0,2\t10\n\n")


class Fixtures(unittest.TestCase):

    def setUp(self):
        self.dir = tempfile.mkdtemp()

    def test_rheocompass_utf16_comma_and_utf8_point_agree(self):
        a = _write(self.dir, "a.csv", _RHEOCOMPASS, encoding="utf-16", newline="\r\n")
        b = _write(self.dir, "b.csv", _RHEOCOMPASS.replace(",", "."), encoding="utf-8")
        ta, tb = read_rheometer(a), read_rheometer(b)
        self.assertEqual(len(ta), 2)
        for x, y in zip(ta, tb):
            self.assertEqual(x.kind, "amplitude_sweep")
            for c in ("strain_amplitude", "Gp", "Gpp", "angular_frequency"):
                np.testing.assert_array_equal(x[c], y[c])
        np.testing.assert_allclose(ta[0]["strain_amplitude"], [1e-4, 1e-3, 1e-2, 0.1, 1.0])   # % -> absolute
        np.testing.assert_allclose(ta[0]["Gp"][:2], [1000.5, 998])
        np.testing.assert_allclose(ta[1]["Gp"], [1000, 1000, 900, 300])                       # kPa -> Pa
        self.assertEqual(ta[0].meta["encoding"], "utf-16")
        self.assertIn("interval", ta[1].meta)

    def test_trios_lims(self):
        text = ("Filename\tgel.tri\nInstrument name\tDiscovery HR-2\nSample name\tgel B\n\n[step]\n"
                "Step name\tFrequency sweep (25.0 °C)\nNumber of points\t3\n"
                "Variables\tAngular frequency\tStorage modulus\tLoss modulus\tComplex viscosity\n"
                "\trad/s\tPa\tPa\tPa.s\n"
                "Data point\t0.1\t1000.5\t500.2\t11180.3\nData point\t1\t1050.3\t520.1\t1172\n"
                "Data point\t10\t1120.8\t580.5\t126\n\n[step]\nStep name\tAmplitude sweep\nNumber of points\t4\n"
                "Variables\tOscillation strain\tStorage modulus\tLoss modulus\tAngular frequency\n"
                "\t%\tkPa\tkPa\trad/s\n"
                "Data point\t0.1\t2\t0.1\t6.28\nData point\t1\t2\t0.1\t6.28\nData point\t10\t1\t0.5\t6.28\n"
                "Data point\t100\t0.1\t0.3\t6.28\n\n[step]\nStep name\tFlow ramp\nNumber of points\t4\n"
                "Variables\tShear rate\tViscosity\n\t1/s\tmPa·s\n"
                "Data point\t0.1\t60000\nData point\t1\t8000\nData point\t10\t1400\nData point\t100\t290\n")
        f = _write(self.dir, "gel.txt", text)
        fs, amp, flow = read_rheometer(f)
        self.assertEqual((fs.kind, amp.kind, flow.kind), ("frequency_sweep", "amplitude_sweep", "flow_curve"))
        self.assertEqual(fs.meta["sample"], "gel B")
        self.assertEqual(fs.meta["temperature"], 25.0)
        np.testing.assert_allclose(fs["Gp"], [1000.5, 1050.3, 1120.8])
        np.testing.assert_allclose(fs["frequency"], np.array([0.1, 1, 10]) / (2 * math.pi))
        np.testing.assert_allclose(amp["strain_amplitude"], [1e-3, 1e-2, 0.1, 1.0])
        np.testing.assert_allclose(amp["Gp"], [2000, 2000, 1000, 100])
        np.testing.assert_allclose(flow["viscosity"], [60, 8, 1.4, 0.29])                  # mPa·s -> Pa·s
        np.testing.assert_allclose(flow["stress"], [6, 8, 14, 29])
        # truncated: fewer rows than declared
        g = _write(self.dir, "cut.txt", text.replace("Data point\t100\t290\n", ""))
        with self.assertRaisesRegex(ValueError, r"cut\.txt.*line \d+.*declares 4 points"):
            read_rheometer(g)

    def test_reptate_all_extensions(self):
        files = {
            "a.osc": ("T=25;\nw G' G''\n0.1 10 5\n1 20 8\n10 40 12\n", "frequency_sweep"),
            "a.tts": ("T=25;Mw=1;\n0.1 10 5\n1 20 8\n", "frequency_sweep"),
            "a.gt": ("gamma=1;\n# a comment\nt Gt\n0.01 100\n0.1 90\n1 80\n", "relaxation"),
            "a.creep": ("stress=10;\nt strain\n1 0.1\n2 0.2\n3 0.3\n", "creep"),
            "a.shear": ("gdot=2;\nt sigma_xy N1 gdot\n0.1 1 0.5 2\n0.2 1.5 0.6 2\n0.3 1.7 0.6 2\n", "flow_curve"),
            "a.laos": ("omega=2;gamma=0.5;\ntime gamma sigma\n" + "".join(
                f"{t:.6f} {0.5 * math.sin(2 * t):.9f} {10 * math.sin(2 * t) + 3 * math.cos(2 * t):.9f}\n"
                for t in np.linspace(0, 2 * math.pi, 201)), "laos"),
        }
        for name, (text, kind) in files.items():
            t, = read_rheometer(_write(self.dir, name, text))
            self.assertEqual(t.kind, kind, name)
        t, = read_rheometer(os.path.join(self.dir, "a.creep"))
        self.assertEqual(t.meta["stress"], 10.0)
        np.testing.assert_allclose(t["compliance"], [0.01, 0.02, 0.03])
        t, = read_rheometer(os.path.join(self.dir, "a.shear"))
        np.testing.assert_allclose(t["N1"], [0.5, 0.6, 0.6])
        np.testing.assert_allclose(t["shear_rate"], [2, 2, 2])
        r = measured_laos(read_rheometer(os.path.join(self.dir, "a.laos"))[0])
        self.assertAlmostEqual(r.Gp[0], 20.0, places=5)      # σ = γ0 (G' sin + G'' cos): 10/0.5, 3/0.5
        self.assertAlmostEqual(r.Gpp[0], 6.0, places=5)
        bad = _write(self.dir, "b.osc", "T=25;\n0.1 10 5\n1 20\n")
        with self.assertRaisesRegex(ValueError, r"b\.osc', line 3, column 'Gpp'.*truncated"):
            read_rheometer(bad)

    def test_generic_table_with_column_map(self):
        f = _write(self.dir, "t.tsv", "time;strain;tau\n0,0;0,5;1,0\n1,0;1,5;2,0\n2,0;2,5;3,0\n")
        t, = read_rheometer(f, columns={"time": ("time", "min"), "strain": ("strain", "%")}, kind="creep")
        np.testing.assert_allclose(t["time"], [0, 60, 120])
        np.testing.assert_allclose(t["strain"], [0.005, 0.015, 0.025])
        self.assertEqual(t.meta["decimal"], ",")
        self.assertEqual(t.meta["ignored_columns"], ["tau"])
        # pyRheo layout (no units): the units must be given
        p = _write(self.dir, "p.txt", "Shear Rate\tViscosity\n0.1\t60\n1\t8\n10\t1.4\n100\t0.29\n")
        with self.assertRaisesRegex(ValueError, r"p\.txt', line 1, column 'Shear Rate'.*no unit.*units="):
            read_rheometer(p)
        t, = read_rheometer(p, units={"Shear Rate": "1/s", "Viscosity": "Pa·s"})
        self.assertEqual(t.kind, "flow_curve")

    def test_errors_name_file_line_column(self):
        text = "Strain\tG'\tG''\n[%]\t[Pa]\t[Pa]\n1\t10\t1\n10\tx\t2\n"
        f = _write(self.dir, "e.tsv", text)
        with self.assertRaisesRegex(ValueError, r"e\.tsv', line 4, column \"G'\".*'x' is not a number"):
            read_rheometer(f)
        f = _write(self.dir, "m.tsv", "Strain\tG'\tG''\n\t[Pa]\t[Pa]\n1\t10\t1\n10\t5\t2\n")
        with self.assertRaisesRegex(ValueError, r"m\.tsv', line 2, column 'Strain'.*no unit.*units=\{'Strain': '%'\}"):
            read_rheometer(f)
        f = _write(self.dir, "u.tsv", "Strain\tG'\tG''\n[furlong]\t[Pa]\t[Pa]\n1\t10\t1\n10\t5\t2\n")
        with self.assertRaisesRegex(ValueError, r"u\.tsv', line 2, column 'Strain'.*'furlong'"):
            read_rheometer(f)
        with self.assertRaisesRegex(ValueError, r"u\.tsv', line 1, column 'Stress'.*does not have"):
            read_rheometer(f, columns={"Stress": "stress"})
        f = _write(self.dir, "r.tsv", "Strain\tG'\tG''\n[%]\t[Pa]\t[Pa]\n1\t10\t1\n10\t5\n")
        with self.assertRaisesRegex(ValueError, r"r\.tsv', line 4, column \"G''\".*truncated"):
            read_rheometer(f)
        f = _write(self.dir, "x.tsv", "A\tB\n[s]\t[Pa]\n1\t2\n")
        with self.assertRaisesRegex(ValueError, r"x\.tsv', line 1.*cannot tell the kind"):
            read_rheometer(f)

    def test_file_size_bound(self):
        from particleShear.experiment import readers
        f = _write(self.dir, "big.csv", "a,b\n1,2\n")
        old = readers.MAX_FILE_BYTES
        readers.MAX_FILE_BYTES = 4
        try:
            with self.assertRaisesRegex(ValueError, "big.csv.*MAX_FILE_BYTES"):
                read_rheometer(f)
        finally:
            readers.MAX_FILE_BYTES = old


class Physics(unittest.TestCase):
    """A synthetic measured sweep from a known model gives the model's numbers back."""

    def test_amplitude_sweep_plateau_and_flow_point(self):
        # G'(γ0) = G0/(1+(γ0/γc)^2), G'' = G0/2·(γ0/γc)/(1+(γ0/γc)^2): flow point at γ0 = 2γc, plateau G0
        G0, gc = 1500.0, 0.05
        d = tempfile.mkdtemp()
        rng = np.random.default_rng(3)
        files = []
        for rep in range(4):
            A = np.logspace(-4, 0.5, 19) * (1 + 0.002 * rep)       # replicates: nearly the same amplitudes
            x = A / gc
            noise = 1 + 0.01 * rng.standard_normal((2, len(A)))
            gp, gpp = G0 / (1 + x ** 2) * noise[0], G0 / 2 * x / (1 + x ** 2) * noise[1]
            text = "Shear Strain [%],Storage Modulus [kPa],Loss Modulus [kPa],Angular Frequency [rad/s]\n" + "".join(
                f"{100 * a:.17g},{p / 1000:.17g},{q / 1000:.17g},6.283\n" for a, p, q in zip(A, gp, gpp))
            files.append(_write(d, f"rep{rep}.csv", text))
        tests = [read_rheometer(f)[0] for f in files]
        self.assertTrue(all(t.kind == "amplitude_sweep" for t in tests))
        s = amplitude_sweep_summary(tests, n_boot=400, rng=1)
        self.assertEqual(set(s.n_seeds.tolist()), {4})
        lo, hi = s.plateau_ci
        self.assertLessEqual(lo, G0 * (1 + 1e-4 ** 2 / gc ** 2) ** -1 * 1.0)
        self.assertTrue(lo <= G0 <= hi * (1 + 1e-5), (lo, G0, hi))
        self.assertAlmostEqual(s.flow_point, 2 * gc, delta=0.1 * gc)
        with tempfile.TemporaryDirectory() as out:
            res = analyse_files(files, out=out, pool=True, n_boot=200)
            self.assertTrue(os.path.isfile(os.path.join(out, "measured_analysis.csv")))
        plateau = [r for r in res["rows"] if r["quantity"] == "plateau"][0]
        self.assertEqual(plateau["n_tests"], 4)
        self.assertEqual(plateau["unit"], "Pa")

    def test_flow_curve_relaxation_creep_frequency(self):
        d = tempfile.mkdtemp()
        rate = np.logspace(-2, 2, 9)
        f = _write(d, "flow.csv", "Shear Rate [1/s],Shear Stress [Pa]\n" + "".join(
            f"{r:.17g},{5 + 2 * r ** 0.5:.17g}\n" for r in rate))
        with self.assertWarnsRegex(UserWarning, "one seed only"):
            fit = flow_curve_fit(read_rheometer(f), n_boot=50)
        self.assertAlmostEqual(fit.fit.sigma_y, 5.0, places=5)
        self.assertAlmostEqual(fit.fit.n, 0.5, places=5)
        t = np.linspace(0, 100, 501)
        g = _write(d, "relax.csv", "Time [s],Relaxation Modulus [Pa]\n" + "".join(
            f"{a:.17g},{50 + 400 * math.exp(-a / 2):.17g}\n" for a in t))
        r = relaxation_summary(read_rheometer(g)[0])
        self.assertAlmostEqual(r["G_plateau"], 50.0, places=6)
        c = _write(d, "c.creep", "stress=20;\n" + "".join(f"{a:.17g} {0.1 + 0.01 * a:.17g}\n" for a in t))
        r = creep_summary(read_rheometer(c)[0])
        self.assertAlmostEqual(r["creep_rate"], 0.01, places=9)
        self.assertAlmostEqual(r["creep_viscosity"], 2000.0, places=4)
        fs = _write(d, "fs.csv", "Frequency [Hz],G' [Pa],G'' [Pa]\n1,10,5\n2,20,8\n4,40,12\n")
        tab = frequency_sweep_table(read_rheometer(fs))
        np.testing.assert_allclose(tab["angular_frequency"], 2 * math.pi * np.array([1, 2, 4]))
        np.testing.assert_allclose(tab["tan_delta"], [0.5, 0.4, 0.3])


if __name__ == "__main__":
    unittest.main()
