"""The one entry of a measurement: :func:`measure` runs a batch of one protocol and returns its results.

Every caller — :func:`~particleShear.run.api.doParticleShearSimulation` (a batch of one),
:func:`~particleShear.run.batch.run_batch`, and through them the series and sweeps — measures
through :func:`measure`, which normalizes the runs (:func:`~particleShear.run.rheometer.normalize_protocol`)
and hands them to their protocol's driver: the oscillatory protocol's
(:func:`~particleShear.run.sessions.measure_batch`: the documented run's phases, its output file and
snapshots) or every other protocol's (:func:`~particleShear.run.rheometer.measure_rheometer`: the
same sessions, constitution and pre-equilibration, then the protocol's rate schedule).  Either
returns one :class:`~particleShear.run.result.SimulationResult` per run.
"""
__docformat__ = "numpy"

from .rheometer import measure_rheometer, normalize_protocol
from .sessions import measure_batch

__all__ = ["measure"]

#: the driver of a protocol that has its own (every other protocol: ``measure_rheometer``)
_DRIVERS = {"oscillatory": measure_batch}


def measure(runs):
    """Constitute, pre-equilibrate and measure runs that share a protocol and a step schedule.

    Parameters
    ----------
    runs : list of dict
        Complete, validated keyword dicts of the runs (every argument of
        :func:`~particleShear.run.api.doParticleShearSimulation`, defaults filled in).

    Returns
    -------
    list of SimulationResult
        One per run, in order; each records its normalized arguments in ``parameters``.
    """
    runs = [normalize_protocol(kw) for kw in runs]
    return _DRIVERS.get(runs[0]["protocol"], measure_rheometer)(runs)
