"""Scripts written against particleShear 1.0.2 run unchanged.

* the six force-register lists hold the reference's entries, in its order and granularity
  (one entry per central elastic visit, one per central viscous visit, two per tangential visit),
  checked against an independent sphere-by-sphere evaluation of the interaction laws
  (docs/engine.md; manual eqs. S1-3, S1-5) written here from the model's equations;
* the evaluation handler's momenta are plain Python values summed sphere by sphere (int masses
  give an int total mass, as the reference computes them);
* ``False`` (and None) mean "no file" wherever the reference accepts it;
* the documented step loop (``evaluate_stress_tensors`` with ``movableSphereList()``, ``sphereList``
  or any list/tuple of the ensemble's spheres) gives the tensors of the internal path bit for bit.
"""
import io
import math
import os
import tempfile
import unittest

import numpy as np

from particleShear import (EnsembleLinkable, EvaluationHandler, OscillatoryShearExperiment, OscillatorySimulation,
                           OscillatorySimulationFragmentation, SphereLinkable, StressTensorEvaluation)

L = 500.0


# -- an independent, sphere-by-sphere evaluation of one force phase ------------------------------------
def _min_image(dx, dy, shift):
    """Lees-Edwards minimum image of a separation, one period at a time (half-open convention), and the
    number of periods taken off in y (the image's velocity differs by −that·Ly·γ̇)."""
    ky = 0
    while dy >= L / 2:
        dy -= L
        dx -= shift
        ky += 1
    while dy < -L / 2:
        dy += L
        dx += shift
        ky -= 1
    while dx >= L / 2:
        dx -= L
    while dx < -L / 2:
        dx += L
    return dx, dy, ky


def _law(d, d0, k, c):
    """Compressive central law (S1-5a blended with S1-5b, capped at d0/1000); 0 beyond d0."""
    if d > d0:
        return 0.0
    return -k * (1 - c) * (d0 - d) - k * c * d0 * (d0 / max(d, d0 / 1000) - 1)


def reference_force_phase(ens):
    """The six register lists, the totals and the final relation states of one force phase, evaluated
    visit by visit as the reference does, from the ensemble's state and relations read through the API.

    Order: every central elastic visit, then every central viscous visit, then every tangential visit;
    visits by sphere in list order, each over its relations in ``neighbors`` order.  A tangential
    visit applies half its (Coulomb-limited) force as a couple, ``+f·t`` on the visitor and ``−f·t`` on
    its neighbour, with torques ``d·f·r/(r_a + r_b)`` on both (S1-3).  Registration: target immobile →
    dropped; source immobile or the pair acting through the periodic boundary → external.
    """
    spheres = list(ens.sphereList)
    idx = {id(s): q for q, s in enumerate(spheres)}
    S = [dict(x=s.x, y=s.y, vx=s.xspeed, vy=s.yspeed, w=s.omega, r=s.r) for s in spheres]
    if ens.applyingShear:
        mobile = [p["r"] < p["y"] < L - p["r"] for p in S]
    else:
        mobile = [True] * len(S)
    rel = {}
    order = []
    for a, s in enumerate(spheres):
        partners = []
        for relation in s.neighbors:
            b = idx[id(relation.theSphere)]
            partners.append(b)
            rel[a, b] = {"state": relation.interface_type, "xi": relation.friction_position,
                         "deq": getattr(relation, "equilibrium_distance", 0)}
        order.append(partners)
    k, nu, kt, nut, mu, c = ens.k, ens.nu, ens.k_t, ens.nu_t, ens.mu, ens.central_repulsion_coefficient
    shift = L * ens.shear
    rate = ens.shear_rate

    def geometry(a, b):
        pa, pb = S[a], S[b]
        rx, ry = pb["x"] - pa["x"], pb["y"] - pa["y"]
        dx, dy, ky = _min_image(rx, ry, shift)
        d = math.sqrt(dx * dx + dy * dy)
        n = (dx / d, dy / d)
        t = (-n[1], n[0])
        crossing = math.sqrt(rx * rx + ry * ry) != d
        vrx = pb["vx"] - pa["vx"] - ky * L * rate   # across the y boundary the image moves with ±Ly·γ̇
        vry = pb["vy"] - pa["vy"]
        vn = vrx * n[0] + vry * n[1]
        vt = vrx * t[0] + vry * t[1] - (pa["r"] * pa["w"] + pb["r"] * pb["w"])
        return d, n, t, crossing, vn, vt, pa["r"] + pb["r"]

    out = {"pair": [], "ext": [], "imom": [], "emom": []}
    F = [[0.0, 0.0] for _ in S]
    T = [0.0 for _ in S]

    def force(target, source, f, crossing):
        F[target][0] += f[0]
        F[target][1] += f[1]
        if not mobile[target]:
            return
        if not mobile[source] or crossing:
            out["ext"].append((target, f))
        else:
            out["pair"].append((target, source, f))

    def torque(target, source, m, crossing):
        T[target] += m
        if not mobile[target]:
            return
        if not mobile[source] or crossing:
            out["emom"].append((target, m))
        else:
            out["imom"].append((target, source, m))

    visits = [(a, b) for a in range(len(S)) for b in order[a]]
    for a, b in visits:   # central elastic
        d, n, t, crossing, vn, vt, d0 = geometry(a, b)
        if rel[a, b]["state"] == "permanent":
            deq = rel[a, b]["deq"]
            fe = -k * (deq - d) if d >= deq else _law(d, deq, k, c)
        elif d < d0:
            fe = _law(d, d0, k, c)
        else:
            continue
        force(a, b, (fe * n[0], fe * n[1]), crossing)
    for a, b in visits:   # central viscous, every relation
        d, n, t, crossing, vn, vt, d0 = geometry(a, b)
        fv = nu * vn
        force(a, b, (fv * n[0], fv * n[1]), crossing)
    for a, b in visits:   # tangential, two visits per pair in this order
        d, n, t, crossing, vn, vt, d0 = geometry(a, b)
        r_ab = rel[a, b]
        permanent = r_ab["state"] == "permanent"
        if not permanent and d >= d0:
            continue
        ft = (nut * vt if d < d0 else 0.0) + kt * r_ab["xi"]
        if permanent:
            fa = ft
        else:
            fc = abs(mu * _law(d, d0, k, c))
            if abs(ft) <= fc:
                r_ab["state"] = rel[b, a]["state"] = "stick"
            else:
                r_ab["state"] = rel[b, a]["state"] = "slip"
                r_ab["xi"] = rel[b, a]["xi"] = 0.0
            fa = math.copysign(min(abs(ft), fc), ft)
        f = fa / 2
        ra, rb = S[a]["r"], S[b]["r"]
        force(a, b, (f * t[0], f * t[1]), crossing)
        force(b, a, (-f * t[0], -f * t[1]), crossing)
        torque(a, b, d * f * ra / (ra + rb), crossing)
        torque(b, a, d * f * rb / (ra + rb), crossing)
    out["total"] = [(q, F[q]) for q in range(len(S)) if mobile[q]]
    out["moment"] = [(q, T[q]) for q in range(len(S))]
    out["states"] = {key: v["state"] for key, v in rel.items()}
    return out


# -- scenes -------------------------------------------------------------------------------------------
def two_sphere_scene(positions, velocities, xi=None, link=False, shear_plates=False, c=0.0, extra=(), nu=0.01,
                     mu=0.1, shear=None):
    """Linkable spheres of diameter 120 µm in a 500 µm cell (frictional unless ``mu=0``); ``xi`` sets ξ."""
    ens = EnsembleLinkable(L, L, 0, k=1, nu=nu, k_t=1, nu_t=0.01, mu=mu)
    for q, ((x, y), (vx, vy, w)) in enumerate(zip(list(positions) + [e[0] for e in extra],
                                                  list(velocities) + [e[1] for e in extra])):
        s = SphereLinkable("grey", x, y, 120, 1, q, force_register=ens, size_x=L, size_y=L)
        ens.sphereList.append(s)
        s.xspeed, s.yspeed, s.omega = vx, vy, w
    ens.set_central_repulsion_coefficient(c)
    if shear is not None:   # (γ, γ̇): Lees-Edwards offset and rate before the relations are made
        ens.setShear(shear[0])
        ens.setShearRate(shear[1])
    a, b = ens.sphereList[0], ens.sphereList[1]
    if link:
        a.establish_permanent_link(b)
    ens.test_neighbor_relation()
    if xi is not None:
        a.neighbors[0].friction_position = xi[0]
        b.neighbors[0].friction_position = xi[1]
    ens.applyingShear = shear_plates
    return ens


SCENES = {
    # ξ_ab large: visit 1 slips (ξ reset), visit 2 sticks on the viscous part alone (the reference quirk)
    "slip_then_stick": dict(positions=[(200.0, 250.0), (300.0, 262.0)],
                            velocities=[(3.0, -1.0, 0.2), (-2.0, 0.5, -0.1)], xi=(5.0, -0.3)),
    "sticking_divergent_law": dict(positions=[(200.0, 250.0), (310.0, 245.0)],
                                   velocities=[(1.0, 0.4, -0.05), (-0.5, 0.2, 0.3)], xi=(0.3, 0.2), c=1.0),
    "through_the_boundary": dict(positions=[(30.0, 250.0), (480.0, 262.0)],
                                 velocities=[(-1.0, 2.0, 0.1), (1.5, -0.5, 0.0)], xi=(0.5, -0.4)),
    "through_the_sheared_boundary": dict(positions=[(250.0, 20.0), (300.0, 470.0)],
                                         velocities=[(1.0, 0.5, 0.1), (-0.5, -1.0, 0.2)], xi=(0.1, -0.2),
                                         shear=(0.1, 40.0)),
    "against_a_plate": dict(positions=[(250.0, 50.0), (260.0, 150.0)],
                            velocities=[(0.5, 0.0, 0.3), (-1.0, -2.0, 0.1)], xi=(0.2, 0.1), shear_plates=True),
    "stretched_link": dict(positions=[(200.0, 250.0), (300.0, 250.0)],
                           velocities=[(-1.0, 0.3, 0.2), (1.0, -0.2, 0.1)], xi=(0.7, 0.4), link=True),
    # ν = 0 and μ = 0: the viscous and tangential visits still register their zero forces
    "inviscid_frictionless": dict(positions=[(200.0, 250.0), (300.0, 262.0)],
                                  velocities=[(3.0, -1.0, 0.2), (-2.0, 0.5, -0.1)], nu=0.0, mu=0.0),
    "three_spheres": dict(positions=[(200.0, 250.0), (300.0, 262.0)],
                          velocities=[(3.0, -1.0, 0.2), (-2.0, 0.5, -0.1)], xi=(0.05, -0.02),
                          extra=[((210.0, 355.0), (0.2, -1.5, 0.4))]),
}


class ForceRegisterOrderTest(unittest.TestCase):
    """Each register list after a step equals, entry by entry, the sphere-by-sphere evaluation above.

    Tolerance: both sides evaluate the same expressions in possibly different association (e.g. the torque
    ``d·f·r/(r_a + r_b)``), so values agree to a few ulp; 1e-12 of the list's largest entry is far below
    any physical difference (a wrong term, sign, visit or filter changes an entry by O(1) of its size).
    """

    def _close(self, got, want, scale, msg):
        got = np.atleast_1d(np.asarray(got, dtype=float))
        want = np.atleast_1d(np.asarray(want, dtype=float))
        self.assertEqual(got.shape, want.shape, msg)
        self.assertTrue(np.all(np.abs(got - want) <= 1e-12 * scale), f"{msg}: {got.tolist()} != {want.tolist()}")

    def _check(self, name, spec):
        ens = two_sphere_scene(**spec)
        # the first step: the relations were made (and ξ set) through the API before it
        want = reference_force_phase(ens)
        ens.mechanical_simulation_step(cool_factor=1, dt=1e-3)   # the register is read after the step
        return self._compare(name, ens, want)

    def _compare(self, name, ens, want):
        reg = ens.force_register
        sl = ens.sphereList
        for key, attr, has_source in (("pair", "pair_register", True), ("ext", "external_force_register", False),
                                      ("imom", "internal_moment_register", True),
                                      ("emom", "external_moment_register", False),
                                      ("total", "total_particle_force_register", False),
                                      ("moment", "unbalanced_moment_register", False)):
            got = getattr(reg, attr)
            exp = want[key]
            self.assertEqual(len(got), len(exp), f"{name}: {attr} has {len(got)} entries, expected {len(exp)}")
            values = [e[-1] for e in exp]
            scale = max([float(np.max(np.abs(v))) for v in values] + [1e-300])
            for q, (g, e) in enumerate(zip(got, exp)):
                msg = f"{name}: {attr}[{q}]"
                self.assertIs(g[0], sl[e[0]], msg + " target")
                if has_source:
                    self.assertIs(g[1], sl[e[1]], msg + " source")
                self._close(g[-1], e[-1], scale, msg)
        for (a, b), state in want["states"].items():
            rel = [r for r in sl[a].neighbors if r.theSphere is sl[b]][0]
            self.assertEqual(rel.interface_type, state, f"{name}: state of {a}->{b}")
        return want

    def test_scenes(self):
        for name, spec in SCENES.items():
            with self.subTest(scene=name):
                self._check(name, spec)

    def test_scenes_through_the_engine(self):
        # the engine's force phase on the ensemble's own state, its terms given to the register
        # (Force_register.set_from_engine): the same entries, in the same order
        from particleShear.base.engine_adapter import state_of_ensemble
        from particleShear.base.register import KeptTerms
        from particleShear.engine.step import BatchEngine
        for name, spec in SCENES.items():
            with self.subTest(scene=name):
                ens = two_sphere_scene(**spec)
                want = reference_force_phase(ens)
                kept = KeptTerms()
                eng = BatchEngine(state_of_ensemble(ens), guard=False, keep_terms=True, terms_to=kept,
                                  numbers_relations=True)
                eng.force_phase()
                eng.flush()                    # the states of the relations into the ensemble's table
                self.assertTrue(ens.force_register.set_from_engine(ens, eng, kept.last, current=True))
                self._compare(name, ens, want)

    def test_scenes_exercise_every_list(self):
        """The scenes above are not vacuous: each list is non-empty in some scene, and the slip quirk occurs."""
        seen = set()
        for spec in SCENES.values():
            want = reference_force_phase(two_sphere_scene(**spec))
            seen |= {k for k in ("pair", "ext", "imom", "emom") if want[k]}
        self.assertEqual(seen, {"pair", "ext", "imom", "emom"})
        want = reference_force_phase(two_sphere_scene(**SCENES["slip_then_stick"]))
        self.assertEqual(len(want["pair"]), 8)   # 2 elastic + 2 viscous + 2 × 2 tangential entries
        self.assertEqual(want["states"][0, 1], "stick")

    def test_register_reset_and_empty(self):
        """Lists are rebuilt per force phase; without contacts the pair lists are empty."""
        ens = two_sphere_scene([(100.0, 100.0), (300.0, 300.0)], [(0.0, 0.0, 0.0), (0.0, 0.0, 0.0)])
        ens.mechanical_simulation_step(cool_factor=1, dt=1e-3)
        reg = ens.force_register
        self.assertEqual(reg.pair_register, [])
        self.assertEqual(reg.internal_moment_register, [])
        self.assertEqual(len(reg.total_particle_force_register), 2)


class EvaluationHandlerValuesTest(unittest.TestCase):
    """Momenta of the handler are Python values summed over the spheres as given (the manual's API:
    ``total_mass = Σ m``, ``xg = Σ m x / Σ m``, ``v_mean = Σ m v / Σ m``, ``Σ (m x v_y − m y v_x + ω I)``)."""

    def _scene(self, masses):
        ens = EnsembleLinkable(L, L, 0, k=1, nu=0.01, k_t=1, nu_t=0.01, mu=0.1)
        pos = [(200.0, 250.0, 3.0, -1.0, 0.2), (300.0, 262.0, -2.0, 0.5, -0.1), (100.0, 400.0, 0.3, 0.7, 0.0)]
        for q, (m, (x, y, vx, vy, w)) in enumerate(zip(masses, pos)):
            s = SphereLinkable("grey", x, y, 120, m, q, force_register=ens, size_x=L, size_y=L)
            ens.sphereList.append(s)
            s.xspeed, s.yspeed, s.omega = vx, vy, w
        return ens

    def _record(self, ens, h, ev):
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        h.record(ens, ev)

    def test_int_masses(self):
        ens = self._scene([1, 2, 3])
        h = EvaluationHandler()
        ev = StressTensorEvaluation(L, L)
        self._record(ens, h, ev)
        self.assertIs(type(h.total_mass), int)
        self.assertEqual(h.total_mass, 6)
        self.assertIs(type(h.xg), list)
        self.assertIs(type(h.v_mean[0]), float)
        ms = [1, 2, 3]
        sl = ens.sphereList
        self.assertEqual(h.xg, [sum(m * s.x for m, s in zip(ms, sl)) / 6, sum(m * s.y for m, s in zip(ms, sl)) / 6])
        self.assertEqual(h.v_mean, [sum(m * s.xspeed for m, s in zip(ms, sl)) / 6,
                                    sum(m * s.yspeed for m, s in zip(ms, sl)) / 6])
        ang = sum(m * s.x * s.yspeed - m * s.y * s.xspeed + s.omega * s.inertia for m, s in zip(ms, sl))
        self.assertEqual(h.angular_momentum_around_origin, ang)
        # what 1.0.2 scripts compute: an int total mass times the mean-velocity list repeats the list
        before = h.total_mass * h.v_mean
        self.assertEqual(len(before), 12)
        for _ in range(20):
            ens.mechanical_simulation_step(cool_factor=1, dt=1e-3)
        self._record(ens, h, ev)
        after = h.total_mass * h.v_mean
        # Σ m v is conserved by the pair forces (Newton's third law): equal up to rounding
        np.testing.assert_allclose(after, before, rtol=0, atol=1e-12)

    def test_float_masses_and_assignment(self):
        ens = self._scene([1.0, 2.5, 3.0])
        h = EvaluationHandler()
        self._record(ens, h, StressTensorEvaluation(L, L))
        self.assertIs(type(h.total_mass), float)
        self.assertEqual(h.total_mass, 6.5)
        with self.assertRaises(TypeError):
            h.total_mass * h.v_mean
        h.total_mass = 7   # still assignable, as a plain attribute
        self.assertEqual(h.total_mass, 7)

    def test_changed_mass_is_not_taken_as_given(self):
        ens = self._scene([1, 2, 3])
        ens.sphereList[1].m = 2.5
        h = EvaluationHandler()
        self._record(ens, h, StressTensorEvaluation(L, L))
        self.assertEqual(h.total_mass, 6.5)


class FalseMeansNoFileTest(unittest.TestCase):
    """``False`` (and None) as a file or folder means "none", as in the reference."""

    def test_simulation_information(self):
        for sim in (OscillatorySimulation("", saveData=False), OscillatorySimulationFragmentation("", saveData=False)):
            with self.subTest(cls=type(sim).__name__):
                sim.function_call = "call"
                sim.write_information_on_simulation_to_file(False)
                sim.write_information_on_simulation_to_file(None)
                buf = io.StringIO()
                sim.write_information_on_simulation_to_file(buf)
                self.assertEqual(buf.getvalue(), "")   # saveData=False: nothing written (1.0.2)
                sim.saveData = True
                sim.write_information_on_simulation_to_file(False)
                sim.write_information_on_simulation_to_file(buf)
                self.assertIn("Function call : \ncall", buf.getvalue())
                # no folder named "False" or "None" (nor any other) appears where the script runs
                here = os.getcwd()
                with tempfile.TemporaryDirectory() as d:
                    os.chdir(d)
                    try:
                        sim.createFolder(False)
                        sim.createFolder(None)
                        self.assertEqual(os.listdir(d), [])
                    finally:
                        os.chdir(here)

    def test_experiment_without_file(self):
        ens = two_sphere_scene(**SCENES["slip_then_stick"])
        for no_file in (False, None):
            with self.subTest(output_file=no_file):
                exp = OscillatoryShearExperiment(ens, 1e-3, 1.0, 0.1, no_file, imageOutputFolder=False,
                                                 imageBaseFileName=False)
                exp.results = {}
                exp.write_experiment_description_information_to_file()
                exp.prepare_recording()
                exp.write_output_information_to_file()
                exp.save_canvas_image(0)
                self.assertEqual(exp.n_images_saved, 0)


def random_scene(seed, n=40):
    """A relaxed frictional scene of ``n`` bimodal spheres, crosslinked and cut, for the step-loop tests."""
    rng = np.random.default_rng(seed)
    side = math.sqrt(n * math.pi * 28.2 ** 2 / 1.5)
    k = 3.1e9
    ens = EnsembleLinkable(side, side, 0, k=k, nu=2e3, k_t=k, nu_t=2e3, mu=0.0)
    ens.set_random_generator(rng)
    xs, ys, big = rng.random(n) * side, rng.random(n) * side, rng.integers(0, 2, n)
    for q in range(n):
        r = 25.0 * (1.18 if big[q] else 0.85)
        ens.sphereList.append(SphereLinkable("grey", float(xs[q]), float(ys[q]), 2 * r, 0.125 * (r / 25) ** 2, q,
                                             force_register=ens, size_x=side, size_y=side))
    for _ in range(30):
        ens.mechanical_simulation_step(cool_factor=0.7, dt=4e-7)
    ens.set_central_repulsion_coefficient(1)
    ens.mu = 0.01
    ens.test_neighbor_relation()
    ens.makeAllLinksPermanent()
    ens.cutRandomLine()
    ens.applyingShear = True
    return ens


class MechanicalRelaxationTest(unittest.TestCase):
    """``mechanical_relaxation(N, cool_factor, dt, theTk, StressTensorEvaluator)`` is its definition
    (MODEL_SPEC, the class chain): N calls of ``mechanical_simulation_step(cool_factor, dt)``, each
    followed by the Tk update and the stress evaluation when given; so its states equal those N
    calls bit for bit, the window is updated N times and the evaluator holds the last step's tensors."""

    def test_its_definition(self):
        class Tk:
            updates = 0

            def update(self):
                Tk.updates += 1

        a, b = random_scene(5, n=24), random_scene(5, n=24)
        for ens in (a, b):
            ens.setShearRate(3.0)
        ev_a, ev_b = (StressTensorEvaluation(e.size_x, e.size_y) for e in (a, b))
        a.mechanical_relaxation(17, 0.98, 2e-7, theTk=Tk(), StressTensorEvaluator=ev_a)
        for _ in range(17):
            b.mechanical_simulation_step(0.98, 2e-7)
        b.evaluate_stress_tensors(ev_b)
        for name in ("x", "y", "phi", "xspeed", "yspeed", "omega"):
            self.assertEqual(a.sphere_arrays[name].tobytes(), b.sphere_arrays[name].tobytes(), name)
        self.assertEqual((a.t, a.shear, a.step_count), (b.t, b.shear, b.step_count))
        self.assertGreater(abs(a.shear), 0.0)
        self.assertEqual(Tk.updates, 17)
        self.assertEqual(ev_a.tensors.tobytes(), ev_b.tensors.tobytes())
        self.assertGreater(np.abs(ev_a.tensors).max(), 0.0)


class DocumentedStepLoopTest(unittest.TestCase):
    """The README's loop gives the internal path's tensors bit for bit (same array operations)."""

    DT = 1.1e-7

    def _step(self, ens, ev, rate, spheres=None):
        ens.setShearRate(rate)
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        if spheres is None:
            ens.evaluate_stress_tensors(ev)             # the package's own protocol
        else:
            ev.evaluate_stress_tensors(ens.force_register, spheres(ens), ens.shear_rate)
        ens.mechanical_simulation_step_calculate_acceleration(0.9997, self.DT)
        ens.mechanical_simulation_step_calculate_movement(self.DT)
        return ev.tensors.copy()

    def test_same_tensors_bit_for_bit(self):
        choices = {"movableSphereList()": lambda e: e.movableSphereList(),
                   "tuple": lambda e: tuple(e.movableSphereList()),
                   "plain list": lambda e: [s for s in e.sphereList if e.canMove(s)]}
        for label, spheres in choices.items():
            with self.subTest(spheres=label):
                a, b = random_scene(5), random_scene(5)
                self.assertLess(len(a.movableSphereList()), len(a.sphereList))   # plates present
                ev_a, ev_b = StressTensorEvaluation(a.size_x, a.size_y), StressTensorEvaluation(b.size_x, b.size_y)
                for step in range(25):
                    rate = 3e3 * math.cos(0.3 * step)
                    ta = self._step(a, ev_a, rate, spheres)
                    tb = self._step(b, ev_b, rate)
                    self.assertTrue(np.array_equal(ta, tb), f"step {step}: {ta - tb}")
                    self.assertTrue(np.any(ta != 0))

    def test_sphere_list_without_plates(self):
        a, b = random_scene(7), random_scene(7)
        a.applyingShear = b.applyingShear = False
        ev_a, ev_b = StressTensorEvaluation(a.size_x, a.size_y), StressTensorEvaluation(b.size_x, b.size_y)
        for step in range(10):
            ta = self._step(a, ev_a, 0.0, lambda e: e.sphereList)
            tb = self._step(b, ev_b, 0.0)
            self.assertTrue(np.array_equal(ta, tb), f"step {step}")

    def test_all_spheres_with_plates(self):
        """With plates, ``sphereList`` puts every sphere's spin into the centrifugal tensor while the
        unbalanced-force tensor stays a sum over the register's (mobile) totals (eqs. S1-17, S1-21)."""
        ens = random_scene(9)
        ev = StressTensorEvaluation(ens.size_x, ens.size_y)
        for step in range(3):
            self._step(ens, ev, 2e3, lambda e: e.sphereList)
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        ev.evaluate_stress_tensors(ens.force_register, ens.sphereList, ens.shear_rate)
        V = (ens.size_x * 1e-6) * (ens.size_y * 1e-6)
        K = sum(s.inertia * 1e-18 * s.omega ** 2 / 2 for s in ens.sphereList)
        self.assertAlmostEqual(ev.stress_tensor_spin_kinetic_energy[0][0], -K / V, delta=1e-12 * K / V)
        unb = np.zeros((2, 2))
        for s, f in ens.force_register.total_particle_force_register:
            unb += np.outer(np.array(f) * 1e-12, (np.array((s.x, s.y)) - (ens.size_x / 2, ens.size_y / 2)) * 1e-6)
        unb /= V
        np.testing.assert_allclose(ev.stress_tensor_unbalanced_forces, unb, rtol=0, atol=1e-12 * np.abs(unb).max())

    def test_selection_is_a_list(self):
        ens = random_scene(11, n=30)
        ev0 = StressTensorEvaluation(ens.size_x, ens.size_y)
        for _ in range(5):                    # sheared steps with friction: the spheres spin
            self._step(ens, ev0, 2e3)
        ens.mechanical_simulation_step_calculate_forces()
        sel = ens.movableSphereList()
        self.assertIsInstance(sel, list)
        self.assertEqual(sel, [s for s in ens.sphereList if ens.canMove(s)])
        self.assertIsNot(ens.movableSphereList(), sel)   # a new list on each call
        # the evaluation reads the list it is given, sphere by sphere: reversed, the same sums in another
        # order (rounding, 1e-12 of the largest entry); without one sphere, the spin tensor (eq. S1-21,
        # a sum over the listed spheres) loses exactly that sphere's −I ω²/2 / V
        ens.record_total_particle_forces()
        ev = StressTensorEvaluation(ens.size_x, ens.size_y)
        ev.evaluate_stress_tensors(ens.force_register, sel, ens.shear_rate)
        ref = ev.tensors.copy()
        spin = np.array(ev.stress_tensor_spin_kinetic_energy, dtype=float)
        ev.evaluate_stress_tensors(ens.force_register, sel[::-1], ens.shear_rate)
        np.testing.assert_allclose(ev.tensors, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
        spinning = max(sel, key=lambda s: abs(s.omega))
        self.assertNotEqual(spinning.omega, 0.0)
        sel.remove(spinning)
        ev.evaluate_stress_tensors(ens.force_register, sel, ens.shear_rate)
        V = (ens.size_x * 1e-6) * (ens.size_y * 1e-6)
        own = -spinning.inertia * 1e-18 * spinning.omega ** 2 / 2 / V
        np.testing.assert_allclose(np.array(ev.stress_tensor_spin_kinetic_energy, dtype=float), spin - own * np.eye(2),
                                   rtol=0, atol=1e-12 * np.abs(spin).max())
        self.assertGreater(abs(own), 1e-6 * np.abs(spin).max())   # the dropped sphere's share is visible


if __name__ == "__main__":
    unittest.main()
