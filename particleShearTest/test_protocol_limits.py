"""Protocols refuse what they cannot resolve, before any work (docs/protocols.md,
"Limits and errors"): every step of an amplitude or frequency sweep is checked for resolution like
the first, and the memory of every protocol's record is estimated from its own steps and bounded
like the oscillatory run's, with one ValueError naming the parameter, its flag, the estimate and the
limit.

"Before any work" is checked by what did not happen: no ensemble was built (the session builder is
replaced by one that fails the test) and no file was written.  The machine's memory is replaced by a
fixed value, so no assertion depends on this machine.
"""
import contextlib
import io
import os
import re
import tempfile
import unittest
import warnings
from unittest import mock

from particleShear.run import validation as V
from particleShear.run.rheometer import protocol_steps, normalize_protocol, PROTOCOL_DEFAULTS
from particleShear.sweep.cost import run_steps

GiB = 2 ** 30


def _never_built(*args, **kwargs):
    raise AssertionError("an ensemble was built: the run was not refused before any work")


@contextlib.contextmanager
def _no_work(memory=None):
    """No session may be built; ``available_memory`` fixed when ``memory`` is given."""
    with contextlib.ExitStack() as st:
        st.enter_context(mock.patch("particleShear.run.sessions.build_sessions", _never_built))
        if memory is not None:
            st.enter_context(mock.patch.object(V, "available_memory", return_value=memory))
        st.enter_context(warnings.catch_warnings())
        warnings.simplefilter("ignore")
        yield


def _refused(test, memory=None, **kw):
    """Run doParticleShearSimulation(**kw) with saveData into a fresh folder; return the error message."""
    from particleShear import doParticleShearSimulation
    with tempfile.TemporaryDirectory() as d, _no_work(memory):
        with test.assertRaises(ValueError) as cm:
            doParticleShearSimulation(**dict(dict(N=20, doDrawing=False, verbose=False, saveData=True,
                                                  root_folder=d, seed=1), **kw))
        test.assertEqual(os.listdir(d), [])          # nothing written
    return str(cm.exception)


class TestSweepStepsResolved(unittest.TestCase):
    def test_every_frequency_of_a_sweep_is_checked(self):
        msg = _refused(self, protocol="frequency_sweep", sweep_frequencies=[0.25, 5, 1000])
        self.assertIn("sweep_frequencies[1]=5 is out of range", msg)
        self.assertIn("11.2 steps, fewer than 100", msg)
        self.assertIn("--sweep-frequencies", msg)
        allowed = float(re.search(r"sweep_frequencies <= ([0-9.e+-]+)", msg).group(1))
        # the allowed bound is the one that passes: a sweep up to it validates, just past it does not
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            V.validate_run(dict(N=20, protocol="frequency_sweep", sweep_frequencies=[0.25, allowed * 0.999]))
            with self.assertRaises(ValueError):
                V.validate_run(dict(N=20, protocol="frequency_sweep", sweep_frequencies=[0.25, allowed * 1.01]))

    def test_the_last_frequency_alone_is_refused(self):
        msg = _refused(self, protocol="frequency_sweep", sweep_frequencies=[0.25, 0.5, 1000])
        self.assertIn("sweep_frequencies[2]=1000", msg)
        self.assertIn("0.056 steps", msg)

    def test_a_later_amplitude_with_a_longer_time_step_is_checked(self):
        # the time-step rule halves dt for A <= 0.05: at relative_frequency 0.8 the step at A = 0.01
        # has 140 steps per period, the one at A = 0.1 only 70
        msg = _refused(self, protocol="amplitude_sweep", sweep_amplitudes=[0.01, 0.1], relative_frequency=0.8)
        self.assertIn("sweep_amplitudes[1]=0.1 is out of range", msg)
        self.assertIn("70 steps, fewer than 100", msg)
        self.assertIn("relative_frequency <= 0.56", msg)
        self.assertIn("--relative-frequency", msg)

    def test_a_coarsened_time_step_is_checked_at_every_step(self):
        msg = _refused(self, protocol="frequency_sweep", sweep_frequencies=[0.25, 0.5], time_step_factor=60)
        self.assertIn("time_step_factor=60 is out of range", msg)
        self.assertIn("at sweep_frequencies[1]=0.5", msg)
        self.assertIn("--time-step-factor", msg)

    def test_resolved_sweeps_pass(self):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            V.validate_run(dict(N=20, protocol="frequency_sweep", sweep_frequencies=[0.25, 0.1, 0.025]))
            V.validate_run(dict(N=20, protocol="amplitude_sweep", sweep_amplitudes=[0.01, 0.1, 1.0]))


class TestProtocolMemory(unittest.TestCase):
    def test_long_creep_is_refused_naming_hold_time_estimate_and_limit(self):
        msg = _refused(self, memory=8 * GiB, protocol="creep", creep_stress=50, hold_time=1e7)
        self.assertIn("hold_time=10000000.0 is out of range", msg)
        self.assertIn("5.6e+08 protocol steps of protocol='creep'", msg)
        self.assertIn("needs ~41.7 GiB", msg)                   # the estimate
        self.assertIn("80% of the 8 GiB of memory available", msg)   # the limit
        self.assertIn("(flag --hold-time)", msg)
        allowed = float(re.search(r"allowed hold_time <= ([0-9.e+]+)", msg).group(1))
        with _no_work(8 * GiB):
            V.validate_run(dict(N=20, protocol="creep", creep_stress=50, hold_time=allowed * 0.99))
            with self.assertRaises(ValueError):
                V.validate_run(dict(N=20, protocol="creep", creep_stress=50, hold_time=allowed * 1.02))

    def test_every_protocol_names_its_own_parameter(self):
        cases = [(dict(protocol="steady", relative_rate=0.001, total_strain=500.0), "total_strain", "--total-strain"),
                 (dict(protocol="relaxation", hold_time=1e6), "hold_time", "--hold-time"),
                 (dict(protocol="frequency_sweep", sweep_frequencies=[0.025, 0.02], periods=5000), "periods",
                  "--periods"),
                 (dict(protocol="amplitude_sweep", sweep_amplitudes=[0.1, 0.2], periods=2000), "periods", "--periods")]
        for kw, name, flag in cases:
            with self.subTest(protocol=kw["protocol"]):
                msg = _refused(self, memory=GiB, **kw)
                self.assertIn(f"{name}=", msg)
                self.assertIn(f"protocol={kw['protocol']!r}", msg)
                self.assertIn("80% of the 1 GiB of memory available", msg)
                self.assertIn(f"allowed {name} <=", msg)
                self.assertIn(f"(flag {flag})", msg)

    def test_the_step_limit_names_the_parameter(self):
        msg = _refused(self, protocol="creep", creep_stress=50, hold_time=1e9)
        self.assertIn("hold_time=1000000000.0 is out of range", msg)
        self.assertIn("more than the limit of 1e+09", msg)
        self.assertIn("allowed hold_time <=", msg)
        self.assertIn("(flag --hold-time)", msg)

    def test_the_estimate_counts_the_protocols_own_steps(self):
        for kw in (dict(protocol="creep", creep_stress=50, hold_time=1e7),
                   dict(protocol="steady", relative_rate=0.01, total_strain=3.0),
                   dict(protocol="relaxation", hold_time=50.0),
                   dict(protocol="frequency_sweep", sweep_frequencies=[0.25, 0.1])):
            with self.subTest(protocol=kw["protocol"]):
                from particleShear.run.batch import _signature_defaults
                p = normalize_protocol(dict(_signature_defaults(), N=20, **kw))
                st = protocol_steps(p)
                own = sum(st["segments"]) if "segments" in st else st["steps"]
                cost = V.estimate_run_cost(p)
                self.assertEqual(cost["protocol_steps"], own)
                self.assertEqual(run_steps(dict(PROTOCOL_DEFAULTS, **p)), own)
                self.assertEqual(cost["memory"]["recording"], own * V.PROTOCOL_RECORD_BYTES_PER_STEP[kw["protocol"]])

    def test_estimate_matches_a_run(self):
        from particleShear import doParticleShearSimulation
        with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
            warnings.simplefilter("ignore")
            kw = dict(N=20, protocol="creep", creep_stress=50, hold_time=5.0)
            cost = V.validate_run(kw)
            res = doParticleShearSimulation(**kw, seed=1, doDrawing=False, verbose=False, return_result=True)
        self.assertEqual(len(res.series["t"]), cost["protocol_steps"])

    def test_cli_refuses_in_one_line_before_any_work(self):
        from particleShear.run.cli import main
        with tempfile.TemporaryDirectory() as d:
            err = io.StringIO()
            with _no_work(8 * GiB), contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                rc = main(["--protocol", "creep", "--creep-stress", "50", "--hold-time", "1e7", "--N", "20",
                           "--save", d, "--quiet"])
            self.assertEqual(rc, 2)
            self.assertEqual(os.listdir(d), [])
        lines = err.getvalue().strip().splitlines()
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("--hold-time", lines[0])
        self.assertIn("41.7 GiB", lines[0])


if __name__ == "__main__":
    unittest.main()
