"""Simulation classes: ensemble construction + experiment + output file (docs/output.md).

:class:`OscillatorySimulation` and its :class:`RunSession` (:mod:`.oscillatory`) and the classes of
crosslinked ensembles cut into particles (:mod:`.fragmentation`), gathered here (each subclass
module imports the module of its base class, never this one).
"""
__docformat__ = "numpy"
from .oscillatory import MeasurementSchedule, OscillatorySimulation, RunSession, check_output_folder
from .fragmentation import (OscillatorySimulationFragmentation, Simulation_dermal_filler_rheology,
                            Simulation_interlocking_rheology)

__all__ = ["MeasurementSchedule", "RunSession", "OscillatorySimulation", "OscillatorySimulationFragmentation",
           "Simulation_dermal_filler_rheology", "Simulation_interlocking_rheology", "check_output_folder"]
