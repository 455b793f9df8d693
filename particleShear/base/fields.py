"""Layout of the documented ensembles' per-sphere state block (fields × spheres), which a batch of
ensembles shares (:func:`particleShear.base.engine_adapter.state_of_ensembles`)."""
__docformat__ = "numpy"

import math

__all__ = ["FIELDS", "ROW"]

#: the per-sphere fields of a documented ensemble's state block (fields × spheres) and their defaults;
#: rows advanced or gathered together sit next to each other: (x, y, phi) are moved by
#: (xspeed, yspeed, omega)·dt in one pass, (xforce, yforce, torque) kicked in one pass
FIELDS = {
    "x": 0.0, "y": 0.0, "phi": -math.pi / 2, "xspeed": 0.0, "yspeed": 0.0, "omega": 0.0,
    "r": 1.0, "m": 1.0, "inertia": 0.5, "xforce": 0.0, "yforce": 0.0, "torque": 0.0,
    "central_repulsion_coefficient": 0.0, "permanent_ratio_central": 1.0,
    "permanent_ratio_tangential": 1.0, "keep_viscosity_coefficients_constant": 1.0,
}
#: row of each field in that block
ROW = {name: k for k, name in enumerate(FIELDS)}

