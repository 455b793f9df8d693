"""The one entry of a measurement: :func:`measure` runs a batch of one protocol and returns its results.

Every caller — :func:`~particleShear.run.api.doParticleShearSimulation` (a batch of one),
:func:`~particleShear.run.batch.run_batch`, and through them the series and sweeps — measures
through :func:`measure`, which builds each checked run's session
(:class:`~particleShear.run.validation.RunParameters`, made once per run by
:func:`~particleShear.run.validation.validated_run`;
:func:`~particleShear.run.sessions.build_sessions`) and hands them to the one measurement driver,
:func:`~particleShear.simulation.driver.measure_sessions`, whatever their protocol: the driver
chooses the protocol's part from the protocol registry.  This module gives it what lies above the
simulation layer (:data:`CONCLUSION`: the result type, the protocols' analysis, their file).
``measure_batch`` and ``measure_rheometer`` (the two drivers of before) are deprecated names of
:func:`measure`.
"""
__docformat__ = "numpy"
import warnings

from ..simulation.driver import Conclusion, measure_sessions
from . import sessions as _sessions
from .result import SimulationResult
from .rheometer_analysis import analyse_record, analyse_sweep
from .rheometer_files import write_protocol_file

__all__ = ["CONCLUSION", "measure", "measure_batch", "measure_rheometer"]

#: what the driver needs of the layers above it to make a replica's result: the one result type,
#: the analysis of a recorded protocol and of a sweep, the file of a protocol other than "oscillatory"
CONCLUSION = Conclusion(result=SimulationResult, analyse_record=analyse_record, analyse_sweep=analyse_sweep,
                        write=write_protocol_file)


def measure(runs):
    """Constitute, pre-equilibrate and measure runs that share a protocol and a step schedule.

    Parameters
    ----------
    runs : list of RunParameters
        The checked arguments of the runs (:func:`~particleShear.run.validation.validated_run`:
        complete, normalized, with their seed and run id), each read as it is by its session.

    Returns
    -------
    list of SimulationResult
        One per run, in order; each records its normalized arguments in ``parameters``.
    """
    # the sessions module's builder, looked up on call (a test replaces it to check that nothing is built)
    _, _, sessions = _sessions.build_sessions(runs)
    return measure_sessions(sessions, conclusion=CONCLUSION)


def _deprecated(name):
    """The deprecated name ``name`` of :func:`measure` (one of the two drivers of before)."""
    def alias(runs):
        warnings.warn(f"{name} is deprecated: run.measurement.measure measures every protocol",
                      DeprecationWarning, stacklevel=2)
        return measure(runs)
    alias.__name__ = alias.__qualname__ = name
    alias.__doc__ = """Deprecated: :func:`measure` (every protocol's runs, "oscillatory" included).

    Parameters
    ----------
    runs : list of RunParameters

    Returns
    -------
    list of SimulationResult
    """
    return alias


#: deprecated names of :func:`measure`: the drivers of "oscillatory" and of the other protocols of 2.x
measure_batch = _deprecated("measure_batch")
measure_rheometer = _deprecated("measure_rheometer")
