"""Layer 2: concrete spheres and ensembles, model constants."""
__docformat__ = "numpy"
from .model import r_estimate, adjust_m, particle_shear_model_parameters
from .spheres import Sphere, SphereLeesEdwards, SphereFriction, SphereFrictionLeesEdwards
from .ensembles import Ensemble, EnsembleFriction, EnsembleLeesEdwards, EnsembleFrictionLeesEdwards

__all__ = ["r_estimate", "particle_shear_model_parameters", "Sphere", "SphereLeesEdwards",
           "SphereFriction", "SphereFrictionLeesEdwards", "Ensemble", "EnsembleFriction",
           "EnsembleLeesEdwards", "EnsembleFrictionLeesEdwards"]
