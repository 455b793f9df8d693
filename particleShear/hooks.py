"""The named entry points of higher layers that a lower module calls (late binding).

A module imports only its own and lower layers (:mod:`particleShear.layers`).  Three calls go the
other way by design: a result's ``plot()`` draws with the plots layer (an optional layer, backed by
matplotlib), and ``doParticleShearSimulationSeries`` of the run layer hands its runs to the sweep
layer's executor.  They are named here, as ``"module:function"``, and resolved at call time with
:func:`entry` — no import statement, so the import graph keeps its layers, and this table is the
one list of such calls.
"""
__docformat__ = "numpy"
import importlib

__all__ = ["ENTRY_POINTS", "entry"]

#: name → ``"module:function"`` of a higher layer
ENTRY_POINTS = {
    "plot_result": "particleShear.plot:plot_result",
    "plot_rheometer_result": "particleShear.rheometer_plot:plot_rheometer_result",
    "run_series": "particleShear.sweep.series:run_series",
}


def entry(name):
    """The function of the entry point ``name``, imported on use.

    Parameters
    ----------
    name : str
        A key of :data:`ENTRY_POINTS`.

    Returns
    -------
    callable
    """
    module, _, function = ENTRY_POINTS[name].partition(":")
    return getattr(importlib.import_module(module), function)
