"""The one entry of a measurement: :func:`measure` runs a batch of one protocol and returns its results.

Every caller — :func:`~particleShear.run.api.doParticleShearSimulation` (a batch of one),
:func:`~particleShear.run.batch.run_batch`, and through them the series and sweeps — measures
through :func:`measure`, which hands the checked runs
(:class:`~particleShear.run.validation.RunParameters`, made once per run by
:func:`~particleShear.run.validation.validated_run`) unchanged to their protocol's driver: the oscillatory protocol's
(:func:`~particleShear.run.sessions.measure_batch`: the documented run's phases, its output file and
snapshots) or every other protocol's (:func:`~particleShear.run.rheometer.measure_rheometer`: the
same sessions, constitution and pre-equilibration, then the protocol's rate schedule).  Either
returns one :class:`~particleShear.run.result.SimulationResult` per run.
"""
__docformat__ = "numpy"

from .rheometer import measure_rheometer
from .sessions import measure_batch

__all__ = ["measure"]

#: the driver of a protocol that has its own (every other protocol: ``measure_rheometer``)
_DRIVERS = {"oscillatory": measure_batch}


def measure(runs):
    """Constitute, pre-equilibrate and measure runs that share a protocol and a step schedule.

    Parameters
    ----------
    runs : list of RunParameters
        The checked arguments of the runs (:func:`~particleShear.run.validation.validated_run`:
        complete, normalized, with their seed and run id), handed to the driver as they are.

    Returns
    -------
    list of SimulationResult
        One per run, in order; each records its normalized arguments in ``parameters``.
    """
    return _DRIVERS.get(runs[0]["protocol"], measure_rheometer)(runs)
