"""Drawing options shared by an ensemble and its spheres (see docs/output.md for the images)."""
__docformat__ = "numpy"

__all__ = ["Graphical_output_configuration"]


class Graphical_output_configuration:
    """Colours and switches of the particle drawing; every argument is stored under its own name.

    Colours are Tk/Pillow colour names (e.g. ``"grey"``, ``"darkorchid"``).  Some options
    (``color_spheres_boundary``, ``draw_permanent_connections``, ``color_permanent_connections``,
    the volume and boundary forces, ``force_scale`` and the speeds) are stored for
    compatibility with particleShear 1.0.2 but the drawing does not use them: permanent links
    are always drawn as blue centre-to-centre lines (see docs/output.md).

    Parameters
    ----------
    draw_spheres_as : {"spheres", "dots", "none"}
        How a sphere is drawn: its disc outline, a dot of radius 2 pixels, or not at all.
    color_spheres_volume : str
        Colour of the sphere discs.
    color_spheres_boundary : str
        Colour of spheres touching the boundary (stored, not used).
    draw_rotation_line : bool
        Draw a radius marking each sphere's rotation angle φ.
    color_rotation_line : str
        Colour of the rotation line.
    draw_active_interface : bool
        Draw the contact chord of every touching pair (locked or slip colour by its state).
    color_interface_locked : str
        Colour of a sticking contact.
    color_interface_slip : str
        Colour of a slipping contact.
    draw_permanent_connections : bool
        Draw permanent links (stored; links are always drawn).
    color_permanent_connections : str
        Colour of permanent links (stored; links are drawn in blue).
    draw_permanent_interfaces : bool
        Draw the contact chord of permanent links (in dark orange).
    draw_volume_forces : bool
        Draw the volume forces (stored, not used).
    color_volume_forces : str
        Colour of the volume forces (stored, not used).
    draw_boundary_forces : bool
        Draw the forces on the plate spheres (stored, not used).
    color_boundary_forces : str
        Colour of the boundary forces (stored, not used).
    force_scale : float
        Scale of drawn force arrows (stored, not used).
    draw_speeds : bool
        Draw the velocities (stored, not used).
    color_speeds : str
        Colour of the velocities (stored, not used).

    Raises
    ------
    ValueError
        If ``draw_spheres_as`` is not one of the three allowed values.
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
        self.draw_spheres_as = draw_spheres_as
        self.color_spheres_volume = color_spheres_volume
        self.color_spheres_boundary = color_spheres_boundary
        self.draw_rotation_line = draw_rotation_line
        self.color_rotation_line = color_rotation_line
        self.draw_active_interface = draw_active_interface
        self.color_interface_locked = color_interface_locked
        self.color_interface_slip = color_interface_slip
        self.draw_permanent_connections = draw_permanent_connections
        self.color_permanent_connections = color_permanent_connections
        self.draw_permanent_interfaces = draw_permanent_interfaces
        self.draw_volume_forces = draw_volume_forces
        self.color_volume_forces = color_volume_forces
        self.draw_boundary_forces = draw_boundary_forces
        self.color_boundary_forces = color_boundary_forces
        self.force_scale = force_scale
        self.draw_speeds = draw_speeds
        self.color_speeds = color_speeds
