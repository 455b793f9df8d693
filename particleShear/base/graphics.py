"""Drawing options shared by an ensemble and its spheres (spec §10.7)."""

__all__ = ["Graphical_output_configuration"]


class Graphical_output_configuration:
    """Colours and switches of the particle drawing; every argument is stored under its own name."""

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
