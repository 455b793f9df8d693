"""Layer 1: points, circles, pair physics, Lees-Edwards geometry, force register, stress tensors."""
__docformat__ = "numpy"
from .laws import (elastic_force_law, elastic_force_law_plateau, distance_transform_plateau,
                   PlateauConfiguration, elastic_force_law_tensile,
                   elastic_force_law_tensile_exponential, TensileConfiguration)
from .points import (Point, PointLeesEdwards, Circle, CircleMass, CircleMassNeighbors,
                     CircleBasicElasticity, CircleFrictionElasticity, dotProduct2)
from .relations import neighbor_relation
from .register import Force_register, SphereSelection
from .stress import StressTensorEvaluation
from .graphics import Graphical_output_configuration
from .stability import SimulationInstabilityError, StabilityGuard
from .canvas import (CanvasPoints, CanvasPointsMass, CanvasPointsNeighbors, CanvasPointsShear,
                     CanvasPointsBasicElasticity, CanvasPointsBasicElasticityLeesEdwards,
                     CanvasPointsFrictionElasticityLeesEdwards)

__all__ = [
    "elastic_force_law", "elastic_force_law_plateau", "distance_transform_plateau",
    "PlateauConfiguration", "elastic_force_law_tensile", "elastic_force_law_tensile_exponential",
    "TensileConfiguration", "Point", "PointLeesEdwards", "Circle", "CircleMass",
    "CircleMassNeighbors", "CircleBasicElasticity", "CircleFrictionElasticity", "dotProduct2",
    "neighbor_relation", "Force_register", "StressTensorEvaluation",
    "Graphical_output_configuration", "CanvasPoints", "CanvasPointsMass", "CanvasPointsNeighbors",
    "CanvasPointsShear", "CanvasPointsBasicElasticity", "CanvasPointsBasicElasticityLeesEdwards",
    "CanvasPointsFrictionElasticityLeesEdwards", "SimulationInstabilityError", "StabilityGuard",
]
