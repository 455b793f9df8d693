"""The path of a parameter from the public call to the force kernel (issue 45, "Parameters as data").

A run's arguments are checked, completed, normalized, seeded and identified once
(:func:`particleShear.run.validation.validated_run`); the immutable
:class:`~particleShear.run.validation.RunParameters` it returns travels unchanged to the sessions,
and a parameter's value (here μ, ``theMu``) reaches the engine's per-replica constants
(``BatchState.mu``) and the pair constants of the Coulomb bound (``PairConstants.mu``) as given, through
the ensemble's :class:`~particleShear.linkable.builders.EnsembleRecipe` (its hops counted here).  A run,
a batch, a series and a sweep validate each run once.
"""
import concurrent.futures
import contextlib
import os
import pickle
import sys
import tempfile
import unittest
import warnings
from unittest import mock

import numpy as np

import particleShear.engine.forces as forces
import particleShear.run.validation as validation
import particleShear.simulation.oscillatory as oscillatory
import particleShear.simulation.fragmentation as fragmentation
from particleShear.linkable.builders import EnsembleRecipe
from particleShear.run.api import doParticleShearSimulation, doParticleShearSimulationSeries
from particleShear.run.batch import run_batch
import particleShear.run.batch as batch
from particleShear.run.validation import CheckedPoint, RunParameters, checked_point, validated_run
from particleShear.simulation import provenance
from particleShear.sweep import Sweep

#: a short run (amplitude 0.2: no μ = 0 relaxation block in the constitution)
SMALL = dict(N=20, cut_lines=0, relative_frequency=0.2, pre_periods=0.2, periods=1, post_periods=0, seed=1,
             doDrawing=False, verbose=False, backend="numpy", theAmplitude=0.2)
MU = 0.37


@contextlib.contextmanager
def counted(function, *modules):
    """Count the calls of ``function`` made through the names it has in ``modules``."""
    calls = []

    def wrapper(*args, **kwargs):
        calls.append(args)
        return function(*args, **kwargs)

    with contextlib.ExitStack() as stack:
        for module in modules:
            for name, value in vars(module).items():
                if value is function:
                    stack.enter_context(mock.patch.object(module, name, wrapper))
        yield calls


def identity_modules():
    """Every loaded particleShear module that holds ``run_identity`` under some name."""
    return [m for name, m in sys.modules.items() if name.startswith("particleShear") and m is not None
            and any(v is provenance.run_identity for v in vars(m).values())]


class TestOncePerRun(unittest.TestCase):
    """Validation and identity are computed exactly once per run."""

    def test_one_call_checks_and_identifies_once(self):
        with counted(validation._checked, validation) as checks, \
                counted(provenance.run_identity, *identity_modules()) as ids, \
                self.assertWarns(Warning):       # periods=1: no standard error (MeasurementWarning)
            result = doParticleShearSimulation(theMu=MU, return_result=True, **SMALL)
        self.assertEqual(len(checks), 1)
        self.assertEqual(len(ids), 1)
        # the id computed by the check is the run's, and equal to a fresh computation
        run = validated_run(dict(result.parameters, seed=1, backend="numpy"))
        self.assertEqual(result.run_id, run.run_id)

    def test_batch_checks_and_identifies_each_replica_once(self):
        runs = [dict(SMALL, theMu=m, seed=s) for m, s in ((MU, 1), (0.5, 2))]
        with counted(validation._checked, validation) as checks, \
                counted(provenance.run_identity, *identity_modules()) as ids, \
                self.assertWarns(Warning):
            results = run_batch(runs)
        self.assertEqual(len(checks), 2)
        self.assertEqual(len(ids), 2)
        self.assertEqual([r.parameters["theMu"] for r in results], [MU, 0.5])


#: a sweep of two points, one run each (a tiny run: N = 30, 112 steps a period), writing its files
SWEEP = {"parameters": dict(N=30, relative_frequency=0.5, pre_periods=0.5, periods=1, post_periods=0.5,
                            doDrawing=False, plotStress=False, saveData=True, backend="numpy"),
         "grid": {"theAmplitude": [0.2, 0.1]}, "seeds": {"root": 7, "repetitions": 1}}


class TestOncePerSweepRun(unittest.TestCase):
    """A sweep checks each point once and its worker does not check a run again (issue 45)."""

    def _sweep(self, batch_size):
        """Run :data:`SWEEP` in this process; the checks, run ids and schedule keys it computed, its rows."""
        with tempfile.TemporaryDirectory() as d, warnings.catch_warnings(), \
                counted(validation._checked, validation) as checks, \
                counted(provenance.run_identity, *identity_modules()) as ids, \
                counted(batch.schedule_key, batch) as keys, \
                concurrent.futures.ThreadPoolExecutor(1) as ex:
            warnings.simplefilter("ignore")      # periods=1: no standard error (MeasurementWarning)
            sweep = Sweep(SWEEP, d)
            n_checks, n_ids = len(checks), len(ids)
            rows = sweep.run(executor=ex, progress=False, batch_size=batch_size)
            return (n_checks, n_ids), (len(checks) - n_checks, len(ids) - n_ids, len(keys)), rows

    def test_a_sweep_run_is_validated_once_and_identified_for_its_task(self):
        (made_checks, _), (run_checks, run_ids, keys), rows = self._sweep(None)
        self.assertEqual([r["status"] for r in rows], ["ok", "ok"])
        self.assertEqual(made_checks, 2)       # the SPEC's check: one per point
        self.assertEqual(run_checks, 0)        # the worker does not validate again (was 1 per run)
        # per run: its task's SweepRun, its results row, the table sorted at the end, the rows read back
        # (was 6: the worker's validation and the recording of its outcome identified it again)
        self.assertEqual(run_ids, 4 * 2)
        self.assertEqual(keys, 0)

    def test_a_batched_sweep_groups_once(self):
        (made_checks, _), (run_checks, _, keys), rows = self._sweep(4)
        self.assertEqual([r["status"] for r in rows], ["ok", "ok"])
        self.assertEqual((made_checks, run_checks), (2, 0))
        self.assertEqual(keys, 2)              # batches(): one schedule key per run (was 2: run_batch again)

    def test_a_run_of_a_checked_point_is_its_validated_run(self):
        """CheckedPoint.run gives what validated_run gives for the same arguments, and pickles."""
        ss = np.random.SeedSequence(7, spawn_key=(3,))
        for extra in ({}, dict(protocol="amplitude_sweep", sweep_amplitudes=[0.05, 0.1])):
            with tempfile.TemporaryDirectory() as d, warnings.catch_warnings():
                warnings.simplefilter("ignore")
                params = dict(SWEEP["parameters"], theAmplitude=0.2, **extra)
                point = checked_point(dict(params, root_folder=os.curdir))
                self.assertIsInstance(point, CheckedPoint)
                point = pickle.loads(pickle.dumps(point))
                run = point.run(d, ss, return_result=True, verbose=False)
                want = validated_run(dict(params, root_folder=d, seed=ss, return_result=True, verbose=False))
                self.assertIsInstance(run, RunParameters)
                self.assertEqual(dict(run), dict(want))
                self.assertEqual((run.run_id, run.seed_entropy, run.spawn_key),
                                 (want.run_id, want.seed_entropy, want.spawn_key))
                self.assertEqual(run.cost, want.cost)
                with self.assertRaises(ValueError):     # the values a run sets are checked all the same
                    point.run(os.path.join(d, "missing"), ss, return_result=True, verbose=False)
                with self.assertRaises(TypeError):
                    point.run(d, ss, return_result=1, verbose=False)
                with self.assertRaises(TypeError):
                    point["theMu"] = 0.5

    def test_the_sweep_id_is_the_id_of_the_checked_run(self):
        """The id a sweep computes for a run (and gives its worker) is the one validated_run computes."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sweep = Sweep(SWEEP, os.path.join(tempfile.gettempdir(), "never-made"))
            for run in sweep.runs:
                ss = np.random.SeedSequence(run.seed_entropy, spawn_key=run.spawn_key)
                self.assertEqual(validated_run(dict(run.parameters, seed=ss, root_folder=os.curdir)).run_id, run.run_id)


#: a series of two runs (one amplitude, two μ) of the short run
SERIES = dict(N=20, cut_lines=0, relative_frequency=0.2, pre_periods=0.2, periods=1, post_periods=0, seed=1,
              doDrawing=False, plotStress=False, verbose=False, backend="numpy", amplitudes=[0.2], mu=[MU, 0.5],
              N_repetitions=1)


class TestOncePerSeriesRun(unittest.TestCase):
    """A series checks each run once: its worker measures the run from its checked arguments (was twice)."""

    def _series(self, **kw):
        with warnings.catch_warnings(), counted(validation._checked, validation) as checks, \
                concurrent.futures.ThreadPoolExecutor(1) as ex:
            warnings.simplefilter("ignore")      # periods=1: no standard error (MeasurementWarning)
            results = doParticleShearSimulationSeries(executor=ex, **dict(SERIES, **kw))
        return len(checks), results

    def test_each_run_is_validated_once(self):
        with tempfile.TemporaryDirectory() as d:
            for kw in ({}, dict(batch_size=2), dict(root_folder=d)):
                with self.subTest(**{k: v != d and v for k, v in kw.items()}):
                    checks, results = self._series(**kw)
                    self.assertEqual(checks, 2)
                    self.assertEqual([r.parameters["theMu"] for r in results], [MU, 0.5])
                    # the run id the series gave its worker is the checked run's
                    for r in results:
                        ss = np.random.SeedSequence(r.seed, spawn_key=r.spawn_key)
                        with warnings.catch_warnings():
                            warnings.simplefilter("ignore")
                            want = validated_run(dict(r.parameters, seed=ss, backend="numpy"))
                        self.assertEqual(r.run_id, want.run_id)


class TestRunParameters(unittest.TestCase):
    """The checked arguments cannot change on their way down, and survive a process boundary."""

    def setUp(self):
        with self.assertWarns(Warning):
            self.run = validated_run(dict(SMALL, theMu=MU))

    def test_complete_and_immutable(self):
        self.assertIsInstance(self.run, dict)
        self.assertEqual(self.run["theMu"], MU)
        self.assertIn("contact_law", self.run)         # defaults filled in
        for change in (lambda r: r.__setitem__("theMu", 0.5), lambda r: r.update(theMu=0.5),
                       lambda r: r.pop("theMu"), lambda r: r.setdefault("x", 1), lambda r: r.clear(),
                       lambda r: r.__delitem__("theMu"), lambda r: r.popitem()):
            with self.assertRaises(TypeError):
                change(self.run)
        self.assertEqual(self.run["theMu"], MU)
        copy = dict(self.run)
        copy["theMu"] = 0.5                              # a plain copy is the caller's to change
        self.assertEqual(self.run["theMu"], MU)

    def test_pickles_with_its_identity_and_seed(self):
        back = pickle.loads(pickle.dumps(self.run))
        self.assertIsInstance(back, RunParameters)
        self.assertEqual(dict(back), dict(self.run))
        self.assertEqual((back.run_id, back.seed_entropy, back.spawn_key),
                         (self.run.run_id, self.run.seed_entropy, self.run.spawn_key))
        self.assertEqual(back.generator.random(), self.run.generator.random())

    def test_identity_is_the_provenance_identity(self):
        self.assertEqual(self.run.run_id, provenance.run_identity(self.run, self.run.seed_entropy, self.run.spawn_key))


class TestMuReachesTheKernel(unittest.TestCase):
    """A changed ``theMu`` reaches ``BatchState.mu`` and the pair constants unchanged."""

    def test_mu_in_batch_state_and_pair_constants(self):
        """The measurement's BatchState.mu (made at the session's hand-over) and every candidate's constant μ (the row ``mu`` of the
        pair constants, written by ``PairConstants.set_bonds`` on every backend) equal theMu."""
        states, pair_mu = [], []
        state_from_ensembles, set_bonds = oscillatory.state_from_ensembles, forces.PairConstants.set_bonds

        def capture_state(*args, **kwargs):
            st = state_from_ensembles(*args, **kwargs)
            states.append(np.asarray(st.mu).copy())
            return st

        def capture_constants(C, *args, **kwargs):
            set_bonds(C, *args, **kwargs)
            if states:      # the measurement's pair constants (the constitution's relaxations may run at μ = 0)
                pair_mu.append(np.asarray(C.mu).copy())

        with mock.patch.object(oscillatory, "state_from_ensembles", capture_state), \
                mock.patch.object(forces.PairConstants, "set_bonds", capture_constants), self.assertWarns(Warning):
            result = doParticleShearSimulation(theMu=MU, return_result=True, **SMALL)
        self.assertEqual(result.parameters["theMu"], MU)
        self.assertTrue(states)
        for mu in states:                          # the measurement's state: μ of the replica as given
            np.testing.assert_array_equal(mu, [MU])
        self.assertTrue(pair_mu)
        for mu in pair_mu:                         # every pair constant of the Coulomb bound: μ as given
            self.assertTrue(np.all(mu == MU), mu)


    def test_mu_travels_as_one_object_in_two_records(self):
        """The hops of μ: the call's value is, as the very object, ``RunParameters["theMu"]``, then the field
        ``mu`` of the run's :class:`EnsembleRecipe`, which the constitution (on the engine's state, a run's)
        sets as the state's μ (read into ``BatchState.mu``, above): no builder or constructor argument, no
        dict repacked on the way."""
        mu = float("0.37")                  # an object of its own, followed by identity
        recipes, constitution = [], fragmentation.state_constitution

        def capture(recipe, **kw):
            recipes.append(recipe)
            return constitution(recipe, **kw)

        with mock.patch.object(fragmentation, "state_constitution", capture), self.assertWarns(Warning):
            result = doParticleShearSimulation(theMu=mu, return_result=True, **SMALL)
        self.assertEqual(len(recipes), 1)
        self.assertIsInstance(recipes[0], EnsembleRecipe)
        self.assertIs(recipes[0].mu, mu)
        self.assertIs(result.parameters["theMu"], mu)


    @unittest.skipUnless(sys.version_info >= (3, 11), "names functions by code.co_qualname (Python 3.11)")
    def test_hops_of_mu(self):
        """The functions that take μ itself as an argument, from the call to the measurement's state: only
        the recipe and the ensemble's μ on the way to the kernel (was: the builder's generator and its
        constitution, four ensemble constructors), beside the documented simulation's own three
        constructors (its header, file name and pre-equilibration length read ``sim.mu``).  Readers of the
        value are no hops: the checks (particleShear.checks), the run identity's hashing, the time-step rule."""
        mu = float("0.37")                  # followed by identity
        passed, done = [], []
        readers = ("particleShear.checks", "particleShear.simulation.provenance", "abc")

        def profile(frame, event, arg):
            if event != "call" or done:
                return
            code = frame.f_code
            if code.co_name == "state_from_ensembles":      # the measurement's state: the trip ends here
                done.append(code)
                return
            if frame.f_globals.get("__name__") in readers or code.co_name == "time_steps_from_model":
                return
            arguments = code.co_varnames[:code.co_argcount + code.co_kwonlyargcount]
            if any(frame.f_locals.get(name) is mu for name in arguments):
                passed.append(code.co_qualname.rpartition("<locals>.")[2])

        sys.setprofile(profile)
        try:
            with self.assertWarns(Warning):
                result = doParticleShearSimulation(theMu=mu, return_result=True, **SMALL)
        finally:
            sys.setprofile(None)
        self.assertTrue(done)
        self.assertIs(result.parameters["theMu"], mu)
        simulation = ["Simulation_interlocking_rheology.__init__", "Simulation_dermal_filler_rheology.__init__",
                      "OscillatorySimulationFragmentation.__init__"]
        # the call, then (in RunParameters, not an argument) the recipe (dataclass __init__) and the ensemble's
        # μ (the ReplicaValue descriptor of the canvas: its replica cell), read into BatchState.mu by
        # state_from_ensembles
        self.assertEqual(sorted(passed), sorted(["doParticleShearSimulation", *simulation, "__init__",
                                                 "ReplicaValue.__set__"]))


if __name__ == "__main__":
    unittest.main()
