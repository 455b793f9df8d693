"""The stability guard's rule holds the same for the documented classes and the engine.

A :class:`~particleShear.base.stability.StabilityGuard` installed on an ensemble and the guard of a
:class:`~particleShear.engine.step.BatchEngine` on the same ensemble's state (a batch of one) must
give the same verdict, and that verdict must be the documented definition evaluated here on its
own: the peculiar kinetic energy ``½ Σ (m |v − γ̇ (y − L/2) e_x|² + I ω²)`` against
``N·k·r_mean² + Σ m (γ̇_max·L/2)²``, and the closest transient contact ``min d/(r_i + r_j)``
against 0.05.  Each threshold is approached from both sides by a factor 1 ± 2 % (far above
round-off, far below the factors by which a real blow-up exceeds it).
Units: µm, s, mg per m depth.
"""
import math
import unittest

import numpy as np

from particleShear import EnsembleLinkable, SphereLinkable
from particleShear.base.stability import SimulationInstabilityError, StabilityGuard
from particleShear.base.engine_adapter import state_of_ensemble
from particleShear.engine.step import BatchEngine, EngineInstability

L = 400.0
K = 3.0
RATE = 0.5


def ensemble(positions, diameter=40.0, rate=RATE):
    """Spheres of one size at ``positions`` (µm), every one moving with the affine flow of ``rate``."""
    ens = EnsembleLinkable(L, L, 0, k=K, nu=0.1, k_t=K, nu_t=0.1, mu=0.1)
    for n, (x, y) in enumerate(positions):
        ens.sphereList.append(SphereLinkable("grey", x, y, diameter, 2.0, n, force_register=ens))
    ens.setShearRate(rate)
    for s in ens.sphereList:                      # at rest relative to the flow, without spin
        s.xspeed = rate * (s.y - L / 2)
        s.omega = 0.0
    return ens


def kinetic_energy(ens, rate=RATE):
    """The definition: ½ Σ m |u|² + I ω², u the velocity relative to the affine flow."""
    e = 0.0
    for s in ens.sphereList:
        u = s.xspeed - rate * (s.y - L / 2)
        e += 0.5 * (s.m * (u * u + s.yspeed ** 2) + s.inertia * s.omega ** 2)
    return e


def default_bound(ens, rate_max=RATE):
    """The definition: N·k·r_mean² + Σ m (γ̇_max·L/2)²."""
    spheres = list(ens.sphereList)
    r_mean = sum(s.r for s in spheres) / len(spheres)
    return len(spheres) * K * r_mean ** 2 + sum(s.m for s in spheres) * (rate_max * L / 2) ** 2


def verdicts(ens):
    """(class guard's reason or None, engine guard's message or None) on the same state."""
    ens.stability_guard = StabilityGuard(interval=1)
    try:
        ens.mechanical_simulation_step_calculate_forces()
        by_class = None
    except SimulationInstabilityError as exc:
        by_class = exc.reason
    engine = BatchEngine(state_of_ensemble(ens), guard=True, check_interval=1, numbers_relations=True)
    engine.rate_max[...] = RATE
    try:
        engine.force_phase()
        by_engine = None
    except EngineInstability as exc:
        by_engine = str(exc)
    return by_class, by_engine


class TestOneRule(unittest.TestCase):

    def assertVerdicts(self, ens, failure):
        """Both guards stop ``ens`` naming ``failure``, or (None) both pass it."""
        for verdict in verdicts(ens):
            if failure is None:
                self.assertIsNone(verdict)
            else:
                self.assertIn(failure, verdict)

    def test_kinetic_energy_bound_from_both_sides(self):
        far = [(50.0, 50.0), (250.0, 90.0), (120.0, 300.0)]       # no contacts
        for factor, fails in ((0.98, False), (1.02, True)):
            with self.subTest(factor=factor):
                ens = ensemble(far)
                s = ens.sphereList[1]
                excess = factor * default_bound(ens)
                s.yspeed = math.sqrt(2 * excess / s.m)            # all the peculiar energy in one sphere
                self.assertAlmostEqual(kinetic_energy(ens), excess, delta=1e-12 * excess)
                self.assertVerdicts(ens, "kinetic energy" if fails else None)

    def test_spin_counts_in_the_kinetic_energy(self):
        ens = ensemble([(50.0, 50.0), (250.0, 90.0)])
        s = ens.sphereList[0]
        s.omega = math.sqrt(2 * 1.02 * default_bound(ens) / s.inertia)
        self.assertVerdicts(ens, "kinetic energy")

    def test_interpenetration_from_both_sides(self):
        r = 20.0
        for ratio, fails in ((0.049, True), (0.051, False)):
            with self.subTest(ratio=ratio):
                d = ratio * 2 * r
                ens = ensemble([(200.0, 200.0), (200.0 + d, 200.0), (60.0, 330.0)], diameter=2 * r)
                self.assertVerdicts(ens, "interpenetrate" if fails else None)

    def test_non_finite_state(self):
        ens = ensemble([(50.0, 50.0), (250.0, 90.0)])
        # the engine's state of the ensemble is its own rows: a value past the setter's check, as a
        # diverging torque would leave it
        state_of_ensemble(ens).omega[1] = np.nan
        self.assertVerdicts(ens, "non-finite")


if __name__ == "__main__":
    unittest.main()
