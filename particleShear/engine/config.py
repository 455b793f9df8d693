"""The configuration of a :class:`~particleShear.engine.step.BatchEngine`, fixed at its construction.

An :class:`EngineConfig` says how an engine steps (integrator, Verlet skin, stability guard, force
register, numbering of relations, the cells' Lees-Edwards images and strain); the engine is given
one when it is built (or builds one from its keyword arguments) and reads it, never changes it.
The engine's state (positions, relations, neighbour lists, clock, the Verlet predictor) is the
engine's and changes with every step; its configuration does not: an :class:`EngineConfig` is a
frozen dataclass, so assigning one of its fields raises :class:`dataclasses.FrozenInstanceError`,
and the engine exposes the fields as read-only properties of the same names.
"""
__docformat__ = "numpy"

import dataclasses

import numpy as np

__all__ = ["EngineConfig", "INTEGRATORS"]

#: the integrators an engine steps with
INTEGRATORS = ("euler", "verlet")


@dataclasses.dataclass(frozen=True)
class EngineConfig:
    """How a :class:`~particleShear.engine.step.BatchEngine` steps (immutable).

    Parameters
    ----------
    integrator : {"euler", "verlet"}
        ``"euler"``: the reference's semi-implicit Euler.  ``"verlet"``: velocity Verlet with a
        half-kick predictor (see :class:`~particleShear.engine.step.BatchEngine`).
    skin_factor : float
        Verlet skin in units of each replica's largest radius (> 0).
    check_interval : int
        Steps between the checks of the stability guard (≥ 1).
    guard : bool or tuple of bool
        Whether the stability guard checks every replica (a bool) or, per replica, which it checks
        (a tuple of B bools; any sequence or array of bools is turned into one).
    min_distance_ratio : float
        The guard's smallest d/(r_i + r_j) of a transient contact.
    max_kinetic_energy : float or None
        The guard's bound of the kinetic energy relative to the flow (mg·µm²/s² per m depth);
        None: the engine's default bound.
    keep_terms : bool
        Keep the per-term arrays of each force phase for the force register; an engine so
        configured needs the receiver of those arrays, ``BatchEngine(..., terms_to=f)``.
    numbers_relations : bool
        Number the relations as they form (their creation numbers order a documented ensemble's
        neighbours; the adapters build an engine on an ensemble's memory with True).
    lees_edwards : bool
        True: every replica is a Lees-Edwards cell (images offset by ``Ly·γ``, moving with
        ``Ly·γ̇``); False: plain periodic cells (the documented ``use_lees_edwards = False``
        ensembles).
    strain_only_while_shearing : bool
        True: the strain advances by ``γ̇·dt`` only in the steps where the state applies shear
        (``state.applying_shear``; the documented frictionless canvases); False: in every step.

    Raises
    ------
    ValueError
        If ``skin_factor`` is not > 0, ``integrator`` is unknown or ``check_interval`` is < 1.
    """

    integrator: str = "euler"
    skin_factor: float = 0.5
    check_interval: int = 4
    guard: object = True
    min_distance_ratio: float = 0.05
    max_kinetic_energy: object = None
    keep_terms: bool = False
    numbers_relations: bool = False
    lees_edwards: bool = True
    strain_only_while_shearing: bool = False

    def __post_init__(self):
        if not self.skin_factor > 0:
            raise ValueError(f"skin_factor={self.skin_factor!r} is out of range: allowed > 0")
        if self.integrator not in INTEGRATORS:
            raise ValueError(f"integrator={self.integrator!r} is not allowed: one of {INTEGRATORS}")
        if not int(self.check_interval) >= 1:
            raise ValueError(f"check_interval={self.check_interval!r} is out of range: allowed ≥ 1")
        guard = np.asarray(self.guard, dtype=bool)
        fixed = dict(check_interval=int(self.check_interval), keep_terms=bool(self.keep_terms),
                     guard=bool(guard) if guard.ndim == 0 else tuple(bool(g) for g in guard.ravel()),
                     numbers_relations=bool(self.numbers_relations),
                     lees_edwards=bool(self.lees_edwards),
                     strain_only_while_shearing=bool(self.strain_only_while_shearing))
        for name, value in fixed.items():      # (a frozen dataclass sets its own fields this way)
            object.__setattr__(self, name, value)

    def replace(self, **changes):
        """A copy with ``changes`` (:func:`dataclasses.replace`).

        Parameters
        ----------
        **changes
            New values of fields.

        Returns
        -------
        EngineConfig
        """
        return dataclasses.replace(self, **changes)

    def guard_mask(self, B):
        """The guard per replica.

        Parameters
        ----------
        B : int
            Replicas of the batch.

        Returns
        -------
        ndarray of bool (B,)
            True where the stability guard checks the replica (a new writable array).

        Raises
        ------
        ValueError
            If :attr:`guard` is a tuple of another length than B.
        """
        return np.broadcast_to(np.asarray(self.guard, dtype=bool), (B,)).copy()
