"""Model constants from physical properties: radius, mass, spring constant, time constant.

Units are those of the engine (docs/design.md): lengths in µm (1 canvas pixel = 1 µm), masses in mg
per metre of cylinder depth, spring constants in mg·s⁻² per metre of depth; the Young modulus is in Pa
and the density in kg/m³.  The spring constant is eq. S1-8 of the manual, the radii eq. S1-14.
"""
__docformat__ = "numpy"
import math

from ..base.points import _check_finite, _check_positive

__all__ = ["r_estimate", "adjust_m", "particle_shear_model_parameters"]


def r_estimate(size_x, size_y, packing_fraction, N, bimodal_upper=1.2, bimodal_lower=0.8):
    """Mean radius of N discs whose expected total area fills ``packing_fraction · size_x · size_y`` (eq. S1-14).

    Each disc has radius ``r·bimodal_upper`` or ``r·bimodal_lower`` with probability 1/2, so
    ``r = sqrt(size_x·size_y·packing_fraction / (N·π) · 2 / (bimodal_upper² + bimodal_lower²))``.
    The ensembles call it with ``bimodal_upper = √bf`` and ``bimodal_lower = 1/√bf`` for the
    bimodal factor ``bf`` (the large/small radius ratio).

    Parameters
    ----------
    size_x, size_y : float
        Width and height of the periodic cell (µm), > 0.
    packing_fraction : float
        Nominal (uncompressed) area fraction φ of the discs, > 0 (typically 1-2).
    N : int
        Number of discs, >= 1.
    bimodal_upper, bimodal_lower : float, optional
        Factors of the large and the small radius relative to the returned radius (dimensionless).

    Returns
    -------
    float
        The radius ``r`` (µm).
    """
    return math.sqrt(size_x * size_y * packing_fraction / N / math.pi
                     / (bimodal_upper ** 2 + bimodal_lower ** 2) * 2)


def adjust_m(m, r_actual, r_mean):
    """Mass of a disc of radius ``r_actual`` when a disc of radius ``r_mean`` has mass ``m``.

    The mass scales with the disc area: ``m · r_actual² / r_mean²`` (the multiplication order
    reproduces the masses of particleShear 1.0.2 bit for bit).

    Parameters
    ----------
    m : float
        Mass of a disc of radius ``r_mean`` (mg per metre of depth).
    r_actual : float
        Radius of the disc whose mass is wanted (µm).
    r_mean : float
        Radius of the reference disc (µm), > 0.

    Returns
    -------
    float
        The mass (mg per metre of depth).
    """
    return m * r_actual * r_actual / r_mean / r_mean  # this order reproduces the reference masses exactly


class particle_shear_model_parameters:
    """Radius, mass, spring constant and time constant of the model, from the physical properties.

    The builders derive every constant of an ensemble from these (see docs/parameters.md).  The
    inputs are stored under their own names; the derived attributes are

    * ``size_x_m``, ``size_y_m``: the cell size in m;
    * ``r``: :func:`r_estimate` with ``bimodal_upper = √bimodal_factor``, ``bimodal_lower = 1/√bimodal_factor``
      (µm), and ``r_m`` the same in m;
    * ``m = π · r_m² · density · 1e6``: the mass of a disc of radius ``r`` (mg per metre of depth);
    * ``k = π/8 · Young_modulus_spheres · 1e6``: the contact spring constant of two parallel
      cylinders (eq. S1-8; mg·s⁻² per metre of depth);
    * ``time_constant = sqrt(m/k) / sqrt(max(bimodal_factor, 1/bimodal_factor))`` (s).

    Parameters
    ----------
    size_x, size_y : float, optional
        Width and height of the periodic cell (µm), > 0.
    N : int, optional
        Number of spheres, >= 1.
    packing_fraction : float, optional
        Nominal area fraction φ of the spheres (eq. S1-14), > 0.
    Young_modulus_spheres : float, optional
        Young modulus E of the sphere material (Pa), > 0.
    density : float, optional
        Density of the sphere material (kg/m³), > 0.
    bimodal_factor : float, optional
        Ratio of the large to the small radius, > 0 (the builders pass 1).

    Raises
    ------
    ValueError
        If a parameter is out of its range (the message names it and its value).
    """

    def __init__(self, size_x=500, size_y=500, N=100, packing_fraction=1, Young_modulus_spheres=10000,
                 density=50, bimodal_factor=1):
        _check_positive("size_x", size_x)
        _check_positive("size_y", size_y)
        if int(N) != N or N < 1:
            raise ValueError(f"N must be a positive integer, got {N!r}")
        _check_positive("packing_fraction", packing_fraction)
        _check_positive("Young_modulus_spheres", Young_modulus_spheres)
        _check_positive("density", density)
        _check_positive("bimodal_factor", bimodal_factor)
        self.bimodal_factor = bimodal_factor
        self.size_x = size_x
        self.size_y = size_y
        self.N = N
        self.packing_fraction = packing_fraction
        self.Young_modulus_spheres = Young_modulus_spheres
        self.density = density
        self.size_x_m = size_x / 1e6
        self.size_y_m = size_y / 1e6
        self.r = r_estimate(size_x, size_y, packing_fraction, N, bimodal_upper=math.sqrt(bimodal_factor),
                            bimodal_lower=1 / math.sqrt(bimodal_factor))
        self.r_m = self.r / 1e6
        self.m = math.pi * self.r_m ** 2 * density * 1e6
        self.k = math.pi / 8 * Young_modulus_spheres * 1e6
        self.time_constant = math.sqrt(self.m / self.k) / math.sqrt(max(bimodal_factor, 1 / bimodal_factor))
