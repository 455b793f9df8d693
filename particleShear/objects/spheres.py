"""Concrete non-crosslinkable spheres: frictionless or frictional, with or without Lees-Edwards geometry.

These are the sphere classes of particleShear 1.0.2 (public API).  The ensembles create them; a
sphere created alone keeps its own state and computes its pair forces with the engine's terms
evaluated on the pair (base/points.py).
Lengths are in µm, masses in mg per metre of depth (docs/design.md).
"""
__docformat__ = "numpy"
from ..base.points import CircleBasicElasticity, CircleFrictionElasticity

__all__ = ["Sphere", "SphereLeesEdwards", "SphereFriction", "SphereFrictionLeesEdwards"]


class Sphere(CircleBasicElasticity):
    """Frictionless sphere without Lees-Edwards geometry (legacy).

    Central elastic and viscous contact forces only (eq. S1-5a/b).

    Parameters
    ----------
    color : str
        Fill colour of the disc in drawings (a Tk/Pillow colour name).
    x, y : float
        Initial position of the centre (µm).
    diameter : float
        Diameter of the disc (µm), > 0.
    m : float, optional
        Mass (mg per metre of depth); the moment of inertia is ``m·r²/2``.
    my_index : int, optional
        Index of the sphere in its ensemble (its creation index).
    theCanvas : tkinter.Canvas or False, optional
        Canvas of the live drawing, False for none.
    doDrawing : bool, optional
        Whether the sphere draws itself on ``theCanvas``.
    force_register : object or None, optional
        Receiver of the recorded forces (the ensemble, for the stress tensors); None creates a
        private ``Force_register``.
    """

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None):
        CircleBasicElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register)
        self.myindex = my_index


class SphereLeesEdwards(CircleBasicElasticity):
    """Frictionless sphere in a Lees-Edwards cell of ``size_x × size_y`` µm.

    (The NameError of particleShear 1.0.2 on construction is fixed; the index keeps its 1.0.2
    spelling ``myindex``.)

    Parameters
    ----------
    color : str
        Fill colour of the disc in drawings (a Tk/Pillow colour name).
    x, y : float
        Initial position of the centre (µm).
    diameter : float
        Diameter of the disc (µm), > 0.
    m : float, optional
        Mass (mg per metre of depth); the moment of inertia is ``m·r²/2``.
    myindex : int, optional
        Index of the sphere in its ensemble (its creation index).
    theCanvas : tkinter.Canvas or False, optional
        Canvas of the live drawing, False for none.
    doDrawing : bool, optional
        Whether the sphere draws itself on ``theCanvas``.
    force_register : object or None, optional
        Receiver of the recorded forces (the ensemble, for the stress tensors); None creates a
        private ``Force_register``.
    size_x, size_y : float, optional
        Width and height of the Lees-Edwards cell (µm).
    """

    def __init__(self, color, x, y, diameter, m=1, myindex=1, theCanvas=False, doDrawing=False,
                 force_register=None, size_x=500, size_y=500):
        CircleBasicElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register,
                                       use_lees_edwards=True)
        self.myindex = myindex
        self.size_x = size_x
        self.size_y = size_y


class SphereFriction(CircleFrictionElasticity):
    """Frictional sphere without Lees-Edwards geometry (legacy).

    Central and tangential (Coulomb friction) contact forces.

    Parameters
    ----------
    color : str
        Fill colour of the disc in drawings (a Tk/Pillow colour name).
    x, y : float
        Initial position of the centre (µm).
    diameter : float
        Diameter of the disc (µm), > 0.
    m : float, optional
        Mass (mg per metre of depth); the moment of inertia is ``m·r²/2``.
    my_index : int, optional
        Index of the sphere in its ensemble (its creation index).
    theCanvas : tkinter.Canvas or False, optional
        Canvas of the live drawing, False for none.
    doDrawing : bool, optional
        Whether the sphere draws itself on ``theCanvas``.
    force_register : object or None, optional
        Receiver of the recorded forces (the ensemble, for the stress tensors); None creates a
        private ``Force_register``.
    """

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None):
        CircleFrictionElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register)
        self.myindex = my_index


class SphereFrictionLeesEdwards(CircleFrictionElasticity):
    """Frictional sphere in a Lees-Edwards cell of ``size_x × size_y`` µm.

    Central and tangential (Coulomb friction) contact forces; the sphere used by the simulations.

    Parameters
    ----------
    color : str
        Fill colour of the disc in drawings (a Tk/Pillow colour name).
    x, y : float
        Initial position of the centre (µm).
    diameter : float
        Diameter of the disc (µm), > 0.
    m : float, optional
        Mass (mg per metre of depth); the moment of inertia is ``m·r²/2``.
    my_index : int, optional
        Index of the sphere in its ensemble (its creation index).
    theCanvas : tkinter.Canvas or False, optional
        Canvas of the live drawing, False for none.
    doDrawing : bool, optional
        Whether the sphere draws itself on ``theCanvas``.
    force_register : object or None, optional
        Receiver of the recorded forces (the ensemble, for the stress tensors); None creates a
        private ``Force_register``.
    size_x, size_y : float, optional
        Width and height of the Lees-Edwards cell (µm).
    """

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None, size_x=500, size_y=500):
        CircleFrictionElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing,
                                          force_register, use_lees_edwards=True)
        self.myindex = my_index
        self.size_x = size_x
        self.size_y = size_y
