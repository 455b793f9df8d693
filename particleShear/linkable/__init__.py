"""Layer 3: permanent links, compact particles, cutting, builders."""
__docformat__ = "numpy"
from .spheres import neighbor_relation_linkable, SphereLinkable, SphereLinkableAdjustableInterfaceStrength
from .canvas import CanvasPointsLinkable, EnsembleLinkable

__all__ = ["neighbor_relation_linkable", "SphereLinkable", "SphereLinkableAdjustableInterfaceStrength",
           "CanvasPointsLinkable", "EnsembleLinkable"]

try:  # compact particles and builders (filled in by their own modules)
    from .compact import EnsembleCompactParticles, EnsembleCompactParticlesAdjustableInterfaceStrength
    from .builders import (EnsembleCompactParticlesFromModelParameters,
                           EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters)
    __all__ += ["EnsembleCompactParticles", "EnsembleCompactParticlesAdjustableInterfaceStrength",
                "EnsembleCompactParticlesFromModelParameters",
                "EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters"]
except ImportError:  # pragma: no cover - during development only
    pass
