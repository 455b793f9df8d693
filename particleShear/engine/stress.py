"""Every stress tensor as one function, with its name and output-column stem in one registry.

Each function takes the :class:`StressInputs` of one force phase of a batch and returns a
``(B, 2, 2)`` array (Pa; index ``[b, a, c]``: replica, force component, position component).
A tensor reads per-replica sums of rows of products (its *rows*: :func:`pair_rows` and
:func:`sphere_rows` functions); :func:`evaluate_all` sums the rows of every tensor in two
reductions, one over the pairs and one over the spheres.  Each row is summed per replica over
its own segment, so a tensor's numbers do not depend on which other rows, tensors or replicas
are summed with it.  Units as in the reference: forces ×1e-12 (N per m depth), lengths ×1e-6
(m), torques and inertias ×1e-18, volume ``V = Lx·Ly·1e-12`` m², lever arms from the cell
centre.  Definitions: reference manual eq. S1-16 … S1-24 (docs/engine.md).
"""
__docformat__ = "numpy"

import collections
import functools

import numpy as np

from .forces import CF_CL, CT, pair_roles, replica_sums, shear_from_sums
from .state import spread
from .xp import array_namespace

__all__ = ["StressInputs", "Tensor", "TENSORS", "OVERALL", "EXTERNAL", "ROWS", "KINETIC_ROWS", "evaluate_all",
           "pair_rows", "sphere_rows", "SUMMED_ROWS", "tensors_from_sums", "outer_entries",
           "love_weber_entries", "external_entries", "unbalanced_entries", "spin_entry", "otsuki_entries"]



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

    def sums(self, rows):
        """Per-replica sums of the rows of ``rows`` (a :func:`pair_rows` or :func:`sphere_rows`
        function), (k, B), evaluated once per force phase.

        Parameters
        ----------
        rows : callable
            ``rows(self) -> (k, P)`` or ``(k, B·N)`` array.

        Returns
        -------
        ndarray (k, B)
            ``out[r, b]`` = Σ over replica b's rows of row r (the unit of the rows).
        """
        memo = self.__dict__.setdefault("_row_sums", {})
        if rows not in memo:
            self.reduce((rows,))
        return memo[rows]

    def reduce(self, groups):
        """Sum the rows of every function of ``groups`` not summed yet: the pair rows in one
        reduction, the sphere rows in another (each row over each replica's own segment, so the
        same numbers as a reduction of its own).

        Parameters
        ----------
        groups : iterable of callable
            :func:`pair_rows` and :func:`sphere_rows` functions.
        """
        memo = self.__dict__.setdefault("_row_sums", {})
        groups = tuple(groups)
        for by_pair in (True, False):
            todo = [g for g in groups if g.by_pair is by_pair and g not in memo]
            if not todo:
                continue
            blocks = [g(self) for g in todo]
            W = blocks[0] if len(blocks) == 1 else array_namespace(blocks[0]).concatenate(blocks)
            S = self.per_replica(W, by_pair)
            k = 0
            for g, b in zip(todo, blocks):
                memo[g] = S[k:k + len(b)]
                k += len(b)

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
    return q.x - spread(q.Lx / 2, q.rep, q.B)


def _y_centred(q):
    """``y − Ly/2`` of every sphere (µm)."""
    return q.y - spread(q.Ly / 2, q.rep, q.B)


def pair_rows(function):
    """Mark a row function as rows over the candidate pairs (see :meth:`StressInputs.reduce`).

    Parameters
    ----------
    function : callable
        ``function(q) -> (k, P)``: k rows of products, one value per candidate pair of the batch.

    Returns
    -------
    callable
        ``function``, with ``by_pair = True``.
    """
    function.by_pair = True
    return function


def sphere_rows(function):
    """Mark a row function as rows over the spheres (see :meth:`StressInputs.reduce`).

    Parameters
    ----------
    function : callable
        ``function(q) -> (k, B·N)``: k rows of products, one value per sphere of the batch.

    Returns
    -------
    callable
        ``function``, with ``by_pair = False``.
    """
    function.by_pair = False
    return function


def outer_entries(ux, uy, wx, wy):
    """The entries ``u_a·w_c`` of ``u ⊗ w`` in the order (x, x), (x, y), (y, x), (y, y).

    Parameters
    ----------
    ux, uy, wx, wy : float or ndarray
        The components of ``u`` and ``w`` (any units).

    Returns
    -------
    tuple
        The four products (the product of the units).
    """
    return ux * wx, ux * wy, uy * wx, uy * wy


def love_weber_entries(fx_i, fy_i, fx_j, fy_j, own_j, dx, dy, internal):
    """F ⊗ (x_i − x_j) = −F ⊗ D of a pair counted as internal (eq. S1-19), 0 otherwise.

    A pure expression of its arguments (numbers inside the compiled step, arrays in the NumPy row
    function), written once for both (docs/backends.md, "One law, two drivers").

    Parameters
    ----------
    fx_i, fy_i : float or ndarray
        The force on i (mg·µm·s⁻² per m depth).
    fx_j, fy_j : float or ndarray
        The force of j's own visit (read only with ``own_j``).
    own_j : bool
        j's visit has a force of its own (spheres with parameters of their own): F is then the mean
        of the two visits' forces (1.0.2 registers each visit with half); else F is the force on i.
    dx, dy : float or ndarray
        D = x_j − x_i, the minimum-image pair vector (µm).
    internal : bool or ndarray of bool
        The pair is internal: both spheres mobile, no image shift, a relation.

    Returns
    -------
    tuple
        The four entries (xx, xy, yx, yy) (mg·µm²·s⁻² per m depth).
    """
    if own_j:
        fx, fy = (fx_i + fx_j) * 0.5, (fy_i + fy_j) * 0.5
    else:
        fx, fy = fx_i, fy_i
    return outer_entries(fx * internal, fy * internal, -dx, -dy)


def external_entries(fx_i, fy_i, fx_j, fy_j, own_j, xc_i, yc_i, xc_j, yc_j, ext_i, ext_j):
    """F ⊗ (x_target − c) of a pair's external entries (eq. S1-16): F_i at i, −F_j at j.

    Where j's visit has a force of its own the entries add (F_i − F_j) ⊗ (x_j − c), exactly 0
    where F_j = F_i (a batch's replica equals its single run).

    Parameters
    ----------
    fx_i, fy_i : float or ndarray
        The force on i (mg·µm·s⁻² per m depth).
    fx_j, fy_j : float or ndarray
        The force of j's own visit (read only with ``own_j``).
    own_j : bool
        j's visit has a force of its own.
    xc_i, yc_i, xc_j, yc_j : float or ndarray
        The positions of i and j from the cell centre (µm).
    ext_i, ext_j : bool or ndarray of bool
        i (j) is mobile and receives the pair force as an external force (a pair through the
        boundary or with an immobile partner; a relation).

    Returns
    -------
    tuple
        The four entries (xx, xy, yx, yy) (mg·µm²·s⁻² per m depth).
    """
    xj, yj = xc_j * ext_j, yc_j * ext_j
    a, b, c, d = outer_entries(fx_i, fy_i, xc_i * ext_i - xj, yc_i * ext_i - yj)
    if own_j:
        e, f, g, h = outer_entries(fx_i - fx_j, fy_i - fy_j, xj, yj)
        a, b, c, d = a + e, b + f, c + g, d + h
    return a, b, c, d


def unbalanced_entries(fx, fy, mob, xc, yc):
    """F_total ⊗ (x − c) of a mobile sphere (eq. S1-17), 0 for an immobile one.

    Parameters
    ----------
    fx, fy : float or ndarray
        The sphere's total force (mg·µm·s⁻² per m depth).
    mob : bool or ndarray of bool
        The sphere is mobile.
    xc, yc : float or ndarray
        Its position from the cell centre (µm).

    Returns
    -------
    tuple
        The four entries (xx, xy, yx, yy) (mg·µm²·s⁻² per m depth).
    """
    return outer_entries(fx * mob, fy * mob, xc, yc)


def spin_entry(inertia, omega, mob):
    """I ω² of a mobile sphere (eq. S1-21), 0 for an immobile one.

    Parameters
    ----------
    inertia : float or ndarray
        Moment of inertia (mg·µm² per m depth).
    omega : float or ndarray
        Spin (rad/s).
    mob : bool or ndarray of bool
        The sphere is mobile.

    Returns
    -------
    float or ndarray
        I ω² (mg·µm²·s⁻² per m depth).
    """
    return inertia * omega * omega * mob


def otsuki_entries(m, vx, vy, rate, yc, mob):
    """P ⊗ P / m of a mobile sphere, P = m (v_x − γ̇ (y − Ly/2), v_y) (Otsuki & Hayakawa), 0 for an
    immobile one; already in SI, unlike the other rows.

    Parameters
    ----------
    m : float or ndarray
        Mass (mg per m depth).
    vx, vy : float or ndarray
        Velocity (µm/s).
    rate : float or ndarray
        Shear rate γ̇ of the sphere's replica (1/s).
    yc : float or ndarray
        Height from the cell centre ``y − Ly/2`` (µm).
    mob : bool or ndarray of bool
        The sphere is mobile.

    Returns
    -------
    tuple
        The four entries (xx, xy, yx, yy) (J per m depth: P in kg·m/s, m in kg).
    """
    px = m * 1e-12 * (vx - rate * yc)
    py = m * 1e-12 * vy
    w = mob / (m * 1e-6)
    return outer_entries(px * w, py * w, px, py)


def _stack(entries):
    """The (k, n) rows of a tuple of k arrays of entries (filled row by row: a quarter of ``stack``'s cost)."""
    W = array_namespace(entries[0]).empty((len(entries),) + entries[0].shape)
    for r, e in enumerate(entries):
        W[r] = e
    return W


@pair_rows
def _love_weber_rows(q):
    """:func:`love_weber_entries` of every candidate."""
    return _stack(love_weber_entries(q.fx_i, q.fy_i, q.fx_j, q.fy_j, q.fx_j is not None, q.dx, q.dy, q.internal))


@pair_rows
def _external_rows(q):
    """:func:`external_entries` of every candidate."""
    C = q.C
    _, ei, ej = q.roles
    xc, yc = q.tensor(_x_centred), q.tensor(_y_centred)
    return _stack(external_entries(q.fx_i, q.fy_i, q.fx_j, q.fy_j, q.fx_j is not None, xc[C.ai], yc[C.ai], xc[C.aj],
                                   yc[C.aj], ei, ej))


@pair_rows
def _internal_torque_rows(q):
    """d·F_T of the internal pairs (the pair's two torques sum to d·F_T)."""
    return (q.dF * q.internal)[None]


@sphere_rows
def _unbalanced_rows(q):
    """:func:`unbalanced_entries` of every sphere."""
    return _stack(unbalanced_entries(q.fx, q.fy, q.mob, q.tensor(_x_centred), q.tensor(_y_centred)))


@sphere_rows
def _torque_rows(q):
    """The net torque of every sphere, immobile ones included."""
    return q.torque[None]


@sphere_rows
def _spin_rows(q):
    """:func:`spin_entry` of every sphere."""
    return spin_entry(q.inertia, q.omega, q.mob)[None]


@sphere_rows
def _otsuki_rows(q):
    """:func:`otsuki_entries` of every sphere."""
    return _stack(otsuki_entries(q.m, q.vx, q.vy, spread(q.rate, q.rep, q.B), q.tensor(_y_centred), q.mob))


class Linear(collections.namedtuple("Linear", "rows index coef scale per_volume")):
    """A tensor as a linear map of the per-replica sums of one row function (:func:`linear_tensor`).

    Entry ``e`` of the tensor, in the order (xx, xy, yx, yy), is
    ``(sums[index[e]] · (coef[e] · scale)) / (V if per_volume else 1)``.  ``coef`` holds ±1, ±½ and
    ±0 only, so ``coef · scale`` is exact and each entry is the sum times one factor, then divided by
    V: the same rounding as the definition written out, down to the sign of a zero entry (a sum
    times ±0: the sign of the sum, or NaN, as ``value · 0`` in the definition).

    Attributes
    ----------
    rows : callable
        A :func:`pair_rows` or :func:`sphere_rows` function.
    index : tuple of int
        Per entry, the row of ``rows`` whose sum it takes (4 items).
    coef : tuple of float
        Per entry, ±1, ±½ or ±0 (4 items).
    scale : float or callable
        The unit factor, or ``scale(q) -> (B,)`` per replica (as ``CF_CL / V``).
    per_volume : bool
        Divide by the cell volume V (m² per m depth).
    """


def linear_tensor(rows, index, coef, scale, per_volume=False):
    """Make a tensor function of :data:`TENSORS` from its :class:`Linear` map (a decorator).

    The decorated function gives the name and the docstring (the definition, its equation); its
    body is not run.  The returned function evaluates the map on its own; :func:`evaluate_all`
    evaluates the maps of every such tensor of the registry together (one gather, one product,
    one division for all of them), with the same numbers.

    Parameters
    ----------
    rows, index, coef, scale, per_volume
        The fields of :class:`Linear`.

    Returns
    -------
    callable
        A decorator: ``function -> tensor function`` with the attribute ``linear``.
    """
    spec = Linear(rows, tuple(index), tuple(float(c) for c in coef), scale, bool(per_volume))

    def decorate(function):
        @functools.wraps(function)
        def tensor(q):
            return _LinearMaps((spec,))(q)[:, 0]
        tensor.linear = spec
        return tensor
    return decorate


class _LinearMaps:
    """The :class:`Linear` maps of several tensors evaluated at once: ``(q) -> (B, n, 2, 2)``.

    The sums of the maps' row functions are stacked, gathered to the n·4 entries, multiplied by ``coef · scale`` and divided by V or 1 (exact).

    Parameters
    ----------
    specs : sequence of Linear
        The maps, in the order of the result's second axis.
    """

    def __init__(self, specs):
        self.specs = tuple(specs)
        self.rows = tuple(dict.fromkeys(s.rows for s in self.specs))
        self.coef = np.array([s.coef for s in self.specs])                   # (n, 4)
        # the constant scales, and the columns of each per-replica one (a function of q)
        self.const = np.array([1.0 if callable(s.scale) else float(s.scale) for s in self.specs])
        self.varying = [(f, [k for k, s in enumerate(self.specs) if s.scale is f])
                        for f in dict.fromkeys(s.scale for s in self.specs if callable(s.scale))]
        self.per_volume = [k for k, s in enumerate(self.specs) if s.per_volume]
        self._index = None                                                   # the gather, once the row counts are known

    def _gather(self, sizes):
        base = dict(zip(self.rows, np.cumsum((0,) + sizes[:-1])))
        return np.array([base[s.rows] + e for s in self.specs for e in s.index])

    def __call__(self, q):
        xp = array_namespace(q.V)
        sums = [q.sums(r) for r in self.rows]
        if self._index is None:
            self._index = self._gather(tuple(len(S) for S in sums))
        B, n = q.B, len(self.specs)
        A = xp.concatenate(sums)
        scale = xp.empty((B, n, 1))
        scale[:, :, 0] = xp.asarray(self.const)
        for f, cols in self.varying:
            scale[:, cols, 0] = q.tensor(f)[:, None]
        T = A[xp.asarray(self._index)].T.reshape(B, n, 4) * (xp.asarray(self.coef) * scale)
        if self.per_volume:
            cols = xp.asarray(self.per_volume)
            T[:, cols] /= q.V[:, None, None]
        return T.reshape(B, n, 2, 2)


def _force_per_volume(q):
    """``CF_CL / V`` per replica: forces ×1e-12 and lever arms ×1e-6 over the volume (1/m² per m depth)."""
    return CF_CL / q.V


_FULL = (0, 1, 2, 3)


@linear_tensor(_love_weber_rows, _FULL, (1, 1, 1, 1), _force_per_volume)
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


@linear_tensor(_external_rows, _FULL, (-1, -1, -1, -1), _force_per_volume)
def external_forces(q):
    """σ_ext = −(1/V) Σ_external F ⊗ (x_target − c) (eq. S1-16): a mobile sphere of a pair through
    the boundary or with an immobile partner receives the pair force at its own centre.

    Its xy entry is −τ_surface of :func:`~particleShear.engine.forces.shear_stresses`, bit for bit
    (the same rows, the same sums).

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """


@linear_tensor(_unbalanced_rows, _FULL, (1, 1, 1, 1), _force_per_volume)
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


@linear_tensor(_unbalanced_rows, _FULL, (1, 1, 1, 1), _force_per_volume)
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


@linear_tensor(_torque_rows, (0, 0, 0, 0), (0.0, -0.5, 0.5, 0.0), CT, per_volume=True)
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


@linear_tensor(_internal_torque_rows, (0, 0, 0, 0), (0.0, -0.5, 0.5, 0.0), CT, per_volume=True)
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


@linear_tensor(_spin_rows, (0, 0, 0, 0), (-0.5, -0.0, -0.0, -0.5), 1e-18, per_volume=True)
def spin_kinetic_energy(q):
    """σ_cen = −(1/V) Σ_mobile I ω²/2 · 1 (eq. S1-21; inertias and ω² ×1e-18).

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """


@linear_tensor(_otsuki_rows, _FULL, (-1, -1, -1, -1), 1.0, per_volume=True)
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


def overall(q):
    """σ = σ_LW + σ_Tint + σ_cen (eq. S1-24); its xy entry is −τ_internal of
    :func:`~particleShear.engine.forces.shear_stresses`, bit for bit (the same sums in the same
    formula), so G does not depend on whether tensors are kept.

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 2, 2)
        The tensor of each replica (Pa; ``[b, force component, position component]``).
    """
    out = q.tensor(love_weber) + q.tensor(internal_torque) + q.tensor(spin_kinetic_energy)
    # Σ F_x,i·D_y is minus the Love-Weber row's sum (the same products with the sign of D flipped: exact)
    tau_internal, _ = shear_from_sums(-q.sums(_love_weber_rows)[1], q.sums(_internal_torque_rows)[0],
                                      q.sums(_external_rows)[1], q.V)
    out[:, 0, 1] = -tau_internal
    return out


#: one registry entry per tensor: name (StressTensorEvaluation attribute), output-column stem, equation,
#: function, and the row functions it sums (:func:`pair_rows`, :func:`sphere_rows`)
Tensor = collections.namedtuple("Tensor", "name stem equation function rows")
TENSORS = (
    Tensor("stress_tensor_LW", "stress_tensor_Love_Weber", "S1-19", love_weber, (_love_weber_rows,)),
    Tensor("stress_tensor_linear_acceleration_otsuki", "stress_tensor_peculiar_acceleration_otsuki", "Otsuki",
           peculiar_acceleration_otsuki, (_otsuki_rows,)),
    Tensor("stress_tensor_with_external_forces", "stress_tensor_from_external_forces", "S1-16", external_forces,
           (_external_rows,)),
    Tensor("stress_tensor_linear_acceleration", "stress_tensor_linear_acceleration", "S1-17", linear_acceleration,
           (_unbalanced_rows,)),
    Tensor("stress_tensor_unbalanced_forces", "stress_tensor_unbalanced_linear_forces", "S1-17",
           unbalanced_forces, (_unbalanced_rows,)),
    Tensor("stress_tensor_unbalanced_torque", "stress_tensor_tangential_torque", "S1-22", unbalanced_torque,
           (_torque_rows,)),
    Tensor("stress_tensor_internal_torque", "stress_tensor_internal_tangential_torque", "S1-22", internal_torque,
           (_internal_torque_rows,)),
    Tensor("stress_tensor_spin_kinetic_energy", "stress_tensor_centrifugal", "S1-21", spin_kinetic_energy,
           (_spin_rows,)),
    Tensor("overall_stress_tensor", "stress_tensor_overall", "S1-24", overall,
           (_love_weber_rows, _internal_torque_rows, _spin_rows, _external_rows)),
)
#: the positions in :data:`TENSORS` of the tensors whose xy entries are −τ_internal and −τ_surface
#: (:func:`~particleShear.engine.forces.shear_from_sums`)
OVERALL, EXTERNAL = ([t.function for t in TENSORS].index(f) for f in (overall, external_forces))
#: every row function of :data:`TENSORS`, once
ROWS = tuple(dict.fromkeys(r for t in TENSORS for r in t.rows))
#: the sphere rows of the spheres' motion (I, ω, m, v: a caller's list of spheres in
#: :class:`~particleShear.base.stress.StressTensorEvaluation`); the other sphere rows read the force
#: phase's totals
KINETIC_ROWS = (_spin_rows, _otsuki_rows)


#: the rows the compiled step sums (:mod:`.numba_step`, :func:`tensors_from_sums`), in the order of its
#: sums: the pair rows, then the sphere rows, with the number of rows of each
SUMMED_ROWS = ((_love_weber_rows, 4), (_external_rows, 4), (_internal_torque_rows, 1), (_unbalanced_rows, 4),
               (_torque_rows, 1), (_spin_rows, 1), (_otsuki_rows, 4))


#: the tensors of :data:`TENSORS` that are :class:`Linear` maps, evaluated together by :func:`evaluate_all`
_LINEAR = tuple(k for k, t in enumerate(TENSORS) if hasattr(t.function, "linear"))
_LINEAR_MAPS = _LinearMaps([TENSORS[k].function.linear for k in _LINEAR])


def evaluate_all(q):
    """(B, 9, 2, 2) array of every tensor of :data:`TENSORS`, in registry order.

    The :class:`Linear` tensors are evaluated together (the same numbers as each on its own), then
    the others (the overall tensor, which adds three of them) one by one.

    Parameters
    ----------
    q : StressInputs
        The force phase of the batch.

    Returns
    -------
    ndarray (B, 9, 2, 2)
        ``out[b, t]`` is tensor ``TENSORS[t]`` of replica b (Pa).
    """
    q.reduce(ROWS)
    xp = array_namespace(q.V)
    out = xp.empty((q.B, len(TENSORS), 2, 2))
    out[:, _LINEAR] = linear = _LINEAR_MAPS(q)
    memo = q.__dict__.setdefault("_tensors", {})
    for n, k in enumerate(_LINEAR):
        memo.setdefault(TENSORS[k].function, linear[:, n])
    for k, t in enumerate(TENSORS):
        if k not in _LINEAR:
            out[:, k] = q.tensor(t.function)
    return out


def tensors_from_sums(sums, V):
    """Every tensor of :data:`TENSORS` from the per-replica sums of its rows (the compiled step's).

    The sums take the place of :meth:`StressInputs.reduce`; the tensors are then what
    :func:`evaluate_all` makes of them, the same functions (so the same numbers as the NumPy force
    phase when the sums are the same bits).

    Parameters
    ----------
    sums : ndarray (19, B)
        The sums of the rows of :data:`SUMMED_ROWS`, in its order (each row's unit), per replica.
    V : ndarray (B,)
        The cell volume of each replica (m² per m depth).

    Returns
    -------
    ndarray (B, 9, 2, 2)
        As :func:`evaluate_all` (Pa).
    """
    q = StressInputs(B=sums.shape[1], V=V)
    memo = q.__dict__.setdefault("_row_sums", {})
    k = 0
    for rows, n in SUMMED_ROWS:
        memo[rows] = sums[k:k + n]
        k += n
    return evaluate_all(q)
