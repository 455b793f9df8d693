"""The documented ranges of the stiffness and viscosity factors are the ranges that run.

Beyond them the explicit step diverges during the constitution (whose step ``time_step_factor``
does not change), so they are refused before any work; at their limits a run ends with finite
moduli; and an instability found at the first check of the measurement (the state the
constitution left) says so instead of advising a smaller time step that cannot help.
"""
import math
import unittest
import warnings
from unittest import mock

from particleShear import doParticleShearSimulation
from particleShear.base.stability import SimulationInstabilityError
from particleShear.engine.step import EngineInstability
from particleShear.run.batch import _guarded
from particleShear.run.validation import STIFF_VISCOUS, UPPER

TINY = dict(N=40, doDrawing=False, plotStress=False, verbose=False, periods=3, pre_periods=0.5, seed=1,
            return_result=True)


class TestRangesThatRun(unittest.TestCase):
    def test_limits_run(self):
        # each limit with the others at their defaults (N = 40, one seed; measured margins ≥ 20 %)
        for name in ("relative_viscosity", "relative_transversal_link_strength", "interface_reenforcement_central"):
            with self.subTest(name=name), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = doParticleShearSimulation(**TINY, **{name: UPPER[name]})
                self.assertTrue(all(math.isfinite(g) for g in (*r.G_surface, *r.G_internal)))

    def test_beyond_is_refused_before_work(self):
        cases = [dict(relative_viscosity=UPPER["relative_viscosity"] * 1.01),
                 dict(relative_transversal_link_strength=UPPER["relative_transversal_link_strength"] * 1.01),
                 dict(interface_reenforcement_central=UPPER["interface_reenforcement_central"] * 1.01),
                 dict(relative_viscosity=3.0, relative_transversal_link_strength=1.2),      # 3.6 > 3.5
                 dict(relative_viscosity=1.0, interface_reenforcement_central=5.5)]         # 5.5 > 5
        def no_work(*a, **k):
            raise AssertionError("a run was started")
        for kw in cases:
            with self.subTest(kw=kw), mock.patch("particleShear.run.api.measure", no_work), \
                    self.assertRaisesRegex(ValueError, "out of range"):
                doParticleShearSimulation(**TINY, **kw)

    def test_kept_viscosities_lift_the_reinforcement_product(self):
        # with the viscosities kept constant rv·irc is not a viscosity: only the single ranges apply
        bound = STIFF_VISCOUS["relative_viscosity*interface_reenforcement_central"]
        kw = dict(relative_viscosity=1.0, interface_reenforcement_central=bound * 2)
        with mock.patch("particleShear.run.api.measure", side_effect=AssertionError("a run was started")), \
                self.assertRaisesRegex(ValueError, "out of range"):
            doParticleShearSimulation(**TINY, **kw)
        from particleShear.run.validation import _check_stiff_viscous
        _check_stiff_viscous(dict(kw, relative_transversal_link_strength=1.0, keep_viscosity_coefficients_constant=True))


class TestAdviceAfterTheConstitution(unittest.TestCase):
    def raising(self, step, phase):
        def phase_fn(engine):
            raise EngineInstability(f"replica 0: non-finite state at step {step} of phase {phase!r}", replica=0,
                                    step=step, phase=phase)
        with self.assertRaises(SimulationInstabilityError) as cm:
            _guarded(phase_fn, None, dt=1e-7)
        return cm.exception

    def test_step_zero_of_the_measurement_blames_the_constitution(self):
        e = self.raising(0, "pre-equilibration")
        self.assertIn("constitution", str(e))
        self.assertIn("time_step_factor does not change", str(e))
        self.assertIsNone(e.suggested_dt)

    def test_a_later_step_suggests_a_smaller_step(self):
        for step, phase in ((4, "pre-equilibration"), (0, "protocol")):
            e = self.raising(step, phase)
            self.assertIn("try dt <= 5e-08 s", str(e))
            self.assertEqual(e.suggested_dt, 5e-8)


if __name__ == "__main__":
    unittest.main()
