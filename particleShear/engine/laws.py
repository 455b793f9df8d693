"""Central force laws over arrays, written once (eq. S1-5a/b, S1-6; docs/parameters.md).

Forces in mg·µm·s⁻² per m depth; negative = repulsion.
"""
import numpy as np

__all__ = ["central_law", "tensile_law"]


def central_law(d, d0, k, c):
    """Compressive law: ``−k(1−c)(d0−d) − k·c·d0·(d0/max(d, d0/1000) − 1)`` for ``d ≤ d0``, else 0.

    ``c`` blends the linear law (eq. S1-5a, c = 0) and the divergent law (eq. S1-5b, c = 1);
    the ratio ``d0/d`` is capped at 1000 (eq. S1-6).  All arguments broadcast.
    """
    inside = -k * (1 - c) * (d0 - d) + (-k * c * d0) * (d0 / np.maximum(d, d0 / 1000) - 1)
    return np.where(d > d0, 0.0, inside)


def tensile_law(d, d_eq, k):
    """Linear tensile law of a stretched bond, ``k (d − d_eq)`` (≥ 0 for ``d ≥ d_eq``, attractive)."""
    return k * (d - d_eq)
