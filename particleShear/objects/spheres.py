"""Concrete non-crosslinkable spheres (spec §10.4)."""
from ..base.points import CircleBasicElasticity, CircleFrictionElasticity

__all__ = ["Sphere", "SphereLeesEdwards", "SphereFriction", "SphereFrictionLeesEdwards"]


class Sphere(CircleBasicElasticity):
    """Frictionless sphere without Lees-Edwards geometry (legacy)."""

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None):
        CircleBasicElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register)
        self.myindex = my_index


class SphereLeesEdwards(CircleBasicElasticity):
    """Frictionless sphere in a Lees-Edwards cell (the reference's NameError on construction is fixed)."""

    def __init__(self, color, x, y, diameter, m=1, myindex=1, theCanvas=False, doDrawing=False,
                 force_register=None, size_x=500, size_y=500):
        CircleBasicElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register,
                                       use_lees_edwards=True)
        self.myindex = myindex
        self.size_x = size_x
        self.size_y = size_y


class SphereFriction(CircleFrictionElasticity):
    """Frictional sphere without Lees-Edwards geometry (legacy)."""

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None):
        CircleFrictionElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register)
        self.myindex = my_index


class SphereFrictionLeesEdwards(CircleFrictionElasticity):
    """Frictional sphere in a Lees-Edwards cell of ``size_x × size_y`` µm."""

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None, size_x=500, size_y=500):
        CircleFrictionElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing,
                                          force_register, use_lees_edwards=True)
        self.myindex = my_index
        self.size_x = size_x
        self.size_y = size_y
