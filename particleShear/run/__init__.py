"""Layer 5: ``doParticleShearSimulation``, ``doParticleShearSimulationSeries`` and the command line."""
__docformat__ = "numpy"
from .api import SimulationResult, doParticleShearSimulation, doParticleShearSimulationSeries
from .batch import run_batch
from .guard import UnknownParameterError

__all__ = ["doParticleShearSimulation", "doParticleShearSimulationSeries", "SimulationResult", "run_batch",
           "UnknownParameterError"]
