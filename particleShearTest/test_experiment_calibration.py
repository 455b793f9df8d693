"""Calibration recovers a held-out grid point and its modulus scale.

The campaign is a synthetic results.csv (written with the package's table writer) from a model family
in which each grid point (theMu × cut_lines) has its own normalised amplitude sweep; the "measured"
sweep is an independent draw of one grid point with its moduli multiplied by a known factor standing
for E.
"""
import math
import os
import tempfile
import unittest

import numpy as np

from particleShear.experiment import MeasuredTest
from particleShear.experiment.calibration import calibrate

AMPS = (0.002, 0.005, 0.01, 0.03, 0.1, 0.3, 0.8)
E_SIM = 8000.0
TRUE = (0.3, 5)
SCALE = 2500.0


def model(A, mu, cuts):
    """G′, G″ (Pa) of a grid point: the crossover strain depends on mu, the loss level on cut_lines."""
    g0 = 0.05 * E_SIM
    gc = 0.02 + 0.2 * mu
    gp = g0 / math.sqrt(1 + (A / gc) ** 2)
    gpp = g0 * (0.02 * cuts + 0.3 * (A / gc) / (1 + (A / gc) ** 1.5))
    return gp, gpp


def noisy(rng, v):
    return v * math.exp(0.02 * rng.standard_normal())


def write_campaign(folder, seeds=3):
    from particleShear.sweep.spec import sweep_parameter_defaults
    from particleShear.sweep.table import table_columns, write_table
    rng = np.random.default_rng(11)
    params = sweep_parameter_defaults()
    rows = []
    for mu in (0.1, 0.3, 1.0):
        for cuts in (0, 5):
            for rep in range(seeds):
                for A in AMPS:
                    gp, gpp = model(A, mu, cuts)
                    r = dict(params, theMu=mu, cut_lines=cuts, theAmplitude=A, repetition=rep, status="ok",
                             error="", run_id=f"{len(rows):012x}", Young_modulus_spheres=E_SIM)
                    r.update(Gp_surface=noisy(rng, gp), Gpp_surface=noisy(rng, gpp), Gp_internal=gp,
                             Gpp_internal=gpp)
                    rows.append(r)
    write_table(os.path.join(folder, "results.csv"), rows, table_columns(list(params)))


def measured_replicates(n=3, amps=AMPS[1:]):
    rng = np.random.default_rng(99)
    out = []
    for r in range(n):
        gp = [noisy(rng, SCALE * model(A, *TRUE)[0]) for A in amps]
        gpp = [noisy(rng, SCALE * model(A, *TRUE)[1]) for A in amps]
        out.append(MeasuredTest("amplitude_sweep", {"strain_amplitude": amps, "Gp": gp, "Gpp": gpp},
                                {"label": "held-out", "replicate": r}))
    return out


class TestCalibration(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        write_campaign(cls.tmp.name)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_recovers_grid_point_and_scale(self):
        cal = calibrate(measured_replicates(), self.tmp.name, n_boot=500, seed=0)
        best = cal.best
        self.assertEqual((float(best["theMu"]), int(best["cut_lines"])), TRUE)
        self.assertEqual(sorted(cal.varying), ["cut_lines", "theMu"])
        self.assertLessEqual(best["scale_ci_low"], SCALE)
        self.assertGreaterEqual(best["scale_ci_high"], SCALE)
        self.assertLessEqual(best["E_ci_low"], SCALE * E_SIM)
        self.assertGreaterEqual(best["E_ci_high"], SCALE * E_SIM)
        self.assertAlmostEqual(best["E_to_use"], best["scale"] * E_SIM)
        self.assertGreater(best["p_best"], 0.5)
        self.assertEqual(len(cal.rows), 6)
        self.assertLess(best["mismatch"], cal.rows[1]["mismatch"])
        # the overlap is the measured range (it starts above the campaign's smallest amplitude)
        self.assertEqual(best["overlap_min"], AMPS[1])
        with tempfile.TemporaryDirectory() as d:
            path = cal.write_csv(os.path.join(d, "calibration.csv"))
            with open(path) as fh:
                self.assertEqual(fh.readline().split(",")[:4], ["rank", "label", "theMu", "cut_lines"])

    def test_one_replicate_and_same_intervals_for_same_seed(self):
        one = measured_replicates(1)
        a = calibrate(one[0], self.tmp.name, n_boot=200, seed=3)
        b = calibrate(one, self.tmp.name, n_boot=200, seed=3)
        self.assertEqual((float(a.best["theMu"]), int(a.best["cut_lines"])), TRUE)
        self.assertEqual(a.rows, b.rows)
        self.assertIn("one measured replicate", " ".join(a.notes))

    def test_bad_input_named(self):
        m = measured_replicates(1)
        for kw, word in ((dict(n_boot=0), "n_boot=0"), (dict(estimator="plates"), "estimator='plates'"),
                         (dict(confidence=1.5), "confidence=1.5"), (dict(seed=-1), "seed=-1")):
            with self.subTest(kw=kw), self.assertRaisesRegex(ValueError, word):
                calibrate(m, self.tmp.name, **kw)
        freq = MeasuredTest("frequency_sweep", {"angular_frequency": [1, 2], "Gp": [1, 2], "Gpp": [1, 2]})
        with self.assertRaisesRegex(ValueError, "kind='frequency_sweep'"):
            calibrate(freq, self.tmp.name)
        far = MeasuredTest("amplitude_sweep", {"strain_amplitude": [5.0, 9.0], "Gp": [1, 2], "Gpp": [1, 2]})
        with self.assertRaisesRegex(ValueError, "sweep_dir=.*no grid point"):
            calibrate(far, self.tmp.name)

    def test_cli_and_figure(self):
        from particleShear.run.cli import main
        m = measured_replicates(1)[0]
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "measured.csv")
            with open(path, "w") as fh:
                fh.write("Strain [1],G' [Pa],G'' [Pa]\n")        # read by read_rheometer
                for row in zip(m["strain_amplitude"], m["Gp"], m["Gpp"]):
                    fh.write(",".join(repr(float(v)) for v in row) + "\n")
            self.assertEqual(main(["calibrate", path, self.tmp.name, "--n-boot", "100", "--out", d]), 0)
            self.assertTrue(os.path.exists(os.path.join(d, "calibration.csv")))
            from particleShear.plot import _has_matplotlib
            if _has_matplotlib():
                self.assertGreater(os.path.getsize(os.path.join(d, "calibration.png")), 1000)
            self.assertEqual(main(["calibrate", path, self.tmp.name, "--n-boot", "0"]), 2)


if __name__ == "__main__":
    unittest.main()
