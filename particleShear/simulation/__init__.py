"""Layer 4: evaluation handlers, the oscillatory shear experiment, simulation classes, output and drawing.

Importing this package imports neither Pillow nor tkinter; they are loaded only when
something is drawn or saved (see :mod:`particleShear.simulation.drawing`).
"""
__docformat__ = "numpy"
from .evaluation import EvaluationHandler, EvaluationHandlerPlotter, demodulation  # noqa: F401
from .experiment import OscillatoryShearExperiment
from .formats import OUTPUT_FORMATS, RunData, RunFileError, read_run, verify_run
from .microstructure_pictures import microstructure_pictures
from .provenance import run_identity
from .simulations import (OscillatorySimulation, OscillatorySimulationFragmentation,
                          Simulation_dermal_filler_rheology, Simulation_interlocking_rheology)

__all__ = ["EvaluationHandler", "EvaluationHandlerPlotter", "OscillatoryShearExperiment", "OscillatorySimulation",
           "OscillatorySimulationFragmentation", "Simulation_dermal_filler_rheology",
           "Simulation_interlocking_rheology", "read_run", "verify_run", "RunData", "RunFileError", "OUTPUT_FORMATS",
           "run_identity", "microstructure_pictures"]
