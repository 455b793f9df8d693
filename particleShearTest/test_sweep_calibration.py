"""The calibrated ``--dry-run`` projection (particleShear.sweep.calibration): arithmetic with an injected
calibration and a fake clock, the cache key, and the documented directions of --workers and --batch-size.

No assertion depends on how fast this machine is: the clock and the simulations are replaced.
"""
import io
import json
import os
import sys
import tempfile
import unittest
from unittest import mock

from particleShear.sweep import calibration as C
from particleShear.sweep.cost import run_steps

BASE = dict(N=30, bimodal_factor=1.4, theMu=0.1, relative_transversal_link_strength=1, theAmplitude=0.1,
            relative_viscosity=1, periods=1, pre_periods=0.5, post_periods=0.5, relative_frequency=0.25,
            saveData=False)


def _cal(per_step=(1e-4, 1e-4, 1e-4), fixed=(0.5, 0.5, 0.5), batch_fraction=0.5, replicas=4, N=30, steps=400):
    single = [f + c * steps for c, f in zip(per_step, fixed)]
    med = sorted(single)[len(single) // 2]
    return {"N": N, "steps": steps, "per_step_s": list(per_step), "fixed_s": list(fixed), "single_s": single,
            "replicas": replicas, "batch_s": batch_fraction * replicas * med}


def _same_schedule(p):
    return "one"


class FakeClock:
    """Advances by the cost the fake run reports: steps × per_step + fixed."""

    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


class TestProjection(unittest.TestCase):
    def test_cost_is_fixed_plus_steps_times_per_step(self):
        cal = _cal()
        c = C.project_cost([BASE], [10], cal, workers=1, cores=1)
        expected = 10 * (0.5 + run_steps(BASE) * 1e-4)      # same N as calibrated: no scaling
        self.assertAlmostEqual(c["cpu_s"], expected, places=9)
        self.assertAlmostEqual(c["wall_s"], expected, places=9)

    def test_workers_divide_the_wall_time_up_to_the_cores(self):
        cal = _cal()
        one = C.project_cost([BASE], [40], cal, workers=1, cores=4)
        four = C.project_cost([BASE], [40], cal, workers=4, cores=4)
        eight = C.project_cost([BASE], [40], cal, workers=8, cores=4)
        self.assertAlmostEqual(one["cpu_s"], four["cpu_s"])
        self.assertAlmostEqual(four["wall_s"], one["wall_s"] / 4)      # wall = CPU / min(workers, cores)
        self.assertAlmostEqual(eight["wall_s"], four["wall_s"])        # more workers than cores buys nothing
        self.assertEqual(eight["parallel"], 4)

    def test_fewer_tasks_than_workers(self):
        c = C.project_cost([BASE], [2], _cal(), workers=8, cores=8)
        self.assertEqual(c["parallel"], 2)
        self.assertAlmostEqual(c["wall_s"], c["cpu_s"] / 2)

    def test_batches_cost_less_per_run_and_follow_the_measured_ratio(self):
        cal = _cal(batch_fraction=0.5, replicas=4)      # a batch of 4 costs half a single run per run
        single = C.project_cost([BASE], [32], cal, workers=1, cores=1)
        b4 = C.project_cost([BASE], [32], cal, workers=1, cores=1, batch_size=4, schedule=_same_schedule)
        b32 = C.project_cost([BASE], [32], cal, workers=1, cores=1, batch_size=32, schedule=_same_schedule)
        self.assertAlmostEqual(b4["cpu_s"] / single["cpu_s"], 0.5)     # the calibrated point itself
        self.assertLess(b32["cpu_s"], b4["cpu_s"])                      # larger batches: cheaper per run
        # c0 + b c1 with c0 + c1 = 1 and 4 c1 + c0 = 2: c1 = 1/3, per-run fraction at 32: 2/3/32 + 1/3
        self.assertAlmostEqual(b32["cpu_s"] / single["cpu_s"], (2 / 3) / 32 + 1 / 3)
        self.assertEqual(b32["tasks"], 1)
        self.assertEqual(b4["tasks"], 8)

    def test_batches_of_one_cost_single_runs(self):
        cal = _cal(batch_fraction=0.5)
        a = C.project_cost([BASE], [5], cal, cores=1)
        b = C.project_cost([BASE], [5], cal, cores=1, batch_size=1, schedule=_same_schedule)
        self.assertAlmostEqual(a["cpu_s"], b["cpu_s"])

    def test_larger_N_costs_more(self):
        cal = _cal()
        small = C.project_cost([BASE], [1], cal, cores=1)
        big = C.project_cost([dict(BASE, N=300)], [1], cal, cores=1)
        self.assertGreater(big["cpu_s"], small["cpu_s"])

    def test_range_holds_the_central_value_and_the_sample_spread(self):
        cal = _cal(per_step=(1e-4, 2e-4, 4e-4), fixed=(0.1, 0.1, 0.1))
        c = C.project_cost([BASE], [10], cal, cores=1)
        self.assertLessEqual(c["wall_low_s"], c["wall_s"] * (1 - C.MIN_SPREAD) + 1e-12)
        self.assertGreaterEqual(c["wall_high_s"], c["wall_s"] * (1 + C.MIN_SPREAD) - 1e-12)
        slowest = C.project_cost([BASE], [10], _cal(per_step=(4e-4,), fixed=(0.1,)), cores=1)
        self.assertGreaterEqual(c["wall_high_s"], slowest["wall_s"] - 1e-12)
        self.assertIn("range", C.format_projection(c, 1))


class TestMeasurement(unittest.TestCase):
    def test_fake_clock_recovers_per_step_and_fixed_cost(self):
        clock = FakeClock()

        def run(kw):       # a run costs 0.3 s + 1e-3 s per protocol step on the fake clock
            clock.t += 0.3 + 1e-3 * run_steps(kw)

        def batch(kws):
            clock.t += 0.5 * len(kws) * (0.3 + 1e-3 * run_steps(kws[0]))

        cal = C.measure_calibration(BASE, steps=400, repeats=2, replicas=4, timer=clock, run=run, batch=batch)
        for c, f in zip(cal["per_step_s"], cal["fixed_s"]):
            self.assertAlmostEqual(c, 1e-3)
            self.assertAlmostEqual(f, 0.3)
        self.assertAlmostEqual(cal["batch_s"] / (4 * cal["single_s"][0]), 0.5)
        self.assertEqual(len(cal["per_step_s"]), 2)

    def test_no_warning_about_values_the_user_did_not_set(self):
        # the user's point measures 3 periods (no warning); the calibration shortens it to a
        # fraction of a period, which validate_run warns about: the user never set those values
        import warnings
        from particleShear.run.validation import validate_run
        from particleShear.run.batch import _signature_defaults
        p = dict(_signature_defaults(), **dict(BASE, periods=3, relative_frequency=0.01), cut_lines=0)
        clock = FakeClock()

        def run(kw):
            validate_run(kw)
            clock.t += 0.3 + 1e-3 * run_steps(kw)

        def batch(kws):
            for kw in kws:
                validate_run(kw)
            clock.t += 1.0

        self.assertLess(C._shortened(p, 400, "")["periods"], 1)     # the calibration's own value
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            validate_run(dict(C._shortened(p, 400, ""), root_folder=""))
            self.assertEqual(len(caught), 1)                        # a warning the user would not expect
            caught.clear()
            C.measure_calibration(p, steps=400, repeats=2, replicas=2, timer=clock, run=run, batch=batch)
        self.assertEqual([str(w.message) for w in caught], [])

    def test_bad_arguments(self):
        for kw in ({"steps": 4}, {"repeats": 0}, {"replicas": 1}):
            with self.assertRaises(ValueError) as cm:
                C.measure_calibration(BASE, run=lambda kw: None, batch=lambda kws: None, **kw)
            self.assertIn(next(iter(kw)), str(cm.exception))


class TestCache(unittest.TestCase):
    def test_key_names_host_version_and_configuration(self):
        k = C.calibration_key(BASE, 400, 4, host="hostA", version="1.0")
        self.assertTrue(k.startswith("hostA|1.0|"))
        self.assertNotEqual(k, C.calibration_key(BASE, 400, 4, host="hostB", version="1.0"))
        self.assertNotEqual(k, C.calibration_key(BASE, 400, 4, host="hostA", version="1.1"))
        self.assertNotEqual(k, C.calibration_key(dict(BASE, N=60), 400, 4, host="hostA", version="1.0"))
        self.assertNotEqual(k, C.calibration_key(BASE, 800, 4, host="hostA", version="1.0"))
        # the seed and the output folder do not change the cost: same key
        self.assertEqual(k, C.calibration_key(dict(BASE, seed=5, root_folder="x"), 400, 4, host="hostA",
                                              version="1.0"))

    def test_cached_per_key_and_refreshed_on_request(self):
        calls = []

        def run(kw):
            calls.append(kw)

        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "sub", "calibration.json")
            kw = dict(path=path, host="h", version="v", run=run, batch=lambda kws: None, timer=FakeClock())
            _, cached = C.load_or_measure(BASE, repeats=1, **kw)
            self.assertFalse(cached)
            n = len(calls)
            _, cached = C.load_or_measure(BASE, repeats=1, **kw)
            self.assertTrue(cached)
            self.assertEqual(len(calls), n)                    # nothing ran again
            _, cached = C.load_or_measure(dict(BASE, N=60), repeats=1, **kw)
            self.assertFalse(cached)                           # another configuration: measured
            _, cached = C.load_or_measure(BASE, repeats=1, refresh=True, **kw)
            self.assertFalse(cached)
            with open(path) as fh:
                self.assertEqual(len(json.load(fh)), 2)

    def test_cache_dir_from_environment(self):
        with mock.patch.dict(os.environ, {"PARTICLESHEAR_CACHE_DIR": "/x/y"}):
            self.assertEqual(C.cache_path(), os.path.join("/x/y", "calibration.json"))
        env = {k: v for k, v in os.environ.items() if k not in ("PARTICLESHEAR_CACHE_DIR", "XDG_CACHE_HOME")}
        with mock.patch.dict(os.environ, env, clear=True):
            self.assertTrue(C.cache_path().endswith(os.path.join(".cache", "particleShear", "calibration.json")))


class TestCli(unittest.TestCase):
    def test_dry_run_uses_the_injected_calibration_and_batch_size(self):
        from particleShear.sweep.cli import main
        spec = {"parameters": dict(N=30, relative_frequency=0.25, pre_periods=0.5, periods=1, post_periods=0.5,
                                   doDrawing=False, plotStress=False),
                "grid": {"theAmplitude": [0.05, 0.2]}, "seeds": {"root": 1, "repetitions": 16}}
        outputs = {}
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "s.json")
            with open(path, "w") as fh:
                json.dump(spec, fh)
            for flags in ((), ("--batch-size", "16"), ("--workers", "1"), ("--no-calibrate",)):
                out = io.StringIO()
                with mock.patch.object(C, "measure_calibration", return_value=_cal()) as m, \
                        mock.patch.dict(os.environ, {"PARTICLESHEAR_CACHE_DIR": d}), \
                        mock.patch.object(sys, "stdout", out):
                    self.assertEqual(main([path, "--out", os.path.join(d, "o"), "--dry-run", "--workers", "2",
                                           *flags]), 0)
                outputs[flags] = out.getvalue()
                if flags == ("--no-calibrate",):
                    m.assert_not_called()
            self.assertFalse(os.path.exists(os.path.join(d, "o")))
        self.assertIn("calibrat", outputs[()])
        self.assertNotIn("calibrated here", outputs[("--no-calibrate",)])
        self.assertIn("batches of up to 16", outputs[("--batch-size", "16")])
        self.assertIn("2 task(s)", outputs[("--batch-size", "16")])    # 2 schedules x 16 runs: 2 batches
        self.assertIn("on 1 of 1 worker(s)", outputs[("--workers", "1")])


if __name__ == "__main__":
    unittest.main()


class TestStaticModelFollowsTheBackend(unittest.TestCase):
    """The static projection (``--no-calibrate``) of a run is that of the backend the run would use:
    ``"auto"`` resolved by the one rule of backend selection, a backend without figures at NumPy's;
    the compiled backend's projection is the smaller at every size (it is faster per step and per
    constitution at N = 150, 1,000 and 10,000, docs/sweeps.md)."""

    def test_auto_is_the_resolved_backend(self):
        from particleShear.sweep import cost
        from particleShear.engine import xp
        for name in ("numpy", "numba"):
            with mock.patch.dict(os.environ, {xp.BACKEND_ENV: name}):
                self.assertEqual(cost.cost_backend(dict(BASE, backend="auto")), name)
                self.assertEqual(cost.run_seconds(dict(BASE, backend="auto")),
                                 cost.run_seconds(dict(BASE, backend=name)))

    def test_device_is_projected_at_numpy(self):
        from particleShear.sweep import cost
        self.assertEqual(cost.cost_backend(dict(BASE, backend="cupy")), "numpy")
        self.assertEqual(cost.run_seconds(dict(BASE, backend="cupy")), cost.run_seconds(dict(BASE, backend="numpy")))

    def test_compiled_projects_less_at_every_size(self):
        from particleShear.sweep import cost
        for N in (20, 150, 1000, 5000, 10000, 40000):
            with self.subTest(N=N):
                self.assertLess(cost.run_seconds(dict(BASE, N=N, backend="numba")),
                                cost.run_seconds(dict(BASE, N=N, backend="numpy")))

    def test_calibrated_shape_uses_the_points_backend(self):
        cal = _cal(N=30)
        at = {be: C.project_cost([dict(BASE, N=1000, backend=be)], [1], cal, cores=1)["cpu_s"]
              for be in ("numpy", "numba")}
        # the same measured costs at N = 30 scaled to N = 1,000 by each backend's shapes: the compiled
        # backend's costs grow faster with N than NumPy's (NumPy's per-call overhead dominates at small
        # N, so its cost per step grows sublinearly), so the same calibration projects more for it
        self.assertGreater(at["numba"], at["numpy"])
