"""pytest only (``python -m unittest`` ignores this file): the order in which a parallel run hands out work.

Under pytest-xdist's ``--dist loadscope`` (the README's test command) each test class is one unit of
work, handed to whichever process is free.  The longest units go first, so that no process is
still running a long one after the other has finished: pytest-xdist's own reordering (classes with
more tests first) is turned off, and the classes named in :data:`LONG_FIRST` (the longest ones,
tens of seconds each on one core) are moved to the front, in that order; every other test keeps
its place.  A name here that no longer exists only loses its place in the order.
"""

#: node-id prefixes of the longest test classes, longest first
LONG_FIRST = (
    "particleShearTest/test_snippets.py::TestSnippets_README_md",
    "particleShearTest/test_snippets.py::TestSnippets_docs_experiment_md",
    "particleShearTest/test_protocol_validation.py::TestProtocolValidation",
    "particleShearTest/test_verdicts.py::TestOscillatoryRuns",
    "particleShearTest/test_snippets.py::TestSnippets_docs_sweeps_md",
    "particleShearTest/test_snippets.py::TestSnippets_docs_protocols_md",
    "particleShearTest/test_verdicts.py::TestProtocolRuns",
    "particleShearTest/test_microstructure.py::TestStroboscopicRuns",
    "particleShearTest/test_backend.py::TestBatchOnTheStandInDevice",
    "particleShearTest/test_sweep_faults.py::TestKilledDriver",
)


def pytest_configure(config):
    """Keep the collection order for ``--dist loadscope`` (the order set below)."""
    if hasattr(config.option, "loadscopereorder"):
        config.option.loadscopereorder = False


def pytest_sessionstart(session):
    """The compiled backend's loops, compiled (or loaded) before any test of this process
    (:func:`particleShearTest.warm_compiled_backend`)."""
    from particleShearTest import warm_compiled_backend
    warm_compiled_backend()


def _rank(item):
    for k, prefix in enumerate(LONG_FIRST):
        if item.nodeid.startswith(prefix):
            return k
    return len(LONG_FIRST)


def pytest_collection_modifyitems(session, config, items):
    """The classes of :data:`LONG_FIRST` first, in its order; the rest as collected (a stable sort)."""
    items.sort(key=_rank)
