"""Layer 3: permanent links, compact particles, cutting, builders."""
__docformat__ = "numpy"
from .spheres import neighbor_relation_linkable, SphereLinkable, SphereLinkableAdjustableInterfaceStrength
from .canvas import CanvasPointsLinkable, EnsembleLinkable
from .compact import EnsembleCompactParticles, EnsembleCompactParticlesAdjustableInterfaceStrength
from .builders import (EnsembleCompactParticlesFromModelParameters,
                       EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters)

__all__ = ["neighbor_relation_linkable", "SphereLinkable", "SphereLinkableAdjustableInterfaceStrength",
           "CanvasPointsLinkable", "EnsembleLinkable", "EnsembleCompactParticles",
           "EnsembleCompactParticlesAdjustableInterfaceStrength", "EnsembleCompactParticlesFromModelParameters",
           "EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters"]
