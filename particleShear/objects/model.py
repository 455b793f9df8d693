"""Model constants from physical properties (spec §5)."""
import math

from ..base.points import _check_finite, _check_positive

__all__ = ["r_estimate", "adjust_m", "particle_shear_model_parameters"]


def r_estimate(size_x, size_y, packing_fraction, N, bimodal_upper=1.2, bimodal_lower=0.8):
    """Mean radius (µm) of N discs, radii ``r·upper`` or ``r·lower`` with equal probability, filling φ·Lx·Ly."""
    return math.sqrt(size_x * size_y * packing_fraction / N / math.pi
                     / (bimodal_upper ** 2 + bimodal_lower ** 2) * 2)


def adjust_m(m, r_actual, r_mean):
    """Mass scaled with the disc area: ``m · r_actual² / r_mean²``."""
    return m * r_actual * r_actual / r_mean / r_mean  # this order reproduces the reference masses exactly


class particle_shear_model_parameters:
    """Radius (µm), mass (mg/m), spring constant (mg·s⁻²/m, eq. S1-8) and time constant (s) of the model."""

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
