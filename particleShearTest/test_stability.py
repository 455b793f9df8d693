"""Stability matrix and stability guard (issue "Accuracy and stability").

Every case builds a real ensemble with the docs/engine.md builder (``do_debug=True``: ten times shorter
constitution, same physics), runs the experiment's fixed-plate pre-equilibration and a limited
number of protocol steps (docs/engine.md, the reference per-step order), and asserts physical
truths at every step through a read-only monitor installed where the stability guard sits
(``ensemble.stability_guard``; it is called after every force phase with the pair geometry
of the step):

* the state stays finite;
* the peculiar kinetic energy (relative to the affine flow) stays bounded (see ``KE_FRACTION``);
* the overall stress tensor is symmetric to ``SYM_TOL`` relative (eq. S1-24: it is the sum of a
  symmetric part and of torque terms that cancel exactly in its construction — docs/engine.md — so only
  round-off remains, ~1e-16);
* no sphere pair passes through another: ``min d/(r_i + r_j)`` over transient contacts stays > 0
  and no pair's contact normal flips sign between consecutive steps while it is in contact
  (a flip within one step means the centres crossed; a stable step moves spheres by ≪ d).

Scenes without a packing (two spheres at near-total overlap, coincident centres, spheres on the
periodic boundary) use a dilute two-sphere builder ensemble with positions set by hand; the
same monitor checks them, plus energy statements specific to an isolated pair.

Slow full runs (convergence, long protocols) live in ``benchmarks/accuracy_study.py``.
Units: µm, s, mg per m depth (internal units of docs/engine.md); energies in mg·µm²·s⁻² per m.
"""
import math
import os
import re
import tempfile
import unittest

import numpy as np

from particleShear import Simulation_interlocking_rheology, doParticleShearSimulation
from particleShear.base.laws import elastic_force_law_plateau
from particleShear.base.stability import SimulationInstabilityError, StabilityGuard
from particleShear.objects.spheres import CircleBasicElasticity
from particleShearTest.classes_loops import classes_pre_equilibrate, classes_run_protocol

#: relative asymmetry allowed for the overall stress tensor (round-off level is ~1e-16)
SYM_TOL = 1e-13
#: Energy balance bounds the peculiar kinetic energy: KE ≤ U_el(0) + W_drive (viscous forces and
#: damping only remove energy).  U_el(0) of a builder packing is a few % of E_ref = Σ ½ k r_i²
#: (the linear-law energy of compressing every sphere by its own radius; measured KE peaks
#: 2–4 % of E_ref when the fixed-plate relaxation releases it), so we allow KE_FRACTION·E_ref for
#: it; the drive can at most set every sphere moving at the peak plate speed A·2πf·Ly/2 relative
#: to the flow, KE_drive = ½ Σ m (A·2πf·Ly/2)², allowed twice.  A blow-up exceeds this by orders
#: of magnitude within a few steps (the coarse-dt guard test below reaches > 10³·E_ref).
KE_FRACTION = 0.1


class ContactMonitor:
    """Per-step recorder of finiteness, pair penetration, normal flips and peculiar kinetic energy.

    Installed as ``ens.stability_guard``; reads ``ens._g`` (pair indices ``ai, aj``, distance
    ``d``, contact distance ``d0 = r_i + r_j``, unit normal ``nx, ny``, ``trans`` mask) and the
    state arrays; never writes.  ``skip_first`` excludes the given initial configuration
    (e.g. coincident centres) from the penetration minimum.
    """

    def __init__(self, skip_first=False):
        self.skip_first = skip_first
        self.steps = 0
        self.finite = True
        self.min_ratio = math.inf
        self.flips = 0
        self.max_ke = 0.0
        self.ke = []
        self.ratios = []
        self._prev = None

    def check(self, ens, step=None, phase=None, dt=None):
        a = ens.sphere_arrays
        st = np.concatenate([a["x"], a["y"], a["xspeed"], a["yspeed"], a["omega"]])
        self.finite &= bool(np.isfinite(st).all())
        rate = ens.shear_rate or 0.0
        u = a["xspeed"] - rate * (a["y"] - ens.size_y / 2)
        ke = 0.5 * float(a["m"] @ (u * u + a["yspeed"] ** 2) + a["inertia"] @ (a["omega"] ** 2))
        self.ke.append(ke)
        self.max_ke = max(self.max_ke, ke)
        g = ens._g
        cur = None
        if g is not None and g.P:
            r = g.d / g.d0
            tr = np.ones(g.P, bool) if g.trans is None else g.trans
            if tr.any() and not (self.skip_first and self.steps == 0):
                self.min_ratio = min(self.min_ratio, float(r[tr].min()))
            self.ratios.append(float(r[tr].min()) if tr.any() else math.inf)
            touch = g.d < g.d0
            key = g.ai[touch].astype(np.int64) * 1_000_003 + g.aj[touch]
            cur = (key, g.nx[touch].copy(), g.ny[touch].copy())
            if self._prev is not None and len(key):
                pk, pnx, pny = self._prev
                _, i0, i1 = np.intersect1d(pk, key, assume_unique=True, return_indices=True)
                dot = pnx[i0] * cur[1][i1] + pny[i0] * cur[2][i1]
                self.flips += int((dot < 0).sum())
        self._prev = cur
        self.steps += 1


def reference_energy(ens):
    """E_ref = Σ ½ k r_i² (mg·µm²·s⁻² per m): compressing every sphere by its radius (linear law)."""
    return 0.5 * float(ens.k) * float((ens.sphere_arrays["r"] ** 2).sum())


def pair_energy(d, d0, k, c=1.0):
    """Elastic energy stored by the default law (docs/engine.md, cap included) at distance d: ∫_d^d0 −F(s) ds."""
    cap = d0 / 1000
    lin = 0.5 * k * (1 - c) * (d0 - d) ** 2
    e = max(d, cap)
    nl = k * c * d0 * (d0 * math.log(d0 / e) - (d0 - e)) + (k * c * 999 * d0 * (cap - d) if d < cap else 0.0)
    return lin + nl


def build(N=30, seed=1, links=True, cut_lines=3, packing_fraction=1.5, E=8000.0, mu=0.01, c=1.0, rv=0.1,
          rf=0.25, A=0.2, avoid=True, integrator="euler"):
    """Builder ensemble + experiment (no guard: the monitor and the test assertions decide).

    ``rf`` (relative frequency) 0.25 puts the strain peak 1/4 period ≈ 56 steps into the protocol.
    """
    sim = Simulation_interlocking_rheology(
        "", do_permanent_links=links, cut_lines=cut_lines, N=N, packing_fraction=packing_fraction,
        bimodal_factor=1.4, amplitude=A, Young_modulus_spheres=E, density=50, mu=mu, relative_viscosity=rv,
        relative_y_scale_force=1e8, relative_frequency=rf, relative_transversal_link_strength=1,
        avoid_horizontal_angle_degree=15, avoid_height_spanning_particles=avoid, interface_reenforcement_central=1,
        interface_reenforcement_tangential=1, central_repulsion_coefficient=c,
        keep_viscosity_coefficients_constant=False, cut_top_bottom=False, doCutByTriangulation=True,
        remove_link_fraction=0, edge_fuzziness=0, doDrawing=False, saveData=False)
    sim.baseline_pre_periods = 0
    sim.baseline_post_periods = 0
    sim.rng = seed
    sim.stability_guard = False
    sim.integrator = integrator
    sim.initEnsemble(do_debug=True)
    exp = sim.createExperiment(False, periods=1, plotStress=False)
    return sim, exp, sim.theEnsemble


def shear(exp, n_steps, pre=True, monitor=None):
    """Pre-equilibrate (fixed plates, docs/engine.md) and run ``n_steps`` protocol steps with every tensor kept."""
    ens = exp.theEnsemble
    mon = monitor or ContactMonitor()
    ens.stability_guard = mon
    f_step = 0.5 ** (exp.f * exp.dt)      # cool_factor 0.5 per period, as doParticleShearSimulation
    if pre:
        classes_pre_equilibrate(exp, N=25, cool_factor=f_step)
    ens.t = 0
    ens.applyingShear = True
    exp.keep_tensor_history = True
    exp.prepare_recording()
    classes_run_protocol(exp, f_step, n_steps)
    return mon


def quarter_period_steps(exp, extra=8, cap=400):
    """Steps to the strain peak (¼ period) plus a few, capped (µs-scale cases stay fast)."""
    return min(cap, int(1 / (4 * exp.f * exp.dt)) + extra)


class StabilityAssertions:
    def assert_physical(self, exp, mon, ke_fraction=KE_FRACTION, label=""):
        ens = exp.theEnsemble
        self.assertGreater(mon.steps, 0, label)
        self.assertTrue(mon.finite, f"{label}: non-finite state")
        a = ens.sphere_arrays
        for name in ("x", "y", "xspeed", "yspeed", "omega"):
            self.assertTrue(np.isfinite(a[name]).all(), f"{label}: {name} not finite")
        # positions wrapped into the cell (docs/engine.md)
        self.assertTrue(((a["x"] >= 0) & (a["x"] < ens.size_x)).all(), f"{label}: x outside [0, Lx)")
        self.assertTrue(((a["y"] >= 0) & (a["y"] < ens.size_y)).all(), f"{label}: y outside [0, Ly)")
        E_ref = reference_energy(ens)
        KE_drive = 0.5 * float(a["m"].sum()) * (exp.amplitude * 2 * math.pi * exp.f * ens.size_y / 2) ** 2
        bound = ke_fraction * E_ref + 2 * KE_drive
        if os.environ.get("STAB_DEBUG"):
            print(f"\n{label}: KE/E_ref={mon.max_ke / E_ref:.3g} KE/bound={mon.max_ke / bound:.3g} "
                  f"min_ratio={mon.min_ratio:.3g} steps={mon.steps}")
        self.assertLess(mon.max_ke, bound, f"{label}: peculiar KE {mon.max_ke:.3g} vs bound {bound:.3g}")
        self.assertGreater(mon.min_ratio, 0.0, f"{label}: a transient pair reached d = 0")
        self.assertEqual(mon.flips, 0, f"{label}: a contact normal flipped (pair passed through)")
        T = exp.plotter.tensor_history
        self.assertIsNotNone(T)
        self.assertEqual(len(T), exp.N_steps)
        self.assertTrue(np.isfinite(T).all(), f"{label}: non-finite stress")
        al = T[:, 8]
        num = np.abs(al[:, 0, 1] - al[:, 1, 0])
        den = np.abs(al[:, 0, 0]) + np.abs(al[:, 1, 1])
        self.assertTrue((num[den == 0] == 0).all(), f"{label}: asymmetric stress without normal stress")
        asym = num[den > 0] / den[den > 0]
        self.assertLess(float(asym.max(initial=0.0)), SYM_TOL, f"{label}: overall stress tensor asymmetric")


class TestStabilityMatrix(StabilityAssertions, unittest.TestCase):
    """One axis of the parameter space at a time, everything else at the defaults of the paper runs."""

    def run_case(self, label, n_steps=None, ke_fraction=KE_FRACTION, **kw):
        sim, exp, ens = build(**kw)
        mon = shear(exp, n_steps or quarter_period_steps(exp))
        self.assert_physical(exp, mon, ke_fraction, label)
        return exp, mon

    def test_young_modulus(self):
        for E in (1e2, 1e4, 1e7):
            with self.subTest(E=E):
                self.run_case(f"E={E}", E=E)

    def test_strain_amplitude(self):
        for A in (0.001, 0.2, 2.0):
            with self.subTest(A=A):
                exp, mon = self.run_case(f"A={A}", A=A, N=20)
                # the protocol did reach (almost) the peak strain: the run tested what it claims
                self.assertGreater(exp.theEnsemble.shear, 0.9 * A)

    def test_packing_fraction(self):
        for phi in (0.9, 2.5):
            with self.subTest(phi=phi):
                self.run_case(f"phi={phi}", packing_fraction=phi)

    def test_friction_coefficient(self):
        for mu in (0.0, 1.0):
            with self.subTest(mu=mu):
                self.run_case(f"mu={mu}", mu=mu, links=False, cut_lines=0)

    def test_repulsion_coefficient(self):
        for c in (0.0, 1.0):
            with self.subTest(c=c):
                self.run_case(f"c={c}", c=c, links=False, cut_lines=0, packing_fraction=2.0)

    def test_relative_viscosity(self):
        for rv in (0.01, 1.0):
            with self.subTest(rv=rv):
                self.run_case(f"rv={rv}", rv=rv)

    def test_relative_frequency(self):
        for rf in (0.001, 0.25):
            with self.subTest(rf=rf):
                self.run_case(f"rf={rf}", rf=rf, n_steps=80)

    def test_plateau_law(self):
        old = CircleBasicElasticity.call_back_elastic_force_law
        CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
        try:
            for phi in (1.5, 2.5):
                with self.subTest(phi=phi):
                    self.run_case(f"plateau phi={phi}", packing_fraction=phi, N=20)
        finally:
            CircleBasicElasticity.call_back_elastic_force_law = old

    def test_verlet_integrator(self):
        self.run_case("verlet", integrator="verlet", A=2.0, N=20)

    def test_sphere_count(self):
        for N in (2, 500):
            with self.subTest(N=N):
                self.run_case(f"N={N}", N=N, links=N > 2, cut_lines=3 if N > 2 else 0, avoid=N > 2,
                              n_steps=60 if N > 2 else None)

    def test_five_thousand_spheres_few_steps(self):
        sim, exp, ens = build(N=5000, links=False, cut_lines=0)
        mon = ContactMonitor()
        shear(exp, 5, pre=False, monitor=mon)
        self.assert_physical(exp, mon, label="N=5000")


class TestExtremeGeometry(StabilityAssertions, unittest.TestCase):
    """Two spheres placed by hand in a dilute builder ensemble (radii ≈ 40–50 µm in the 500 µm cell)."""

    def pair(self, xy0, xy1, applying_shear=False):
        sim, exp, ens = build(N=2, links=False, cut_lines=0, packing_fraction=0.05, avoid=False)
        s0, s1 = ens.sphereList[0], ens.sphereList[1]
        for s, (x, y) in ((s0, xy0), (s1, xy1)):
            s.x, s.y = x, y
            s.xspeed = s.yspeed = s.omega = 0.0
        ens.applyingShear = applying_shear
        ens.setShearRate(0)
        return sim, exp, ens

    def until_apart(self, exp, mon, n_max=100):
        """Undamped steps without shear (reference order) until the pair has separated; steps taken."""
        ens = exp.theEnsemble
        ens.stability_guard = mon
        for n in range(1, n_max + 1):
            ens.mechanical_simulation_step(1.0, exp.dt)
            if len(ens.contact_pairs()[0]) == 0:
                return n
        self.fail(f"pair still in contact after {n_max} steps")

    def overlap_run(self, ratio):
        sim, exp, ens = self.pair((250.0, 250.0), (250.0, 250.0))
        d0 = float(ens.sphere_arrays["r"].sum())
        ens.sphereList[1].x = 250.0 + ratio * d0
        mon = ContactMonitor()
        self.until_apart(exp, mon)
        return exp, ens, mon, pair_energy(ratio * d0, d0, float(ens.k))

    def test_near_total_overlap(self):
        """Start at d = 0.05·(r_i+r_j): the pair is pushed apart without passing through and, being a
        passive pair (elastic + viscous, no damping), leaves with at most its stored elastic energy U0."""
        exp, ens, mon, U0 = self.overlap_run(0.05)
        self.assertTrue(mon.finite)
        self.assertEqual(mon.flips, 0)
        self.assertGreaterEqual(mon.min_ratio, 0.05 * (1 - 1e-12))        # repulsion only opens the gap
        ke = np.array(mon.ke)
        self.assertLessEqual(ke.max(), U0)                                 # no energy created
        self.assertGreater(ke[-1], 0.5 * U0)                               # viscous loss is moderate (rv 0.1)
        ens.mechanical_simulation_step(1.0, exp.dt)                        # apart: no force, KE constant
        a = ens.sphere_arrays
        ke_next = 0.5 * float(a["m"] @ (a["xspeed"] ** 2 + a["yspeed"] ** 2) + a["inertia"] @ a["omega"] ** 2)
        self.assertAlmostEqual(ke_next, ke[-1], delta=1e-12 * ke[-1])

    @unittest.expectedFailure
    def test_deeper_overlap_creates_energy_at_default_dt(self):
        """Known limit (see docs/accuracy.md): from d = 0.01·(r_i+r_j) the divergent law (local stiffness
        k·(d0/d)² = 10⁴ k) is not resolved by the default dt and the explicit step creates energy
        (measured KE ≈ 1.4·U0; ≈ 57·U0 from 0.001; ≈ 44·U0 from coincident centres).  Physically KE ≤ U0."""
        exp, ens, mon, U0 = self.overlap_run(0.01)
        self.assertEqual(mon.flips, 0)
        self.assertLessEqual(max(mon.ke), U0)

    def test_coincident_centres(self):
        """d = 0: a random normal (docs/engine.md) and the capped force 999·k·c·d0 (eq. S1-6) separate the pair."""
        sim, exp, ens = self.pair((250.0, 250.0), (250.0, 250.0))
        d0 = float(ens.sphere_arrays["r"].sum())
        mon = ContactMonitor(skip_first=True)
        self.until_apart(exp, mon)
        self.assertTrue(mon.finite)
        self.assertEqual(mon.flips, 0)
        # after the first kick the centres are apart and the gap only opens
        self.assertGreater(mon.ratios[1], 0.0)
        self.assertTrue(all(b >= a * (1 - 1e-12) for a, b in zip(mon.ratios[1:], mon.ratios[2:])))
        a = ens.sphere_arrays
        # momentum conserved by the equal and opposite pair force: Σ m v = 0 (up to round-off)
        p = ens.total_momentum()
        scale = float(a["m"] @ np.hypot(a["xspeed"], a["yspeed"]))
        self.assertLess(float(np.hypot(*p)), 1e-12 * scale)
        # the first kick is the capped force acting for one dt: |Δp| = 999·k·d0·dt per sphere (5 %:
        # the following steps add the far smaller forces of the opening gap)
        self.assertLess(abs(float(a["m"][0] * math.hypot(a["xspeed"][0], a["yspeed"][0]))
                            - 999 * float(ens.k) * d0 * exp.dt) / (999 * float(ens.k) * d0 * exp.dt), 0.05)

    def test_sphere_on_periodic_boundary(self):
        Lx, Ly = 500.0, 500.0
        tiny = 1e-9
        cases = {
            "x=0": ((0.0, 250.0), (None, 250.0), False),
            "x=Lx-tiny": ((Lx - tiny, 250.0), (None, 250.0), False),
            "y=0 (plates)": ((250.0, 0.0), (250.0, None), True),
            "y=Ly-tiny": ((250.0, Ly - tiny), (250.0, None), False),
        }
        for label, (p0, p1, plates) in cases.items():
            with self.subTest(label):
                sim, exp, ens = self.pair((100.0, 100.0), (300.0, 300.0))
                d0 = float(ens.sphere_arrays["r"].sum())
                s0, s1 = ens.sphereList
                s0.x, s0.y = p0
                # partner overlaps by 20 % across the boundary
                if p1[0] is None:
                    s1.x, s1.y = (p0[0] + 0.8 * d0) % Lx if p0[0] else Lx - 0.8 * d0, p1[1]
                else:
                    s1.x, s1.y = p1[0], (p0[1] + 0.8 * d0) % Ly if p0[1] else Ly - 0.8 * d0
                ens.applyingShear = plates
                mon = ContactMonitor()
                shear(exp, 60, pre=False, monitor=mon)
                self.assert_physical(exp, mon, label=label)
                # the pair did interact through the boundary and was pushed apart
                self.assertGreater(mon.ratios[-1] if math.isfinite(mon.ratios[-1]) else 1.0, 0.8)


class TestStabilityGuard(unittest.TestCase):
    """A blow-up must stop with a clear, actionable error and never leak NaN into results or files."""

    def test_two_sphere_blow_up(self):
        sim, exp, ens = build(N=2, links=False, cut_lines=0, packing_fraction=0.05, avoid=False)
        s0, s1 = ens.sphereList
        s0.x, s0.y, s1.x, s1.y = 250.0, 250.0, 250.0 + 0.9 * float(ens.sphere_arrays["r"].sum()), 250.0
        s1.xspeed = -1e3 * float(ens.sphere_arrays["r"].sum()) / exp.dt     # head-on at 1000 d0 per step
        ens.applyingShear = False
        ens.stability_guard = StabilityGuard()
        ens.phase = "test"
        dt = 40 * exp.dt
        first = ens.step_count
        with self.assertRaises(SimulationInstabilityError) as cm:
            for _ in range(5):
                ens.mechanical_simulation_step(1.0, dt)
        e = cm.exception
        self.assertLess(e.step - first, 5)
        self.assertEqual(e.phase, "test")
        self.assertIsNotNone(e.pair)
        self.assertLess(e.suggested_dt, dt)
        for word in ("step", "test", "dt"):
            self.assertIn(word, str(e))

    def test_full_run_coarse_time_step(self):
        with tempfile.TemporaryDirectory() as tmp:
            doParticleShearSimulation.last_result = None
            with self.assertRaises(SimulationInstabilityError) as cm:
                doParticleShearSimulation(tmp, N=20, do_permanent_links=False, cut_lines=0, seed=1,
                                          time_step_factor=40, doDrawing=False, plotStress=False, verbose=False,
                                          saveData=True, return_result=True)
            e = cm.exception
            self.assertIsInstance(e.step, int)
            self.assertIn(e.phase, ("pre-equilibration", "protocol"))
            self.assertIsNotNone(e.pair)
            self.assertIn(f"step {e.step}", str(e))
            self.assertIn(repr(e.phase), str(e))
            m = re.search(r"time step ([0-9.eE+-]+) s, try dt <= ([0-9.eE+-]+) s", str(e))
            self.assertIsNotNone(m, str(e))
            sim_dt, sug = float(m.group(1)), float(m.group(2))
            self.assertLess(e.suggested_dt, sim_dt)
            self.assertAlmostEqual(sug, e.suggested_dt, delta=1e-3 * e.suggested_dt)   # printed with 4 digits
            # no result was published and no (partial) output file is left
            self.assertIsNone(doParticleShearSimulation.last_result)
            self.assertEqual(os.listdir(tmp), [])


if __name__ == "__main__":
    unittest.main()
