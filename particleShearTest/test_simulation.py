"""Tests of layers 4 and 5: demodulation, recording, output file, seeds, validation, drawing, the manual's Part 4 scenarios 8–10 (frictional and crosslinked assemblies at rest and during shear).

Run with ``python -m pytest particleShearTest/test_simulation.py`` or ``python -m unittest``.
Short protocols (``relative_frequency`` raised, few spheres) keep the whole file fast.
"""
import concurrent.futures
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

from particleShear import (EnsembleLinkable, EvaluationHandler, OscillatoryShearExperiment,
                           Simulation_interlocking_rheology, StressTensorEvaluation, doParticleShearSimulation,
                           doParticleShearSimulationSeries)
from particleShear.run.cli import main as cli_main
from particleShear.simulation.evaluation import demodulation
from particleShear.simulation.output import TABLE_COLUMNS, experiment_description_text

#: a quick configuration: frictional spheres only, ~300 protocol steps
QUICK = dict(N=20, do_permanent_links=False, cut_lines=0, relative_frequency=0.2, pre_periods=0.5, periods=1,
             post_periods=0.5, doDrawing=False, plotStress=False, verbose=False)


def reference_demodulation(t, s, f, A, pre, P, post):
    """Direct transcription of the reference formula (docs/analysis.md, "The R evaluation"; drift-sign quirk included)."""
    t = list(t)
    s = list(s)
    e = 1 if P >= 2 else 0
    if pre > 0:
        sel = [k for k, ti in enumerate(t) if 2 * pre / (3 * f) <= ti < pre / f]
        S1 = sum(s[k] for k in sel) / len(sel)
        T1 = sum(t[k] for k in sel) / len(sel)
    else:
        S1, T1 = s[0], t[0]
    if post > 0:
        sel = [k for k, ti in enumerate(t) if (pre + P) / f < ti <= (pre + P + post / 3) / f]
        S2 = sum(s[k] for k in sel) / len(sel)
        T2 = sum(t[k] for k in sel) / len(sel)
    else:
        S2, T2 = s[-1], t[-1]
    D = (S2 - S1) / (T1 - T2)
    num_a = den_a = num_b = den_b = 0.0
    for ti, si in zip(t, s):
        if (pre + e) / f <= ti <= (pre + P) / f:
            a = math.sin(2 * math.pi * (f * ti - pre))
            b = math.cos(2 * math.pi * (f * ti - pre))
        else:
            a = b = 0.0
        sc = si - (ti - pre / f) * D
        num_a += sc * a
        den_a += a * a
        num_b += sc * b
        den_b += b * b
    SA, SB = num_a / den_a, num_b / den_b
    return [SA, SB, SA / A, SB / A]


class TestDemodulation(unittest.TestCase):
    f, A, pre, P, post = 1000.0, 0.2, 2, 3, 1
    Gp, Gpp = 383.7, 424.2

    def signal(self, drift=5.0e4, offset=1234.5, n_per_period=1000):
        dt = 1 / (self.f * n_per_period)
        n = int((self.pre + self.P + self.post) * n_per_period)
        t = (np.arange(n) + 0.5) * dt     # no sample on a window boundary: whole periods in the window
        phase = 2 * np.pi * (self.f * t - self.pre)
        exc = (t >= self.pre / self.f) & (t <= (self.pre + self.P) / self.f)
        osc = np.where(exc, self.A * (self.Gp * np.sin(phase) + self.Gpp * np.cos(phase)), 0.0)
        return t, offset + drift * t + osc

    def test_correct_sign_recovers_moduli(self):
        # 1000 samples per period, none on a window edge: the discrete projections on sin/cos are exact to
        # ~1e-9 for whole periods; the drift is removed up to its discretisation, ~1e-7 of G: 1e-6 bounds both
        t, s = self.signal()
        SA, SB, Gp, Gpp = demodulation(t, s, self.f, self.A, self.pre, self.P, self.post, correct_drift_sign=True)
        self.assertLess(abs(Gp - self.Gp) / self.Gp, 1e-6)
        self.assertLess(abs(Gpp - self.Gpp) / self.Gpp, 1e-6)
        self.assertAlmostEqual(SA, Gp * self.A, delta=1e-9 * abs(SA))

    def test_default_is_reference_rule(self):
        t, s = self.signal()
        s = s + 3.0 * np.sin(7.3 * t * self.f)  # something the projections do not remove exactly
        ours = demodulation(t, s, self.f, self.A, self.pre, self.P, self.post)
        ref = reference_demodulation(t, s, self.f, self.A, self.pre, self.P, self.post)
        # the same formula, sums of 6000 terms in another order (NumPy vs a Python loop), with the drift
        # term cancelling most of the signal: rounding ≲ 1e-12, so 1e-9 relative
        for a, b in zip(ours, ref):
            self.assertLess(abs(a - b), 1e-9 * abs(b))
        # the quirk doubles a linear drift instead of removing it: the default result differs
        correct = demodulation(t, s, self.f, self.A, self.pre, self.P, self.post, correct_drift_sign=True)
        self.assertGreater(abs(ours[2] - correct[2]), 1e-3)

    def test_no_drift_both_signs_agree(self):
        t, s = self.signal(drift=0.0)
        a = demodulation(t, s, self.f, self.A, self.pre, self.P, self.post)
        b = demodulation(t, s, self.f, self.A, self.pre, self.P, self.post, correct_drift_sign=True)
        self.assertLess(abs(a[2] - b[2]), 1e-9 * abs(b[2]))
        self.assertLess(abs(a[2] - self.Gp) / self.Gp, 1e-6)

    def test_without_baselines(self):
        t, s = self.signal(drift=0.0)
        keep = (t >= self.pre / self.f) & (t <= (self.pre + self.P) / self.f)
        t2 = t[keep] - self.pre / self.f
        r = demodulation(t2, s[keep], self.f, self.A, 0, self.P, 0)
        ref = reference_demodulation(t2, s[keep], self.f, self.A, 0, self.P, 0)
        for a, b in zip(r, ref):  # first and last samples serve as baselines
            self.assertLess(abs(a - b), 1e-9 * abs(b))


class TestEvaluationHandler(unittest.TestCase):
    def ensemble(self):
        ens = EnsembleLinkable(200, 200, 0, k=1, nu=0.5, m=1, k_t=1, nu_t=0.5, mu=0.3)
        from particleShear import SphereLinkable
        for p, (x, y, d) in enumerate(((100, 100, 60), (150, 110, 50), (100, 150, 50))):
            ens.sphereList.append(SphereLinkable("grey", x, y, d, 1.0, p + 1, False, False, ens, 200, 200))
        ens.sphereList[0].xspeed = 1.0
        return ens

    def test_record_without_evaluator(self):
        ens = self.ensemble()
        h = EvaluationHandler()
        L0 = None
        for _ in range(40):
            ens.mechanical_simulation_step_calculate_forces()
            ens.record_total_particle_forces()
            h.record(ens)                       # reference crashed here (the reference defects listed in docs/output.md #34)
            if L0 is None:
                L0 = h.angular_momentum_around_origin
            ens.mechanical_simulation_step_calculate_acceleration(1, 0.05)
            ens.mechanical_simulation_step_calculate_movement(0.05)
            ens.reset_force()
        self.assertIsInstance(h.theEvaluator, StressTensorEvaluation)
        self.assertEqual(len(h.t), 40)
        self.assertEqual(len(h.stress_tensor_LW), 40)
        self.assertEqual(h.t[1], 0.05)
        self.assertEqual(h.overall_stress_tensor2, [])
        # the recorded shear stresses are the xy entries of the recorded tensors (τ_internal = −σ_xy of
        # eq. S1-24, τ_surface = −σ_ext,xy of eq. S1-16; docs/output.md), at every step
        for n in (0, 20, 39):
            self.assertEqual(h.shear_stress[n], -h.overall_stress_tensor[n][0][1])
            self.assertEqual(h.force[n], -h.stress_tensor_with_external_forces[n][0][1])
        self.assertNotEqual(h.shear_stress[0], 0.0)            # the first steps have contacts
        self.assertAlmostEqual(h.total_mass, 3.0)
        # isolated, undamped, nothing crosses the boundary: Σ (m x v_y − m y v_x + I ω) is conserved from the
        # first recorded step to the last (symplectic Euler, pair forces central or couples); rounding only,
        # 1e-12 of the scale Σ m |x| |v| ≈ 100
        self.assertNotEqual(L0, 0.0)
        self.assertLess(abs(h.angular_momentum_around_origin - L0), 1e-12 * 100)
        self.assertEqual(h.Gprime, 0.0)  # no strain recorded
        h2 = EvaluationHandler()
        h2.allocate(5, keep_tensor_history=False)
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        h2.record(ens, StressTensorEvaluation(200, 200))
        self.assertEqual(h2.stress_tensor_LW, [])
        self.assertIsNotNone(h2.last_tensors)

    def test_running_estimates_on_demand(self):
        h = EvaluationHandler()
        g = np.linspace(-1, 1, 11)
        h._grow(11)
        h._scal[:11, 1] = g
        h._scal[:11, 2] = 2 * g
        h._scal[:11, 4] = -5 * g
        h._n = 11
        self.assertAlmostEqual(h.Gprime, 5.0)
        self.assertAlmostEqual(h.viscosity, 2.5)


def parse_header(text):
    """The downstream regular expressions (docs/output.md, "Downstream compatibility") on the first 100 lines (first match wins)."""
    head = "\n".join(text.split("\n")[:100])
    num = r"([0-9]*\.?[0-9]*)"
    gnum = r"(-?[0-9]*\.?[0-9]*)"
    patterns = {
        "N": r"N=([0-9]*) spheres", "packing": r"nominal packing density = " + num,
        "E": r"Young modulus of the individual spheres = " + num + " Pa", "mu": r"Friction coefficient = " + num,
        "links": r"do_permanent_links=([a-zA-Z]*),", "cut_lines": r"cut_lines=([0-9]*),",
        "amplitude": r"amplitude=" + num + ",", "pre": r"baseline_pre_periods = ([0-9]*)",
        "post": r"baseline_post_periods = ([0-9]*)", "periods": r"runSimulation\(periods=([0-9]*),",
        "rts": r"relative_transversal_link_strength=" + num + "[,)]", "rv": r"relative_viscosity=" + num,
        "damping": r"Damping factor = " + num, "Gp": r"G'=" + gnum, "Gpp": r"G''=" + gnum,
        "Gp_s": r"G'\(by surface force\)=" + gnum, "Gpp_s": r"G''\(by surface force\)=" + gnum,
        "rf": r"relative_frequency=" + num, "f": r"Frequency = " + num + "Hz",
        "angle": r"avoid_horizontal_angle_degree=" + num, "stress": r"Stress = ([0-9eE.+\-]*)Pa",
        "irc": r"interface_reenforcement_central=" + num, "irt": r"interface_reenforcement_tangential=" + num,
        "keep": r"keep_viscosity_coefficients_constant=([a-zA-Z]*)", "ctb": r"cut_top_bottom=([a-zA-Z]*)",
        "tri": r"doCutByTriangulation=([a-zA-Z]*)", "rlf": r"remove_link_fraction=" + num,
        "removed": r"Actual fraction of randomly removed non-essential permanent bonds = " + num,
    }
    out = {}
    for key, pat in patterns.items():
        m = re.search(pat, head)
        out[key] = m.group(1) if m else None
    return out


def read_table(text):
    lines = text.split("\n")
    start = next(k for k, line in enumerate(lines[:200]) if re.search(r"Detailed[a-zA-Z0-9\s].*data", line))
    header = lines[start + 1].split("\t")
    rows = [line.split("\t") for line in lines[start + 2:]]
    return header, rows


class TestOutputFile(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.res = doParticleShearSimulation(root_folder=cls.dir.name, N=30, cut_lines=3, relative_frequency=0.2,
                                            pre_periods=2, periods=3, post_periods=1, doDrawing=False,
                                            plotStress=False, saveData=True, seed=7, verbose=False,
                                            return_result=True)
        with open(cls.res.output_path, encoding="utf-8", newline="") as fh:
            cls.text = fh.read()

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def test_file_name_and_atomicity(self):
        name = os.path.basename(self.res.output_path)
        f = self.res.f
        expected = ("dermal_filler0.01_f_" + str(round(f * 10000) / 10000) + "_strain_0.2_nr_1.txt")
        self.assertEqual(name, expected)
        # the file and its JSON sidecar, no temporary file left
        self.assertEqual(sorted(os.listdir(self.dir.name)), [expected[: -len(".txt")] + ".json", expected])
        self.assertFalse(self.text.endswith("\n"))

    def test_header_regexes(self):
        h = parse_header(self.text)
        self.assertEqual(h["N"], "30")
        self.assertEqual(h["packing"], "1.5")
        self.assertEqual(h["E"], "8000")
        self.assertEqual(h["mu"], "0.01")
        self.assertEqual(h["links"], "True")
        self.assertEqual(h["cut_lines"], "3")
        self.assertEqual(h["amplitude"], "0.2")
        self.assertEqual((h["pre"], h["post"], h["periods"]), ("2", "1", "3"))
        self.assertEqual(h["rts"], "1")
        self.assertEqual(h["rv"], "0.1")
        self.assertEqual(float(h["damping"]), self.res.damping_factor)
        self.assertEqual(float(h["Gp"]), self.res.G_internal[0])
        self.assertEqual(float(h["Gpp"]), self.res.G_internal[1])
        self.assertEqual(float(h["Gp_s"]), self.res.G_surface[0])
        self.assertEqual(float(h["Gpp_s"]), self.res.G_surface[1])
        self.assertEqual(h["rf"], "0.2")
        self.assertEqual(float(h["f"]), self.res.f)
        self.assertEqual(h["angle"], "15")
        self.assertAlmostEqual(float(h["stress"]), math.hypot(*self.res.stress_internal))
        self.assertEqual((h["irc"], h["irt"]), ("1", "1"))
        self.assertEqual((h["keep"], h["ctb"], h["tri"]), ("False", "False", "True"))
        self.assertEqual((h["rlf"], h["removed"]), ("0", "0"))
        # fixed bookkeeping defects (the reference defects listed in docs/output.md #21, #22)
        self.assertIn("\nPost-measurement periods = 1 [-]\n", self.text)
        self.assertIn("\nSimulated time = " + str(6 / self.res.f) + "s\n", self.text)
        # literal layout details of the reference header (docs/output.md, "Blocks")
        self.assertTrue(self.text.startswith("Dermal filler Ensemble: \n\tCutting lines used to generate the "
                                             "particles3\n\tN=30 spheres, nominal packing density = 1.5\n"))
        self.assertIn("\tYoung modulus of the individual spheres = 8000 Pa \n", self.text)
        self.assertIn("\n\n\n\nFunction call : \nSimulation_interlocking_rheology(root_folder=", self.text)
        self.assertIn("\n\ttheSimulation.runSimulation(periods=3, cool_factor=0.5)\n\nOscillatory shear "
                      "experiment\n\nModel parameters\n", self.text)
        self.assertIn("Characteristic viscosity  = ", self.text)
        self.assertIn("[-]\n\n\nRheology experiment information\n", self.text)
        self.assertIn("Post-measurement periods = 1 [-]\n\n\nOutput data\nSummary data\n", self.text)
        self.assertIn("Pa\n\n\nDetailed stress tensor data\nindex\tt\t", self.text)

    def test_table_round_trip(self):
        header, rows = read_table(self.text)
        self.assertEqual(header, TABLE_COLUMNS)
        self.assertEqual(len(header), 42)
        self.assertEqual(len(rows), self.res.N_steps)
        self.assertTrue(all(len(r) == 42 for r in rows))
        data = np.array([[float(v) for v in r] for r in rows])
        np.testing.assert_array_equal(data[:, 0], np.arange(len(rows)))
        col = {name: data[:, k] for k, name in enumerate(header)}
        s = self.res.series
        np.testing.assert_array_equal(col["t"], s["t"])
        np.testing.assert_array_equal(col["stress_measured_at_surface"], s["stress_surface"])
        np.testing.assert_array_equal(col["shear_stress_internal_stress-tensor"], s["stress_internal"])
        # strain is the running sum of rate·dt (docs/engine.md, "One step")
        dt = self.res.dt
        np.testing.assert_array_equal(col["strain"][1:], col["strain"][:-1] + col["strain_rate"][:-1] * dt)
        # the header G values are reproduced by the reference formula (docs/analysis.md) from the stored
        # columns (written with str(), read back exactly): the same sums in another order, 1.3e-15 measured
        p = self.res.parameters
        for c, G in (("shear_stress_internal_stress-tensor", self.res.G_internal),
                     ("stress_measured_at_surface", self.res.G_surface)):
            r = reference_demodulation(col["t"], col[c], self.res.f, 0.2, p["pre_periods"], p["periods"],
                                       p["post_periods"])
            self.assertLess(abs(r[2] - G[0]), 1e-12 * abs(G[0]))
            self.assertLess(abs(r[3] - G[1]), 1e-12 * abs(G[1]))

        def tensor(stem):
            return np.stack([col[stem + "_" + ab] for ab in ("00", "01", "10", "11")], axis=1)

        lw, ext = tensor("stress_tensor_Love_Weber"), tensor("stress_tensor_from_external_forces")
        lin, unb = tensor("stress_tensor_linear_acceleration"), tensor("stress_tensor_unbalanced_linear_forces")
        tint, cen = tensor("stress_tensor_internal_tangential_torque"), tensor("stress_tensor_centrifugal")
        overall = tensor("stress_tensor_overall")
        # identities of the definitions (eq. S1-24; action and reaction for σ_LW = σ_ext + σ_linacc; docs/output.md):
        # sums of the same terms grouped differently, rounding ≲ 1e-15 of the largest entry (5e-16 measured),
        # so 1e-12 of it; σ_linacc is σ_unb copied (m·a = F_total), written twice: equal exactly
        scale = np.abs(lw).max()
        np.testing.assert_allclose(overall, lw + tint + cen, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(lw, ext + lin, rtol=0, atol=1e-12 * scale)
        np.testing.assert_array_equal(lin, unb)
        np.testing.assert_allclose(overall[:, 1], overall[:, 2], rtol=0, atol=1e-12 * scale)
        # the shear-stress columns are the tensors' xy entries, bit for bit (the same row sums in the one
        # formula of engine.forces.shear_from_sums)
        np.testing.assert_array_equal(-overall[:, 1], col["shear_stress_internal_stress-tensor"])
        np.testing.assert_array_equal(-ext[:, 1], col["stress_measured_at_surface"])

    def test_next_number_and_reference_header_switch(self):
        sim = Simulation_interlocking_rheology(self.dir.name, cut_lines=3, N=30, amplitude=0.2, mu=0.01,
                                               relative_frequency=0.2, Young_modulus_spheres=8000,
                                               packing_fraction=1.5, relative_viscosity=0.1)
        sim.model = mock.Mock(time_constant=0.2 / self.res.f)
        self.assertTrue(sim.file_path().endswith("_nr_2.txt"))
        ens = mock.Mock(model=False, k=1.0, nu=2.0, k_t=3.0, nu_t=4.0, mu=0.5, size_x=500, size_y=500, N=10,
                        spec=["model", "k", "nu", "k_t", "nu_t", "mu", "size_x", "size_y", "N", "particle_info"])
        ens.particle_info.return_value = "info"
        exp = OscillatoryShearExperiment(ens, 1e-3, 10.0, 0.2, False)
        exp.baseline_pre_periods, exp.periods, exp.baseline_post_periods = 2, 3, 1
        fixed = experiment_description_text(exp)
        quirk = experiment_description_text(exp, reference_header=True)
        self.assertIn("Simulated time = 0.6s\n", fixed)
        self.assertIn("Post-measurement periods = 1 [-]\n", fixed)
        self.assertIn("Simulated time = 0.3s\n", quirk)
        self.assertIn("Post-measurement periods = 2 [-]\n", quirk)


class TestRunLayer(unittest.TestCase):
    def test_seed_reproducibility(self):
        a = doParticleShearSimulation(seed=11, return_result=True, **QUICK)
        b = doParticleShearSimulation(seed=11, return_result=True, **QUICK)
        c = doParticleShearSimulation(seed=12, return_result=True, **QUICK)
        self.assertEqual(a.G_surface, b.G_surface)
        self.assertEqual(a.G_internal, b.G_internal)
        for key in ("t", "strain", "stress_surface", "stress_internal"):
            np.testing.assert_array_equal(a.series[key], b.series[key])
        self.assertFalse(np.array_equal(a.series["stress_internal"], c.series["stress_internal"]))
        self.assertEqual(a.seed, 11)
        self.assertIs(doParticleShearSimulation.last_result, c)
        self.assertEqual(a.G, doParticleShearSimulation(seed=11, **QUICK))
        self.assertEqual(a.N_steps, len(a.series["t"]))
        for phase in ("constitution", "pre_equilibration", "protocol", "total"):
            self.assertIn(phase, a.timings)

    def test_invalid_parameters_raise_before_work(self):
        bad = [dict(theAmplitude=-0.1), dict(theAmplitude=0), dict(theMu=-0.01), dict(N=1), dict(N=2.5),
               dict(packing_fraction=0), dict(imageFileType="gif"), dict(cool_factor=0), dict(cool_factor=1.5),
               dict(periods=0), dict(pre_periods=-1), dict(Young_modulus_spheres=-5), dict(density=0),
               dict(relative_frequency=0), dict(central_repulsion_coefficient=2), dict(remove_link_fraction=1.5),
               dict(avoid_horizontal_angle_degree=90), dict(cut_lines=-1), dict(saveData=True),
               dict(saveOutputImages=True), dict(saveData=True, root_folder="/no/such/folder/xyz"),
               dict(seed=-3), dict(theAmplitude=float("nan"))]
        with mock.patch.object(Simulation_interlocking_rheology, "initEnsemble",
                               side_effect=AssertionError("simulation work started")):
            for kw in bad:
                with self.subTest(**{k: repr(v) for k, v in kw.items()}):
                    with self.assertRaises(ValueError) as cm:
                        doParticleShearSimulation(doDrawing=False, plotStress=False, verbose=False, **kw)
                    name = next(iter(kw)) if "root_folder" not in kw else "root_folder"
                    if name in ("saveData", "saveOutputImages"):
                        name = "root_folder"
                    self.assertIn(name, str(cm.exception))
            with self.assertRaises(TypeError):
                doParticleShearSimulation(doDrawing="yes", verbose=False)
            sim = Simulation_interlocking_rheology("", saveData=True)
            with self.assertRaises(ValueError):
                sim.runSimulation()

    def test_interrupted_run_leaves_no_file(self):
        with tempfile.TemporaryDirectory() as d:
            with mock.patch.object(OscillatoryShearExperiment, "write_output_information_to_file",
                                   side_effect=KeyboardInterrupt):
                with self.assertRaises(KeyboardInterrupt):
                    doParticleShearSimulation(root_folder=d, saveData=True, seed=1, **QUICK)
            self.assertEqual(os.listdir(d), [])

    def test_headless_run_does_not_import_pil_or_tkinter(self):
        code = ("import sys\nfrom particleShear import doParticleShearSimulation\n"
                "doParticleShearSimulation(N=20, do_permanent_links=False, cut_lines=0, relative_frequency=0.2,"
                " pre_periods=0.2, periods=1, post_periods=0, seed=1, verbose=False)\n"  # doDrawing/plotStress True
                "print('PIL' in sys.modules, 'tkinter' in sys.modules)\n")
        env = dict(os.environ)
        env.pop("DISPLAY", None)
        env.pop("WAYLAND_DISPLAY", None)
        env.pop("PARTICLESHEAR_RENDERER", None)
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(out.stdout.strip(), "False False")
        self.assertEqual(out.stderr.count("no display available"), 1)

    def test_images_headless(self):
        with tempfile.TemporaryDirectory() as d:
            r = doParticleShearSimulation(root_folder=d, saveOutputImages=True, imageFileType="png", seed=2,
                                          renderer="pillow", return_result=True,
                                          **dict(QUICK, doDrawing=True))
            files = sorted(os.listdir(r.image_folder))
            image_N = int(r.N_steps / 200) if r.N_steps > 200 else 1
            expected = ["image%07d.png" % k for k in range(0, r.N_steps, image_N)]
            self.assertEqual(files, expected)
            # named after the run (no text file exists: saveData=False), not after a ".txt" path
            self.assertTrue(r.image_folder.endswith("_nr_1_images"), r.image_folder)
            self.assertEqual(os.listdir(d), [os.path.basename(r.image_folder)])
            self.assertEqual(r.output_path, None)  # saveData=False: no text file, only images
            from PIL import Image
            with Image.open(os.path.join(r.image_folder, files[-1])) as im:
                self.assertEqual(im.size, (500, 500 + 44))  # cell (1 px = 1 µm) + caption strip

    def test_image_folder_names_take_the_number(self):
        """``<run name>_images``; the reference's ``<file>.txt_images_folder`` with reference_header=True;
        a folder under either name takes its number (docs/output.md, "Snapshots")."""
        quick = dict(QUICK, doDrawing=False, saveOutputImages=True, imageFileType="png", renderer="pillow",
                     return_result=True, seed=2)
        with tempfile.TemporaryDirectory() as d:
            r1 = doParticleShearSimulation(root_folder=d, reference_header=True, **quick)
            r2 = doParticleShearSimulation(root_folder=d, **quick)
            r3 = doParticleShearSimulation(root_folder=d, **quick)
            self.assertTrue(r1.image_folder.endswith("_nr_1.txt_images_folder"), r1.image_folder)
            self.assertTrue(r2.image_folder.endswith("_nr_2_images"), r2.image_folder)
            self.assertTrue(r3.image_folder.endswith("_nr_3_images"), r3.image_folder)
            self.assertEqual(sorted(os.listdir(d)), sorted(os.path.basename(r.image_folder) for r in (r1, r2, r3)))

    def test_tk_backend_with_fake_tkinter(self):
        """Exercise the live drawing code paths (particle window, stress plot) without a display."""
        import types
        calls = {"oval": 0, "line": 0, "update": 0, "destroy": 0}

        class Widget:
            def __init__(self, *a, **k):
                pass

            def title(self, *a):
                pass

            def update(self):
                calls["update"] += 1

            def destroy(self):
                calls["destroy"] += 1

        class Canvas(Widget):
            def pack(self):
                pass

            def delete(self, *a):
                pass

            def create_oval(self, *a, **k):
                calls["oval"] += 1

            def create_line(self, *a, **k):
                self.assert_coords(a)
                calls["line"] += 1

            @staticmethod
            def assert_coords(a):
                assert len(a) == 4 and all(np.isfinite(a))

        fake = types.ModuleType("tkinter")
        fake.Tk, fake.Toplevel, fake.Canvas, fake.TclError = Widget, Widget, Canvas, RuntimeError
        with mock.patch.dict(sys.modules, {"tkinter": fake}), mock.patch.dict(os.environ, {"DISPLAY": ":0"}):
            r = doParticleShearSimulation(seed=4, renderer="tk", return_result=True,
                                          **dict(QUICK, doDrawing=True, plotStress=True, do_permanent_links=True,
                                                 cut_lines=2))
        self.assertGreater(calls["oval"], 3 * r.N_steps)   # stress plot: three dots per step + spheres
        self.assertGreater(calls["line"], 0)
        self.assertGreater(calls["update"], 0)
        self.assertEqual(calls["destroy"], 2)               # both windows closed at the end

    def test_series_on_executor(self):
        kw = dict(N=20, relative_frequency=0.2, pre_periods=0.5, periods=1, post_periods=0.5, doDrawing=False,
                  plotStress=False, cut_lines=2)
        with concurrent.futures.ThreadPoolExecutor(max_workers=2) as ex:
            res = doParticleShearSimulationSeries(amplitudes=[0.2, 0.1], mu=[0.01], N_repetitions=1,
                                                  do_uncrosslinked_control=True, executor=ex, seed=5, **kw)
        self.assertEqual([(r.parameters["theAmplitude"], r.parameters["do_permanent_links"]) for r in res],
                         [(0.2, True), (0.2, False), (0.1, True), (0.1, False)])
        children = np.random.SeedSequence(5).spawn(4)
        again = doParticleShearSimulation(**dict(kw, theAmplitude=0.1, theMu=0.01, do_permanent_links=False,
                                                 cut_lines=0, seed=children[3], verbose=False, return_result=True))
        self.assertEqual(again.G_surface, res[3].G_surface)
        self.assertEqual(res[1].spawn_key, (1,))

    def test_cli(self):
        err, out = io.StringIO(), io.StringIO()
        with mock.patch.object(sys, "stderr", err), mock.patch.object(sys, "stdout", out):
            rc = cli_main(["--N", "20", "--no-permanent-links", "--cut-lines", "0", "--relative-frequency", "0.2",
                           "--pre-periods", "0.5", "--periods", "1", "--post-periods", "0.5", "--seed", "3"])
        self.assertEqual(rc, 0)
        self.assertIn("(internal estimator)", out.getvalue())
        self.assertIn("(surface estimator)", out.getvalue())
        self.assertIn("[protocol]", err.getvalue())
        self.assertIn("remaining", err.getvalue())
        err = io.StringIO()
        with mock.patch.object(sys, "stderr", err):
            rc = cli_main(["--amplitude", "-1", "--quiet"])
        self.assertEqual(rc, 2)
        self.assertIn("--amplitude", err.getvalue())  # the flag the user typed (issue 10)


class TestStochasticScenarios(unittest.TestCase):
    """The manual's Part 4 scenarios 8–10 (frictional assembly at rest, during shear; crosslinked assembly during shear)
    with the tolerances stated there (three seeds each)."""

    seeds = (1, 2, 3)

    @staticmethod
    def build(seed, do_permanent_links, N, cut_lines, pre_periods):
        sim = Simulation_interlocking_rheology(
            "", do_permanent_links=do_permanent_links, cut_lines=cut_lines, N=N, packing_fraction=1.5,
            bimodal_factor=1.4, amplitude=0.2, Young_modulus_spheres=8000, density=50, mu=0.01,
            relative_viscosity=0.1, relative_y_scale_force=1e8, relative_frequency=0.025,
            relative_transversal_link_strength=1, avoid_horizontal_angle_degree=15,
            avoid_height_spanning_particles=True, interface_reenforcement_central=1,
            interface_reenforcement_tangential=1, central_repulsion_coefficient=1,
            keep_viscosity_coefficients_constant=False, cut_top_bottom=False, doCutByTriangulation=True,
            remove_link_fraction=0, edge_fuzziness=0, doDrawing=False, saveData=False)
        sim.baseline_pre_periods = pre_periods
        sim.baseline_post_periods = 1
        sim.rng = seed
        sim.initEnsemble(do_debug=True)
        exp = sim.createExperiment(False, periods=2, plotStress=False)  # cool_factor 1 → per-step factor 1
        exp.pre_equilibrate(N=25)
        ens = sim.theEnsemble
        ens.t = 0
        ens.applyingShear = True
        ens.setShearRate(0)
        return exp, ens

    def shear(self, exp):
        exp.keep_tensor_history = True  # every tensor at every step (runs that keep nothing evaluate only σ_xy)
        exp.prepare_recording()
        n = int((0.15 * exp.periods + exp.baseline_pre_periods) / (exp.f * exp.dt))
        exp.run_protocol(1, n)
        self.assertGreater(exp.theEnsemble.shear, 0.9 * exp.amplitude)
        return exp.theEvaluator.tensors

    def check(self, T, full=True):
        lw, ot, ext, lin, unb, tq, tint, cen, al = T
        self.assertGreater(lw[0, 0], 500)
        self.assertGreater(lw[1, 1], 500)
        if full:
            self.assertLess(abs(lw[0, 1] / lw[0, 0]), 0.1)
            self.assertLess(abs(lw[1, 0] / lw[0, 0]), 0.1)
            self.assertGreater(al[0, 0], 500)
            self.assertGreater(al[1, 1], 500)
        self.assertLess(abs(al[0, 1] - al[1, 0]) / (abs(al[0, 0]) + abs(al[1, 1])), 1e-15)
        self.assertTrue((np.abs(lin) < 0.1 * abs(al[0, 0])).all())
        self.assertLess(abs(ext[0, 0] - al[0, 0]) / al[0, 0], 0.1)
        self.assertLess(abs(ext[1, 1] - al[1, 1]) / al[1, 1], 0.1)

    def test_11_8_frictional_assembly_at_rest(self):
        for seed in self.seeds:
            with self.subTest(seed=seed):
                exp, ens = self.build(seed, False, 45, 5, 2)
                ev = StressTensorEvaluation(500, 500)
                ens.mechanical_simulation_step_calculate_forces()
                ens.record_total_particle_forces()
                ens.evaluate_stress_tensors(ev)
                ens.mechanical_simulation_step_calculate_acceleration(1, exp.dt)
                ens.mechanical_simulation_step_calculate_movement(exp.dt)
                self.check(ev.tensors)

    def test_11_9_frictional_assembly_during_shear(self):
        for seed in self.seeds:
            with self.subTest(seed=seed):
                exp, ens = self.build(seed, False, 45, 5, 0.1)
                self.check(self.shear(exp))

    def test_11_10_crosslinked_assembly_during_shear(self):
        for seed in self.seeds:
            with self.subTest(seed=seed):
                exp, ens = self.build(seed, True, 60, 3, 0.1)
                self.check(self.shear(exp), full=False)


if __name__ == "__main__":
    unittest.main()
