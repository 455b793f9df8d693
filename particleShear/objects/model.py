"""Model constants from physical properties (µm, mg per m depth, mg·s⁻² per m depth, Pa, kg/m³).

Spring constant: eq. S1-8; radii: eq. S1-14.
"""
__docformat__ = "numpy"
import math

from ..checks import integer, positive as _check_positive

__all__ = ["r_estimate", "adjust_m", "particle_shear_model_parameters"]


def r_estimate(size_x, size_y, packing_fraction, N, bimodal_upper=1.2, bimodal_lower=0.8):
    """Mean radius r (µm) of N discs that fill ``packing_fraction·size_x·size_y`` on average (eq. S1-14).

    Parameters
    ----------
    size_x, size_y : float
        Cell size (µm), > 0.
    packing_fraction : float
        Nominal area fraction φ, > 0.
    N : int
        Number of discs, >= 1.
    bimodal_upper, bimodal_lower : float, optional
        Radii ``r·bimodal_upper``, ``r·bimodal_lower`` (probability 1/2 each); the ensembles pass √bf, 1/√bf.
    """
    return math.sqrt(size_x * size_y * packing_fraction / N / math.pi
                     / (bimodal_upper ** 2 + bimodal_lower ** 2) * 2)


def adjust_m(m, r_actual, r_mean):
    """Mass ``m·r_actual²/r_mean²`` of a disc of radius ``r_actual`` when one of ``r_mean`` has mass ``m``.

    Parameters
    ----------
    m : float
        Mass of the reference disc (mg per m depth).
    r_actual, r_mean : float
        Radius of the disc and of the reference disc (µm), ``r_mean`` > 0.
    """
    return m * r_actual * r_actual / r_mean / r_mean  # this order reproduces the reference masses exactly


class particle_shear_model_parameters:
    """Radius, mass, spring constant and time constant of the model (docs/parameters.md).

    Inputs are stored under their own names (ValueError when out of range); derived: ``size_x_m``,
    ``size_y_m`` (m); ``r`` (:func:`r_estimate` with √bimodal_factor, 1/√bimodal_factor; µm) and
    ``r_m`` (m); ``m = π·r_m²·density·1e6``; ``k = π/8·Young_modulus_spheres·1e6`` (eq. S1-8);
    ``time_constant = sqrt(m/k)/sqrt(max(bimodal_factor, 1/bimodal_factor))`` (s).

    Parameters
    ----------
    size_x, size_y : float, optional
        Cell size (µm), > 0.
    N : int, optional
        Number of spheres, >= 1.
    packing_fraction : float, optional
        Nominal area fraction φ (eq. S1-14), > 0.
    Young_modulus_spheres, density : float, optional
        Young modulus E (Pa) and density (kg/m³) of the sphere material, > 0.
    bimodal_factor : float, optional
        Large/small radius ratio, > 0 (the builders pass 1).
    """

    def __init__(self, size_x=500, size_y=500, N=100, packing_fraction=1, Young_modulus_spheres=10000,
                 density=50, bimodal_factor=1):
        inputs = dict(size_x=size_x, size_y=size_y, N=N, packing_fraction=packing_fraction,
                      Young_modulus_spheres=Young_modulus_spheres, density=density, bimodal_factor=bimodal_factor)
        for name, value in inputs.items():
            if name == "N":
                integer(name, value, 1)
            else:
                _check_positive(name, value)
        vars(self).update(inputs)
        self.size_x_m, self.size_y_m = size_x / 1e6, size_y / 1e6
        self.r = r_estimate(size_x, size_y, packing_fraction, N, bimodal_upper=math.sqrt(bimodal_factor),
                            bimodal_lower=1 / math.sqrt(bimodal_factor))
        self.r_m = self.r / 1e6
        self.m = math.pi * self.r_m ** 2 * density * 1e6
        self.k = math.pi / 8 * Young_modulus_spheres * 1e6
        self.time_constant = math.sqrt(self.m / self.k) / math.sqrt(max(bimodal_factor, 1 / bimodal_factor))
