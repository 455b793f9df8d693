"""The whole step in one compiled call (engine/numba_step.py) against the NumPy engine: the same bits.

The compiled step calls the NumPy engine's own pure functions on numbers in the NumPy engine's
order of operations (the per-replica sums in NumPy's pairwise order), so trajectories, relations,
histories, creation numbers and the sampled stresses are equal bit for bit (signs of zeros
included), not merely close.  Scenes: crosslinked particles with cut bonds, frictional spheres,
frictionless spheres (the shortcut), a batch mixing frictionless and frictional replicas, the
velocity Verlet integrator, the Hertz and the plateau law of the laws folder, plates off (the constitution's relaxation), a run's whole
constitution and measurement, a diverging replica (the same guard verdict, also in blocks), a pair at
distance 0 (the compiled step draws its random normal from the replica's generator), a block's
replicas on two threads, and the lists rebuilt inside the compiled blocks (against the rebuilds
between calls and NumPy; a list outgrowing its slot; a pair at d = 0 after such a rebuild), and the
engine's force phase and movement called alone (the kernel's phases, NumPy's bits and guard report).
Skipped without Numba.
"""
import unittest
import warnings

import numpy as np

from particleShear.engine import numba_driver, numba_step
from particleShearTest.test_numba_driver import _bits

HAVE_NUMBA = numba_driver.available()

FRICTIONAL_BONDS = dict(theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.2)
FRICTIONAL = dict(theMu=0.3, do_permanent_links=False, cut_lines=0, theAmplitude=0.1)
FRICTIONLESS = dict(theMu=0.0, do_permanent_links=False, cut_lines=0, theAmplitude=0.2)


def _measure(scenes, backend, integrator="euler", periods=1, law=None):
    """Pre-equilibration and protocol (0.5 + periods + 0.5 periods) of constituted ensembles in one engine."""
    from particleShear.base.engine_adapter import state_from_ensembles
    from particleShear.engine.loops import pre_equilibrate, protocol
    from particleShear.engine.step import BatchEngine
    from particleShearTest.test_engine import constituted

    sc = constituted(11, **FRICTIONAL_BONDS)[2]      # one schedule for every batch
    ensembles = [constituted(11 + n, **scene)[1] for n, scene in scenes]
    eng = BatchEngine(state_from_ensembles(ensembles, backend=backend, laws=[law] * len(ensembles)),
                      integrator=integrator)
    pre_equilibrate(eng, sc["N_pre"], sc["dt"], sc["dt_max"], sc["cool"])
    out = protocol(eng, sc["dt"], sc["f"], [sc["A"]] * len(ensembles), sc["cool"], 0.5, periods, 0.5)
    return eng, out


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestCompiledStepBits(unittest.TestCase):

    def assert_same_engines(self, a, b):
        for key in ("pos", "vel", "phi"):
            np.testing.assert_array_equal(_bits(getattr(a.s, key)), _bits(getattr(b.s, key)), err_msg=key)
        for key in ("gamma", "t"):
            np.testing.assert_array_equal(_bits(getattr(a.s, key)), _bits(getattr(b.s, key)), err_msg=key)
        for r in range(a.s.B):
            p, q = a.pairs_of(r), b.pairs_of(r)
            for key in ("i", "j", "state", "active", "birth"):
                np.testing.assert_array_equal(getattr(p, key), getattr(q, key), err_msg=key)
            np.testing.assert_array_equal(_bits(p.xi), _bits(q.xi), err_msg="xi")
        self.assertEqual(a.step_count, b.step_count)
        np.testing.assert_array_equal(a.s.contacts.rebuilds, b.s.contacts.rebuilds)

    def assert_same_records(self, a, b):
        for key in ("t", "strain", "strain_rate", "stress_internal", "stress_surface"):
            np.testing.assert_array_equal(_bits(a[key]), _bits(b[key]), err_msg=key)

    def assert_same_tree(self, a, b, path):
        """The same dicts (but their candidates ``C``), sequences, Nones and arrays' bits, nested."""
        if isinstance(a, dict):
            self.assertEqual(a.keys(), b.keys(), path)
            for k in a:
                if k != "C":
                    self.assert_same_tree(a[k], b[k], f"{path}.{k}")
        elif isinstance(a, (list, tuple)):
            self.assertEqual(len(a), len(b), path)
            for k, (x, y) in enumerate(zip(a, b)):
                self.assert_same_tree(x, y, f"{path}[{k}]")
        elif a is None:
            self.assertIsNone(b, path)
        else:
            a, b = np.asarray(a), np.asarray(b)
            self.assertEqual((a.dtype, a.shape), (b.dtype, b.shape), path)
            np.testing.assert_array_equal(_bits(a) if a.dtype.kind == "f" else a,
                                          _bits(b) if b.dtype.kind == "f" else b, err_msg=path)

    def test_scenes_bit_identical(self):
        """Every scene: the engine's state after pre-equilibration and protocol and the recorded
        series equal NumPy's bit for bit; no step of these scenes falls back (no note)."""
        cases = {"bonds and friction": ([(0, FRICTIONAL_BONDS)], "euler", None),
                 "friction": ([(1, FRICTIONAL)], "euler", None),
                 "frictionless shortcut": ([(2, FRICTIONLESS)], "euler", None),
                 "frictionless and frictional replicas": ([(2, FRICTIONLESS), (1, FRICTIONAL)], "euler", None),
                 "velocity Verlet": ([(0, FRICTIONAL_BONDS)], "verlet", None),
                 "Hertz law, two replicas": ([(0, FRICTIONAL_BONDS), (1, FRICTIONAL)], "euler", ("hertz", (0.05,))),
                 "plateau law (prepared constants)": ([(0, FRICTIONAL_BONDS)], "euler",
                                                      ("plateau", (0.3, 0.8, 0.1)))}
        for name, (scenes, integrator, law) in cases.items():
            with self.subTest(name):
                e_np, ref = _measure(scenes, "numpy", integrator, law=law)
                with warnings.catch_warnings():       # no step on NumPy but the tensor samples
                    warnings.filterwarnings("error", "backend='numba': this step runs on NumPy", RuntimeWarning)
                    e_nb, got = _measure(scenes, "numba", integrator, law=law)
                self.assertGreater(e_nb.step_count, 250)
                self.assertGreater(np.abs(ref["stress_surface"]).max(), 0.0)
                self.assert_same_records(ref, got)
                self.assert_same_engines(e_np, e_nb)
                if name == "bonds and friction":
                    self.assertTrue(np.any(e_nb.pairs_of(0).xi != 0.0))      # the ξ rule really ran

    def test_the_step_ran_compiled(self):
        """The compiled step ran every step of pre-equilibration and protocol (not the NumPy phases),
        the protocol's first and last steps, which sample every tensor, included."""
        from unittest import mock

        from particleShear.engine.step import BatchEngine
        phases = []
        original = BatchEngine._force_phase

        def numpy_phase(engine, sample=False):
            if engine.backend.compiled:          # (the ensembles' constitution runs on NumPy engines)
                phases.append(sample)
            return original(engine, sample)

        with mock.patch.object(BatchEngine, "_force_phase", numpy_phase):
            eng, _ = _measure([(0, FRICTIONAL_BONDS)], "numba")
        self.assertEqual(phases, [])
        self.assertGreater(eng.step_count, 250)

    def test_every_tensor_sampled_compiled(self):
        """Every tensor sampled at every step (a kept tensor history), in compiled blocks and in the
        step-by-step path of a controller, and N1 every 7th step: the tensors, their N1 and the
        series are NumPy's bits (the rows of :mod:`~particleShear.engine.stress` are summed per
        replica in NumPy's order inside the compiled step), with the NumPy force phase never run;
        the overall tensor's xy entry is −τ_internal and the external one's −τ_surface."""
        import contextlib
        from unittest import mock

        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.rheometer import OVERALL, shear_record
        from particleShear.engine.stress import EXTERNAL
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        for integrator in ("euler", "verlet"):
            records = []
            for backend in ("numpy", "numba"):
                ens = [constituted(71, **FRICTIONAL_BONDS)[1], constituted(72, **FRICTIONAL)[1]]
                eng = BatchEngine(state_from_ensembles(ens, backend=backend), integrator=integrator)
                eng.s.applying_shear = True
                rate_of = lambda i: np.array([300.0, -200.0]) * np.cos(0.01 * i)        # noqa: E731
                numpy_phase = mock.patch.object(BatchEngine, "_force_phase", side_effect=AssertionError("ran on NumPy"))
                with numpy_phase if backend == "numba" else contextlib.nullcontext():
                    rec = shear_record(eng, ens[0].dt, 0.999, 90, rate_of, keep_tensors=True, end_tensors=True)
                    rec_n1 = shear_record(eng, ens[0].dt, 0.999, 30, rate_of, tensors_every=7)
                    ctl = shear_record(eng, ens[0].dt, 0.999, 12, rate_of, keep_tensors=True,
                                       after_step=lambda i, a, b: None)         # (a controller: step by step)
                records.append((rec, rec_n1, ctl))
            for a, b in zip(*records):
                self.assertEqual(sorted(a), sorted(b))
                for key in a:
                    with self.subTest(integrator=integrator, key=key):
                        np.testing.assert_array_equal(_bits(a[key]), _bits(b[key]))
            rec, rec_n1, _ = records[1]
            self.assertGreater(np.abs(rec["tensors"]).max(), 0.0)
            np.testing.assert_array_equal(_bits(rec["stress_internal"]), _bits(-rec["tensors"][:, :, OVERALL, 0, 1]))
            np.testing.assert_array_equal(_bits(rec["stress_surface"]), _bits(-rec["tensors"][:, :, EXTERNAL, 0, 1]))
            self.assertEqual(int(np.isfinite(rec_n1["N1"][:, 0]).sum()), 5)         # (steps 0, 7, … 28)

    def test_terms_kept_for_a_force_register(self):
        """An engine that keeps its terms for a force register (the documented experiment's) runs
        compiled, in blocks and step by step, and hands the terms of its last force phase to its
        ``terms_to`` with NumPy's bits: every array of them (the elastic and viscous parts of
        each visit, the tangential visits, the forces on i and j, geometry, roles, totals), with
        spheres sharing their parameters and with spheres of their own, at B = 1 and 2."""
        import contextlib
        from unittest import mock

        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.base.register import KeptTerms
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        for own in (False, True):
            for B in (1, 2):
                for last in ("block", "step"):
                    terms = []
                    for backend in ("numpy", "numba"):
                        ens = [constituted(61 + b, **FRICTIONAL_BONDS)[1] for b in range(B)]
                        for k, sphere in enumerate(ens[0].sphereList[:9] if own else ()):
                            sphere.central_repulsion_coefficient = 0.5 + 0.05 * k
                            sphere.permanent_ratio_central = 1.0 + 0.2 * k
                        kept = KeptTerms()
                        eng = BatchEngine(state_from_ensembles(ens, backend=backend), keep_terms=True, terms_to=kept)
                        eng.s.applying_shear = True
                        eng.set_rate(np.array([400.0, -300.0][:B]))
                        patch = mock.patch.object(BatchEngine, "_force_phase", side_effect=AssertionError("NumPy"))
                        with patch if backend == "numba" else contextlib.nullcontext():
                            eng.steps(30, 0.999, ens[0].dt)
                            if last == "step":
                                eng.step(0.999, ens[0].dt, sample=True)
                        terms.append(kept.last)
                    self.assertEqual(terms[1]["fx_j"] is not None, own)
                    self.assertTrue(np.any(terms[1]["F"] != 0.0))
                    self.assert_same_tree(terms[0], terms[1], f"own={own} B={B} {last}")

    def test_a_force_phase_keeps_its_record_and_terms(self):
        """The record and the kept terms of the engine's compiled force phase alone are rows of its own
        buffers: its movement, later steps (whole, in blocks) and later force phases leave them as they were."""
        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.base.register import KeptTerms
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        ens = constituted(63, **FRICTIONAL_BONDS)[1]
        kept = KeptTerms()
        eng = BatchEngine(state_from_ensembles([ens], backend="numba"), keep_terms=True, terms_to=kept)
        eng.s.applying_shear = True
        eng.set_rate(np.array([400.0]))
        g = eng.force_phase()[0]
        self.assertIsNot(g.dx.base, None)       # (the compiled phase's own rows)
        terms = kept.last
        arrays = lambda: [np.array(a) for a in (*g[:8], *terms["parts"][0], terms["F"], terms["dx"], terms["fx_i"],  # noqa: E731
                                                terms["totals"])]
        before = arrays()
        eng.accelerate(0.999, ens.dt, g)
        eng.move(ens.dt, g)
        eng.step(0.999, ens.dt, sample=True)
        eng.steps(5, 0.999, ens.dt)
        eng.force_phase()
        for a, b in zip(before, arrays()):
            np.testing.assert_array_equal(_bits(a) if a.dtype.kind == "f" else a, _bits(b) if b.dtype.kind == "f" else b)
        self.assertIsNot(kept.last, terms)

    def test_engine_phases_run_compiled(self):
        """``BatchEngine.force_phase``, ``accelerate`` and ``move`` called by an engine's user on the
        ``"numba"`` backend run the compiled step kernel's phases (the NumPy phases never run, the
        compiled workspace covers the engine) and give the NumPy engine's phases' bits over 100
        steps: positions, velocities, relations and their history, clock and strain, every field
        of each force phase's record, the sampled stresses and tensors and the kept terms, with
        both integrators and two replicas."""
        import contextlib
        from unittest import mock

        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.base.register import KeptTerms
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        for integrator, keep in (("euler", False), ("verlet", True)):
            engines, seen = [], []
            for backend in ("numpy", "numba"):
                ens = [constituted(65, **FRICTIONAL_BONDS)[1], constituted(66, **FRICTIONAL)[1]]
                kept = KeptTerms() if keep else None
                eng = BatchEngine(state_from_ensembles(ens, backend=backend), integrator=integrator, keep_terms=keep,
                                  terms_to=kept)
                eng.s.applying_shear = True
                numpy_phases = (mock.patch.object(BatchEngine, "_force_phase", side_effect=AssertionError("NumPy")),
                                mock.patch.object(BatchEngine, "_move", side_effect=AssertionError("NumPy move")))
                records = []
                with contextlib.ExitStack() as stack:
                    if backend == "numba":
                        for p in numpy_phases:
                            stack.enter_context(p)
                    for k in range(100):
                        eng.set_rate(np.array([400.0, -300.0]) * np.cos(0.03 * k))
                        sample = "tensors" if k % 25 == 0 else bool(k % 7 == 0)
                        g, out = eng.force_phase(sample)
                        records.append((tuple(g), out, kept.last if keep else None))
                        eng.accelerate(0.999, ens[0].dt, g)
                        eng.move(ens[0].dt, g)
                        if backend == "numba":
                            ws = numba_step.last_workspace(eng)
                            self.assertIsNotNone(ws)
                            self.assertIsNone(ws.why)
                engines.append(eng)
                seen.append(records)
            self.assertEqual(engines[1].step_count, 100)
            self.assertEqual(engines[1].notes, set())
            self.assert_same_engines(*engines)
            np.testing.assert_array_equal(engines[0].s.contacts.rebuilds, engines[1].s.contacts.rebuilds)
            self.assertTrue(np.any(engines[1].pairs_of(0).xi != 0.0))      # (the ξ rule really ran)
            self.assert_same_tree(seen[0], seen[1], integrator)

    def test_engine_force_phase_reports_at_once(self):
        """An unsound guard verdict in ``BatchEngine.force_phase``: raised by the phase itself, at once,
        with the same EngineInstability (replica, step, phase, message) and the same forces written,
        on NumPy and on the compiled phase."""
        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine, EngineInstability
        from particleShearTest.test_engine import constituted

        got = []
        for backend in ("numpy", "numba"):
            ens = [constituted(31 + k, **FRICTIONAL)[1] for k in range(2)]
            eng = BatchEngine(state_from_ensembles(ens, backend=backend), check_interval=1)
            eng.s.vel[:, eng.s.N:] *= 1e6
            with self.assertRaises(EngineInstability) as ctx:
                eng.force_phase()
            e = ctx.exception
            got.append((str(e), e.replica, e.step, e.phase, eng.s.frc.copy(), eng.step_count))
        self.assertEqual(got[0][:4], got[1][:4])
        self.assertEqual(got[0][1], 1)
        np.testing.assert_array_equal(_bits(got[0][4]), _bits(got[1][4]))
        self.assertEqual(got[0][5], got[1][5])

    def test_documented_experiment_runs_compiled(self):
        """The documented experiment's own pre-equilibration and protocol
        (``OscillatoryShearExperiment.oscillatory_shear_experiment``, an engine on the ensemble's
        state keeping its terms for the force register) run compiled where Numba is installed (no
        NumPy force phase) and give NumPy's moduli, bit for bit."""
        import os
        from unittest import mock

        from particleShear.engine.step import BatchEngine
        from particleShear.simulation.simulations import Simulation_interlocking_rheology

        results = {}
        for backend in ("numpy", "numba"):
            s = Simulation_interlocking_rheology("", N=20, cut_lines=2, do_permanent_links=True, relative_frequency=0.2,
                                                 doDrawing=False, saveData=False)
            s.baseline_pre_periods = s.baseline_post_periods = 0.5
            s.rng = np.random.default_rng(3)
            s.initEnsemble()
            exp = s.createExperiment(False, 1, False)
            sched = s.measurement_schedule(0.5)
            phases = []
            original = BatchEngine._force_phase

            def counted(engine, sample=False):
                phases.append(sample)
                return original(engine, sample)

            with mock.patch.dict(os.environ, {"PARTICLESHEAR_BACKEND": backend}), \
                    mock.patch.object(BatchEngine, "_force_phase", counted):
                G = exp.oscillatory_shear_experiment(cool_factor=sched.cool,
                                                     N_pre_equilibration_fixed_boundaries=sched.N_pre)
            results[backend] = (G, len(phases))
        self.assertEqual(results["numba"][0], results["numpy"][0])
        self.assertGreater(results["numpy"][1], 100)
        self.assertEqual(results["numba"][1], 0)

    def test_documented_step_loop_runs_compiled(self):
        """The documented step loop of the README (``setShearRate``, forces, totals, every tensor of
        ``StressTensorEvaluation`` over ``movableSphereList()``, acceleration, movement) on an
        ensemble's own state: its force phase and its tensors' row sums run compiled where Numba is
        installed (NumPy's relations and row sums never run) and the spheres and all nine tensors
        are NumPy's bits at every step."""
        import math
        import os
        from unittest import mock

        from particleShear import StressTensorEvaluation
        from particleShear.engine.stress import TENSORS, StressInputs
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        runs = {}
        for backend in ("numpy", "numba"):
            ens = constituted(81, **FRICTIONAL_BONDS)[1]
            ens.applyingShear = True
            ev = StressTensorEvaluation(ens.size_x, ens.size_y)
            no_numpy = (mock.patch.object(BatchEngine, "relations", side_effect=AssertionError("NumPy relations")),
                        mock.patch.object(StressInputs, "per_replica", side_effect=AssertionError("NumPy sums")))
            seen = []
            with mock.patch.dict(os.environ, {"PARTICLESHEAR_BACKEND": backend}):
                if backend == "numba":
                    for p in no_numpy:
                        p.start()
                try:
                    for k in range(40):
                        ens.setShearRate(300.0 * math.cos(0.05 * k))
                        ens.mechanical_simulation_step_calculate_forces()
                        ens.record_total_particle_forces()
                        ev.evaluate_stress_tensors(ens.force_register, ens.movableSphereList(), ens.shear_rate)
                        seen.append(np.array([getattr(ev, t.name) for t in TENSORS]))
                        ens.mechanical_simulation_step_calculate_acceleration(0.999, ens.dt)
                        ens.mechanical_simulation_step_calculate_movement(ens.dt)
                finally:
                    if backend == "numba":
                        for p in no_numpy:
                            p.stop()
            spheres = np.array([(q.x, q.y, q.xspeed, q.yspeed, q.omega) for q in ens.sphereList])
            runs[backend] = (np.array(seen), spheres)
        self.assertGreater(np.abs(runs["numba"][0]).max(), 0.0)
        for a, b in zip(runs["numpy"], runs["numba"]):
            np.testing.assert_array_equal(_bits(a), _bits(b))

    def test_plateau_law_set_the_1_0_2_way_runs_compiled(self):
        """The plateau law set as 1.0.2 scripts set it (``CircleBasicElasticity.call_back_elastic_force_law``,
        its ``PlateauConfiguration``) runs compiled in the documented step loop (NumPy's relations
        never run), with NumPy's bits; a slope changed halfway, and the callback set back to the
        linear law, take effect at the next force phase on both backends, as 1.0.2 reads them."""
        import math
        import os
        from unittest import mock

        from particleShear import (CircleBasicElasticity, PlateauConfiguration, elastic_force_law,
                                   elastic_force_law_plateau)
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        runs = {}
        slope = PlateauConfiguration.relative_plateau_slope
        for backend in ("numpy", "numba"):
            ens = constituted(91, **FRICTIONAL_BONDS)[1]
            ens.applyingShear = True
            patch = mock.patch.object(BatchEngine, "relations", side_effect=AssertionError("NumPy relations"))
            try:
                with mock.patch.dict(os.environ, {"PARTICLESHEAR_BACKEND": backend}), \
                        (patch if backend == "numba" else mock.patch.dict({})), warnings.catch_warnings():
                    warnings.filterwarnings("error", "backend='numba': this step runs on NumPy", RuntimeWarning)
                    CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
                    for k in range(90):
                        if k == 30:
                            PlateauConfiguration.relative_plateau_slope = 0.4
                        if k == 60:
                            CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law
                        ens.setShearRate(300.0 * math.cos(0.05 * k))
                        ens.mechanical_simulation_step_calculate_forces()
                        ens.mechanical_simulation_step_calculate_acceleration(0.999, ens.dt)
                        ens.mechanical_simulation_step_calculate_movement(ens.dt)
            finally:
                CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law
                PlateauConfiguration.relative_plateau_slope = slope
            runs[backend] = np.array([(q.x, q.y, q.xspeed, q.yspeed, q.omega) for q in ens.sphereList])
        np.testing.assert_array_equal(_bits(runs["numpy"]), _bits(runs["numba"]))

    def test_plates_off_relaxation_and_numbers(self):
        """The constitution's relaxation (plates off, μ = 0 blocks, drift removal) on the ensembles' own
        state, whose engine numbers the relations as they form: the same bits and creation numbers."""
        from particleShear.base.engine_adapter import state_of_ensembles
        from particleShear.engine.relax import free_relaxation
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        engines = []
        for backend in ("numpy", "numba"):
            e = constituted(21, **FRICTIONAL_BONDS)[1]
            eng = BatchEngine(state_of_ensembles([e], backend=backend), skin_factor=0.2, numbers_relations=True)
            free_relaxation(eng, 60, e.dt, e.dt_max, eng.s.mu.copy())
            engines.append(eng)
        self.assertFalse(engines[1].s.applying_shear)
        self.assert_same_engines(*engines)
        self.assertGreater(engines[1].pairs_of(0).birth.max(), 0)

    def test_spheres_with_their_own_parameters(self):
        """Spheres with parameters of their own (a repulsion coefficient, permanent ratios, kept
        viscosities differing between the spheres of a replica, beside a replica whose spheres share
        theirs): each visit of a relation sees its own sphere's constants, the central force on j is
        that of j's visit; compiled (the NumPy force phase never runs) with NumPy's bits, the sampled
        stresses included."""
        import contextlib
        from unittest import mock

        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        engines, samples = [], []
        for backend in ("numpy", "numba"):
            ens = [constituted(61, **FRICTIONAL_BONDS)[1], constituted(62, **FRICTIONAL_BONDS)[1]]
            for k, sphere in enumerate(ens[0].sphereList[:9]):
                sphere.central_repulsion_coefficient = 0.5 + 0.05 * k
                sphere.permanent_ratio_central = 1.0 + 0.2 * k
                sphere.permanent_ratio_tangential = 2.0 - 0.1 * k
                sphere.keep_viscosity_coefficients_constant = bool(k % 2)
            s = state_from_ensembles(ens, backend=backend)
            self.assertIsNotNone(s.visit)
            eng = BatchEngine(s)
            numpy_phase = mock.patch.object(BatchEngine, "_force_phase", side_effect=AssertionError("ran on NumPy"))
            with numpy_phase if backend == "numba" else contextlib.nullcontext():
                eng.set_rate(np.array([400.0, -300.0]))
                eng.steps(40, 0.999, ens[0].dt)
                samples.append([eng.step(0.999, ens[0].dt, sample=True) for _ in range(5)]
                               + [eng.step(0.999, ens[0].dt, sample="tensors") for _ in range(3)])
            engines.append(eng)
        self.assertIsNotNone(engines[1].s.contacts.C.Kj)
        self.assert_same_engines(*engines)
        for a, b in zip(*samples):
            self.assertEqual(len(a), len(b))
            for x, y in zip(a, b):
                np.testing.assert_array_equal(_bits(np.asarray(x)), _bits(np.asarray(y)))

    def test_plain_periodic_and_held_strain(self):
        """Plain periodic cells (no Lees-Edwards images) with the strain held while not shearing, then
        advancing while shearing, at a nonzero rate, in blocks and step by step: compiled (the NumPy
        force phase never runs) with NumPy's bits."""
        import contextlib
        from unittest import mock

        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        engines = []
        for backend in ("numpy", "numba"):
            ens = [constituted(51 + k, **FRICTIONAL)[1] for k in range(2)]
            eng = BatchEngine(state_from_ensembles(ens, backend=backend), lees_edwards=False,
                              strain_only_while_shearing=True)
            numpy_phase = mock.patch.object(BatchEngine, "_force_phase", side_effect=AssertionError("ran on NumPy"))
            with numpy_phase if backend == "numba" else contextlib.nullcontext():
                for applying in (False, True):
                    eng.s.applying_shear = applying
                    eng.set_rate(np.array([300.0, -500.0]))
                    eng.steps(30, 0.999, ens[0].dt)
                    for _ in range(3):
                        eng.step(0.999, ens[0].dt)
            engines.append(eng)
        self.assert_same_engines(*engines)
        self.assertTrue(np.all(engines[1].s.gamma != 0.0))       # (it advanced while shearing)

    def test_guard_in_blocks_reports_the_first_failure(self):
        """Three replicas stepped far above the stable step in compiled blocks (each replica to its own
        next rebuild), the last one also kicked: replica 0 diverges at the guard's second check, the
        kicked replica 2 at its first; the compiled blocks, which step replica 0 first, report what
        NumPy's step-by-step loop reports: the earliest failing step (replica 2, step 0)."""
        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine, EngineInstability
        from particleShearTest.test_engine import constituted

        errors = []
        for backend in ("numpy", "numba"):
            ens = [constituted(31 + k, **FRICTIONAL)[1] for k in range(3)]
            eng = BatchEngine(state_from_ensembles(ens, backend=backend))
            N = eng.s.N
            eng.s.vel[:, 2 * N:] *= 1e6
            with self.assertRaises(EngineInstability) as ctx:
                eng.steps(400, 1.0, ens[0].dt * 20)
            errors.append((str(ctx.exception), ctx.exception.step, ctx.exception.replica))
        self.assertEqual(errors[0], errors[1])
        self.assertEqual(errors[0][1:], (0, 2))

    def test_batch_replica_equals_single_run(self):
        _, both = _measure([(0, FRICTIONAL_BONDS), (1, FRICTIONAL)], "numba")
        for col, scene in enumerate((FRICTIONAL_BONDS, FRICTIONAL)):
            _, single = _measure([(col, scene)], "numba")
            for key in ("t", "strain", "stress_internal", "stress_surface"):
                np.testing.assert_array_equal(_bits(single[key][:, 0]), _bits(both[key][:, col]), err_msg=key)

    def test_run_bit_identical(self):
        """A whole run (constitution, pre-equilibration, protocol, demodulation): the same series,
        moduli and run id on both backends; the result records the backend used."""
        from particleShear import doParticleShearSimulation
        kw = dict(seed=5, N=40, relative_frequency=0.2, periods=2, pre_periods=0.5, post_periods=0.5,
                  return_result=True, verbose=False, doDrawing=False, plotStress=False)
        a = doParticleShearSimulation(backend="numpy", **kw)
        b = doParticleShearSimulation(backend="numba", **kw)
        self.assertEqual(b.parameters["backend"], "numba")
        self.assertEqual(a.run_id, b.run_id)
        self.assertEqual(a.G_surface, b.G_surface)
        self.assertEqual(a.G_internal, b.G_internal)
        for key in ("t", "strain", "stress_surface", "stress_internal"):
            np.testing.assert_array_equal(_bits(a.series[key]), _bits(b.series[key]), err_msg=key)

    def test_guard_verdict_identical(self):
        """A replica driven unstable (a step far above the stable one): the same EngineInstability
        (replica, step, phase, reason) on both backends."""
        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine, EngineInstability
        from particleShearTest.test_engine import constituted

        errors = []
        for backend in ("numpy", "numba"):
            e = constituted(31, **FRICTIONAL)[1]
            eng = BatchEngine(state_from_ensembles([e], backend=backend))
            eng.s.vel[...] *= 1e6
            with self.assertRaises(EngineInstability) as ctx:
                for _ in range(400):
                    eng.step(1.0, e.dt * 20)
            errors.append((str(ctx.exception), ctx.exception.step, ctx.exception.replica))
        self.assertEqual(errors[0], errors[1])

    def test_pair_at_distance_zero(self):
        """Two spheres at the same place: the compiled step draws the random normal from the replica's
        generator (as forces.normals does) and goes on compiled (the NumPy force phase never runs);
        the same bits and the same next number of the generator."""
        import contextlib
        from unittest import mock

        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        engines = []
        for backend in ("numpy", "numba"):
            e = constituted(41, **FRICTIONAL)[1]
            s = state_from_ensembles([e], backend=backend)
            s.pos[:, 1] = s.pos[:, 0]
            eng = BatchEngine(s, guard=False)        # (the guard would stop the interpenetration)
            numpy_phase = mock.patch.object(BatchEngine, "_force_phase", side_effect=AssertionError("ran on NumPy"))
            with numpy_phase if backend == "numba" else contextlib.nullcontext():
                for _ in range(5):
                    eng.step(0.999, e.dt)
            engines.append(eng)
        self.assert_same_engines(*engines)
        self.assertEqual(engines[0].s.rng[0].random(), engines[1].s.rng[0].random())

    def test_random_directions_at_zero_R(self):
        """Coincident frictional spheres in the plate band (immobile, so ``R = v_i·dt − D = 0`` at every
        step) in a batch beside a sliding frictional pair: the compiled step updates the ξ of the
        other pairs, stops before the ξ of the pair at ``|R| = 0``, whose direction the caller draws
        from the replica's generator, and resumes with that pair's ξ alone; the same bits as NumPy
        (ξ included: no pair's ξ is updated twice) and the same next number of each generator, step
        by step and in blocks."""
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import two_sphere_replicas

        specs = [(([5.0, 5.0], [0.5, 0.5]), [0.0, 0.0], 0.5, 1), (([5.0, 6.5], [5.0, 5.0]), [0.0, 1.0], 0.5, 2)]
        engines = []
        for backend in ("numpy", "numba"):
            eng = BatchEngine(two_sphere_replicas(specs, backend), guard=False)
            for _ in range(4):
                eng.step(1.0, 1e-3)
            eng.steps(4, 1.0, 1e-3)
            engines.append(eng)
        self.assert_same_engines(*engines)
        self.assertTrue(np.all(engines[1].pairs_of(1).xi != 0.0))       # (the sliding pair integrates ξ)
        # the coincident pair drew two directions per step: its normal at d = 0, its R at |R| = 0
        expected = np.random.default_rng(1)
        for _ in range(2 * 8):
            expected.random()
        self.assertEqual(engines[1].s.rng[0].random(), expected.random())
        self.assertEqual(engines[0].s.rng[1].random(), engines[1].s.rng[1].random())

    def test_distance_zero_in_one_replica_of_a_block(self):
        """A batch of three whose middle replica has a pair at d = 0 and runs Verlet blocks: that
        replica's step takes its normal from its own generator and the others are not held back;
        every replica is its single run's bits, on NumPy as compiled."""
        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        dt = constituted(42, **FRICTIONAL)[1].dt

        def engine(backend, seeds):
            s = state_from_ensembles([constituted(s, **FRICTIONAL)[1] for s in seeds], backend=backend)
            if 43 in seeds:
                b = seeds.index(43) * s.N
                s.pos[:, b + 1] = s.pos[:, b]
            eng = BatchEngine(s, guard=False, integrator="verlet")
            eng.steps(40, 0.999, dt)
            return eng

        batch = engine("numba", [42, 43, 44])
        self.assert_same_engines(engine("numpy", [42, 43, 44]), batch)
        for k, seed in enumerate((42, 43, 44)):
            single = engine("numba", [seed])
            for key in ("pos", "vel", "phi"):
                got = getattr(batch.s, key).reshape(getattr(batch.s, key).shape[:-1] + (3, -1))[..., k, :]
                np.testing.assert_array_equal(_bits(got), _bits(getattr(single.s, key)), err_msg=key)

    def test_pair_at_distance_zero_in_a_verlet_block(self):
        """A block of Verlet steps whose first step meets a pair at d = 0 (before any half kick): its
        normal is drawn and the block goes on; the same bits as NumPy."""
        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        engines = []
        for backend in ("numpy", "numba"):
            e = constituted(43, **FRICTIONAL)[1]
            s = state_from_ensembles([e], backend=backend)
            s.pos[:, 1] = s.pos[:, 0]
            eng = BatchEngine(s, guard=False, integrator="verlet")
            eng.steps(6, 0.999, e.dt)
            engines.append(eng)
        self.assert_same_engines(*engines)
        np.testing.assert_array_equal(_bits(engines[0].s.predictor.half), _bits(engines[1].s.predictor.half))

    def test_zero_R_draws_from_the_replica_generator(self):
        """``R = v_i dt − D = 0`` exactly (sphere i moves onto j's place in one step): the ξ rule's
        random direction is drawn from the replica's generator in the compiled step as on NumPy —
        the same state and the same next number of the generator."""
        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_invariants import random_ensemble

        dt = 2.0 ** -20
        after = []
        for backend in ("numpy", "numba"):
            e = random_ensemble(2, 1000.0, seed=3, packing_fraction=0.05)
            s = state_from_ensembles([e], backend=backend)
            s.rng = [np.random.default_rng(7)]
            s.pos[:, 0], s.pos[:, 1] = (100.0, 500.0), (300.0, 500.0)    # 200 µm apart: a candidate, no contact
            s.vel[...] = 0.0
            s.vel[0, 0] = 200.0 / dt                                      # exactly onto j's place in one step
            eng = BatchEngine(s, guard=False, skin_factor=2.0)
            eng.set_rate(np.zeros(1))
            eng.step(1.0, dt)
            self.assertEqual(len(eng.pairs_of(0).i), 1)
            after.append((eng, s.rng[0].random()))
        self.assert_same_engines(after[0][0], after[1][0])
        self.assertEqual(after[0][1], after[1][1])
        self.assertNotEqual(after[1][1], np.random.default_rng(7).random())    # one number was drawn


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestCompiledSearch(unittest.TestCase):
    def test_same_pairs_as_the_numpy_search(self):
        """The compiled search (cell list, or every pair on a grid of fewer than 3 cells per side) gives
        the NumPy searches' pairs in their order: random replicas of 2 … 1,500 spheres, radii small
        and large against the box (both kinds of grid), Lees-Edwards offsets of zero, a fraction of a
        cell and many cells, a NaN position, positions a period outside the box, skins from 0 to 20 µm,
        and a dense replica with more pairs than the first buffer holds."""
        from particleShear.engine import neighbours
        rng = np.random.default_rng(0)
        grids = set()
        for t in range(240):
            N = int(rng.integers(2, 200)) if t % 2 else int(rng.integers(200, 1500))
            L = 500.0 if t % 3 else 2000.0
            x, y, r = rng.uniform(0, L, N), rng.uniform(0, 0.8 * L, N), rng.uniform(10, 40 if t % 5 else 150, N)
            if t % 10 == 0:
                x[0] = np.nan
            if t % 7 == 0:
                y[-1] += 0.8 * L        # (a sphere above the box: binned at its image, as NumPy's)
            if t == 11:
                x, y = rng.uniform(0, 60, N), rng.uniform(0, 60, N)      # dense: ≈ N²/2 pairs
            shift = float(rng.choice([0.0, 37.5, -620.0, 5e4]))
            skin = float(rng.uniform(0, 20))
            with self.subTest(t=t, N=N):
                want_all = neighbours.near_pairs_all(x, y, r, L, 0.8 * L, shift, skin)
                want_cells = neighbours.near_pairs_cells(x, y, r, L, 0.8 * L, shift, skin)
                got = numba_step.search(x, y, r, L, 0.8 * L, shift, skin)
                for want in (want_all, want_cells):
                    np.testing.assert_array_equal(got[0], want[0])
                    np.testing.assert_array_equal(got[1], want[1])
                grids.add(min(neighbours.cell_grid(L, 0.8 * L, 2 * float(r.max()) + skin, N)) >= 3)
                if t == 11:
                    self.assertGreater(len(got[0]), 16 * N)
        self.assertEqual(grids, {True, False})


    def test_history_merge_same_rows(self):
        """The history merge compiled (``state.carried_rows``, the same function, its positions by one
        linear pass) gives NumPy's keys and rows: random tables of 0 … 5,000 keys, kept subsets
        (bonds, relations) that the new candidates miss or hold, new keys unsorted with repeats or
        sorted and unique, with either merge size."""
        from particleShear.engine import state
        rng = np.random.default_rng(2)
        compiled = numba_step.compile_carried_kernel()
        for t in range(300):
            old = np.unique(rng.integers(0, 9000, int(rng.integers(0, 5000)))).astype(np.int64)
            kept = old[rng.random(len(old)) < rng.random()] if len(old) else old
            k = rng.integers(0, 9000, int(rng.integers(0, 5000))).astype(np.int64)
            if t % 2:
                k = np.unique(k)
            want = state.carried_rows(old, kept, k)
            with self.subTest(t=t):
                for got in (numba_step.carried(old, kept, k), compiled(old, kept, k, state._MERGE_MIN),
                            compiled(old, kept, k, 2 ** 62)):
                    np.testing.assert_array_equal(got[0], want[0])
                    np.testing.assert_array_equal(got[1], want[1])
                self.assertTrue(np.all(np.diff(want[0]) > 0))
                self.assertTrue(np.isin(kept, want[0]).all())           # every kept key stays
                carried = want[1] < len(old)
                np.testing.assert_array_equal(old[want[1][carried]], want[0][carried])   # each reads its own row
                self.assertFalse(np.isin(want[0][~carried], old).any())  # and only new keys read none


    def test_merged_history_is_the_carry(self):
        """The one-pass history merge of a rebuild inside a block (``_merged_history``) writes the keys
        and fields of ``_carry_kernel`` (``carried_rows`` of the bonds kept, ``carried_fields``): random
        tables of 0 … 3,000 sorted unique keys with bonds and relations, new keys sorted (with repeats
        or unique) that hold or miss them; its count alone (``at < 0``) is the same number."""
        from particleShear.engine import numba_driver as nd
        from particleShear.engine import state
        f = nd.jit_laws(True, ((numba_step, "_merged_history"),))
        merged = f["_merged_history"]
        rng = np.random.default_rng(5)
        S = numba_step._TABLE_SCALE
        for t in range(200):
            m = int(rng.integers(0, 3000))
            old = np.unique(rng.integers(0, 120, m) * S + rng.integers(0, 120, m)).astype(np.int64)
            m = len(old)
            st = rng.choice(np.array([state.STICK, state.SLIP, state.PERMANENT], np.int8), m)
            de, act, num = rng.random(m), rng.random(m) < 0.5, rng.integers(0, 99, m).astype(np.int64)
            z = rng.random((2, m))
            c = int(rng.integers(0, 3000))
            k = np.sort(rng.integers(0, 120, c) * S + rng.integers(0, 120, c)).astype(np.int64)
            if t % 2:
                k = np.unique(k)
            key, src = state.carried_rows(old, old[st == state.PERMANENT], k)
            want = state.carried_fields(src, st, de, act, num, z)
            b, n0, at = 3, 7, 5
            W = at + len(key) + 2
            Si, s_state, s_xi = np.zeros((3, W), np.int64), np.zeros(W, np.int8), np.zeros((2, W))
            s_active, s_birth, s_deq = np.zeros(W, np.bool_), np.zeros(W, np.int64), np.zeros(W)
            with self.subTest(t=t):
                self.assertEqual(merged(old, k, st, de, act, num, z, -1, b, n0, Si, s_state, s_xi, s_active, s_birth,
                                        s_deq), len(key))
                self.assertFalse(Si.any())
                n = merged(old, k, st, de, act, num, z, at, b, n0, Si, s_state, s_xi, s_active, s_birth, s_deq)
                self.assertEqual(n, len(key))
                cols = slice(at, at + n)
                np.testing.assert_array_equal(Si[0, cols], b)
                np.testing.assert_array_equal(Si[1, cols], key // S + n0)
                np.testing.assert_array_equal(Si[2, cols], key % S + n0)
                for got, expected in zip((s_state, s_deq, s_active, s_birth), want[:4]):
                    np.testing.assert_array_equal(got[cols], expected)
                np.testing.assert_array_equal(_bits(s_xi[:, cols]), _bits(want[4]))

    def test_linear_positions_are_searchsorted(self):
        """``_positions_linear`` (the compiled merge's positions) is ``numpy.searchsorted`` (left) of a
        sorted array in a sorted array: repeats in either, empty arrays, values below and above all."""
        from particleShear.engine import numba_driver as nd
        linear = nd.jit_laws(True, ((numba_step, "_positions_linear"),))["_positions_linear"]
        rng = np.random.default_rng(4)
        for t in range(200):
            a = np.sort(rng.integers(0, 300, int(rng.integers(0, 400)))).astype(np.int64)
            v = np.sort(rng.integers(-20, 320, int(rng.integers(0, 400)))).astype(np.int64)
            with self.subTest(t=t):
                np.testing.assert_array_equal(linear(a, v, 0), np.searchsorted(a, v))

    def test_rebuild_same_table_as_numpy(self):
        """The compiled rebuild of a replica's pair table (``numba_step.rebuild``: the compiled search
        of the table's keys, their sort, the compiled history merge and gathers) gives the table NumPy's
        ``build_candidates`` gives, every field to the bit with its dtype and C order: random
        replicas of 1 … 1,200 spheres whose old table holds bonds (kept beyond reach), relations
        with ξ and creation numbers, Lees-Edwards offsets, a dense replica, an infinite offset."""
        from particleShear.engine import neighbours, state
        rng = np.random.default_rng(3)
        for t in range(120):
            N = int(rng.integers(1, 150)) if t % 3 else int(rng.integers(150, 1200))
            L = float(np.sqrt(N) * 40.0)
            x, y, r = rng.uniform(0, L, N), rng.uniform(0, L, N), rng.uniform(10, 16, N)
            if t == 7:
                x, y = rng.uniform(0, 50, N), rng.uniform(0, 50, N)      # dense: more pairs than the buffer
            shift = float(rng.choice([0.0, 0.3 * L, -2.5 * L])) if t != 5 else np.inf
            skin = float(rng.uniform(0, 8))
            table = neighbours.build_candidates(x, y, r, L, L, 0.0, skin, state.PairTable())
            C = len(table)
            table.state[:] = rng.choice([state.STICK, state.SLIP, state.PERMANENT], C, p=[0.5, 0.2, 0.3])
            table.active[:] = rng.random(C) < 0.6
            table.xi[:] = rng.normal(size=(2, C))
            table.d_eq[:] = rng.uniform(20, 30, C)
            table.birth[:] = rng.permutation(C)
            x = (x + rng.normal(0, 15, N)) % L      # moved: bonds out of reach, new pairs
            with np.errstate(invalid="ignore"):        # (NumPy's search at an infinite offset)
                want = neighbours.build_candidates(x, y, r, L, L, shift, skin, table.copy())
                got = numba_step.rebuild(x, y, r, L, L, shift, skin, table.copy())
            with self.subTest(t=t, N=N):
                for name in state.PairTable.ARRAYS:
                    a, b = getattr(got, name), getattr(want, name)
                    self.assertEqual((a.dtype, a.shape, a.flags.c_contiguous, a.tobytes()),
                                     (b.dtype, b.shape, True, b.tobytes()), name)

    def test_constants_same_as_numpy(self):
        """The compiled constants of candidates (``numba_step.constant_rows``, ``forces.pair_rows`` on
        numbers) are NumPy's (``pair_rows`` on arrays) to the bit: per-replica constants, bonds with
        and without kept viscosities, spheres with parameters of their own (``visit``), B = 1 and 4."""
        from particleShear.engine.forces import PairConstants
        from particleShear.engine.state import PERMANENT, BatchState, ReplicaPairs
        for B in (1, 4):
            for own in (False, True):
                blocks = []
                for backend in ("numpy", "numba"):
                    g = np.random.default_rng(B + 2 * own)
                    s = BatchState(B, 20, backend=backend)
                    s.Lx[:], s.Ly[:] = g.uniform(150, 200, B), g.uniform(150, 200, B)
                    s.r[:] = g.uniform(8, 12, B * 20)
                    for name in ("k", "nu", "k_t", "nu_t", "mu", "c", "prc", "prt"):
                        getattr(s, name)[:] = g.uniform(0.1, 1.0, B)
                    s.keep[:] = g.integers(0, 2, B)
                    if own:
                        s.visit = np.ascontiguousarray(g.uniform(0.1, 1.0, (4, B * 20)))
                        s.visit[3] = g.integers(0, 2, B * 20)
                    sizes = g.integers(0, 40, B)
                    for b, n in enumerate(sizes):
                        i = g.integers(0, 19, n)
                        s.pairs[b] = ReplicaPairs(i, i + 1 + g.integers(0, 19 - i), g.choice([0, 1, PERMANENT], n),
                                                  np.zeros((2, n)), g.uniform(15, 30, n), np.zeros(n, bool))
                    state_p = np.concatenate([p.state for p in s.pairs])
                    d_eq = np.concatenate([p.d_eq for p in s.pairs])
                    C = PairConstants(s, np.concatenate(([0], np.cumsum(sizes))), state=state_p, d_eq=d_eq,
                                      fill=numba_step.constant_rows if backend == "numba" else None)
                    blocks.append((C.f.tobytes(), C.b.tobytes(), C.perm_code.tobytes()))
                with self.subTest(B=B, own=own):
                    self.assertEqual(blocks[0], blocks[1])


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestOneFunctionTwoDrivers(unittest.TestCase):
    def test_compiled_functions_are_the_modules_functions(self):
        """Every function the compiled step calls is compiled from the code object of the NumPy
        engine's function of that name (no second copy of a rule)."""
        L = numba_driver.jit_laws(True, numba_step.STEP_FUNCTIONS)
        for module, name in numba_step.STEP_FUNCTIONS:
            with self.subTest(name=name):
                self.assertIs(L[name].py_func.__code__, getattr(module, name).__code__)


if __name__ == "__main__":
    unittest.main()


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestCompiledBlocks(unittest.TestCase):
    """The recording loop in compiled blocks (numba_step.run_block): a schedule with N1 samples every
    7 steps and an observer every 50 steps gives NumPy's records bit for bit, and the observer is
    called at the same steps seeing the same rows; a controller (rate from the stresses before)
    steps one at a time and agrees as well."""

    def record(self, backend, controller=False, law=None):
        import math

        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.rheometer import shear_record
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        _, e, sc = constituted(51, **FRICTIONAL_BONDS)
        eng = BatchEngine(state_from_ensembles([e], backend=backend, laws=[law]))
        seen = []

        class Watch:
            every = 50

            def observe(self, engine, phase, step, total):
                seen.append((phase, step, engine.record["stress_surface"][step - 1].copy()))

        rate = [3000.0]

        def rate_of(i):
            return np.full(1, rate[0] if controller else 3000.0 * math.sin(0.01 * i))

        def after(i, tau_int, tau_surf):
            rate[0] = 3000.0 / (1.0 + abs(float(tau_surf[0])))

        out = shear_record(eng, sc["dt"], sc["cool"], 600, rate_of, tensors_every=7, observers=[Watch()],
                           after_step=after if controller else None)
        return out, seen, eng

    def test_blocks_equal_numpy(self):
        for controller in (False, True):
            with self.subTest(controller=controller):
                ref, seen_ref, _ = self.record("numpy", controller)
                got, seen_got, eng = self.record("numba", controller)
                for key in ("t", "strain", "strain_rate", "stress_internal", "stress_surface", "N1"):
                    np.testing.assert_array_equal(_bits(ref[key]), _bits(got[key]), err_msg=key)
                self.assertEqual([s[:2] for s in seen_ref], [s[:2] for s in seen_got])
                self.assertEqual(len(seen_got), 600 // 50)
                for a, b in zip(seen_ref, seen_got):
                    np.testing.assert_array_equal(_bits(a[2]), _bits(b[2]))
                self.assertEqual(int(np.isfinite(got["N1"][:, 0]).sum()), len(range(0, 600, 7)))

    def test_steps_left_to_numpy_notify_once(self):
        """A law the compiled step leaves to NumPy: the loop runs every step itself, and the observer is
        called at the same steps as on NumPy, each once."""
        from particleShear.engine.laws import register_law, unregister_law
        from particleShearTest.test_numba_driver import _python_only_law
        register_law("python_only_blocks", _python_only_law)
        try:
            ref, seen_ref, _ = self.record("numpy", law=("python_only_blocks", ()))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                got, seen_got, _ = self.record("numba", law=("python_only_blocks", ()))
        finally:
            unregister_law("python_only_blocks")
        self.assertEqual([s[:2] for s in seen_got], [s[:2] for s in seen_ref])
        self.assertEqual([s[1] for s in seen_got], list(range(50, 601, 50)))
        np.testing.assert_array_equal(_bits(ref["stress_surface"]), _bits(got["stress_surface"]))


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestThreads(unittest.TestCase):
    """``PARTICLESHEAR_THREADS``: a block's replicas on several threads (numba.prange over replicas)."""

    def test_two_threads_same_bits(self):
        """Three replicas (bonds, friction, none) through pre-equilibration and protocol in blocks on two
        threads: every record and the whole state are the one-thread bits (each replica reads and
        writes only its own rows)."""
        from unittest import mock
        scenes = [(0, FRICTIONAL_BONDS), (1, FRICTIONAL), (2, FRICTIONLESS)]
        one = _measure(scenes, "numba")
        with mock.patch.dict("os.environ", {numba_step.THREADS_VARIABLE: "2"}):
            self.assertEqual(numba_step.threads(), 2)
            two = _measure(scenes, "numba")
        TestCompiledStepBits.assert_same_engines(self, one[0], two[0])
        TestCompiledStepBits.assert_same_records(self, one[1], two[1])

    def test_invalid_thread_count(self):
        from unittest import mock
        for text in ("0", "two", "-1", "1.5"):
            with mock.patch.dict("os.environ", {numba_step.THREADS_VARIABLE: text}):
                with self.assertRaisesRegex(ValueError, "PARTICLESHEAR_THREADS=.*whole number of threads >= 1"):
                    numba_step.threads()


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestRebuildsInBlock(unittest.TestCase):
    """The lists due rebuilt inside the compiled block (numba_step._Slots, _rebuild_replica): the same
    bits as the rebuilds between calls (``REBUILD_IN_BLOCK = False``) and as NumPy, the pair tables
    included; a list that outgrows its slot is left to the rebuild between calls; on two threads."""

    SCENES = [(0, FRICTIONAL_BONDS), (1, FRICTIONAL), (3, FRICTIONAL_BONDS)]

    @staticmethod
    def counted():
        """A patch of ``_settle`` that counts the lists rebuilt inside each block, and the counts."""
        from unittest import mock
        counts, real = [], numba_step._settle

        def settle(engine, slots):
            counts.append(int(slots.rebuilt.sum()))
            return real(engine, slots)
        return counts, mock.patch.object(numba_step, "_settle", settle)

    def assert_same(self, a, b):
        TestCompiledStepBits.assert_same_engines(self, a[0], b[0])
        TestCompiledStepBits.assert_same_records(self, a[1], b[1])
        for r in range(a[0].s.B):
            np.testing.assert_array_equal(_bits(a[0].pairs_of(r).d_eq), _bits(b[0].pairs_of(r).d_eq))
            self.assertEqual(a[0].pairs_of(r).birth_count, b[0].pairs_of(r).birth_count)

    def test_same_bits_as_between_calls_and_numpy(self):
        from unittest import mock
        for integrator in ("euler", "verlet"):
            with self.subTest(integrator=integrator):
                counts, patch = self.counted()
                with patch:
                    inside = _measure(self.SCENES, "numba", integrator)
                self.assertGreater(sum(counts), 0)
                with mock.patch.object(numba_step, "REBUILD_IN_BLOCK", False):
                    counts, patch = self.counted()
                    with patch:
                        between = _measure(self.SCENES, "numba", integrator)
                    self.assertEqual(counts, [])
                self.assert_same(inside, between)
                self.assert_same(inside, _measure(self.SCENES, "numpy", integrator))

    def test_list_outgrowing_its_slot(self):
        """No room after the candidates: a list that grows is rebuilt between calls, one that does not
        inside; the same bits."""
        from unittest import mock
        counts, patch = self.counted()
        with patch, mock.patch.object(numba_step, "SLACK", (0.0, 0)):
            tight = _measure(self.SCENES, "numba")
        self.assertGreater(sum(counts), 0)
        self.assertGreater(int(tight[0].s.contacts.rebuilds.sum()), sum(counts))
        self.assert_same(tight, _measure(self.SCENES, "numpy"))

    def test_two_threads(self):
        from unittest import mock
        counts, patch = self.counted()
        with patch, mock.patch.dict("os.environ", {numba_step.THREADS_VARIABLE: "2"}):
            two = _measure(self.SCENES, "numba")
        self.assertGreater(sum(counts), 0)
        self.assert_same(two, _measure(self.SCENES, "numba"))

    def test_distance_zero_after_a_rebuild_inside(self):
        """A pair at d = 0 in the first step after a list rebuilt inside the block (the replica's
        candidates in its slot's columns): its normal is drawn there from the replica's generator,
        and the step goes on; the same bits as NumPy, Euler and Verlet."""
        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        for integrator in ("euler", "verlet"):
            engines, counts = [], None
            for backend in ("numpy", "numba"):
                ens = [constituted(s, **FRICTIONAL)[1] for s in (42, 43)]
                eng = BatchEngine(state_from_ensembles(ens, backend=backend), guard=False, integrator=integrator)
                eng.steps(3, 0.999, ens[0].dt)
                N = eng.s.N
                eng.s.pos[:, N + 1] = eng.s.pos[:, N]        # (replica 1: spheres 0 and 1 on one place)
                eng.s.contacts.need[:] = True
                counts, patch = self.counted()
                with patch:
                    eng.steps(8, 0.999, ens[0].dt)
                engines.append(eng)
            self.assertGreater(sum(counts), 0)
            TestCompiledStepBits.assert_same_engines(self, *engines)


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestWhatTheModuleKeeps(unittest.TestCase):
    """What the compiled backend keeps for an engine (its workspace, the block slots' buffers) is
    held beside the engine (``numba_step._HELD``), not in its attributes, and goes with it: after
    a whole compiled run and a collection nothing is left (a value that referred to its engine
    would keep it alive for ever)."""

    def test_nothing_is_left_after_a_run(self):
        import gc
        import weakref
        from particleShear import doParticleShearSimulation
        from particleShear.engine import numba_step
        from unittest import mock
        with warnings.catch_warnings(), mock.patch.object(numba_step, "_held", wraps=numba_step._held) as held:
            warnings.simplefilter("ignore")
            doParticleShearSimulation(N=20, seed=1, periods=1, pre_periods=0.5, post_periods=0.5,
                                      relative_frequency=0.2, doDrawing=False, plotStress=False, verbose=False,
                                      backend="numba")
        engines = [weakref.ref(c.args[0]) for c in held.call_args_list]
        self.assertTrue(engines)              # (the run's engines were stepped compiled)
        held.reset_mock()                     # (the spy's record of its calls held the engines)
        gc.collect()
        # this run's engines are gone, and nothing is kept for them (other tests' live engines may be)
        self.assertEqual([r for r in engines if r() is not None], [])
        self.assertFalse(any(e in numba_step._HELD for e in (r() for r in engines) if e is not None))


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestIndicesAsGiven(unittest.TestCase):
    """``numba_driver._indices_as_given`` takes signed indices as given only in the package's own
    compiled engine functions: a function compiled elsewhere (a user's law, a script) still reads
    ``a[-1]`` as the last element, as Python does."""

    def test_negative_index_elsewhere_wraps(self):
        import numba
        from particleShear.engine import numba_driver
        numba_driver.register_helpers()

        @numba.njit(cache=False)
        def last(a, k):
            return a[k]

        a = np.arange(5.0)
        self.assertEqual(last(a, -1), 4.0)
        self.assertEqual(last(a, -5), 0.0)
