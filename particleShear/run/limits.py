"""The limits a run is checked against (docs/parameters.md): resolution, size, steps and seeds, and the
parameter of another protocol than "oscillatory" that makes it too long (the protocol's ``room``).
The resolution limits (``MIN_STEPS_PER_PERIOD``, ``MIN_STEPS_PER_PERIOD_COARSENED``) are the
protocols' (:mod:`particleShear.protocols`), re-exported here.

:mod:`particleShear.run.validation` checks a run against them (and re-exports them); the rheometer's
protocols (:mod:`particleShear.run.rheometer`) check their own steps against the same limits.
"""
__docformat__ = "numpy"
from ..protocols import (MIN_STEPS_PER_PERIOD, MIN_STEPS_PER_PERIOD_COARSENED,  # noqa: F401 - re-exported
                         PROTOCOLS as _PROTOCOLS)

__all__ = ["CELL", "MIN_STEPS_PER_PERIOD", "MIN_STEPS_PER_PERIOD_COARSENED", "MIN_SPHERES_PER_PARTICLE", "MAX_N",
           "MAX_TOTAL_STEPS", "MAX_SERIES_RUNS", "SEED_LIMIT"]

#: cell of every run (µm)
CELL = 500.0
#: fewest spheres per particle of a cut gel (mean): fewer than three bonded discs have no area
#: and no shear rigidity of their own
MIN_SPHERES_PER_PARTICLE = 3
#: most spheres of one run (constitution cost grows faster than N; ~10 kB each)
MAX_N = 1_000_000
#: most integration steps of one run (constitution + pre-equilibration + protocol)
MAX_TOTAL_STEPS = 10 ** 9
#: most runs of one series
MAX_SERIES_RUNS = 100_000
#: integer seeds are below this bound (the 128 bits of entropy numpy draws for a fresh SeedSequence)
SEED_LIMIT = 2 ** 128


def _protocol_room(p, detail, steps_ok):
    """(name, allowed) of the parameter of another protocol than "oscillatory" that makes it longer
    than ``steps_ok`` steps: the protocol's ``room`` (:mod:`particleShear.protocols`), e.g.
    ``total_strain`` (steady), ``hold_time`` (relaxation, creep), the largest of pre_periods /
    periods / post_periods (sweeps)."""
    room = _PROTOCOLS[p["protocol"]].room
    return room(p, detail, steps_ok) if room is not None else ("protocol", "a protocol of fewer steps")
