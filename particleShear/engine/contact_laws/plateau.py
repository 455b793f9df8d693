"""The plateau law of spongy particles: the linear law of a plateau-transformed distance.

``linear(dp, d0, k, c)`` with ``dp`` the distance flattened between ``plateau_begin·d0`` and
``plateau_end·d0`` by the factor ``plateau_slope`` (the manual's ``elastic_force_law_plateau``).  The arithmetic is :func:`particleShear.engine.laws.plateau_law` (shared with
the documented callback ``elastic_force_law_plateau``), evaluated by the engine from constants
prepared once per candidate set.  Its parameters are keywords of ``doParticleShearSimulation``'s
signature (``SIGNATURE``), as in 2.0.0.
"""
__docformat__ = "numpy"

from ...parameter_entry import Parameter
from ..laws import check_plateau, plateau_constants, plateau_inside, plateau_law, register_law

__all__ = ["plateau", "PARAMETERS", "LAW"]

POSITION = 1
#: the parameters are keywords of doParticleShearSimulation's signature (2.0.0)
SIGNATURE = True
PARAMETERS = (
    Parameter('plateau_begin', 0.3, 'float', unit='contact distance', role='law:plateau', doc='Begin of the plateau of ``contact_law="plateau"``, a fraction of the contact distance; allowed 0 < plateau_begin < plateau_end'),
    Parameter('plateau_end', 0.8, 'float', unit='contact distance', role='law:plateau', doc='End of the plateau, a fraction of the contact distance; allowed plateau_begin < plateau_end <= 1'),
    Parameter('plateau_slope', 0.1, 'float', unit='1', role='law:plateau', doc="Slope of the force on the plateau relative to the law's (0 flat, 1 no plateau); allowed 0 ... 1"),
)


def plateau(d, d0, r_i, r_j, k, c, plateau_begin, plateau_end, plateau_slope):
    """Linear law of the plateau-transformed distance (the manual's plateau law): :func:`~particleShear.engine.laws.plateau_law`.

    Parameters
    ----------
    d, d0 : ndarray or float
        Centre distance and contact distance (µm).
    r_i, r_j : ndarray or float
        Radii (µm; not read).
    k, c : ndarray or float
        Spring constant (mg·s⁻² per m depth) and repulsion coefficient.
    plateau_begin, plateau_end : ndarray or float
        Begin and end of the plateau, fractions of ``d0``.
    plateau_slope : ndarray or float
        Relative slope on the plateau (dimensionless).

    Returns
    -------
    ndarray
        Central force on i along ``n_ij`` as if in contact (mg·µm·s⁻² per m depth).
    """
    return plateau_law(d, d0, k, c, plateau_begin, plateau_end, plateau_slope)


def _constants(d0, r_i, r_j, k, c, plateau_begin, plateau_end, plateau_slope):
    """:func:`~particleShear.engine.laws.plateau_constants` of the law's arguments (the radii are not read)."""
    return plateau_constants(d0, k, c, plateau_begin, plateau_end, plateau_slope)


LAW = register_law("plateau", plateau, PARAMETERS, check=check_plateau, prepared=(_constants, plateau_inside),
                   radii=True, built_in=True)
