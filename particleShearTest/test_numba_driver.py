"""The compiled pair loop (engine/numba_driver.py) against the NumPy terms: one law, two drivers.

The compiled loop calls the same pure law functions on numbers that the NumPy engine calls on
arrays (laws.linear_term …, terms.viscous_force, tangential.two_visit_rule), in the same order of
operations, so the results are equal bit for bit (signs of zeros included) — not merely close.
Skipped where Numba is not installed (the ``test`` extra installs it); the package itself never
imports Numba on import (tested here with and without it).
"""
import subprocess
import sys
import unittest
import warnings

import numpy as np

from particleShear.engine import laws, numba_driver, terms

HAVE_NUMBA = numba_driver.available()


def _bits(a):
    """The bit patterns of a float array (equal bits: equal values and equal signs of zero)."""
    return np.ascontiguousarray(a, dtype=float).view(np.int64)


def _candidates(seed, P=600):
    """Random candidate pairs around contact: distances 0.6–1.2 × d0, a third of them bonds
    (d_eq 0.9–1.05 × d0), velocities and histories large enough that some contacts slip."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(20.0, 35.0, (2, P))
    d0 = r.sum(0)
    d = d0 * rng.uniform(0.6, 1.2, P)
    perm = rng.random(P) < 0.3
    d_eq = d0 * rng.uniform(0.9, 1.05, P)
    vn, vt = rng.normal(0.0, 1e3, P), rng.normal(0.0, 1e3, P)
    xi = rng.normal(0.0, 3.0, (2, P))
    return d0, d, perm, d_eq, vn, vt, xi


def _numpy_terms(K, d, vn, vt, touching, active, xi, K_j=None):
    fn, law = terms.central_term(K, d, vn, active)
    F, slip = terms.tangential_term(K, vt, touching.astype(float), xi, law, K_j)
    return fn, law, np.stack(F), slip


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestCompiledPairTerms(unittest.TestCase):
    def test_bit_identical_to_numpy_terms(self):
        """Every form of the compressive law (c = 0, 0.3, 1), with and without bonds, and with the
        visit from j seeing its own k_t, ν_t: central scalar, law, both tangential visits, slip flags
        and the reset histories equal the NumPy terms bit for bit."""
        kernel = numba_driver.compile_pair_kernel()
        for seed, c in ((1, 0.0), (2, 0.3), (3, 1.0)):
            d0, d, perm, d_eq, vn, vt, xi0 = _candidates(seed)
            touching = d < d0
            for bonds in (False, True):
                for own_j in (False, True):
                    with self.subTest(c=c, bonds=bonds, own_j=own_j):
                        K = terms.term_constants(d0, perm if bonds else None, d_eq if bonds else None, 3.1e9, c, 2.2e3,
                                                 2.9e9, 1.9e3, 0.3, prc=0.5, prt=0.7, keep=0.0)
                        K_j = terms.term_constants(d0, perm if bonds else None, d_eq if bonds else None, 3.1e9, c,
                                                   2.2e3, 1.3e9, 0.8e3, 0.3) if own_j else None
                        active = (perm | touching) if bonds else touching
                        xi_np, xi_nb = xi0.copy(), xi0.copy()
                        want = _numpy_terms(K, d, vn, vt, touching, active, xi_np, K_j)
                        got = numba_driver.pair_terms(K, d, vn, vt, touching, active, xi_nb, K_j, kernel=kernel)
                        for name, a, b in zip(("fn", "law", "F"), want[:3], got[:3]):
                            np.testing.assert_array_equal(_bits(a), _bits(b), err_msg=name)
                        np.testing.assert_array_equal(want[3], got[3])
                        np.testing.assert_array_equal(_bits(xi_np), _bits(xi_nb))
                        # the scene is one that tests something: some contacts slip and reset, some stick
                        self.assertTrue(0 < want[3].sum() < touching.sum())
                        self.assertTrue((xi_np == 0).any() and (xi_np != 0).any())

    def test_one_law_changes_both_backends(self):
        """Replacing the body of one law (the linear term, doubled) changes the forces of both
        drivers, and they still agree bit for bit: the compiled loop reads the law, not a copy."""
        d0, d, perm, d_eq, vn, vt, xi0 = _candidates(4)
        touching = d < d0
        K = terms.term_constants(d0, None, None, 3.1e9, 0.3, 2.2e3, 2.9e9, 1.9e3, 0.3)
        before = _numpy_terms(K, d, vn, vt, touching, touching, xi0.copy())
        original = laws.linear_term

        def doubled(d, d0, a_lin):
            return 2.0 * (a_lin * (d0 - d))

        laws.linear_term = doubled
        try:
            kernel = numba_driver.compile_pair_kernel(cache=False)
            after_np = _numpy_terms(K, d, vn, vt, touching, touching, xi0.copy())
            after_nb = numba_driver.pair_terms(K, d, vn, vt, touching, touching, xi0.copy(), kernel=kernel)
        finally:
            laws.linear_term = original
        inside = touching & (d < d0)
        # the linear part doubles: law_after − law_before = a_lin·(d0 − d) on every overlapping pair
        np.testing.assert_allclose(after_np[1][inside] - before[1][inside], (K.a_lin * (d0 - d))[inside], rtol=1e-9)
        np.testing.assert_array_equal(_bits(after_np[0]), _bits(after_nb[0]))
        np.testing.assert_array_equal(_bits(after_np[1]), _bits(after_nb[1]))
        # and the kernel of the unchanged law gives the forces before
        np.testing.assert_array_equal(_bits(numba_driver.pair_terms(K, d, vn, vt, touching, touching, xi0.copy())[0]),
                                      _bits(before[0]))

    def test_select_is_a_number_in_compiled_code(self):
        """``select`` on numbers compiles to a branch that returns a float (not a 0-d array)."""
        import numba

        from particleShear.engine.xp import maximum, select
        numba_driver.register_helpers()
        f = numba.njit(lambda c, a, b: select(c, a, b) + maximum(a, b))
        self.assertEqual(f(True, 1.5, 2.0), 3.5)
        self.assertEqual(f(False, 1.5, 2.0), 4.0)
        self.assertIsInstance(f(True, 1.5, 2.0), float)


_SCALE = {"linear": 1.0}


def _python_only_law(d, d0, k, c):
    """A user's law: the linear law, scaled by a number looked up in a dict."""
    return -k * (d0 - d) * _SCALE["linear"]


def _stiffening_law(d, d0, k, c):
    """A user's law: the linear law stiffening with the relative overlap δ/d0 and its square root
    (arithmetic and sqrt only)."""
    x = (d0 - d) / d0
    return -k * (d0 - d) * (1.0 + 0.5 * x + 0.1 * np.sqrt(np.abs(x)))


def _three_halves_law(d, d0, k, c):
    """A user's law: a Hertz-like force ``−k·d0·(δ/d0)^{3/2}`` written with ``**``."""
    x = np.abs(d0 - d) / d0
    return -k * d0 * x ** 1.5


def _small_exp_law(d, d0, k, c):
    """A user's law: the linear law with a small exponential correction (1 % of e^{δ/d0})."""
    return -k * (d0 - d) * (1.0 + 1e-2 * np.exp((d0 - d) / d0))


def _scaled_law(scale):
    """A closure factory: the linear law times ``scale``."""
    def scaled(d, d0, k, c):
        return -scale * k * (d0 - d)
    return scaled


_GLOBAL_SCALE = 1.0


def _global_scaled_law(d, d0, k, c):
    """A user's law reading a global number."""
    return -_GLOBAL_SCALE * k * (d0 - d)


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestNumbaBackendRuns(unittest.TestCase):
    """backend="numba" steps the engine in the compiled step: the whole measurement (pre-equilibration
    and protocol, 0.5 + 3 + 0.5 periods, > 1,000 steps) equals the NumPy engine's bit for bit, a
    batch of two equals its single runs, and a scene the loop does not cover runs the NumPy terms
    with a note."""

    SCENES = (dict(theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.2),
              dict(theMu=0.3, do_permanent_links=False, cut_lines=0, theAmplitude=0.1))

    def measure(self, scenes, backend, integrator="euler", periods=1, law=None):
        from particleShear.engine.loops import pre_equilibrate, protocol
        from particleShear.base.engine_adapter import state_from_ensembles
        from particleShear.engine.step import BatchEngine
        from particleShearTest.test_engine import constituted

        sc = constituted(11, **self.SCENES[0])[2]      # one schedule for every batch
        ensembles = [constituted(11 + n, **scene)[1] for n, scene in scenes]
        eng = BatchEngine(state_from_ensembles(ensembles, backend=backend, laws=[law] * len(ensembles)),
                          integrator=integrator)
        pre_equilibrate(eng, sc["N_pre"], sc["dt"], sc["dt_max"], sc["cool"])
        out = protocol(eng, sc["dt"], sc["f"], [sc["A"]] * len(ensembles), sc["cool"], 0.5, periods, 0.5)
        return eng, out

    def assert_same(self, a, b, columns=None):
        for key in ("t", "strain", "stress_internal", "stress_surface"):
            x, y = a[key], b[key]
            if x.ndim == 2 and columns is not None:
                x, y = x[:, columns[0]], y[:, columns[1]]
            np.testing.assert_array_equal(_bits(x), _bits(y), err_msg=key)

    def test_measurement_bit_identical_to_numpy(self):
        for integrator in ("euler", "verlet"):
            with self.subTest(integrator=integrator):
                scenes = [(0, self.SCENES[0])]
                e_np, ref = self.measure(scenes, "numpy", integrator, periods=3)
                with warnings.catch_warnings():
                    warnings.simplefilter("error", RuntimeWarning)   # no fallback on this scene
                    e_nb, got = self.measure(scenes, "numba", integrator, periods=3)
                self.assertGreaterEqual(e_nb.step_count, 1000, "pre-equilibration + protocol steps")
                self.assertGreater(np.max(np.abs(ref["stress_surface"])), 0.0)
                self.assert_same(ref, got)
                p, q = e_np.pairs_of(0), e_nb.pairs_of(0)
                np.testing.assert_array_equal(_bits(p.xi), _bits(q.xi))
                self.assertTrue(np.any(p.xi != 0.0))
                np.testing.assert_array_equal(_bits(e_np.s.pos), _bits(e_nb.s.pos))

    def test_batch_equals_single_runs(self):
        scenes = list(enumerate(self.SCENES))
        _, both = self.measure(scenes, "numba")
        for n, scene in scenes:
            _, single = self.measure([(n, scene)], "numba")
            self.assert_same(single, both, (0, n))

    def test_fallback_is_announced(self):
        """A user's contact law Numba cannot compile (it reads a dict) runs on NumPy, with a note
        naming why, and gives NumPy's numbers."""
        from particleShear.engine.laws import register_law, unregister_law
        register_law("python_only", _python_only_law)
        try:
            scenes = [(0, dict(theMu=0.3, do_permanent_links=False, cut_lines=0, theAmplitude=0.1))]
            with self.assertWarnsRegex(RuntimeWarning, "runs on NumPy .*Numba cannot compile"):
                _, got = self.measure(scenes, "numba", law=("python_only", ()))
            self.assert_same(self.measure(scenes, "numpy", law=("python_only", ()))[1], got)
        finally:
            unregister_law("python_only")

    SCENE = [(0, dict(theMu=0.3, do_permanent_links=False, cut_lines=0, theAmplitude=0.1))]

    def test_user_law_of_rounded_operations_runs_compiled(self):
        """A user's law of arithmetic and sqrt (each operation correctly rounded by IEEE 754, so the
        same bits in NumPy's loops and in Numba's scalar code) runs compiled — no note — and its
        measurement equals NumPy's bit for bit; it changes the forces (not the built-in law)."""
        from particleShear.engine.laws import register_law, unregister_law
        register_law("stiffening", _stiffening_law)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", RuntimeWarning)        # compiled: no fallback note
                e_nb, got = self.measure(self.SCENE, "numba", law=("stiffening", ()))
            e_np, want = self.measure(self.SCENE, "numpy", law=("stiffening", ()))
            self.assert_same(want, got)
            np.testing.assert_array_equal(_bits(e_np.s.pos), _bits(e_nb.s.pos))
            _, linear = self.measure(self.SCENE, "numpy")
            self.assertFalse(np.array_equal(linear["stress_surface"], want["stress_surface"]))
        finally:
            unregister_law("stiffening")

    def test_user_law_with_a_transcendental_function(self):
        """A user's law with ``**`` of a fractional exponent, and one whose transcendental part is a
        small correction (too rare a difference for a sample to find): their compiled code calls
        ``pow`` / ``exp``, so they run on NumPy with a note naming the call, and the measurement on
        ``"numba"`` equals NumPy's bit for bit."""
        from particleShear.engine.laws import register_law, unregister_law
        for name, law, call in (("three_halves", _three_halves_law, "pow"), ("small_exp", _small_exp_law, "exp")):
            with self.subTest(law=name):
                register_law(name, law)
                try:
                    with self.assertWarnsRegex(RuntimeWarning, f"runs on NumPy .*{name}.* calls .*{call}"):
                        _, got = self.measure(self.SCENE, "numba", law=(name, ()))
                    self.assert_same(self.measure(self.SCENE, "numpy", law=(name, ()))[1], got)
                finally:
                    unregister_law(name)

    def test_law_is_compiled_from_its_values(self):
        """Two laws of one closure factory with other values (and so one code object and name) are
        checked and compiled each with its own values: each measurement equals NumPy's bit for bit,
        no note, and the two differ (a stale compiled law would give the first one's forces)."""
        from particleShear.engine.laws import register_law, unregister_law
        runs = []
        for scale in (1.0, 2.5):
            register_law("scaled", _scaled_law(scale), replace=True)
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("error", RuntimeWarning)
                    _, got = self.measure(self.SCENE, "numba", law=("scaled", ()))
                self.assert_same(self.measure(self.SCENE, "numpy", law=("scaled", ()))[1], got)
                runs.append(got["stress_surface"])
            finally:
                unregister_law("scaled")
        self.assertFalse(np.array_equal(runs[0], runs[1]))

    def test_what_the_check_reads(self):
        """The check reads the compiled code: a law of arithmetic and sqrt calls nothing outside the
        exact operations; ``exp`` and ``**`` of a variable exponent are calls it names; the
        fingerprint follows a closure's values and a global's value."""
        from particleShear.engine import law_check
        from particleShear.engine.contact_laws.hertz import hertz
        adapter = law_check.law_adapter(hertz, 6)
        adapter(40.0, (45.0, 20.0, 25.0, 3.1e9, 0.3, 0.05, 0.0, 0.0))
        self.assertEqual(law_check.outside_calls(adapter.law_functions), [])   # (its sqrt: exact in any library)
        for law, calls in ((_stiffening_law, []), (_small_exp_law, ["exp"]), (_three_halves_law, ["pow"])):
            adapter = law_check.law_adapter(law, 3)
            adapter(50.0, (49.0, 3.1e9, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0))
            found = law_check.outside_calls(adapter.law_functions)
            self.assertEqual(len(found), len(calls), found)
            for name, want in zip(found, calls):
                self.assertIn(want, name)
        self.assertNotEqual(law_check.law_fingerprint(_scaled_law(1.0)), law_check.law_fingerprint(_scaled_law(2.0)))
        self.assertEqual(law_check.law_fingerprint(_scaled_law(1.0)), law_check.law_fingerprint(_scaled_law(1.0)))
        before = law_check.law_fingerprint(_global_scaled_law)
        global _GLOBAL_SCALE
        _GLOBAL_SCALE, old = 3.0, _GLOBAL_SCALE
        try:
            self.assertNotEqual(law_check.law_fingerprint(_global_scaled_law), before)
        finally:
            _GLOBAL_SCALE = old

    def test_a_law_whose_bits_differ_runs_on_numpy(self):
        """Fault injection: a check that sees the compiled law one ulp away from NumPy's values sends
        the step to NumPy with the note, and the measurement stays NumPy's."""
        from unittest import mock

        from particleShear.engine import law_check
        from particleShear.engine.laws import register_law, unregister_law
        register_law("stiffening_off", _scaled_law(7.25))   # (values of its own: no verdict kept for it yet)
        real = law_check._probe

        def one_ulp_away(adapter):
            kernel = real(adapter)

            def probe(d, A, out):
                kernel(d, A, out)
                out[:] = np.nextafter(out, np.inf)
            return probe

        try:
            with mock.patch.object(law_check, "_probe", one_ulp_away):
                with self.assertWarnsRegex(RuntimeWarning, "runs on NumPy .*stiffening_off.* differs from NumPy"):
                    _, got = self.measure(self.SCENE, "numba", law=("stiffening_off", ()))
            self.assert_same(self.measure(self.SCENE, "numpy", law=("stiffening_off", ()))[1], got)
        finally:
            unregister_law("stiffening_off")


@unittest.skipUnless(HAVE_NUMBA, "Numba is not installed (pip install particleShear[fast])")
class TestBorrowedViews(unittest.TestCase):
    def test_views_share_memory_and_own_nothing(self):
        """numba_driver.borrowed: in Python the tuple itself; compiled, views of the same memory
        (a write through a view, or a row of it, is the array's) that leave the arrays' reference
        counts as they were, and the other elements as they are."""
        import numba

        numba_driver.register_helpers()
        a, b = np.zeros((2, 5)), np.arange(4, dtype=np.int64)
        args = (a, b, 3.5)
        self.assertIs(numba_driver.borrowed(args), args)
        borrowed = numba_driver.borrowed

        @numba.njit
        def write(a, b, x):
            a, b, x = borrowed((a, b, x))
            row = a[1]
            row[2] = x
            b[3] += 1
            return a.shape[1] + b.shape[0]

        counts = sys.getrefcount(a), sys.getrefcount(b)
        for _ in range(3):
            self.assertEqual(write(a, b, 3.5), 9)
        self.assertEqual((sys.getrefcount(a), sys.getrefcount(b)), counts)
        self.assertEqual(a[1, 2], 3.5)
        self.assertEqual(a.sum(), 3.5)
        self.assertEqual(b.tolist(), [0, 1, 2, 6])

    def test_a_parallel_kernel_keeps_its_stores(self):
        """A kernel of the shape of the block (its arguments rebound by ``borrowed``, a ``prange``
        over replicas writing ``a[b]`` of arrays not read after the loop), compiled on several
        threads through the one compile of the step's kernels (``numba_step.compile_kernel``,
        ``parallel=True``, which turns ``BORROWED_VIEWS`` off): every store reaches the caller's
        arrays.  (With ``borrowed``'s views there, or any call's tuple unpacked, Numba's parfor
        passes removed them as dead: the arrays stayed zero.)"""
        from particleShear.engine import numba_step
        ks, rate, rates = np.zeros(8, np.int64), np.zeros(8), np.arange(1.0, 9.0)
        kernel = numba_step.compile_kernel(None, "_stores", ((sys.modules[__name__], "_stores"),),
                                           lambda: "int64(int64[:], float64[:], float64[:], int64)",
                                           cache=False, parallel=True)
        self.assertEqual(kernel(ks, rate, rates, 7), 0)
        self.assertEqual(ks.tolist(), [7] * 8)
        self.assertEqual(rate.tolist(), rates.tolist())


prange = range      # (numba.prange in the parallel variant, numba_driver.jit_laws)
borrowed = numba_driver.borrowed
BORROWED_VIEWS = True     # (as numba_step's: False in the variant on several threads)


def _stores(ks, rate, rates, n):
    """Replica b's rate and step written in a loop over replicas (test_a_parallel_kernel_keeps_its_stores)."""
    if BORROWED_VIEWS:
        ks, rate, rates = borrowed((ks, rate, rates))
    for b in prange(ks.shape[0]):
        rate[b] = rates[b]
        ks[b] = n
    return 0


class TestNumbaStaysOptional(unittest.TestCase):
    def test_import_without_numba(self):
        """Importing the package (and the compiled driver's module) imports no Numba, and with Numba
        unimportable the driver says it is not available."""
        code = ("import sys; sys.modules['numba'] = None\n"
                "import particleShear\n"
                "from particleShear.engine import numba_driver, laws\n"
                "assert not numba_driver.available()\n"
                "import numpy as np\n"
                "print(laws.blend_inside(np.array([1.0]), 2.0, 0.002, -1.0, -1.0)[0])\n")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(float(out.stdout), -1.0 * (2.0 - 1.0) + -1.0 * (2.0 / 1.0 - 1.0))
        code = "import sys, particleShear\nprint('numba' in sys.modules)"
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
        self.assertEqual(out.stdout.strip(), "False", out.stderr)


if __name__ == "__main__":
    unittest.main()
