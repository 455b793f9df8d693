"""Every stress tensor as one function, with its name and output-column stem in one registry.

Each function takes the :class:`StressInputs` of one force phase of a batch and returns a
``(B, 2, 2)`` array (Pa; index ``[b, a, c]``: replica, force component, position component).
Sums run per replica over its own rows (one reduction over each replica's segment), so a replica's
tensors do not depend on its batch.  Units as in the reference: forces ×1e-12 (N per m depth),
lengths ×1e-6 (m), torques and inertias ×1e-18, volume ``V = Lx·Ly·1e-12`` m², lever arms from
the cell centre.  Definitions: reference manual eq. S1-16 … S1-24 (docs/design.md).
"""
__docformat__ = "numpy"

import collections

import numpy as np

from .forces import pair_roles, replica_sums
from .xp import array_namespace

__all__ = ["StressInputs", "Tensor", "TENSORS", "evaluate_all"]

_ROT = np.array([[0.0, -0.5], [0.5, 0.0]])
_EYE = np.eye(2)


class StressInputs:
    """What the tensors read from one force phase of a batch (all arrays of the step, not copies).

    ``C`` the candidate constants, ``B`` replicas, ``rep`` sphere → replica, ``x, y, vx, vy,
    omega, m, inertia`` sphere state, ``Lx, Ly, rate, V`` per replica, ``mob`` mobility mask,
    ``active``/``shifted`` per candidate, ``dx, dy`` minimum-image pair vectors, ``fx_i, fy_i``
    pair force on i (``fx_j, fy_j``: that of j's own visit where spheres have parameters of their
    own, else None), ``dF`` = d·F_T (internal torque of a pair), ``fx, fy, torque`` sphere totals.
    The arrays are kept as given (views of the step's arrays); nothing is checked or copied.

    Parameters
    ----------
    **arrays
        The inputs by name, stored as attributes: ``C`` (:class:`~particleShear.engine.forces.PairConstants`),
        ``B`` (int, replicas), ``rep`` (B·N,) replica of each sphere; per sphere (B·N,): ``x, y``
        (µm), ``vx, vy`` (µm/s), ``omega`` (rad/s), ``m`` (mg per m depth), ``inertia``
        (mg·µm² per m depth), ``mob`` (bool), ``fx, fy`` (mg·µm·s⁻² per m depth) and ``torque``
        (mg·µm²·s⁻² per m depth); per replica (B,): ``Lx, Ly`` (µm), ``rate`` (1/s), ``V``
        (m², ``Lx·Ly·1e-12``); per candidate (P,): ``active``, ``shifted`` (bool), ``dx, dy``
        (µm), ``fx_i, fy_i`` (mg·µm·s⁻² per m depth) and ``dF`` (mg·µm²·s⁻² per m depth).
    """

    #: the pair force of j's own visit (None: ``fx_i, fy_i``; see :meth:`~particleShear.engine.forces.PairConstants.set_visits`)
    fx_j = fy_j = None

    def __init__(self, **arrays):
        self.__dict__.update(arrays)

    def tensor(self, function):
        """``function(self)``, evaluated once per force phase (the overall tensor reuses its parts).

        The inputs describe one force phase and are made anew for the next, so the memo needs
        no invalidation: its key is the tensor function, its lifetime this object's.

        Parameters
        ----------
        function : callable
            A tensor function of :data:`TENSORS` (``function(q) -> (B, 2, 2)``), or another
            function of the inputs that several tensors read (the pairs' roles).

        Returns
        -------
        object
            Its value ((B, 2, 2) for a tensor).
        """
        memo = self.__dict__.setdefault("_tensors", {})
        if function not in memo:
            memo[function] = function(self)
        return memo[function]

    def per_replica(self, weights, by_pair=True):
        """Σ of ``weights`` per replica (pairs or spheres), in row order.

        Parameters
        ----------
        weights : ndarray (P,) or (B·N,), or (k, P) or (k, B·N)
            One value per candidate pair (``by_pair``) or per sphere; a 2-D array sums each of
            its k rows on its own (one reduction call for all of them).
        by_pair : bool
            True: sum over each replica's candidates (``C.rep``); False: over its spheres.

        Returns
        -------
        ndarray (B,) or (k, B)
            The sums, in the unit of ``weights``.

        Notes
        -----
        A replica's pairs and its spheres are contiguous rows, so each sum is one reduction over
        the replica's own segment (:func:`~particleShear.engine.forces.replica_sums`): it does
        not depend on the rest of the batch.
        """
        W = weights if weights.ndim == 2 else weights[None]
        if by_pair:
            out = replica_sums(self.C, W)
        else:
            xp = array_namespace(W)
            n = W.shape[1] // self.B if self.B else 0
            if n == 0:
                out = xp.zeros((W.shape[0], self.B))
            elif self.C.backend.ordered_reductions:
                out = xp.add.reduceat(W, xp.arange(self.B) * n, axis=1)
            else:                     # a device: one reduction along each replica's row
                out = W.reshape(W.shape[0], self.B, n).sum(axis=2)
        return out if weights.ndim == 2 else out[0]

    def outer(self, u, w, by_pair=True):
        """(B, 2, 2) array of the per-replica sums of ``u_a · w_c`` (u, w: pairs of rows).

        The four products are summed in one reduction over their stacked rows (each row on its
        own, so the same numbers as four separate sums).

        Parameters
        ----------
        u : tuple of two ndarray
            x and y components of the first factor (force components; per pair or per sphere).
        w : tuple of two ndarray
            x and y components of the second factor (lever arms), same length as ``u``.
        by_pair : bool
            True: the rows are candidate pairs; False: spheres.

        Returns
        -------
        ndarray (B, 2, 2)
            ``out[b, a, c] = Σ_rows of b  u_a · w_c`` (unscaled).
        """
        xp = array_namespace(u[0])
        W = xp.empty((4, u[0].shape[0]))      # the four products written in place (no stack)
        for r, (a, c) in enumerate(((0, 0), (0, 1), (1, 0), (1, 1))):
            xp.multiply(u[a], w[c], out=W[r])
        return self.per_replica(W, by_pair).T.reshape(self.B, 2, 2)

    @property
    def roles(self):
        """``(internal, ext_i, ext_j)`` of the relations (:func:`~particleShear.engine.forces.pair_roles`),
        evaluated once per force phase."""
        return self.tensor(_roles)

    @property
    def internal(self):
        """Pairs counted as internal: both spheres mobile, no image shift, a relation (eq. S1-19)."""
        return self.roles[0]


def _roles(q):
    """The pairs' roles of :attr:`StressInputs.roles`."""
    C = q.C
    internal, ext_i, ext_j = pair_roles(q.mob[C.ai], q.mob[C.aj], q.shifted)
    return internal & q.active, ext_i & q.active, ext_j & q.active


def _x_centred(q):
    """``x − Lx/2`` of every sphere (µm): lever arms from the cell centre."""
    return q.x - (q.Lx / 2)[q.rep]


def _y_centred(q):
    """``y − Ly/2`` of every sphere (µm)."""
    return q.y - (q.Ly / 2)[q.rep]


def love_weber(q):
    """σ_LW = (1/V) Σ_internal F_i ⊗ (x_i − x_j) (eq. S1-19); ``x_i − x_j = −D`` for an unshifted pair.

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    w = q.internal
    fx, fy = (q.fx_i, q.fy_i) if q.fx_j is None else ((q.fx_i + q.fx_j) * 0.5, (q.fy_i + q.fy_j) * 0.5)
    return q.outer((fx * w, fy * w), (-q.dx, -q.dy)) * (1e-18 / q.V)[:, None, None]


def external_forces(q):
    """σ_ext = −(1/V) Σ_external F ⊗ (x_target − c) (eq. S1-16): a mobile sphere of a pair through
    the boundary or with an immobile partner receives the pair force at its own centre.

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    C = q.C
    _, ei, ej = q.roles
    xc, yc = q.tensor(_x_centred), q.tensor(_y_centred)
    lever_x = xc[C.ai] * ei - xc[C.aj] * ej     # F on j is −F on i
    lever_y = yc[C.ai] * ei - yc[C.aj] * ej
    S = q.outer((q.fx_i, q.fy_i), (lever_x, lever_y))
    if q.fx_j is not None:
        # j's visit has a force of its own (spheres with parameters of their own): −F_j at j, i.e.
        # F_i ⊗ lever + (F_i − F_j) ⊗ (x_j − c), exactly S where F_j = F_i
        S = S + q.outer((q.fx_i - q.fx_j, q.fy_i - q.fy_j), (xc[C.aj] * ej, yc[C.aj] * ej))
    return -S * (1e-18 / q.V)[:, None, None]


def unbalanced_forces(q):
    """σ_unb = (1/V) Σ_mobile F_total ⊗ (x − c) (eq. S1-17).

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    w = q.mob
    S = q.outer((q.fx * w, q.fy * w), (q.tensor(_x_centred), q.tensor(_y_centred)), by_pair=False)
    return S * (1e-18 / q.V)[:, None, None]


def linear_acceleration(q):
    """σ_linacc = σ_unb (m·a = F_total; gravity neglected, eq. S1-17).

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    return q.tensor(unbalanced_forces)


def unbalanced_torque(q):
    """σ_T = (1/V) Σ_all spheres T·[[0, −½], [½, 0]] (eq. S1-22; immobile spheres included, reference quirk).

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    rot = array_namespace(q.torque).asarray(_ROT)
    return q.per_replica(q.torque, by_pair=False)[:, None, None] * 1e-18 / q.V[:, None, None] * rot


def internal_torque(q):
    """σ_Tint = (1/V) Σ_internal d·F_T·[[0, −½], [½, 0]] (eq. S1-22): the pair's two torques sum to d·F_T.

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    rot = array_namespace(q.dF).asarray(_ROT)
    return q.per_replica(q.dF * q.internal)[:, None, None] * 1e-18 / q.V[:, None, None] * rot


def spin_kinetic_energy(q):
    """σ_cen = −(1/V) Σ_mobile I ω²/2 · 1 (eq. S1-21).

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    k = q.per_replica(q.inertia * q.omega * q.omega * q.mob, by_pair=False) * 1e-18 / 2
    return -(k / q.V)[:, None, None] * array_namespace(k).asarray(_EYE)


def peculiar_acceleration_otsuki(q):
    """σ_ot = −(1/V) Σ_mobile P ⊗ P / m with P = m (v_x − γ̇ (y − Ly/2), v_y) (Otsuki & Hayakawa; for
    comparison only).

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    px = q.m * 1e-12 * (q.vx - q.rate[q.rep] * q.tensor(_y_centred))
    py = q.m * 1e-12 * q.vy
    w = q.mob / (q.m * 1e-6)
    return -q.outer((px * w, py * w), (px, py), by_pair=False) / q.V[:, None, None]


def overall(q):
    """σ = σ_LW + σ_Tint + σ_cen (eq. S1-24).

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    return q.tensor(love_weber) + q.tensor(internal_torque) + q.tensor(spin_kinetic_energy)


#: one registry entry per tensor: name (StressTensorEvaluation attribute), output-column stem, equation
Tensor = collections.namedtuple("Tensor", "name stem equation function")
TENSORS = (
    Tensor("stress_tensor_LW", "stress_tensor_Love_Weber", "S1-19", love_weber),
    Tensor("stress_tensor_linear_acceleration_otsuki", "stress_tensor_peculiar_acceleration_otsuki", "Otsuki",
           peculiar_acceleration_otsuki),
    Tensor("stress_tensor_with_external_forces", "stress_tensor_from_external_forces", "S1-16", external_forces),
    Tensor("stress_tensor_linear_acceleration", "stress_tensor_linear_acceleration", "S1-17", linear_acceleration),
    Tensor("stress_tensor_unbalanced_forces", "stress_tensor_unbalanced_linear_forces", "S1-17",
           unbalanced_forces),
    Tensor("stress_tensor_unbalanced_torque", "stress_tensor_tangential_torque", "S1-22", unbalanced_torque),
    Tensor("stress_tensor_internal_torque", "stress_tensor_internal_tangential_torque", "S1-22", internal_torque),
    Tensor("stress_tensor_spin_kinetic_energy", "stress_tensor_centrifugal", "S1-21", spin_kinetic_energy),
    Tensor("overall_stress_tensor", "stress_tensor_overall", "S1-24", overall),
)


def evaluate_all(q):
    """(B, 9, 2, 2) array of every tensor of :data:`TENSORS`, in registry order.

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 9, 2, 2)
        ``out[b, t]`` is tensor ``TENSORS[t]`` of replica b (Pa).
    """
    tensors = [q.tensor(t.function) for t in TENSORS]
    return array_namespace(tensors[0]).stack(tensors, axis=1)
