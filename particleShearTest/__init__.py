"""Test suite of particleShear (unittest-compatible; pytest collects the same ``test_*.py`` files).

``python -m unittest particleShearTest`` runs every ``test_*.py`` module of this
package through :func:`load_tests`; ``python -m unittest discover`` and
``pytest`` find the same modules on their own.
"""
import os
import unittest

_HERE = os.path.dirname(os.path.abspath(__file__))


def warm_compiled_backend():
    """Compile (or load) the compiled backend's loops once, before any test runs, where Numba is
    installed: a test never sees the one-time "compiling" console message of a first use, whatever
    the order the tests run in (each test process loads them from the disk cache in ≈ 0.4 s)."""
    from particleShear.engine import numba_driver, numba_step
    if numba_driver.available():
        for law in (None, "hertz", "plateau"):
            numba_step.compile_kernels(law=law)
        from particleShear.base.compiled_phases import compile_tensor_kernel
        compile_tensor_kernel()


def load_tests(loader, tests, pattern):
    """Discover every ``test_*.py`` module of this package (unittest's load_tests protocol)."""
    warm_compiled_backend()
    suite = unittest.TestSuite()
    if tests is not None:
        suite.addTests(tests)
    suite.addTests(loader.discover(start_dir=_HERE, pattern=pattern or "test_*.py",
                                   top_level_dir=os.path.dirname(_HERE)))
    return suite
