"""Central force laws: the linear and divergent blend (eqs. S1-5a, S1-5b, S1-6), plateau and tensile variants.

Every law takes Python scalars or NumPy arrays (the engine calls them on whole pair arrays).
Negative = repulsion.  Distances in µm, ``k`` in mg·s⁻² per m depth, forces in mg·µm·s⁻² per m depth.
"""
__docformat__ = "numpy"

import numpy as np

from . import callbacks as _callbacks
from ..engine import laws as _engine_laws

__all__ = [
    "elastic_force_law", "elastic_force_law_plateau", "distance_transform_plateau",
    "PlateauConfiguration", "elastic_force_law_tensile",
    "elastic_force_law_tensile_exponential", "TensileConfiguration",
]


def _scalar_result(value, *args):
    """Return a Python float when every argument was a scalar."""
    return float(value) if all(np.ndim(a) == 0 for a in args) else value


def elastic_force_law(d, d0, k, central_repulsion_coefficient):
    """Blend of the linear (eq. S1-5a) and divergent (eq. S1-5b) law; 0 for d > d0.

    ``-k (1 - c)(d0 - d) - k c d0 (d0/d - 1)``, the divergent part capped at ``d0/d = 1000``
    (eq. S1-6), by :func:`particleShear.engine.laws.central_inside` as in the engine.

    Parameters
    ----------
    d : float or numpy.ndarray
        Centre distance (µm).
    d0 : float or numpy.ndarray
        Contact distance ``r_i + r_j`` (µm).
    k : float or numpy.ndarray
        Spring constant (eq. S1-8).
    central_repulsion_coefficient : float or numpy.ndarray
        Blend ``c`` of the linear (0, eq. S1-5a) and divergent (1, eq. S1-5b) laws.
    """
    c = central_repulsion_coefficient
    if np.ndim(d) == 0 and np.ndim(d0) == 0:
        if d > d0:
            return 0
        f = _engine_laws.central_inside(d, d0, *_engine_laws.central_constants(d0, k, c))
        return _scalar_result(f, k, c)
    return _engine_laws.central_law(d, d0, k, c)


class PlateauConfiguration:
    """Static parameters of the plateau law, as fractions of the contact distance.

    1.0.2's class attributes; a run's ``contact_law="plateau"`` with ``plateau_begin``, ``plateau_end``
    and ``plateau_slope`` gives the same law per run.
    """
    relative_plateau_begin = 0.3
    relative_plateau_end = 0.8
    relative_plateau_slope = 0.1

    @classmethod
    def values(cls):
        """Return ``(begin, end, slope)``, the parameters of :func:`~particleShear.engine.laws.plateau_law`."""
        return cls.relative_plateau_begin, cls.relative_plateau_end, cls.relative_plateau_slope


def distance_transform_plateau(d, plateau_begin, plateau_end, relative_plateau_slope):
    """Map distances to flatten the law between ``plateau_begin`` and ``plateau_end`` (µm).

    Above the end unchanged, between begin and end compressed by ``relative_plateau_slope``
    (0 = flat), below the begin scaled linearly to 0; returns the transformed distance (µm).

    Parameters
    ----------
    d, plateau_begin, plateau_end : float or numpy.ndarray
    relative_plateau_slope : float
    """
    pb, pe, s = plateau_begin, plateau_end, relative_plateau_slope
    if np.ndim(d) == 0 and np.ndim(pb) == 0 and np.ndim(pe) == 0:
        return float(_engine_laws.plateau_distance(d, pb, pe, s))
    return _engine_laws.plateau_distance(np.asarray(d, dtype=float), pb, pe, s)


def elastic_force_law_plateau(d, d0, k, central_repulsion_coefficient):
    """Law of spongy particles: :func:`elastic_force_law` on a plateau-transformed distance; 0 for d > d0.

    The plateau lies between ``relative_plateau_begin·d0`` and ``relative_plateau_end·d0`` of
    :class:`PlateauConfiguration` (:func:`particleShear.engine.laws.plateau_law`, the ``"plateau"`` law).

    Parameters
    ----------
    d, d0, k, central_repulsion_coefficient : float or numpy.ndarray
        As for :func:`elastic_force_law`.
    """
    c = central_repulsion_coefficient
    values = PlateauConfiguration.values()
    if np.ndim(d) == 0 and np.ndim(d0) == 0:
        if d > d0:
            return 0
        return _scalar_result(_engine_laws.plateau_law(d, d0, k, c, *values), k, c)
    d = np.asarray(d, dtype=float)
    return np.where(d > d0, 0.0, _engine_laws.plateau_law(d, d0, k, c, *values))


def elastic_force_law_tensile(d, d0, k):
    """Linear tensile law of permanent links: ``-k (d0 - d)`` (eq. S1-5a in tension).

    Parameters
    ----------
    d : float or numpy.ndarray
        Centre distance of the linked pair (µm).
    d0 : float or numpy.ndarray
        Equilibrium distance of the link (µm).
    k : float or numpy.ndarray
        Spring constant (eq. S1-8).
    """
    return _engine_laws.tensile_inside(d, d0, -k)


class TensileConfiguration:
    """Static parameter of the saturating tensile law (relative decay length)."""
    d_exponential = 0.2


def elastic_force_law_tensile_exponential(d, d0, k):
    """Saturating tensile law ``k d0 δ (1 - exp(-(d - d0)/(d0 δ)))``, δ = ``TensileConfiguration.d_exponential``.

    Slope k at d0, limit ``k·d0·δ``: a bond that weakens smoothly instead of growing without bound.

    Parameters
    ----------
    d, d0, k : float or numpy.ndarray
        As for :func:`elastic_force_law_tensile`.
    """
    delta = TensileConfiguration.d_exponential
    return k * d0 * delta * (1 - np.exp(-(d - d0) / (d0 * delta)))


# the package's law functions accept arrays; the engine knows the registered ones by their callbacks
_callbacks.register_callback(elastic_force_law, "linear")
_callbacks.register_callback(elastic_force_law_plateau, "plateau", lambda: dict(zip(
    ("plateau_begin", "plateau_end", "plateau_slope"), PlateauConfiguration.values())))
_callbacks.register_callback(elastic_force_law_tensile, "tensile")
elastic_force_law_tensile_exponential.accepts_arrays = True
