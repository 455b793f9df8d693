"""Layer 4: evaluation handlers, the oscillatory shear experiment, simulation classes, output and drawing.

Importing this package imports neither Pillow nor tkinter; they are loaded only when
something is drawn or saved (see :mod:`particleShear.simulation.drawing`).
"""
from .evaluation import EvaluationHandler, EvaluationHandlerPlotter, demodulation  # noqa: F401
from .experiment import OscillatoryShearExperiment
from .simulations import (OscillatorySimulation, OscillatorySimulationFragmentation,
                          Simulation_dermal_filler_rheology, Simulation_interlocking_rheology)

__all__ = ["EvaluationHandler", "EvaluationHandlerPlotter", "OscillatoryShearExperiment", "OscillatorySimulation",
           "OscillatorySimulationFragmentation", "Simulation_dermal_filler_rheology",
           "Simulation_interlocking_rheology"]
