"""Layout of the documented ensembles' per-sphere state block (fields × spheres) and of their replica
cells (clock, strain, rate, μ), which a batch of ensembles shares
(:func:`particleShear.base.engine_adapter.state_of_ensembles`)."""
__docformat__ = "numpy"

import math

__all__ = ["FIELDS", "ROW", "REPLICA_FIELDS", "REPLICA_ROW"]

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

#: the per-replica values an ensemble holds in its replica cells (one float each), by attribute, and
#: the :class:`~particleShear.engine.state.BatchState` array whose element the cell is in a batch:
#: clock ``t`` (s), strain ``shear`` (γ), rate ``shear_rate`` (γ̇, 1/s), friction coefficient ``mu``
REPLICA_FIELDS = {"t": "t", "shear": "gamma", "shear_rate": "rate", "mu": "mu"}
#: cell of each value in the replica cells
REPLICA_ROW = {name: k for k, name in enumerate(REPLICA_FIELDS)}
