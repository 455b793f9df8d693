"""Concrete non-crosslinkable spheres of particleShear 1.0.2 (lengths µm, masses mg per m depth)."""
__docformat__ = "numpy"
from ..base.points import CircleBasicElasticity, CircleFrictionElasticity

__all__ = ["Sphere", "SphereLeesEdwards", "SphereFriction", "SphereFrictionLeesEdwards"]


class Sphere(CircleBasicElasticity):
    """Frictionless sphere without Lees-Edwards geometry (legacy): central contact forces (eq. S1-5a/b).

    Parameters
    ----------
    color, x, y, diameter, m, theCanvas, doDrawing, force_register
        As for :class:`~particleShear.base.circles.CircleMass` (and raising as it does).
    my_index : int, optional
        Index in the ensemble (stored as ``myindex``).
    """

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None):
        CircleBasicElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register)
        self.myindex = my_index


class SphereLeesEdwards(CircleBasicElasticity):
    """Frictionless sphere in a Lees-Edwards cell (constructible, unlike in 1.0.2).

    Parameters
    ----------
    color, x, y, diameter, m, theCanvas, doDrawing, force_register
        As for :class:`Sphere`.
    myindex : int, optional
        Index in the ensemble (the 1.0.2 spelling).
    size_x, size_y : float, optional
        Lees-Edwards cell (µm).
    """

    def __init__(self, color, x, y, diameter, m=1, myindex=1, theCanvas=False, doDrawing=False,
                 force_register=None, size_x=500, size_y=500):
        CircleBasicElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register,
                                       use_lees_edwards=True)
        self.myindex, self.size_x, self.size_y = myindex, size_x, size_y


class SphereFriction(CircleFrictionElasticity):
    """Frictional sphere without Lees-Edwards geometry (legacy): central and tangential (Coulomb) forces.

    Parameters
    ----------
    color, x, y, diameter, m, my_index, theCanvas, doDrawing, force_register
        As for :class:`Sphere`.
    """

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None):
        CircleFrictionElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register)
        self.myindex = my_index


class SphereFrictionLeesEdwards(CircleFrictionElasticity):
    """Frictional sphere in a Lees-Edwards cell: the sphere of the simulations.

    Parameters
    ----------
    color, x, y, diameter, m, my_index, theCanvas, doDrawing, force_register
        As for :class:`Sphere`.
    size_x, size_y : float, optional
        Lees-Edwards cell (µm).
    """

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None, size_x=500, size_y=500):
        CircleFrictionElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing,
                                          force_register, use_lees_edwards=True)
        self.myindex, self.size_x, self.size_y = my_index, size_x, size_y
