"""Drawing options shared by an ensemble and its spheres (see docs/output.md for the images)."""
__docformat__ = "numpy"

__all__ = ["Graphical_output_configuration", "HANDLES", "headless"]

#: the attributes of an ensemble or a sphere that hold a live window's handles (the Tk canvas of 1.0.2's
#: scripts, the Tk root, the renderer), each with its value when there is no window
HANDLES = {"theCanvas": False, "theTkSimulation": False, "_renderer": None}


def headless(state):
    """``state``, an object's attribute dict, with its window handles (:data:`HANDLES`) set to no window.

    A handle belongs to the process and the window that made it: it can be neither copied nor
    pickled, and a copy of an ensemble or a sphere draws nowhere (it is headless).

    Parameters
    ----------
    state : dict
        The attributes (left unchanged).

    Returns
    -------
    dict
        A new dict: ``state`` with the handles it has replaced.
    """
    return {**state, **{name: value for name, value in HANDLES.items() if name in state}}


class Graphical_output_configuration:
    """Colours (Tk/Pillow names) and switches of the particle drawing; each argument is stored under its name.

    Parameters
    ----------
    draw_spheres_as : {"spheres", "dots", "none"}
        Disc outline, a dot of radius 2 pixels, or nothing (another value: ValueError).
    color_spheres_volume : str
        Colour of the sphere discs.
    draw_rotation_line, color_rotation_line : bool, str
        Draw a radius marking each sphere's angle φ, in this colour.
    draw_active_interface : bool
        Draw the contact chord of every touching pair.
    color_interface_locked, color_interface_slip : str
        Chord colour of a sticking and of a slipping contact.
    draw_permanent_interfaces : bool
        Draw the contact chord of permanent links (in dark orange).

    Other Parameters
    ----------------
    color_spheres_boundary, draw_permanent_connections, color_permanent_connections : optional
        Stored for 1.0.2 compatibility, not used: links are always drawn as blue centre lines.
    draw_volume_forces, color_volume_forces, draw_boundary_forces, color_boundary_forces : optional
    force_scale, draw_speeds, color_speeds : optional
        Stored, not used.
    """

    def __init__(self, draw_spheres_as="spheres", color_spheres_volume="grey",
                 color_spheres_boundary="green", draw_rotation_line=False, color_rotation_line="black",
                 draw_active_interface=True, color_interface_locked="red", color_interface_slip="green",
                 draw_permanent_connections=True, color_permanent_connections="blue",
                 draw_permanent_interfaces=False, draw_volume_forces=False,
                 color_volume_forces="darkorchid", draw_boundary_forces=False,
                 color_boundary_forces="darkorchid", force_scale=1000, draw_speeds=False,
                 color_speeds="black"):
        if draw_spheres_as not in ("spheres", "dots", "none"):
            raise ValueError(f"draw_spheres_as must be 'spheres', 'dots' or 'none', got {draw_spheres_as!r}")
        for name, value in list(locals().items())[1:]:   # every argument under its own name, in order
            setattr(self, name, value)
