"""Batches of replicas (particleShear.run.batch): a replica's run does not depend on its batch.

A replica of a batch must give exactly — bit for bit — the trajectory record, tensors and
G′/G″ of its single run, whatever the other replicas of the batch are (frictional or not,
crosslinked or not, other μ and amplitude), and a batched series must return exactly the
unbatched series in the same order.  Small N and short protocols keep the runs cheap; the
comparison is exact, so there is no tolerance to justify.
"""
import concurrent.futures
import unittest

import numpy as np

from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries
from particleShear.run.batch import batches, run_batch, schedule_key
from particleShear.simulation.output import sidecar_path
from particleShearTest.classes_loops import classes_pre_equilibrate, classes_run_protocol

#: ~300 protocol steps of 20 spheres (the quick scene of test_simulation.py)
QUICK = dict(N=20, relative_frequency=0.2, pre_periods=0.5, periods=1, post_periods=0.5, doDrawing=False,
             plotStress=False, verbose=False)

#: five mixed replicas sharing one schedule whose constitutions differ: frictional only; crosslinked
#: and cut with stronger friction and a larger amplitude; crosslinked without friction; crosslinked,
#: uncut, at an amplitude below 0.1 (extra relaxation blocks, some with μ = 0); crosslinked with
#: reinforced interfaces (shorter relaxation blocks), cut into three, links removed
MIXED = [dict(QUICK, seed=1, theAmplitude=0.2, theMu=0.01, do_permanent_links=False, cut_lines=0),
         dict(QUICK, seed=2, theAmplitude=0.3, theMu=0.05, do_permanent_links=True, cut_lines=2),
         dict(QUICK, seed=3, theAmplitude=0.1, theMu=0.0, do_permanent_links=True, cut_lines=2),
         dict(QUICK, seed=4, theAmplitude=0.07, theMu=0.01, do_permanent_links=True, cut_lines=0),
         dict(QUICK, seed=5, theAmplitude=0.15, theMu=0.02, do_permanent_links=True, cut_lines=3,
              interface_reenforcement_central=2, remove_link_fraction=0.2)]


def relaxation_sequence(kw):
    """(steps, dt, dt_max, μ) of every relaxation block of a run's constitution (run with the classes)."""
    from particleShear.run.api import _build_simulation, _seed_sequence
    from particleShear.run.batch import _REFERENCE_ARGUMENTS, _signature_defaults
    p = dict(_signature_defaults(), **kw)
    sim = _build_simulation({k: p[k] for k in _REFERENCE_ARGUMENTS}, _seed_sequence(p["seed"])[1], verbose=False,
                            progress=None, correct_drift_sign=False, reference_header=False, renderer="none",
                            time_step_factor=1.0, integrator="euler", stability_guard=False)
    seq = []
    gen = sim.constitution_steps()
    try:
        request = next(gen)
        while True:
            seq.append(request.key + (request.ensemble.mu,))
            request.run()
            request = next(gen)
    except StopIteration:
        return seq


class InlineExecutor(concurrent.futures.Executor):
    """Runs each task at submission (an executor without workers, for deterministic tests)."""

    def submit(self, fn, /, *args, **kwargs):
        fut = concurrent.futures.Future()
        fut.set_result(fn(*args, **kwargs))
        return fut


def assert_same_result(test, a, b):
    """Every number of two SimulationResults equal bit for bit (timings excluded: wall clock)."""
    for name in ("G_surface", "G_internal", "stress_surface", "stress_internal", "seed", "spawn_key", "dt", "f",
                 "N_steps", "damping_factor", "removed_fraction", "n_images", "output_path"):
        test.assertEqual(getattr(a, name), getattr(b, name), name)
    test.assertEqual(sorted(a.series), sorted(b.series))
    for key in a.series:
        x, y = np.asarray(a.series[key]), np.asarray(b.series[key])
        test.assertEqual(x.shape, y.shape, key)
        test.assertTrue(np.array_equal(x, y), key)
        test.assertEqual(x.tobytes(), y.tobytes(), key)  # also the sign of zeros
    # the physical parameters agree; the run-control inputs (output folder, seed object, console,
    # callbacks) are not recorded by the sweep runner behind an unbatched series
    control = {"seed", "root_folder", "verbose", "progress", "return_result"}
    pa = {k: v for k, v in a.parameters.items() if k not in control}
    pb = {k: v for k, v in b.parameters.items() if k not in control}
    test.assertEqual(pa, pb)


class TestBatchOfMixedReplicas(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.batch = run_batch(MIXED)
        cls.single = [doParticleShearSimulation(**kw, return_result=True) for kw in MIXED]
        cls.pair = run_batch([MIXED[2], MIXED[0]])  # other companions, other order

    def test_scene_is_mixed(self):
        # the replicas really differ: links where asked, different moduli, one schedule, and
        # constitutions of different relaxation blocks (the batch groups equal blocks)
        self.assertEqual(len({schedule_key(kw) for kw in MIXED}), 1)
        self.assertEqual(len({r.G_surface for r in self.single}), len(MIXED))
        sequences = [relaxation_sequence(kw) for kw in MIXED]
        self.assertEqual(len({tuple(q) for q in sequences}), len(MIXED))
        self.assertEqual(len({len(q) for q in sequences}), 3)
        self.assertIn(0, [block[3] for block in sequences[3][3:]])   # a μ = 0 block after crosslinking
        self.assertEqual(len({r.N_steps for r in self.single}), 1)
        self.assertGreater(self.single[0].N_steps, 100)

    def test_each_replica_equals_its_single_run(self):
        self.assertEqual(len(self.batch), len(MIXED))
        for n, (b, s) in enumerate(zip(self.batch, self.single)):
            with self.subTest(replica=n):
                assert_same_result(self, b, s)

    def test_replica_independent_of_its_companions(self):
        assert_same_result(self, self.pair[0], self.single[2])
        assert_same_result(self, self.pair[1], self.single[0])

    def test_whole_protocol_recorded(self):
        # the protocol's length by its definition, int((pre + P + post)/f / dt) steps (truncated), each
        # sample at its step's clock k·dt (a running sum of dt: rounding ≲ k·ε·t)
        for r in self.batch:
            T = (QUICK["pre_periods"] + QUICK["periods"] + QUICK["post_periods"]) / r.f
            self.assertEqual(r.N_steps, int(T / r.dt))
            t = np.asarray(r.series["t"])
            self.assertEqual(len(t), r.N_steps)
            k = np.arange(len(t))
            self.assertLessEqual(np.max(np.abs(t - k * r.dt)), len(t) * np.finfo(float).eps * t[-1])
            self.assertTrue(np.all(np.isfinite(r.series["stress_surface"])))


class TestVerletBatch(unittest.TestCase):
    """Velocity Verlet runs are measured by the engine and batch like Euler runs."""

    def test_each_verlet_replica_equals_its_single_run(self):
        runs = [dict(kw, integrator="verlet") for kw in MIXED[:3]]
        batch = run_batch(runs)
        for n, (b, kw) in enumerate(zip(batch, runs)):
            with self.subTest(replica=n):
                assert_same_result(self, b, doParticleShearSimulation(**kw, return_result=True))
        # the integrator matters here (viscous forces): the Euler run of the same seed differs
        euler = doParticleShearSimulation(**MIXED[0], return_result=True)
        self.assertNotEqual(euler.G_surface, batch[0].G_surface)


class TestBatchedSeries(unittest.TestCase):
    KW = dict(amplitudes=[0.1, 0.3], mu=[0.01], cut_lines=2, do_uncrosslinked_control=True, N_repetitions=1,
              seed=5, **QUICK)

    def test_batched_series_equals_unbatched(self):
        # four runs in batches of three: one full and one partial batch
        plain = doParticleShearSimulationSeries(executor=InlineExecutor(), **self.KW)
        batched = doParticleShearSimulationSeries(executor=InlineExecutor(), batch_size=3, **self.KW)
        self.assertEqual(len(plain), 4)
        self.assertEqual(len(batched), len(plain))
        for a, b in zip(batched, plain):
            assert_same_result(self, a, b)

    def test_batched_series_on_a_process_pool(self):
        kw = dict(self.KW, amplitudes=[0.2], cut_lines=0, do_uncrosslinked_control=False, N_repetitions=2)
        plain = doParticleShearSimulationSeries(executor=InlineExecutor(), **kw)
        with concurrent.futures.ProcessPoolExecutor(max_workers=1) as pool:
            batched = doParticleShearSimulationSeries(executor=pool, batch_size=2, **kw)
        for a, b in zip(batched, plain):
            assert_same_result(self, a, b)


class TestBatchGrouping(unittest.TestCase):
    def test_batches_keep_order_and_split_schedules(self):
        runs = [dict(N=20), dict(N=30), dict(N=20, theMu=0.05), dict(N=20), dict(N=30, seed=3)]
        self.assertEqual(batches(runs, 2), [[0, 2], [1, 4], [3]])
        self.assertEqual(batches(runs, 1), [[0], [1], [2], [3], [4]])

    def test_time_step_rule_separates_batches(self):
        # μ > 1 halves dt less often (docs/parameters.md): another schedule
        self.assertNotEqual(schedule_key(dict(theMu=0.01)), schedule_key(dict(theMu=2.0)))
        self.assertNotEqual(schedule_key(dict(theAmplitude=0.2)), schedule_key(dict(theAmplitude=0.6)))
        self.assertEqual(schedule_key(dict(theAmplitude=0.2, seed=1)), schedule_key(dict(theAmplitude=0.3)))


class TestConsoleAndProgress(unittest.TestCase):
    def test_documented_run_prints_reports_and_measures_as_the_api(self):
        # the documented simulation class's own runSimulation is the run doParticleShearSimulation
        # makes (one measurement, in the engine): the verbose messages line by line, numbers
        # included, the progress calls and G′/G″ are the same
        import contextlib
        import io

        from particleShear.messages import console_messages
        from particleShear.run.api import _build_simulation, _seed_sequence
        from particleShear.run.batch import _REFERENCE_ARGUMENTS, _signature_defaults

        def run(through_classes):
            out, prog = io.StringIO(), []
            kw = dict(QUICK, seed=1, do_permanent_links=True, cut_lines=2, verbose=True,
                      progress=lambda *a: prog.append(a[:3]))
            with contextlib.redirect_stdout(out):
                if through_classes:
                    p = dict(_signature_defaults(), **kw)
                    sim = _build_simulation({k: p[k] for k in _REFERENCE_ARGUMENTS}, _seed_sequence(1)[1],
                                            verbose=True, progress=kw["progress"], correct_drift_sign=False,
                                            reference_header=False, renderer="none", time_step_factor=1.0,
                                            integrator="euler", stability_guard=True)
                    with console_messages(True):
                        G = sim.runSimulation(periods=p["periods"], cool_factor=p["cool_factor"], plotStress=False)
                else:
                    G = doParticleShearSimulation(**kw)
            return out.getvalue().splitlines(), prog, G

        engine, classes = run(False), run(True)
        self.assertGreater(len(engine[0]), 15)
        self.assertEqual(engine[0], classes[0])
        self.assertEqual(list(engine[2]), list(classes[2]))
        # progress is throttled in time (~10 calls/s): compare the first and the last call of every phase
        ends = [[c for c in prog if c[1] <= 1 or c[1] == c[2]] for prog in (engine[1], classes[1])]
        self.assertEqual(ends[0], ends[1])
        self.assertEqual([c[0] for c in ends[0]], ["constitution", "constitution", "pre-equilibration",
                                                   "pre-equilibration", "protocol", "protocol"])


class TestBatchStability(unittest.TestCase):
    def test_diverging_replica_stops_the_batch_with_a_clear_error(self):
        # 40× the time step rule: the explicit step is far beyond its stability limit and blows up
        from particleShear import SimulationInstabilityError
        coarse = dict(QUICK, N=20, do_permanent_links=False, cut_lines=0, seed=1, time_step_factor=40)
        doParticleShearSimulation.last_result = None
        with self.assertRaises(SimulationInstabilityError) as cm:
            doParticleShearSimulation(**coarse, return_result=True)
        e = cm.exception
        self.assertIn(e.phase, ("pre-equilibration", "protocol"))
        self.assertIsInstance(e.step, int)
        self.assertLess(e.suggested_dt, 40 * doParticleShearSimulation(**dict(coarse, time_step_factor=1),
                                                                       return_result=True).dt)
        with self.assertRaises(SimulationInstabilityError):
            run_batch([dict(coarse, seed=2), coarse])


class TestBatchBadInput(unittest.TestCase):
    def test_batch_size(self):
        for bad in (0, -1, 1.5, True, "2"):
            with self.subTest(batch_size=bad):
                with self.assertRaisesRegex(ValueError, "batch_size"):
                    doParticleShearSimulationSeries(executor=InlineExecutor(), batch_size=bad, **QUICK)

    def test_backend(self):
        with self.assertRaisesRegex(ValueError, "backend='nonsense'"):
            run_batch([MIXED[0]], backend="nonsense")
        with self.assertRaisesRegex(ValueError, "backend"):
            doParticleShearSimulationSeries(executor=InlineExecutor(), backend="nonsense", **QUICK)

    def test_empty_mixed_or_unknown(self):
        with self.assertRaisesRegex(ValueError, "at least one run"):
            run_batch([])
        with self.assertRaisesRegex(ValueError, r"list_of_kwargs\[1\].*\bN\b"):
            run_batch([dict(QUICK), dict(QUICK, N=30)])
        with self.assertRaisesRegex(ValueError, r"'nonsense' is not a parameter of run_batch list_of_kwargs\[0\]"):
            run_batch([dict(QUICK, nonsense=1)])
        with self.assertRaisesRegex(ValueError, "theMu"):
            run_batch([dict(QUICK), dict(QUICK, theMu=-1)])



SERIES = ("t", "strain", "strain_rate", "stress_surface", "stress_internal")


def assert_same_numbers(test, a, b):
    """G′/G″, stresses, schedule and the five recorded series of two results equal bit for bit."""
    for name in ("G_surface", "G_internal", "stress_surface", "stress_internal", "seed", "spawn_key", "dt", "f",
                 "N_steps", "damping_factor", "removed_fraction"):
        test.assertEqual(getattr(a, name), getattr(b, name), name)
    for key in SERIES:
        test.assertEqual(np.asarray(a.series[key]).tobytes(), np.asarray(b.series[key]).tobytes(), key)


class TestSavedRunsMeasureThroughTheEngine(unittest.TestCase):
    """One seed, one set of numbers: a run that saves its data (text or npz, with or without the
    tensor table) gives bit for bit the G′/G″ and series of the same run without files, and the file
    holds exactly the returned series (text writes str() of each float, which reads back exactly)."""

    KW = dict(QUICK, seed=11, theAmplitude=0.2, theMu=0.05, do_permanent_links=True, cut_lines=2)

    @classmethod
    def setUpClass(cls):
        import tempfile
        cls.tmp = tempfile.TemporaryDirectory()
        cls.plain = doParticleShearSimulation(**cls.KW, return_result=True)
        cls.saved = {}
        for fmt, tensors in (("text", True), ("npz", True), ("text", False)):
            cls.saved[fmt, tensors] = doParticleShearSimulation(
                **cls.KW, root_folder=cls.tmp.name, saveData=True, output_format=fmt,
                saveStressTensorData=tensors, return_result=True)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_saved_equals_unsaved(self):
        self.assertGreater(self.plain.N_steps, 100)
        self.assertNotEqual(self.plain.G_surface[0], 0.0)
        for (fmt, tensors), res in self.saved.items():
            with self.subTest(output_format=fmt, saveStressTensorData=tensors):
                self.assertIsNone(res.write_error)
                assert_same_numbers(self, res, self.plain)

    def test_file_holds_the_returned_series(self):
        from particleShear import read_run
        for (fmt, tensors), res in self.saved.items():
            if not tensors:
                continue  # the text file has no table without the tensor data
            with self.subTest(output_format=fmt):
                data = read_run(res.output_path).series
                for key in SERIES:
                    self.assertEqual(data[key].tobytes(), np.asarray(res.series[key]).tobytes(), key)
                # the tensor table: the overall tensor's xy entry is minus τ_internal bit for bit (the
                # same row sums in the one formula of engine.forces.shear_from_sums)
                np.testing.assert_array_equal(-data["tensors"][:, 8, 0, 1], data["stress_internal"])

    def test_header_and_sidecar(self):
        import json
        import os
        res = self.saved["text", True]
        with open(res.output_path, encoding="utf-8") as fh:
            text = fh.read()
        self.assertTrue(text.startswith("Dermal filler Ensemble"))
        self.assertIn("Function call : \n", text)
        self.assertIn("Detailed stress tensor data", text)
        with open(sidecar_path(res.output_path), encoding="utf-8") as fh:
            meta = json.load(fh)
        self.assertEqual(meta["run_id"], res.run_id)
        self.assertEqual(os.path.basename(res.output_path), meta["file"])
        self.assertEqual([n for n in os.listdir(self.tmp.name) if n.endswith(".part")], [])


class TestBatchedSeriesWithFiles(unittest.TestCase):
    """A batched series that saves its files into a root folder equals the unbatched one bit for bit
    and writes one complete file per run."""

    KW = dict(amplitudes=[0.1, 0.3], mu=[0.01], cut_lines=2, do_uncrosslinked_control=True, N_repetitions=1,
              seed=5, saveData=True, **QUICK)

    def test_batched_series_with_files(self):
        import os
        import tempfile
        from particleShear import read_run
        with tempfile.TemporaryDirectory() as d1, tempfile.TemporaryDirectory() as d2:
            plain = doParticleShearSimulationSeries(root_folder=d1, executor=InlineExecutor(), **self.KW)
            batched = doParticleShearSimulationSeries(root_folder=d2, executor=InlineExecutor(), batch_size=3,
                                                      **self.KW)
            self.assertEqual(len(plain), 4)
            self.assertEqual(len(batched), 4)
            unsaved = doParticleShearSimulationSeries(executor=InlineExecutor(), batch_size=3,
                                                      **dict(self.KW, saveData=False))
            for a, b, c in zip(batched, plain, unsaved):
                assert_same_numbers(self, a, b)
                assert_same_numbers(self, a, c)
                self.assertTrue(os.path.dirname(a.output_path) == d2)
                data = read_run(a.output_path).series
                for key in SERIES:
                    self.assertEqual(data[key].tobytes(), np.asarray(a.series[key]).tobytes(), key)
            self.assertEqual(len({a.output_path for a in batched}), 4)
            self.assertEqual([n for n in os.listdir(d2) if n.endswith(".part")], [])


if __name__ == "__main__":
    unittest.main()


class TestDocumentedSimulationWithPerSphereParameters(unittest.TestCase):
    """A script's simulation whose spheres carry their own parameters (one sphere's permanent ratio,
    set through its handle) runs with runSimulation through the engine, each visit of a relation
    with its own sphere's values: its moduli are those of the experiment's oscillatory_shear_experiment
    on the same constituted ensemble (built again from the seed) bit for bit, and those of the
    documented step loop to rounding."""

    def test_per_sphere_parameters_run_in_the_engine(self):
        from particleShear.base.engine_adapter import uniform_parameters
        from particleShear.simulation.simulations import Simulation_interlocking_rheology

        class Mine(Simulation_interlocking_rheology):
            def initEnsemble(self, do_debug=False):
                ens = Simulation_interlocking_rheology.initEnsemble(self, do_debug)
                ens.sphereList[0].permanent_ratio_central = 2.0
                return ens

        def make():
            s = Mine("", N=20, cut_lines=2, do_permanent_links=True, relative_frequency=0.2, doDrawing=False,
                     saveData=False)
            s.baseline_pre_periods = s.baseline_post_periods = 0.5
            s.rng = np.random.default_rng(3)
            return s

        sim = make()
        G = sim.runSimulation(periods=1, cool_factor=0.5, plotStress=False)
        self.assertFalse(uniform_parameters(sim.theEnsemble))
        self.assertTrue(all(np.isfinite(G)))
        # the same ensemble measured by the classes' experiment directly
        ref = make()
        ref.initEnsemble()
        exp = ref.createExperiment(False, 1, False)
        sched = ref.measurement_schedule(0.5)
        G_ref = exp.oscillatory_shear_experiment(cool_factor=sched.cool, N_pre_equilibration_fixed_boundaries=sched.N_pre)
        self.assertEqual(G, G_ref)       # one step, one protocol loop: the same numbers
        # ... and the classes' documented step loop agrees to rounding: the series agree to ≈ 1e-15 of
        # their scale (test_visit_constants), the moduli are linear in them, so 1e-9 of |G*| is ample
        ref = make()
        ref.initEnsemble()
        exp = ref.createExperiment(False, 1, False)
        exp.prepare_recording()
        ref.theEnsemble.applyingShear = True
        classes_pre_equilibrate(exp, sched.N_pre, sched.cool)
        ref.theEnsemble.t = 0
        classes_run_protocol(exp, sched.cool)
        G_classes = [exp.evaluateStressAndG(useExternalForce=True)[k] for k in (2, 3)]
        scale = float(np.hypot(*G_ref))
        for a, b in zip(G_classes, G_ref):
            self.assertLessEqual(abs(a - b), 1e-9 * scale, (G_classes, G_ref))
