"""Points and circles, the per-sphere API (docs/classes.md, "The documented classes").

:class:`Point` and :class:`PointLeesEdwards` (:mod:`.point_base`), :class:`Circle`, :class:`CircleMass`,
:class:`CircleMassNeighbors` (:mod:`.circles`), :class:`CircleBasicElasticity` and
:class:`CircleFrictionElasticity` (:mod:`.elastic_circles`).  This module gathers them (each subclass
module imports the module of its base class, never this one).
"""
__docformat__ = "numpy"
from .point_base import ArrayField, EnsembleField, Point, PointLeesEdwards, dotProduct2  # noqa: F401
from .circles import Circle, CircleMass, CircleMassNeighbors
from .elastic_circles import CircleBasicElasticity, CircleFrictionElasticity

__all__ = ["Point", "PointLeesEdwards", "Circle", "CircleMass", "CircleMassNeighbors",
           "CircleBasicElasticity", "CircleFrictionElasticity", "ArrayField", "dotProduct2"]
