"""Nothing hangs: pathological inputs end quickly with an error that names what to change.

* the Lees-Edwards wrap and the minimum image cost O(1) in the size of a coordinate and stay
  bit-identical to the one-period-at-a-time reference loop for ordinary coordinates;
* a low-level step refuses a time step that is not a finite real > 0, and stops on a
  non-finite or absurd position with the step, the sphere and the value;
* ``doParticleShearSimulation`` refuses, before any work, runs that would not fit the machine
  or the documented limits, protocols that do not resolve the excitation, ensembles too small
  for their constitution and options of the wrong kind — naming the parameter (the flag from
  the CLI) and the allowed range.

Time bounds are generous upper bounds (10–1000× the measured times), not benchmarks: they
distinguish "returns at once" from "loops for ever".
"""
import contextlib
import inspect
import io
import math
import os
import re
import subprocess
import sys
import tempfile
import unittest
from unittest import mock

import numpy as np

from particleShear import EnsembleLinkable, SphereLinkable, doParticleShearSimulation
from particleShear.engine.box import min_image, wrap as le_wrap
from particleShear.base.stability import SimulationInstabilityError, StabilityGuard
from particleShear.base.engine_adapter import state_of_ensemble
from particleShear.linkable.builders import EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters
from particleShear.run import validation
from particleShear.run.api import doParticleShearSimulationSeries
from particleShear.run.cli import main as cli_main
from particleShear.simulation.simulations import Simulation_interlocking_rheology

L = 500.0
QUIET = dict(doDrawing=False, plotStress=False, verbose=False)


def reference_le_wrap(x, y, vx, Lx, Ly, shift, rate):
    """The reference wrap: one period per pass until every coordinate is inside the cell."""
    y0 = y.copy()
    while (y >= Ly).any():
        m = y >= Ly
        y[m] -= Ly
        x[m] -= shift
    while (y < 0).any():
        m = y < 0
        y[m] += Ly
        x[m] += shift
    vx += (y - y0) * rate
    while (x >= Lx).any():
        x[x >= Lx] -= Lx
    while (x < 0).any():
        x[x < 0] += Lx


def reference_min_image(dx, dy, Lx, Ly, shift):
    """The reference minimum image: y image first (moving x by the shift), half-open intervals."""
    dx, dy = dx.copy(), dy.copy()
    while ((dy >= Ly / 2) | (dy < -Ly / 2)).any():
        k = (dy >= Ly / 2).astype(float) - (dy < -Ly / 2)
        dy = dy - Ly * k
        dx = dx - shift * k
    while ((dx >= Lx / 2) | (dx < -Lx / 2)).any():
        k = (dx >= Lx / 2).astype(float) - (dx < -Lx / 2)
        dx = dx - Lx * k
    return dx, dy


def defaults(**changes):
    """The full argument dict of ``doParticleShearSimulation`` (defaults) with ``changes``."""
    p = {k: v.default for k, v in inspect.signature(doParticleShearSimulation).parameters.items()
         if v.kind is not v.VAR_KEYWORD}
    p.update(QUIET)
    p.update(changes)
    return p


class TestWrapAndMinimumImageOfScalarCells(unittest.TestCase):
    """With one box for all elements: a coordinate of any size ends inside after one call (it is
    folded, never moved one period per pass), and ordinary coordinates give the reference loop's bits."""

    def test_huge_coordinate_wraps_at_once(self):
        # 1e300 / 500 periods: the one-period loop would never end (1e300 − 500 == 1e300)
        def wrap():
            x, y, vx = np.array([1e300, 10.0]), np.array([20.0, -1e300]), np.zeros(2)
            le_wrap(x, y, vx, L, L, 100.0, 0.2)
            return x, y
        x, y = wrap()        # inside after one call: folded, not moved one period per pass (1e300 − 500 == 1e300)
        self.assertTrue(np.all((x >= 0) & (x < L)) and np.all((y >= 0) & (y < L)), (x, y))

    def test_closed_form_is_exact_where_it_can_be(self):
        # 2·10⁶ periods above the cell in y and 2·10⁶ to the right in x, all exactly representable:
        # y → 7, x → 10 − 2e6·shift + 2e6·L ≡ 10 (mod L), vx → vx − 2e6·Ly·γ̇ (Lees-Edwards crossing)
        n = 2_000_000
        x, y, vx = np.array([10.0 + n * L]), np.array([7.0 + n * L]), np.array([1.0])
        le_wrap(x, y, vx, L, L, 100.0, 0.25)
        self.assertEqual(y[0], 7.0)
        self.assertEqual(x[0], 10.0)
        self.assertEqual(vx[0], 1.0 - n * L * 0.25)

    def test_non_finite_coordinates_end_non_finite(self):
        x, y, vx = np.array([np.inf, 1.0, np.nan]), np.array([1.0, -np.inf, 2.0]), np.zeros(3)
        le_wrap(x, y, vx, L, L, 50.0, 0.1)
        self.assertTrue(np.isnan(x[0]) and np.isnan(y[1]) and np.isnan(x[2]))

    def test_ordinary_coordinates_bit_identical_to_reference_loop(self):
        rng = np.random.default_rng(5)
        for shift, rate in ((0.0, 0.0), (100.0, 0.3), (-730.0, -1.0), (1234.5, 2.0)):
            with self.subTest(shift=shift):
                x = rng.uniform(-1.5 * L, 2.5 * L, 400)
                y = rng.uniform(-1.5 * L, 2.5 * L, 400)
                y[:20] = L  # boundary values of the half-open interval
                y[20:40] = 0.0
                x[40:60] = L
                vx = rng.normal(size=400)
                ref = [a.copy() for a in (x, y, vx)]
                reference_le_wrap(*ref, L, L, shift, rate)
                le_wrap(x, y, vx, L, L, shift, rate)
                for got, want in zip((x, y, vx), ref):
                    np.testing.assert_array_equal(got, want)

    def test_minimum_image_bit_identical_and_constant_time(self):
        rng = np.random.default_rng(6)
        dx = rng.uniform(-2 * L, 2 * L, 500)
        dy = rng.uniform(-2 * L, 2 * L, 500)
        for shift in (0.0, 100.0, 900.0):
            with self.subTest(shift=shift):
                gx, gy = min_image(dx, dy, L, L, shift)[:2]
                wx, wy = reference_min_image(dx, dy, L, L, shift)
                np.testing.assert_array_equal(gx, wx)
                np.testing.assert_array_equal(gy, wy)
        # a huge difference or a huge Lees-Edwards shift (strain 10⁶) is folded at once: inside after one call
        big = np.array([1e300, 3.0])
        for dy in (np.array([-1e300, -260.0]), np.array([100.0, -260.0])):
            gx, gy = min_image(big, dy, L, L, 5e8)[:2]
            self.assertTrue(np.all((gx >= -L / 2) & (gx < L / 2)) and np.all((gy >= -L / 2) & (gy < L / 2)))
        # in-cell differences with a shift of 10⁶ cells: exact where representable (3 + 5e8 ≡ 3 mod 500)
        gx, gy = min_image(np.array([3.0]), np.array([-260.0]), L, L, 5e8)[:2]
        self.assertEqual((gx[0], gy[0]), (3.0, 240.0))


class TestEngineBoxIsConstantTime(unittest.TestCase):
    """The engine's wrap and minimum image (particleShear.engine.box) end at once for any coordinate, on
    arrays of box sizes per element, and equal the reference loop for ordinary ones."""

    def test_huge_and_infinite_coordinates(self):
        from particleShear.engine.box import min_image as engine_min_image, wrap as engine_wrap
        Ls = np.full(3, L)

        def wrap():
            x, y, vx = np.array([1e300, 10.0, np.inf]), np.array([20.0, -1e300, 3.0]), np.zeros(3)
            engine_wrap(x, y, vx, Ls, Ls, np.full(3, 100.0), np.full(3, 0.2))
            return x, y
        x, y = wrap()
        self.assertTrue(np.all((x[:2] >= 0) & (x[:2] < L)) and np.all((y[:2] >= 0) & (y[:2] < L)), (x, y))
        self.assertTrue(np.isnan(x[2]))  # infinite: NaN, which the stability guard reports
        big = np.array([1e300, 3.0])
        gx, gy, _, _ = engine_min_image(big, np.array([-1e300, -260.0]), L, L, 5e8)
        self.assertTrue(np.all((gx >= -L / 2) & (gx < L / 2)) and np.all((gy >= -L / 2) & (gy < L / 2)))

    def test_ordinary_coordinates_match_the_classes_kernel(self):
        from particleShear.engine.box import wrap as engine_wrap
        rng = np.random.default_rng(7)
        for shift, rate in ((0.0, 0.0), (100.0, 0.3), (-730.0, -1.0)):
            with self.subTest(shift=shift):
                x = rng.uniform(-1.5 * L, 2.5 * L, 300)
                y = rng.uniform(-1.5 * L, 2.5 * L, 300)
                vx = rng.normal(size=300)
                ref = [a.copy() for a in (x, y, vx)]
                reference_le_wrap(*ref, L, L, shift, rate)
                n = len(x)
                engine_wrap(x, y, vx, np.full(n, L), np.full(n, L), np.full(n, shift), np.full(n, rate))
                # vx too: the engine's correction is the reference's (y' − y)·γ̇, also for several periods
                for got, want in zip((x, y, vx), ref):
                    np.testing.assert_array_equal(got, want)


def two_spheres(x=150.0, xspeed=10.0):
    ens = EnsembleLinkable(L, L, 0, k=1, nu=1, k_t=1, nu_t=1, mu=0.01)
    a = SphereLinkable("grey", x, 200, 120, 1, 1, force_register=ens)
    b = SphereLinkable("grey", 220, 260, 120, 1, 2, force_register=ens)
    ens.sphereList.append(a)
    ens.sphereList.append(b)
    a.xspeed = xspeed
    return ens


class TestLowLevelStep(unittest.TestCase):
    """A step refuses a meaningless dt and stops on a position no step can reach."""

    def test_time_step_must_be_finite_and_positive(self):
        for dt in (0, 0.0, -1e-3, math.inf, -math.inf, math.nan, True):
            for phase in ("mechanical_simulation_step", "mechanical_simulation_step_calculate_acceleration",
                          "mechanical_simulation_step_calculate_movement"):
                with self.subTest(dt=dt, phase=phase):
                    ens = two_spheres()
                    before = ens.sphere_arrays["x"].copy(), ens.sphere_arrays["xspeed"].copy()
                    args = (dt,) if phase.endswith("movement") else (1.0, dt)
                    with self.assertRaisesRegex(ValueError, r"\bdt=.*step 0.*finite time step > 0"):
                        getattr(ens, phase)(*args)
                    # refused before any work: state unchanged
                    np.testing.assert_array_equal(ens.sphere_arrays["x"], before[0])
                    np.testing.assert_array_equal(ens.sphere_arrays["xspeed"], before[1])

    def test_sphere_far_outside_the_cell(self):
        ens = two_spheres(x=1e9)
        with self.assertRaises(SimulationInstabilityError) as cm:
            ens.mechanical_simulation_step(1.0, 0.01)
        e = cm.exception
        self.assertEqual(e.pair, (0,))
        self.assertEqual(e.step, 0)
        for text in ("step 0", "sphere 0", "1000000000", "cell"):
            self.assertIn(text, str(e))

    def test_diverging_velocity_stops_with_the_sphere_and_value(self):
        ens = two_spheres(xspeed=1e300)
        with self.assertRaises(SimulationInstabilityError) as cm, np.errstate(all="ignore"):
            for _ in range(3):
                ens.mechanical_simulation_step(1.0, 0.01)
        self.assertIn("sphere 0", str(cm.exception))
        self.assertIsNotNone(cm.exception.suggested_dt)

    def test_huge_time_step_stops_instead_of_hanging(self):
        ens = two_spheres()
        with self.assertRaises(SimulationInstabilityError) as cm, np.errstate(all="ignore"):
            for _ in range(3):
                ens.mechanical_simulation_step(1.0, 1e300)
        self.assertIn(cm.exception.step, (0, 1, 2))      # stopped within the steps asked for, not later
        self.assertIn("not finite", str(cm.exception))

    def test_guard_names_the_non_finite_value(self):
        ens = two_spheres()
        ens.stability_guard = StabilityGuard(interval=1)
        # the engine's state of the ensemble is its own rows: a value past the setter's check, as a
        # diverging force would leave it
        state_of_ensemble(ens).vy[1] = np.nan
        with self.assertRaises(SimulationInstabilityError) as cm:
            ens.mechanical_simulation_step(1.0, 0.01)
        self.assertEqual(cm.exception.pair, (1,))
        for text in ("step 0", "sphere 1", "nan"):
            self.assertIn(text, str(cm.exception))

    def test_link_across_ensembles_refused(self):
        e1, e2 = two_spheres(), two_spheres()
        a, b = e1.sphereList[0], e2.sphereList[1]
        with self.assertRaisesRegex(ValueError, "another"):
            a.establish_permanent_link(b)
        self.assertEqual([r.interface_type for r in a.neighbors if r.theSphere is b], [])


@contextlib.contextmanager
def no_simulation_work():
    """Fail the test if a simulation starts building its ensemble."""
    with mock.patch.object(Simulation_interlocking_rheology, "initEnsemble",
                           side_effect=AssertionError("simulation work started")):
        yield


class TestRefusedBeforeWork(unittest.TestCase):
    """Each case ends before the ensemble is built with an error naming its parameter."""

    def assertRefused(self, name, kw, error=ValueError, message=None):
        with no_simulation_work(), self.assertRaises(error) as cm:
            doParticleShearSimulation(**dict(QUIET, **kw))
        self.assertRegex(str(cm.exception), rf"(?<![\w-]){re.escape(name)}=")
        if message:
            self.assertRegex(str(cm.exception), message)
        return str(cm.exception)

    def test_pathological_sizes(self):
        cases = [("N", dict(N=10 ** 9)), ("periods", dict(periods=10 ** 9)), ("cut_lines", dict(cut_lines=10 ** 9)),
                 ("pre_periods", dict(pre_periods=1e12)), ("theAmplitude", dict(theAmplitude=1e6)),
                 ("relative_frequency", dict(relative_frequency=100)),
                 ("relative_frequency", dict(relative_frequency=10)),
                 ("relative_frequency", dict(relative_frequency=1e-12)),
                 ("time_step_factor", dict(time_step_factor=1e-12)),
                 ("time_step_factor", dict(time_step_factor=1e6))]
        for name, kw in cases:
            with self.subTest(**kw):
                self.assertRefused(name, kw, message="allowed")

    def test_extreme_material_parameters_name_the_parameter(self):
        for name in ("Young_modulus_spheres", "relative_viscosity", "relative_transversal_link_strength",
                     "interface_reenforcement_central", "interface_reenforcement_tangential", "density", "theMu",
                     "bimodal_factor", "packing_fraction", "edge_fuzziness"):
            with self.subTest(name=name):
                msg = self.assertRefused(name, {name: 1e300}, message="out of range: allowed")
                for internal in ("nu", "k_t", "k"):
                    self.assertNotRegex(msg, rf"\b{internal}\b")

    def test_unvalidated_options_are_validated(self):
        cases = [("return_result", "False"), ("return_result", None), ("verbose", [1]), ("verbose", "False"),
                 ("correct_drift_sign", 1), ("reference_header", "False"), ("stability_guard", None),
                 ("stability_guard", [1]), ("progress", 3), ("time_step_factor", True), ("time_step_factor", "2")]
        for name, bad in cases:
            with self.subTest(name=name, value=bad):
                self.assertRefused(name, {name: bad}, error=TypeError)
        for name, bad in (("renderer", "bogus"), ("renderer", 3), ("integrator", "rk4"),
                          ("time_step_factor", 0), ("time_step_factor", -1.0), ("time_step_factor", math.nan)):
            with self.subTest(name=name, value=bad):
                self.assertRefused(name, {name: bad})

    def test_unwritable_folder_refused_before_work(self):
        if not os.path.isdir("/proc"):
            self.skipTest("no /proc")
        self.assertRefused("root_folder", dict(root_folder="/proc", saveData=True), message="not writable")


class TestResolutionAndConstitution(unittest.TestCase):
    """The limits the refusals state are the limits applied, and they follow from their physics."""

    def test_protocol_step_count_matches_the_estimate(self):
        kw = dict(N=20, do_permanent_links=False, cut_lines=0, relative_frequency=0.2, pre_periods=0.5,
                  periods=1, post_periods=0.5, seed=3)
        r = doParticleShearSimulation(return_result=True, **dict(QUIET, **kw))
        cost = validation.estimate_run_cost(defaults(**kw))
        self.assertEqual(r.N_steps, int(cost["protocol_steps"]))
        # steps per excitation period = 1/(f·dt), from the run's own f and dt
        self.assertAlmostEqual(cost["steps_per_period"], 1 / (r.f * r.dt), delta=1e-9 * cost["steps_per_period"])

    def test_relative_frequency_limit_is_100_steps_per_period(self):
        p = defaults()
        with self.assertRaises(ValueError) as cm:
            validation.validate_simulation_parameters(defaults(relative_frequency=10))
        rf_max = float(re.search(r"relative_frequency <= ([0-9.e+-]+)", str(cm.exception)).group(1))
        ok = validation.estimate_run_cost(defaults(relative_frequency=rf_max * 0.99))
        self.assertGreaterEqual(ok["steps_per_period"], 100)
        validation.validate_simulation_parameters(defaults(relative_frequency=rf_max * 0.99))
        with self.assertRaises(ValueError):
            validation.validate_simulation_parameters(defaults(relative_frequency=rf_max * 1.01))
        self.assertTrue(p)

    def test_smallest_accepted_ensemble_obeys_the_minimum_image(self):
        with self.assertRaises(ValueError) as cm:
            validation.validate_simulation_parameters(defaults(N=3, cut_lines=0))
        msg = str(cm.exception)
        self.assertIn("N=3", msg)
        n_min = int(re.search(r"allowed integers (\d+) <= value", msg).group(1))
        validation.validate_simulation_parameters(defaults(N=n_min, cut_lines=0))
        with self.assertRaises(ValueError):
            validation.validate_simulation_parameters(defaults(N=n_min - 1, cut_lines=0))
        # the largest sphere of the accepted ensemble is smaller than a quarter of the cell
        # (every pair then interacts through one image only)
        ens = EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters(
            N=n_min, packing_fraction=1.5, bimodal_factor=1.4, do_permanent_links=False, cut_lines=0,
            do_pre_equilibration=False, doDrawing=False, rng=1)
        self.assertLess(4 * ens.r_max, L)

    def test_cutting_needs_three_spheres_per_particle(self):
        for triangulation in (True, False):
            with self.subTest(triangulation=triangulation):
                with self.assertRaises(ValueError) as cm:
                    validation.validate_simulation_parameters(defaults(N=100, cut_lines=60,
                                                                       doCutByTriangulation=triangulation))
                cut_max = int(re.search(r"allowed integers 0 <= value <= (\d+)", str(cm.exception)).group(1))
                pieces = cut_max if triangulation else 1 + cut_max * (cut_max + 1) // 2
                self.assertGreaterEqual(100 / pieces, 3)
                validation.validate_simulation_parameters(defaults(N=100, cut_lines=cut_max,
                                                                   doCutByTriangulation=triangulation))
                with self.assertRaises(ValueError):
                    validation.validate_simulation_parameters(defaults(N=100, cut_lines=cut_max + 1,
                                                                       doCutByTriangulation=triangulation))

    def test_memory_of_this_machine_is_the_limit(self):
        with tempfile.TemporaryDirectory() as d, \
                mock.patch.object(validation, "available_memory", return_value=100 * 2 ** 20):
            # 100 MiB: N = 20,000 spheres need ~200 MB
            with self.assertRaisesRegex(ValueError, r"N=20000 .*allowed integers 2 <= value <= ([\d,]+)") as cm:
                validation.validate_simulation_parameters(defaults(N=20000, cut_lines=0))
            n_ok = int(re.search(r"allowed integers 2 <= value <= ([\d,]+)", str(cm.exception)).group(1).replace(",", ""))
            self.assertLessEqual(n_ok * validation.BYTES_PER_SPHERE, 0.8 * 100 * 2 ** 20)
            # a saved tensor table of 1,000 periods (2.2 M steps, ~8 GB of text)
            kw = dict(saveData=True, root_folder=d, periods=1000)
            with self.assertRaises(ValueError) as cm:
                validation.validate_simulation_parameters(defaults(**kw))
            m = re.search(r"allowed periods <= ([0-9.e+]+)", str(cm.exception))
            self.assertIsNotNone(m, str(cm.exception))
            validation.validate_simulation_parameters(defaults(**dict(kw, periods=float(m.group(1)) * 0.99)))
            self.assertEqual(os.listdir(d), [])  # the writability probe left nothing behind
        self.assertGreater(validation.available_memory() or 1, 0)


class TestInstabilityEndsQuickly(unittest.TestCase):

    def test_time_step_factor_1000(self):
        with self.assertRaises(SimulationInstabilityError) as cm:
            doParticleShearSimulation(time_step_factor=1000, seed=1, **QUIET)
        # stopped at the first checks of the pre-equilibration (every 4th step), not after the protocol
        self.assertEqual(cm.exception.phase, "pre-equilibration")
        self.assertLessEqual(cm.exception.step, 8)
        self.assertIn("try dt <=", str(cm.exception))


class TestSeriesRefusedBeforeJobs(unittest.TestCase):

    def test_grid_sizes(self):
        executor = mock.Mock()
        executor.submit.side_effect = AssertionError("a job was submitted")
        cases = [("N_repetitions", dict(N_repetitions=10 ** 9)), ("N_repetitions", dict(N_repetitions=-1)),
                 ("N_repetitions", dict(N_repetitions=1000, amplitudes=list(range(1, 11)), mu=[0.1] * 11)),
                 ("N", dict(N=10 ** 9)), ("renderer", dict(renderer="bogus"))]
        for name, kw in cases:
            with self.subTest(name=name):
                with self.assertRaisesRegex(ValueError, rf"\b{name}="):
                    doParticleShearSimulationSeries(executor=executor, **kw)


class TestCommandLine(unittest.TestCase):
    """Every invalid input: exit status 2, one line on stderr naming the flag, no traceback."""

    def run_cli(self, *argv):
        err, out = io.StringIO(), io.StringIO()
        with mock.patch.object(sys, "stderr", err), mock.patch.object(sys, "stdout", out), no_simulation_work():
            try:
                rc = cli_main(["--quiet", *argv])
            except SystemExit as e:  # argparse
                rc = e.code
        return rc, err.getvalue()

    def test_invalid_inputs(self):
        cases = [("--N", ["--N", "1000000000"]), ("--periods", ["--periods", "1e9"]),
                 ("--cut-lines", ["--cut-lines", "1000000000"]), ("--amplitude", ["--amplitude", "1e6"]),
                 ("--relative-frequency", ["--relative-frequency", "100"]), ("--N", ["--N", "3", "--cut-lines", "0"]),
                 ("--young-modulus", ["--young-modulus", "1e300"]),
                 ("--relative-viscosity", ["--relative-viscosity", "1e300"]),
                 ("--relative-transversal-link-strength", ["--relative-transversal-link-strength", "1e300"]),
                 ("--N", ["--N", "abc"]), ("--bogus", ["--bogus"]), ("--seed", ["--seed", "-3"])]
        if os.path.isdir("/proc"):
            cases.append(("--save", ["--save", "/proc"]))
        for flag, argv in cases:
            with self.subTest(argv=argv):
                rc, err = self.run_cli(*argv)
                self.assertEqual(rc, 2)
                self.assertEqual(err.count("\n"), 1, err)
                self.assertIn(flag, err)
                self.assertNotIn("Traceback", err)
                for python_name in ("theAmplitude", "Young_modulus_spheres", "relative_viscosity", "root_folder"):
                    self.assertNotIn(python_name, err)

    def test_exit_status_of_the_process(self):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [os.getcwd(), os.environ.get("PYTHONPATH")])))
        proc = subprocess.run([sys.executable, "-m", "particleShear", "--quiet", "--amplitude", "1e6"],
                              capture_output=True, text=True, timeout=60, env=env)
        self.assertEqual(proc.returncode, 2)
        self.assertEqual(proc.stderr.count("\n"), 1, proc.stderr)
        self.assertIn("--amplitude", proc.stderr)


if __name__ == "__main__":
    unittest.main()
