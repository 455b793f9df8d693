"""The constitution's relaxation in the engine: free relaxation of a batch.

The builders of ``particleShear.linkable`` relax an ensemble with
:meth:`~particleShear.linkable.compact.EnsembleCompactParticles.free_pre_equilibration`: shear
and plates off, frictionless damped levels from ``dt_max`` halving down to ``dt`` (each level
ending with the removal of the mean velocity), one frictionless block at ``dt``, one block at
``dt`` with the ensemble's μ.  :func:`free_relaxation` runs exactly these steps on every replica
of a :class:`~particleShear.engine.step.BatchEngine`; :func:`remove_linear_drift` is the classes'
``correct_linear_drift`` per replica.  The documented ensembles are relaxed on their own state
and handed their clock and relations back by their adapter,
:func:`particleShear.base.engine_adapter.relax_ensembles` (docs/engine.md, "Runs").

A replica's relaxation does not depend on its batch (every operation of the step is per
replica, see :mod:`.step`; the drift is removed per replica), so a run constituted in a batch
is bit-identical to the same run constituted alone.  Against the classes the engine computes
the same equations with sums in another order: the two agree to rounding over short blocks
(tested), while a long relaxation of a random packing, being chaotic, amplifies rounding.

Units: µm, s, mg per m depth (docs/parameters.md).
"""
__docformat__ = "numpy"

import numpy as np

from ..checks import integer
from .integrate import remove_mean_velocity
from .loops import relaxation_levels

__all__ = ["free_relaxation", "remove_linear_drift", "relaxation_levels", "RELAX_SKIN"]

#: Verlet skin of the relaxation engine, in units of each replica's largest radius.  The
#: contacts of every step are exact for any skin (the list is rebuilt before a pair can have
#: come into contact); in a compressed packing ~0.9 of the candidates are in contact at
#: 0.2 r_max against ~0.6 at 0.5 r_max, so a step works on 30 % fewer pairs, and the extra
#: rebuilds cost less than that (measured: a batch of 32 default constitutions takes ~40 % less
#: CPU time than at 0.5).
RELAX_SKIN = 0.2


def remove_linear_drift(state):
    """Subtract each replica's unweighted mean velocity from its spheres (``correct_linear_drift``):
    :func:`~particleShear.engine.integrate.remove_mean_velocity` of the batch's (vx, vy) rows.

    Parameters
    ----------
    state : BatchState
        The batch; its velocities are changed in place.
    """
    remove_mean_velocity(state.vel[:2], state.B)




def free_relaxation(engine, N, dt, dt_max, mu):
    """``free_pre_equilibration(N)`` of the classes on every replica of ``engine``.

    Shear and plates off.  μ = 0 during the coarse levels (:func:`relaxation_levels`: N steps
    each, :func:`remove_linear_drift` after each) and N undamped steps at ``dt``; then μ of
    each replica and N undamped steps at ``dt``.  ``engine.s.mu`` holds ``mu`` afterwards and the
    pair history is flushed into ``engine.s.pairs``.

    Parameters
    ----------
    engine : BatchEngine
        The batch (its γ̇ should be 0, as in a constitution); advanced in place.
    N : int
        Steps per level and per final block (>= 0).
    dt : float
        Final time step (s), > 0.
    dt_max : float
        Step of the first level (s).
    mu : array_like (B,)
        Friction coefficient of each replica for the last block.

    Returns
    -------
    int
        Number of steps run (``N·(levels + 2)``).

    Raises
    ------
    ValueError
        If ``N`` is negative, ``dt`` is not > 0 or ``dt_max`` is not finite (before any step).
    """
    N = integer("N", N, 0)
    levels = relaxation_levels(dt, dt_max)
    s = engine.s
    mu = np.array(np.broadcast_to(np.asarray(mu, dtype=float), (s.B,)))
    s.applying_shear = False
    engine.set_mu(np.zeros(s.B))
    for level_dt, cf in levels:
        engine.steps(N, cf, level_dt)
        remove_linear_drift(s)
    engine.steps(N, 1, dt)
    engine.set_mu(mu)
    engine.steps(N, 1, dt)
    engine.flush()
    return N * (len(levels) + 2)


