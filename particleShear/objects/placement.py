"""The placement of a random bimodal packing on arrays (lengths µm, masses mg per m depth).

:func:`bimodal_placement` is the one implementation: the documented ensembles'
``_create_spheres`` (:class:`~particleShear.objects.ensembles.RandomBimodalSpheres`) make their
spheres from it, and :func:`particleShear.linkable.builders.constituted_state` an engine state.
"""
__docformat__ = "numpy"

import math

import numpy as np

from .model import adjust_m, r_estimate

__all__ = ["bimodal_factors", "bimodal_placement"]


def bimodal_factors(bimodal_factor):
    """``(1/√bf, √bf)``: the small and large radius in units of ``r_b``.

    Parameters
    ----------
    bimodal_factor : float
        bf, the large/small radius ratio (> 0).

    Returns
    -------
    lower, upper : float
    """
    return math.sqrt(1 / bimodal_factor), math.sqrt(bimodal_factor)


def bimodal_placement(rng, N, Lx, Ly, packing_fraction, lower, upper, m):
    """N spheres of radius ``r_b·lower`` or ``r_b·upper`` (probability 1/2) at random integer positions.

    ``r_b``: :func:`~particleShear.objects.model.r_estimate`; masses ``adjust_m(m, r, r_b)``; no
    overlap check.  Draws, in this order: N sizes, N x, N y (integers in ``[0, L)``, or uniform
    in ``[0, L)`` for a cell narrower than 1 µm); nothing for N = 0.

    Parameters
    ----------
    rng : numpy.random.Generator
    N : int
        Number of spheres (>= 0).
    Lx, Ly : float
        Cell (µm).
    packing_fraction : float
        Nominal area fraction φ (eq. S1-14).
    lower, upper : float
        ``1/√bf`` and ``√bf`` (bf: large/small radius ratio).
    m : float
        Mass of a sphere of radius ``r_b`` (mg per m depth).

    Returns
    -------
    x, y, r, mass : ndarray (N,)
        Positions (µm), radii (µm) and masses (mg per m depth), in index order.
    """
    if N == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0)
    r_b = r_estimate(Lx, Ly, packing_fraction, N, upper, lower)
    large = rng.integers(0, 2, N)
    xs = rng.integers(0, int(Lx), N) if Lx >= 1 else rng.random(N) * Lx
    ys = rng.integers(0, int(Ly), N) if Ly >= 1 else rng.random(N) * Ly
    r = r_b * (lower + (upper - lower) * large)      # (element by element: the reference's scalar arithmetic)
    mass = adjust_m(m, r, r_b)
    return xs.astype(float), ys.astype(float), r, mass
