"""The protocols validated against each other over seeds (docs/protocols.md, "Validation"): the
"quick" configuration of ``benchmarks/validate_protocols.py`` (N = 40, uncut, 4 seeds, holds of
200 τ; about a minute on one core). Each seed is one packing for every protocol of a part (the
runs of a part share ``theAmplitude``, hence the time step and the pre-equilibration), so
differences can be paired. Tolerances are 3 standard errors (a 0.3 % two-sided false-alarm rate
for a normal mean; the runs are seeded, so the outcome is fixed); the N = 150, 8-seed figures of
the same criteria are in docs/protocols.md."""
import contextlib
import importlib.util
import io
import os
import unittest
import warnings

import numpy as np

_PATH = os.path.join(os.path.dirname(__file__), os.pardir, "benchmarks", "validate_protocols.py")
_spec = importlib.util.spec_from_file_location("validate_protocols", _PATH)
vp = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(vp)


class TestProtocolValidation(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
            warnings.simplefilter("ignore")
            cls.out = vp.run_all("quick")
        cls.a, cls.bd = cls.out["a"], cls.out["bd"]

    def test_small_strain_moduli_agree(self):
        """Crosslinked solid at γ₀ = 0.02 and f·τ = 0.0125 (low frequency: a period of 80 τ, longer
        than the ≈ 10–100 τ over which the plate stress settles after a step strain): in linear
        viscoelasticity G′(ω → 0) = G(t → ∞) = 1/J(∞). The oscillatory G′, the relaxation plateau
        G = (σ − σ_res)/γ₀ and the creep inverse (σ₀ − σ_res)/γ(∞) of a creep at
        σ₀ = σ_res + G·γ₀ agree within their seed errors (|difference of the means| ≤ 3 combined
        standard errors). Relaxation and creep start from the same state: their step-0 residual
        stresses are equal bit for bit, and the creep strains by γ₀ within 10 %."""
        gp, gpl, gc, use = self.a["gp"], self.a["gpl"], self.a["gc"], self.a["use"]
        self.assertTrue(self.a["same_start"])
        self.assertGreaterEqual(int(use.sum()), 3)
        for hi, lo in ((gpl, gp), (gc, gp[use]), (gc, gpl[use])):
            m, se, _ = vp.unpaired(hi, lo)
            self.assertLessEqual(abs(m), 3 * se)
        np.testing.assert_allclose(gpl[use] / gc, 1.0, atol=0.1)

    def test_creep_above_yield_flows_at_the_flow_curve_rate(self):
        """Uncrosslinked packing: a creep at σ₀ above the lowest-rate steady stress (≥ σ_y) reaches
        the rate that the same packing's steady flow curve (runs to a strain of 5, log–log
        interpolation) gives for the plate stress the controller held while the creep rate was
        measured; |mean log-rate difference| ≤ 3 paired standard errors."""
        self.assertGreater(self.bd["s0"], self.bd["sig"][:, 0].mean())
        self.assertTrue(np.all(self.bd["crate"] > 0))
        m, se, _ = vp.paired(np.log(self.bd["crate"]), np.log(self.bd["held_rate"]))
        self.assertLessEqual(abs(m), 3 * se)

    def test_oscillatory_amplitude_is_not_below_the_steady_stress_at_the_peak_rate(self):
        """Uncrosslinked packing at γ₀ = 0.3, f·τ = 0.05 (yielded each cycle): the steady stress at
        the peak rate γ₀ω is not an upper bound of the oscillatory first-harmonic amplitude |G*|γ₀
        (a plastic square-wave stress ±σ has the first harmonic (4/π)σ, and each reversal reloads the
        packing through its start-up overshoot). Asserted: |G*|γ₀ ≥ σ(γ₀ω) within 3 paired standard
        errors (one-sided)."""
        m, se, _ = vp.paired(self.bd["gstar"], self.bd["speak"])
        self.assertGreaterEqual(m, -3 * se)


if __name__ == "__main__":
    unittest.main()
