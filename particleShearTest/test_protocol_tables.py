"""The rheometer's protocols in sweeps, tables, series and files (docs/protocols.md).

A sweep's row of a protocol run must be the direct call's result with the same seed (the
run's ``SeedSequence(root, spawn_key=(index,))``), bit for bit; a one-packing sweep writes one
row per step and counts as finished only with every step; ``float_list`` cells and protocol
columns round-trip through the typed table (CSV and Parquet); a protocol run's file is read
back exactly by ``read_run``; the series resumes protocol runs from their rows.

Runs are tiny (N = 30, no cut lines, strains of a few percent): ≈ 0.3–1 s each.
"""
import os
import tempfile
import unittest

import numpy as np

from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries, read_run
from particleShear.simulation.formats import RunFileError, verify_run
from particleShear.sweep import expand_runs, parse_spec, run_sweep
from particleShear.sweep.schema import load_results

SMALL = dict(N=30, cut_lines=0, relative_frequency=0.2, pre_periods=0.2, periods=3, post_periods=0,
             doDrawing=False, plotStress=False)
STEADY = {"parameters": dict(SMALL, protocol="steady", total_strain=0.04),
          "grid": {"relative_rate": [0.01, 0.02, 0.04]}, "seeds": {"root": 5, "repetitions": 1}}
SWEEP = {"parameters": dict(SMALL, protocol="amplitude_sweep"),
         "grid": {"sweep_amplitudes": [[0.05, 0.1, 0.15]]}, "seeds": {"root": 9, "repetitions": 1}}


def direct(run, **extra):
    """The run of a sweep called directly with the sweep's seed."""
    kw = {k: v for k, v in run.parameters.items() if k not in ("root_folder",)}
    kw.update(extra)
    ss = np.random.SeedSequence(run.seed_entropy, spawn_key=tuple(run.spawn_key))
    return doParticleShearSimulation(**dict(kw, seed=ss, verbose=False, return_result=True))


class TestSteadyInASweep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.out = os.path.join(cls.tmp.name, "steady")
        cls.rows = run_sweep(STEADY, cls.out, workers=1, progress=False)
        cls.runs = expand_runs(parse_spec(STEADY))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_rows_equal_the_direct_calls(self):
        self.assertEqual(len(self.rows), 3)
        for run, row in zip(self.runs, self.rows):
            res = direct(run)
            self.assertEqual(row["run_id"], run.run_id)
            self.assertEqual(row["run_id"], res.rows()[0]["run_id"])
            for key in ("stress_surface", "stress_surface_se", "viscosity_internal", "N1", "strain_transient"):
                self.assertEqual(row[key], res.summary[key], key)
            self.assertEqual(row["relative_rate"], run.parameters["relative_rate"])

    def test_typed_table_has_the_protocol_columns(self):
        df = load_results(self.out)
        self.assertEqual(list(df["protocol"]), ["steady"] * 3)
        self.assertEqual(str(df["stress_surface"].dtype), "float64")
        # σ/γ̇ of the table's own columns is the viscosity (a definition evaluated independently)
        np.testing.assert_allclose(df["viscosity_surface"], df["stress_surface"] / df["strain_rate"], rtol=1e-12)
        # the rate in 1/s is relative_rate/τ: the ratio of the two rows' rates is that of the relative rates
        self.assertAlmostEqual(df["strain_rate"][1] / df["strain_rate"][0], 2.0, places=12)

    def test_flow_curve_of_the_table(self):
        from particleShear.analysis import flow_curve_table
        rate, stress = flow_curve_table(load_results(self.out))
        by_rate = sorted(self.rows, key=lambda r: r["relative_rate"])
        np.testing.assert_array_equal(rate, [r["strain_rate"] for r in by_rate])
        np.testing.assert_array_equal(stress[:, 0], [r["stress_surface"] for r in by_rate])

    def test_flow_curve_figure_of_the_folder(self):
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            self.skipTest("matplotlib not installed")
        from particleShear.plot import plot_sweep
        fig = plot_sweep(self.out, path=False, n_boot=50)
        self.assertEqual(fig.get_label(), "flow_curve")
        # the σ panel's points are the table's stresses at its rates (one repetition: the values)
        pts = fig.axes[0].containers[0].lines[0].get_xydata()
        by_rate = sorted(self.rows, key=lambda r: r["relative_rate"])
        np.testing.assert_array_equal(pts[:, 0], [r["strain_rate"] for r in by_rate])
        np.testing.assert_array_equal(pts[:, 1], [r["stress_surface"] for r in by_rate])

    def test_resume_runs_nothing_again(self):
        seen = []
        again = run_sweep(STEADY, self.out, workers=1, progress=seen.append)
        self.assertEqual([r["stress_surface"] for r in again], [r["stress_surface"] for r in self.rows])
        self.assertEqual(seen, [])          # no run reported as run in this call


class TestOnePackingSweepInASweep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.out = os.path.join(cls.tmp.name, "amp")
        cls.rows = run_sweep(SWEEP, cls.out, workers=1, progress=False)
        cls.sweep_run = expand_runs(parse_spec(SWEEP))[0]

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_one_row_per_step_equal_to_the_direct_call(self):
        res = direct(self.sweep_run)
        self.assertEqual([r["sweep_position"] for r in self.rows], [0, 1, 2])
        self.assertEqual([r["sweep_amplitude"] for r in self.rows], [0.05, 0.1, 0.15])
        self.assertEqual({r["run_id"] for r in self.rows}, {self.sweep_run.run_id})
        for row, st in zip(self.rows, res.steps):
            self.assertEqual((row["Gp_surface"], row["Gpp_internal"]), (st["Gp_surface"], st["Gpp_internal"]))
        # the first step is the independent run with the first amplitude (same seed)
        alone = direct(self.sweep_run, protocol="oscillatory", theAmplitude=0.05, sweep_amplitudes=None)
        self.assertEqual(self.rows[0]["Gp_surface"], alone.G_surface[0])

    def test_list_cells_round_trip(self):
        df = load_results(self.out)
        self.assertEqual([list(v) for v in df["sweep_amplitudes"]], [[0.05, 0.1, 0.15]] * 3)
        rows = load_results(self.out, as_frame=False)
        self.assertEqual(rows[0]["sweep_amplitudes"], [0.05, 0.1, 0.15])
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            self.skipTest("pyarrow not installed")
        path = os.path.join(self.tmp.name, "t.parquet")
        df.to_parquet(path)
        import pandas as pd
        back = pd.read_parquet(path)
        self.assertEqual([list(v) for v in back["sweep_amplitudes"]], [[0.05, 0.1, 0.15]] * 3)

    def test_a_run_with_missing_steps_runs_again(self):
        import csv
        out = os.path.join(self.tmp.name, "cut")
        run_sweep(SWEEP, out, workers=1, progress=False)
        table = os.path.join(out, "results.csv")
        with open(table, newline="") as fh:
            lines = list(csv.reader(fh))
        with open(table, "w", newline="") as fh:   # the last step's row lost (a run cut short)
            csv.writer(fh).writerows(lines[:-1])
        again = run_sweep(SWEEP, out, workers=1, progress=False)
        self.assertEqual([r["sweep_position"] for r in again], [0, 1, 2])
        self.assertEqual([r["Gp_surface"] for r in again], [r["Gp_surface"] for r in self.rows])


class TestFilesAndSeries(unittest.TestCase):
    def test_every_format_reads_back_exactly(self):
        with tempfile.TemporaryDirectory() as d:
            for fmt in ("text", "text.gz", "npz", "parquet"):
                for kw in (dict(protocol="steady", relative_rate=0.02, total_strain=0.03),
                           dict(protocol="frequency_sweep", sweep_frequencies=[0.2, 0.3])):
                    with self.subTest(fmt=fmt, protocol=kw["protocol"]):
                        if fmt == "parquet":
                            try:
                                import pyarrow  # noqa: F401
                            except ImportError:
                                self.skipTest("pyarrow not installed")
                        res = doParticleShearSimulation(**SMALL, **kw, seed=3, saveData=True, root_folder=d + "/",
                                                        output_format=fmt, verbose=False, return_result=True)
                        self.assertIsNone(res.write_error)
                        data = read_run(res.output_path)
                        self.assertEqual(data.protocol, kw["protocol"])
                        for key, v in res.series.items():
                            np.testing.assert_array_equal(data.series[key], v)
                        if res.steps:
                            self.assertEqual(sorted(set(data["sweep_position"].tolist())), [0, 1])
                            self.assertEqual(data.steps[1]["Gp_surface"], res.steps[1]["Gp_surface"])
                        else:
                            self.assertEqual(data.summary["stress_surface"], res.summary["stress_surface"])

    def test_a_damaged_file_is_named(self):
        with tempfile.TemporaryDirectory() as d:
            res = doParticleShearSimulation(**SMALL, protocol="creep", creep_stress=20.0, hold_time=5.0, seed=3,
                                            saveData=True, root_folder=d + "/", verbose=False, return_result=True)
            data = read_run(res.output_path)
            self.assertIn("J", data.curves)
            with open(res.output_path, "r+b") as fh:    # cut inside the last row
                fh.truncate(os.path.getsize(res.output_path) - 5)
            with self.assertRaises(RunFileError):
                verify_run(res.output_path)
            with self.assertRaises(RunFileError):
                read_run(res.output_path)

    def test_series_runs_and_resumes_a_protocol(self):
        with tempfile.TemporaryDirectory() as d:
            kw = dict(SMALL, protocol="relaxation", amplitudes=[0.05], hold_time=5.0, seed=4)
            first = doParticleShearSimulationSeries(d + "/", N_repetitions=2, **kw)
            again = doParticleShearSimulationSeries(d + "/", N_repetitions=2, **kw)
            self.assertEqual(len(first), 2)
            self.assertEqual([r.summary["G_plateau_surface"] for r in again],
                             [r.summary["G_plateau_surface"] for r in first])
            self.assertTrue(all(r.protocol == "relaxation" for r in again))
            # resumed from the table's rows (SimulationResult.from_rows: no record), not run again
            self.assertEqual([r.series for r in again], [{}, {}])
            self.assertEqual([len(r.series["t"]) > 0 for r in first], [True, True])


class TestBadSpecs(unittest.TestCase):
    def test_errors_before_any_work(self):
        bad = [dict(STEADY, grid={"relative_rate": [0.01, -0.02]}),
               dict(STEADY, grid={"relative_rat": [0.01]}),
               dict(SWEEP, grid={"sweep_amplitudes": [[0.1, 0.3, 0.2]]}),
               dict(SWEEP, grid={"sweep_amplitudes": [[]]}),
               {"parameters": dict(SMALL, protocol="creep"), "seeds": {"root": 1, "repetitions": 1}}]
        for spec in bad:
            with self.subTest(spec=str(spec.get("grid"))):
                with tempfile.TemporaryDirectory() as d:
                    with self.assertRaises(ValueError):
                        run_sweep(spec, os.path.join(d, "x"), workers=1, progress=False)
                    self.assertFalse(os.path.exists(os.path.join(d, "x", "results.csv")))


if __name__ == "__main__":
    unittest.main()
