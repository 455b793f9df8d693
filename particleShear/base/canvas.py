"""Canvases: the ensemble's state arrays and the documented step (docs/classes.md, "The documented classes").

Each class adds one capability: points and ``sphereList``, mass and force register (:mod:`.canvas_base`),
pair table, Lees-Edwards shear and plates (:mod:`.pair_canvas`), central forces and the step, shear-rate
changes, friction and spin (:mod:`.elastic_canvas`).  This module gathers them (each subclass module
imports the module of its base class, never this one).
"""
__docformat__ = "numpy"
from .canvas_base import (MAX_CELLS_OUTSIDE, CanvasPoints, CanvasPointsMass, NonNegative, ReplicaValue,  # noqa: F401
                          SphereList, check_non_negative, check_time_step)
from .pair_canvas import CanvasPointsNeighbors, CanvasPointsShear
from .elastic_canvas import (CanvasPointsBasicElasticity, CanvasPointsBasicElasticityLeesEdwards,
                             CanvasPointsFrictionElasticityLeesEdwards)

__all__ = ["CanvasPoints", "CanvasPointsMass", "CanvasPointsNeighbors", "CanvasPointsShear",
           "CanvasPointsBasicElasticity", "CanvasPointsBasicElasticityLeesEdwards",
           "CanvasPointsFrictionElasticityLeesEdwards", "SphereList", "check_non_negative", "check_time_step"]
