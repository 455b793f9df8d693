"""Test suite of particleShear (unittest-compatible; pytest collects the same ``test_*.py`` files).

``python -m unittest particleShearTest`` runs every ``test_*.py`` module of this
package through :func:`load_tests`; ``python -m unittest discover`` and
``pytest`` find the same modules on their own.
"""
import os
import unittest

_HERE = os.path.dirname(os.path.abspath(__file__))


def load_tests(loader, tests, pattern):
    """Discover every ``test_*.py`` module of this package (unittest's load_tests protocol)."""
    suite = unittest.TestSuite()
    if tests is not None:
        suite.addTests(tests)
    suite.addTests(loader.discover(start_dir=_HERE, pattern=pattern or "test_*.py",
                                   top_level_dir=os.path.dirname(_HERE)))
    return suite
