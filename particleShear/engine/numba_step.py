"""The whole step of a batch in one compiled call (Numba, optional), from the same pure functions.

:meth:`~particleShear.engine.step.BatchEngine.step` on the ``"numba"`` backend runs the step here:
one call per step does the force phase (Lees-Edwards minimum image, relations and their numbers,
normals, relative velocities, the force terms of :func:`~.numba_driver.pair_term`, pair
forces, the scatter in the order of ``bincount``, the per-replica shear sums when sampled, the
stability guard when due), the kick with the plates and the damping, the sequential ξ rule, the
displacement since the lists were built, the drift, the strain, the wrap and the clock; a step that
samples every tensor also sums the rows of :mod:`~.stress` per replica (the maps of the sums to the
tensors then run on NumPy, :func:`~.stress.tensors_from_sums`).  Every
formula is a pure function of the NumPy engine called here on numbers
(:data:`STEP_FUNCTIONS`: :func:`~.box.period_count`, :func:`~.box.folded`,
:func:`~.integrate.velocity_change`, :func:`~.integrate.plate_velocity`, :func:`~.integrate.damped`,
:func:`~.integrate.xi_rates`, :func:`~.terms.normal_speed`, :func:`~.terms.slip_speed`,
:func:`~.terms.pair_forces`, :func:`~.forces.pair_roles`, :func:`~.forces.shear_rows`,
:func:`~.forces.shear_from_sums`, :func:`~.guard.kinetic_term`, :func:`~.guard.energy_bound`,
:func:`~.guard.verdict_code`, :func:`~.guard.transient_ratio`, :func:`~.neighbours.verlet_bound`
and the laws), in the NumPy engine's order of operations, so the trajectories are the same bits.

A block of steps (:func:`run_block`, the protocols' schedules and the relaxations) also rebuilds the
candidate lists due inside its compiled call, replica by replica (:func:`_rebuild_replica`: the
search, the history merge and the new candidates' constants from the same compiled functions, into
the replica's own slot of columns, :class:`_Slots`); the engine's candidates are handed back once
per block (:func:`_settle`).  What stays in Python: a rebuild outside a block, or one a block
leaves (:meth:`~particleShear.engine.step.BatchEngine.neighbours`; per replica the search and the
history merge run compiled, :func:`rebuild`, and the new candidates' constants in one compiled
pass, :func:`constant_rows`), the draws of the random directions at ``d = 0`` and ``|R| = 0`` (from
each replica's generator, as :func:`~.forces.normals` draws them; the step then goes on compiled),
and the protocol's schedule and observers.  The sums NumPy takes per replica (the shear sums of
``numpy.add.reduceat``, the guard's kinetic energy of ``numpy.sum``) are taken in NumPy's
_pairwise order, so the sampled stresses are the same bits too.  A step the compiled code does not cover (see :func:`reason`) runs on NumPy, with a
one-line note per engine and reason.

The engine's phases run here alone too: :func:`force_phase` (the kernel's force phase,
:func:`launch` with ``forces_only``) and :func:`move` (the kernel from its movement,
:data:`MOVE_ONLY`) are :meth:`~particleShear.engine.step.BatchEngine.force_phase` and
:meth:`~particleShear.engine.step.BatchEngine.move` on the ``"numba"`` backend (the documented
classes step an ensemble in these phases, three calls).  The pieces of a step are public
(:func:`launch`, :func:`step_arguments`, :func:`resume_at_units`, :func:`hand_back`,
:func:`kept_terms`, :func:`step_samples`, :func:`compile_kernel` and the tensors' rows
:func:`pair_tensor_rows`, :func:`sphere_tensor_rows`, :func:`tensor_row_sums`): the documented
classes' tensor sums run through them, beside those classes
(:mod:`particleShear.base.compiled_phases`).
"""
__docformat__ = "numpy"

import logging
import math
import sys
import warnings
import weakref

import numpy as np

from . import box, forces, guard, integrate, law_check, laws, neighbours, numba_driver, state, stress, terms
from .box import MAX_PASSES, folded, period_count
from .forces import pair_roles, pair_rows, shear_from_sums, shear_rows
from .guard import energy_bound, kinetic_term, transient_ratio, verdict_code
from .laws import get_law
from .integrate import damped, flow_shifted, half_velocity_change, plate_velocity, velocity_change, xi_rates
from .neighbours import _INT32_MAX, build_candidates, cell_grid, cell_index, near_pairs, verlet_bound, within_reach
from .numba_driver import borrowed, pair_term
from .phase_laws import force_phase_laws, run_law
from .state import _MERGE_MIN, PERMANENT, carried_fields, carried_rows, synced_history
from .stress import (EXTERNAL, OVERALL, external_entries, love_weber_entries, otsuki_entries, outer_entries,
                     spin_entry, tensors_from_sums, unbalanced_entries)
from .terms import normal_speed, pair_forces, slip_speed, viscous_force

__all__ = ["STEP_FUNCTIONS", "reason", "compile_step_kernel", "compile_block_kernel", "compile_search_kernel",
           "compile_carried_kernel", "compile_constants_kernel", "compile_carry_kernel", "compile_kernels",
           "compile_kernel", "pair_tensor_rows", "sphere_tensor_rows", "tensor_row_sums",
           "run_step", "force_phase", "move", "launch", "resume_at_units", "step_arguments", "hand_back", "kept_terms",
           "step_samples", "draw_directions", "kernels_of", "last_workspace", "run_block", "search", "carried",
           "rebuild", "constant_rows", "NOT_RUN", "UNITS", "MOVE_ONLY", "TENSOR_SUMS", "REBUILD_IN_BLOCK", "SLACK"]

#: the pure functions the compiled step calls besides the laws: ``(module, name)``
STEP_FUNCTIONS = numba_driver.LAW_FUNCTIONS + (
    (box, "period_count"), (box, "folded"), (integrate, "velocity_change"), (integrate, "half_velocity_change"),
    (integrate, "plate_velocity"),
    (integrate, "damped"), (integrate, "xi_rates"), (terms, "normal_speed"), (terms, "slip_speed"),
    (terms, "pair_forces"), (forces, "pair_roles"), (forces, "shear_rows"), (forces, "shear_from_sums"),
    (guard, "kinetic_term"), (guard, "energy_bound"), (guard, "verdict_code"), (guard, "transient_ratio"),
    (neighbours, "verlet_bound"), (neighbours, "within_reach"), (stress, "outer_entries"),
    (stress, "love_weber_entries"), (stress, "external_entries"), (stress, "unbalanced_entries"), (stress, "spin_entry"),
    (stress, "otsuki_entries"))

#: the step's own compiled functions (this module's), and those inlined into their callers
KERNEL_FUNCTIONS = ((numba_driver, "_central_law"), (numba_driver, "pair_term"), (sys.modules[__name__], "_min_image_pair"),
                    (sys.modules[__name__], "_pairwise"), (sys.modules[__name__], "_segment_sum"),
                    (sys.modules[__name__], "_nan_max"), (sys.modules[__name__], "_nan_min"),
                    (sys.modules[__name__], "pair_tensor_rows"),
                    (sys.modules[__name__], "sphere_tensor_rows"), (sys.modules[__name__], "tensor_row_sums"),
                    (sys.modules[__name__], "_step_kernel"))
INLINE = ("pair_term", "_min_image_pair", "_segment_sum", "_nan_max", "_nan_min")
#: the functions of the search (:func:`search`) besides the step's
SEARCH_FUNCTIONS = ((neighbours, "cell_index"), (sys.modules[__name__], "_all_pairs"),
                    (sys.modules[__name__], "_cell_pairs"),
                    (sys.modules[__name__], "_search_kernel"))
#: the constants of a rebuild's candidates (:func:`constant_rows`)
CONSTANT_FUNCTIONS = ((laws, "central_constants"), (terms, "term_rows"), (forces, "geometry_rows"),
                      (forces, "pair_rows"), (sys.modules[__name__], "_constants_kernel"))
assert len(forces.PairConstants.FLOAT_ROWS) == 23      # (the rows _constants_kernel writes)
#: the history merge of a rebuild (:func:`carried`): the pair table's own functions
MERGE_FUNCTIONS = ((state, "_increasing"), (state, "_positions"), (state, "_merge"), (state, "carried_rows"))
#: the functions of the compiled history merge of a rebuild (:func:`rebuild`)
CARRY_FUNCTIONS = MERGE_FUNCTIONS + ((state, "carried_fields"), (sys.modules[__name__], "_carry_kernel"))
#: the functions of the compiled block (:func:`run_block`) besides the step's: its rebuilds run the
#: search and the constants of the rebuild outside a block, and the history merge in one pass
#: (:func:`_rebuild_replica`, :func:`_merged_history`)
BLOCK_FUNCTIONS = ((integrate, "flow_shifted"), (state, "synced_history"), (neighbours, "cell_grid")) + \
    SEARCH_FUNCTIONS + CONSTANT_FUNCTIONS + \
    ((sys.modules[__name__], "_sorted_keys"), (sys.modules[__name__], "_merged_history"),
     (sys.modules[__name__], "_rebuild_replica"),
     (sys.modules[__name__], "_block_kernel"))

#: the types of :func:`_step_kernel`'s arguments, in order (``f``: float64, ``i``: int64, ``b``: bool,
#: ``i1``: int8; ``[:]``, ``[:, :]``: C-contiguous arrays), compiled once before any timing
_ARGUMENTS = ("i i i i f f i b b b i b f[:,:] b i f[:,:] i b[:] b b[:] f[:,:] f[:,:] "   # start, b0, b1, N … half_out
              "f[:,:] f[:,:] f[:,:] f[:] f[:,:] f[:] f[:] i[:] "      # pos … rep_s
              "f[:] f[:] f[:] f[:] f[:] f[:] f[:] f[:] "             # rate … V, le, adv
              "f[:,:] i[:,:] b[:,:] i[:] i[:] i1[:] f[:,:] b[:] i[:] i[:] "  # Cf … next_birth
              "f[:,:] f[:] f[:] f[:] f[:] f[:] "                     # u … skin
              "f[:] f[:] f[:] f[:] f[:] f f "                        # guard_on … max_ke
              "f[:,:] b[:] f[:] f[:] b[:] f[:,:] f[:,:] b[:] f[:,:] f[:,:] f[:,:] "   # work … tsum
              "b f[:,:] f[:,:] b").split()                                  # keep, kt, ktot, forces_only

#: the contact laws of the laws folder whose compiled form is checked bit for bit against NumPy's
#: by the tests (particleShearTest/test_numba_step.py): pure expressions of arithmetic, sqrt, max and
#: min.  Another law runs compiled where :func:`~.law_check.law_bits` finds NumPy's bits on the
#: run's candidates (a law's ``**`` or ``exp`` may round otherwise in the last bit in compiled
#: code), else on NumPy with a note
COMPILED_LAWS = ("hertz", "plateau")

#: what :func:`run_step` returns when the step was not run (the NumPy step runs it)
NOT_RUN = object()

# the kernel's return codes, and the start of a replica a block skips
_DONE, _D_ZERO, _GUARD, _UNITS, _NEED = 0, 1, 2, 3, 4
#: the kernel's status where it stopped for the random directions at ``|R| = 0`` (:func:`resume_at_units`)
UNITS = _UNITS
#: the kernel's start of the movement alone after a force phase and a kick of its own (the ξ rule,
#: displacement, drift, strain, wrap and clock; the phase's geometry in ``work`` rows 0, 1, 5–7 and ``yc``)
MOVE_ONLY = 5
_SKIP = -1
#: the sums of every tensor's rows a sampling step makes (:data:`~.stress.SUMMED_ROWS`)
TENSOR_SUMS = sum(n for _, n in stress.SUMMED_ROWS)

_kernels = {}

#: the loop over a block's replicas (:func:`_block_kernel`): ``range`` here and in the serial
#: compile, ``numba.prange`` in the compile for several threads (:func:`threads`)
prange = range

#: the environment variable of the threads a compiled block steps its replicas on
THREADS_VARIABLE = "PARTICLESHEAR_THREADS"


def threads():
    """The threads a compiled block steps a batch's replicas on: ``PARTICLESHEAR_THREADS`` (default 1).

    More than one runs the replicas of a block in parallel (``numba.prange``; each replica reads and
    writes only its own rows, so the numbers are the same bits on any number of threads).  It is a
    choice of the process, off by default: runs in several processes (sweeps, pools) or threads
    already use the cores, and Numba's default threading layer takes one parallel call at a time.

    Returns
    -------
    int
        The number of threads (≥ 1).

    Raises
    ------
    ValueError
        When the variable is set to anything but a whole number ≥ 1.
    """
    import os
    text = os.environ.get(THREADS_VARIABLE, "").strip()
    if not text:
        return 1
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise ValueError(f"{THREADS_VARIABLE}={text!r} is invalid: allowed a whole number of threads >= 1 "
                         "(1: one thread, the default)")
    return n


def reason(engine):
    """Why this engine's step cannot run in the compiled code (a short text), or None when it can.

    Covered: both integrators, Lees-Edwards and plain periodic replicas (:attr:`~particleShear.engine.step.BatchEngine.lees_edwards`),
    strains advancing or held (:attr:`~particleShear.engine.step.BatchEngine.strain_advances`), replicas with
    and without friction and bonds, spheres with parameters of their own under the linear law (the
    visit from j with its own constants, ``C.Kj``), the linear law
    from the prepared constants or a run's contact law (those of :data:`COMPILED_LAWS`; any other where
    Numba compiles it with NumPy's bits, checked by the workspace: :func:`~.law_check.law_bits`), the tensile law
    of bonds, no force register, samples of the two shear stresses and of every tensor of
    :data:`~.stress.TENSORS` (their rows summed per replica in NumPy's order, :func:`~.stress.tensors_from_sums`).

    Parameters
    ----------
    engine : BatchEngine
        The engine, with its candidates' constants built.

    Returns
    -------
    str or None
    """
    C, s = engine.s.contacts.C, engine.s
    for a in (s.pos, s.vel, s.frc, s.phi, s.r, engine.mmi, C.f, C.i, C.b):
        if not (type(a) is np.ndarray and a.flags.c_contiguous and a.flags.writeable):
            return "state arrays that are not writable C-contiguous NumPy arrays"
    central, tensile = force_phase_laws(s, C)
    if C.Kj is not None and central is not None:
        return "spheres with parameters of their own under a contact law of the laws folder"
    if tensile is not None:
        return "a tensile law callback of the documented classes"
    if central is None:
        return None
    got = _phase_law(s, C)
    if got is None:
        return "a law callback of the documented classes that is a function of its own"
    return None    # (a law outside COMPILED_LAWS is checked bit for bit by the workspace: law_check.law_bits)


def _phase_law(s, C):
    """The central law of a force phase other than the built-in one as ``(name, function, arguments)``
    (the law of every candidate at ``d`` is ``function(d, *arguments)``, what the NumPy phase
    evaluates): the run's contact law (:func:`~.phase_laws.run_law`), or a documented law callback
    that is a registered law (the ``central`` of the state's ``callback_laws``); None otherwise."""
    if s.law is not None:
        got = run_law(s, C)
        return None if got is None else (get_law(s.law).name,) + tuple(got)
    central = getattr(getattr(s, "callback_laws", None), "central", None)
    return None if central is None else central(C)



# the rows of the candidates' float block the step reads (PairConstants.FLOAT_ROWS) and where the
# constants of the force terms start (numba_driver.TERM_BLOCK)
_ILX, _ILY, _IRI, _IRJ, _ID0, _IWI, _IWJ = (forces.PairConstants.FLOAT_ROWS.index(n)
                                           for n in ("Lx", "Ly", "ri", "rj", "d0", "w_i", "w_j"))
_T0 = numba_driver._TERM_START
# the rows of the permanent ratio and the viscosity in the term block (the register's elastic and viscous parts)
_TRC, _TNU = (forces.PairConstants.TERM_ROWS.index(n) for n in ("ratio_c", "nu"))
#: the rows of the terms a step keeps for a force register (``keep``; :func:`kept_terms`)
_KEPT = ("el_i", "v_i", "F_i", "F_j", "fx_i", "fy_i", "el_j", "v_j", "fx_j", "fy_j")


def _min_image_pair(dx, dy, Lx, Ly, shift):
    # the minimum image of one pair (box.min_image element by element)
    hy, hx = Ly / 2, Lx / 2
    ky = 0.0
    for q in range(MAX_PASSES + 1):
        if q == MAX_PASSES:
            dy, k = folded(dy, Ly, -hy, hy)
            dx = dx - shift * k
            ky += k
            break
        k = period_count(dy, hy, -hy)
        if k == 0.0:
            break
        dy = dy - Ly * k
        dx = dx - shift * k
        ky += k
    kx = 0.0
    for q in range(MAX_PASSES + 1):
        if q == MAX_PASSES:
            dx, k = folded(dx, Lx, -hx, hx)
            kx += k
            break
        k = period_count(dx, hx, -hx)
        if k == 0.0:
            break
        dx = dx - Lx * k
        kx += k
    return dx, dy, ky, kx


def _pairwise(a, lo, n):
    """NumPy's _pairwise sum of ``a[lo:lo + n]`` (compiled)."""
    # NumPy's _pairwise summation of a[lo:lo + n] (numpy/_core/src/umath/loops_utils.h.src): the
    # order of numpy.sum along a contiguous axis, so the compiled sums are NumPy's to the bit
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    if n <= 128:
        r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
        r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
        i = 8
        while i < n - n % 8:
            r0 += a[lo + i]
            r1 += a[lo + i + 1]
            r2 += a[lo + i + 2]
            r3 += a[lo + i + 3]
            r4 += a[lo + i + 4]
            r5 += a[lo + i + 5]
            r6 += a[lo + i + 6]
            r7 += a[lo + i + 7]
            i += 8
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        while i < n:
            res += a[lo + i]
            i += 1
        return res
    n2 = n // 2
    n2 -= n2 % 8
    return _pairwise(a, lo, n2) + _pairwise(a, lo + n2, n - n2)


def _nan_max(a, b):
    """``numpy.maximum`` of two numbers (NaN when either is): the reductions of the NumPy engine."""
    return a + b if a != a or b != b else max(a, b)


def _nan_min(a, b):
    """``numpy.minimum`` of two numbers (NaN when either is)."""
    return a + b if a != a or b != b else min(a, b)


def _segment_sum(a, lo, hi):
    # numpy.add.reduceat over one segment: its first element, then the _pairwise sum of the rest
    return a[lo] + _pairwise(a, lo + 1, hi - lo - 1) if hi > lo else 0.0


def pair_tensor_rows(P0, P1, ai, aj, rep, own_j, x, y, Lx, Ly, mob, active, ky, kx, dx, dy, fx_i, fy_i, fx_j, fy_j, dF,
                     tp):
    """The pair rows of every tensor (:mod:`~.stress`: Love-Weber, external, internal torque) of the
    candidates ``P0 … P1 − 1`` into ``tp`` (compiled; the step's sampling steps and the documented
    classes' tensor sums).

    Parameters
    ----------
    P0, P1 : int
        The candidates' range.
    ai, aj, rep : ndarray of int (P,)
        The candidates' sphere rows and replicas.
    own_j : bool
        Spheres with parameters of their own: j receives ``fx_j, fy_j`` (else ``fx_i, fy_i`` are read).
    x, y : ndarray (B·N,)
        Positions (µm).
    Lx, Ly : ndarray (B,)
        Cell sizes (µm).
    mob : ndarray of bool (B·N,)
        The mobility mask.
    active : ndarray of bool (P,)
        The relations.
    ky, kx : ndarray (P,)
        Nonzero where the pair acts through a periodic boundary.
    dx, dy : ndarray (P,)
        The pair vectors (µm).
    fx_i, fy_i, fx_j, fy_j : ndarray (P,)
        The forces on i (and on j, read only with ``own_j``).
    dF : ndarray (P,)
        The tangential torque factors.
    tp : ndarray (9, P)
        Written: the rows.
    """
    for p in range(P0, P1):
        i, j, b = ai[p], aj[p], rep[p]
        internal, ext_i, ext_j = pair_roles(mob[i], mob[j], (ky[p] != 0.0) or (kx[p] != 0.0))
        rel = active[p]
        internal, ext_i, ext_j = internal and rel, ext_i and rel, ext_j and rel     # (StressInputs.roles)
        xc_i, yc_i = x[i] - Lx[b] / 2, y[i] - Ly[b] / 2
        xc_j, yc_j = x[j] - Lx[b] / 2, y[j] - Ly[b] / 2
        tp[0, p], tp[1, p], tp[2, p], tp[3, p] = love_weber_entries(fx_i[p], fy_i[p], fx_j[p], fy_j[p], own_j, dx[p],
                                                                    dy[p], internal)
        tp[4, p], tp[5, p], tp[6, p], tp[7, p] = external_entries(fx_i[p], fy_i[p], fx_j[p], fy_j[p], own_j, xc_i, yc_i,
                                                                  xc_j, yc_j, ext_i, ext_j)
        tp[8, p] = dF[p] * internal


def sphere_tensor_rows(n0, n1, rep, x, y, vx, vy, omega, m, inertia, fx, fy, torque, mob, rate, Lx, Ly, ts):
    """The sphere rows of every tensor (:mod:`~.stress`: unbalanced forces, torques, spin, Otsuki) of
    the spheres ``n0 … n1 − 1`` into ``ts`` (compiled).

    Parameters
    ----------
    n0, n1 : int
        The spheres' range.
    rep : ndarray of int (B·N,)
        Each sphere's replica.
    x, y, vx, vy, omega : ndarray (B·N,)
        Positions (µm), velocities (µm/s), spins (1/s).
    m, inertia : ndarray (B·N,)
        Masses and moments of inertia.
    fx, fy, torque : ndarray (B·N,)
        The totals of the force phase.
    mob : ndarray of bool (B·N,)
        The mobility mask.
    rate : ndarray (B,)
        Shear rates (1/s).
    Lx, Ly : ndarray (B,)
        Cell sizes (µm).
    ts : ndarray (10, B·N)
        Written: the rows.
    """
    for k in range(n0, n1):
        b = rep[k]
        xc, yc = x[k] - Lx[b] / 2, y[k] - Ly[b] / 2
        ts[0, k], ts[1, k], ts[2, k], ts[3, k] = unbalanced_entries(fx[k], fy[k], mob[k], xc, yc)
        ts[4, k] = torque[k]
        ts[5, k] = spin_entry(inertia[k], omega[k], mob[k])
        ts[6, k], ts[7, k], ts[8, k], ts[9, k] = otsuki_entries(m[k], vx[k], vy[k], rate[b], yc, mob[k])


def tensor_row_sums(b0, b1, N, offsets, ends, tp, ts, tsum):
    """The sums of the rows of ``tp`` and ``ts`` per replica ``b0 … b1 − 1`` into ``tsum``, in the
    order of :data:`~.stress.SUMMED_ROWS` and NumPy's (``forces.replica_sums`` and
    ``StressInputs.per_replica``: ``numpy.add.reduceat`` over each replica's segment) (compiled).

    Parameters
    ----------
    b0, b1 : int
        The replicas' range.
    N : int
        Spheres per replica.
    offsets, ends : ndarray of int (B,)
        Replica b's candidates are the columns ``offsets[b] … ends[b] − 1``.
    tp, ts : ndarray (9, P), (10, B·N)
        The pair and sphere rows (:func:`pair_tensor_rows`, :func:`sphere_tensor_rows`).
    tsum : ndarray (19, B)
        Written: the sums.
    """
    for b in range(b0, b1):
        for q in range(9):
            tsum[q, b] = _segment_sum(tp[q], offsets[b], ends[b])
        for q in range(10):
            tsum[9 + q, b] = _segment_sum(ts[q], b * N, (b + 1) * N)


def _step_kernel(start, b0, b1, N, cool, dt, sample, check, applying, numbers, form, custom, A, visit_j, form_j, Tj,
                 free_mode, free, verlet,
                 pred, half, half_out,
           pos, vel, frc, phi, mmi, r, Ly_s, rep_s,
           rate, gamma, t, Lx, Ly, V, le, adv,
           Cf, Ci, Cb, offsets, ends, state_p, xi, active, birth, next_birth,
           u, u_max, strain, bound, r_max, skin,
           guard_on, rate_max, kk, r_mean, m_sum, min_ratio, max_ke,
           work, mob, yc, y0, zero, tau, verdict, need, tp, ts, tsum, keep, kt, ktot, forces_only):
    """One step of the replicas ``b0 … b1 − 1`` on numbers (compiled; run by :func:`run_step` for the
    whole batch and by :func:`_block_kernel` for one replica at a time).

    The replicas' spheres are the rows ``b0·N … b1·N − 1`` and replica b's candidates the columns
    ``offsets[b] … ends[b] − 1`` (those of ``b0 … b1 − 1`` side by side, ``ends[b] = offsets[b + 1]``,
    where the step runs more than one replica; a replica a block steps alone may have free columns
    after its own, the room of its rebuilds, :func:`_block_kernel`); nothing of another replica is read or written, so a replica's
    step is the same numbers whatever else the batch holds or in which order its replicas step.
    ``start`` 0 runs the whole step; 3 runs it with the random normals of the pairs at ``d = 0``
    given (``work`` rows 5, 6, drawn by the caller after :data:`_D_ZERO`); 1 resumes at the ξ rule
    once the caller gave the random directions at ``|R| = 0`` (``work`` rows 8, 9), from the first
    such pair on (the pairs before it had theirs in the call that stopped there).  ``pred[b]``:
    replica b's velocity terms see the velocities half a kick ahead (``half``; velocity Verlet after
    its first step).  ``sample``: 0 no stresses, 1 the two shear stresses (``tau``), 2 also the sums of
    every tensor's rows (``tsum``, :data:`~.stress.SUMMED_ROWS`: the pair rows in ``tp``, the sphere
    rows in ``ts``, summed per replica as NumPy sums them).  ``keep``: the step keeps the terms of
    its force phase for a force register (the rows :data:`_KEPT` of ``kt``, the sphere totals in
    ``ktot``; :func:`kept_terms`).  ``forces_only``: the force phase alone (:func:`launch`),
    the forces and torques left in ``frc`` and its geometry in ``work``; ``start`` 5: the movement
    alone (:data:`MOVE_ONLY`: the ξ rule, displacement, drift, strain, wrap and clock after a force
    phase and a kick of their own, its geometry in ``work`` and ``yc``).  The other arguments are
    the engine's (the flags of the step, the state's
    sphere rows, the per-replica box, strain, rate and clock, the candidates' blocks and history,
    the Verlet bookkeeping, the guard's constants) and the buffers of its :class:`_Workspace`;
    everything is written in place.  Returns :data:`_DONE`, or :data:`_D_ZERO` (nothing changed: a
    pair at ``d = 0`` whose normal is not given), :data:`_GUARD` (after the force phase) or :data:`_UNITS`.
    """
    P0, P1 = offsets[b0], ends[b1 - 1] if b1 > b0 else offsets[b0]
    n0, n1 = b0 * N, b1 * N
    T = Cf[_T0:_T0 + 12]
    # the visit from j: its own constants where spheres have parameters of their own (visit_j), else i's
    k_t_j, nu_t_j = (Tj[8], Tj[9]) if visit_j else (T[8], T[9])
    dxs, dys, kys, kxs, ds, nxs, nys, dvxs, mxs, mys, dFs = (work[0], work[1], work[2], work[3], work[4], work[5],
                                                             work[6], work[7], work[8], work[9], work[10])
    if start != 1:
        if start != 5:       # (5: the movement alone, after a force phase and a kick of their own)
            # -- the force phase: geometry of every candidate first (nothing changes before d = 0 is ruled out)
            coincident = False
            for p in range(P0, P1):
                b, i, j = Ci[0, p], Ci[1, p], Ci[2, p]
                dx, dy, ky, kx = _min_image_pair(pos[0, j] - pos[0, i], pos[1, j] - pos[1, i], Cf[_ILX, p], Cf[_ILY, p],
                                       Ly[b] * gamma[b] * le[b])
                d = np.sqrt(dx * dx + dy * dy)
                coincident = coincident or d == 0.0
                dxs[p], dys[p], kys[p], kxs[p], ds[p] = dx, dy, ky, kx, d
            if coincident and start != 3:
                return _D_ZERO
            for k in range(n0, n1):
                yc[k] = pos[1, k] - Ly_s[k] / 2
                mob[k] = (r[k] < pos[1, k]) and (pos[1, k] < Ly_s[k] - r[k]) if applying else True
                frc[0, k] = 0.0
                frc[1, k] = 0.0
                frc[2, k] = 0.0
            for b in range(b0, b1):
                tau[0, b] = 0.0
                tau[1, b] = 0.0
                verdict[3, b] = math.inf
            # relations, terms and the pair forces on i (the scatter's first half, in pair order)
            for p in range(P0, P1):
                b, i, j = Ci[0, p], Ci[1, p], Ci[2, p]
                d = ds[p]
                touching = d < Cf[_ID0, p]
                rel = Cb[0, p] or touching
                if rel and not active[p]:
                    state_p[p] = 0                      # a new relation starts sticking
                    if numbers:
                        birth[p] = next_birth[b]
                        next_birth[b] += 1
                if not rel:
                    xi[0, p] = 0.0                      # an opened contact loses its history
                    xi[1, p] = 0.0
                active[p] = rel
                if d == 0.0:      # (the random normal the caller drew, as forces.normals draws it)
                    nx, ny = nxs[p], nys[p]
                else:
                    nx, ny = dxs[p] / d, dys[p] / d
                dvx = -(Cf[_ILY, p] * (rate[b] * le[b])) * kys[p]
                if pred[b]:     # velocity Verlet: the velocity terms see the velocities half a kick ahead
                    vi0, vi1, vi2 = vel[0, i] + half[0, i], vel[1, i] + half[1, i], vel[2, i] + half[2, i]
                    vj0, vj1, vj2 = vel[0, j] + half[0, j], vel[1, j] + half[1, j], vel[2, j] + half[2, j]
                else:
                    vi0, vi1, vi2, vj0, vj1, vj2 = vel[0, i], vel[1, i], vel[2, i], vel[0, j], vel[1, j], vel[2, j]
                rv = (vj0 - vi0 + dvx, vj1 - vi1)
                vn = normal_speed(rv, nx, ny)
                vt = slip_speed(rv, nx, ny, Cf[_IRI, p], Cf[_IRJ, p], vi2, vj2) if free_mode != 1 else 0.0
                q = p if custom else 0                # (the run law's arguments: A is (8, 1) without one)
                fn, law, F_i, F_j, slip, reset = pair_term(
                    form, d, vn, vt, touching, rel, xi[0, p], xi[1, p], T[0, p], T[1, p], T[2, p], T[3, p], T[4, p],
                    T[5, p], T[6, p], T[7, p], T[8, p], T[9, p], T[10, p], T[11, p], k_t_j[p], nu_t_j[p], free_mode != 1,
                    custom, (A[0, q], A[1, q], A[2, q], A[3, q], A[4, q], A[5, q], A[6, q], A[7, q]))
                if reset:
                    xi[0, p] = 0.0
                    xi[1, p] = 0.0
                if free_mode == 2 and free[p]:   # a replica without friction and bonds in a batch with others
                    xi[0, p] = 0.0
                    xi[1, p] = 0.0
                    slip = slip or rel
                state_p[p] = np.int8(slip) + np.int8(2) * np.int8(Cb[0, p])
                ft = (F_i + F_j) * 0.5
                fx, fy, dF, _ = pair_forces(fn, ft, nx, ny, d, None)
                fx_j, fy_j = fx, fy
                if visit_j:       # j receives the central force of its own visit (PairConstants.set_visits)
                    term_j = pair_term(form_j, d, vn, vt, touching, rel, xi[0, p], xi[1, p], Tj[0, p], Tj[1, p], Tj[2, p],
                                       Tj[3, p], Tj[4, p], Tj[5, p], Tj[6, p], Tj[7, p], Tj[8, p], Tj[9, p], Tj[10, p],
                                       Tj[11, p], k_t_j[p], nu_t_j[p], False, False,
                                       (A[0, 0], A[1, 0], A[2, 0], A[3, 0], A[4, 0], A[5, 0], A[6, 0], A[7, 0]))
                    fx_j, fy_j, _, _ = pair_forces(term_j[0], ft, nx, ny, d, None)
                    if keep:
                        kt[6, p], kt[7, p] = term_j[1] * Tj[_TRC, p], viscous_force(Tj[_TNU, p], vn, rel)
                        kt[8, p], kt[9, p] = fx_j, fy_j
                if keep:          # the terms of i's visit (terms.elastic_term, viscous_term: the same products)
                    kt[0, p], kt[1, p] = law * T[_TRC, p], viscous_force(T[_TNU, p], vn, rel)
                    kt[2, p], kt[3, p], kt[4, p], kt[5, p] = F_i, F_j, fx, fy
                nxs[p], nys[p], dvxs[p], mxs[p], mys[p] = nx, ny, dvx, fx_j, fy_j
                frc[0, i] += fx
                frc[1, i] += fy
                frc[2, i] += dF * Cf[_IWI, p]
                dFs[p] = dF
                if sample:
                    internal, ext_i, ext_j = pair_roles(mob[i], mob[j], (kys[p] != 0.0) or (kxs[p] != 0.0))
                    if visit_j:
                        work[11, p], work[12, p], work[13, p] = shear_rows(internal, ext_i, ext_j, rel, yc[i], yc[j],
                                                                           dys[p], fx, dF, fx_j)
                    else:
                        work[11, p], work[12, p], work[13, p] = shear_rows(internal, ext_i, ext_j, rel, yc[i], yc[j],
                                                                           dys[p], fx, dF, None)
                    if sample == 2:      # (the force on i, for the tensors' pair rows below)
                        work[14, p], work[15, p] = fx, fy
                if check:
                    verdict[3, b] = _nan_min(verdict[3, b], transient_ratio(d, Cf[_ID0, p], rel, Cb[1, p]))
            # the scatter's second half: −F on j and the torque on j, in pair order
            for p in range(P0, P1):
                j = Ci[2, p]
                frc[0, j] += -mxs[p]
                frc[1, j] += -mys[p]
                frc[2, j] += dFs[p] * Cf[_IWJ, p]
            if keep:          # the totals of the phase (the kick resets them)
                for k in range(n0, n1):
                    ktot[0, k], ktot[1, k], ktot[2, k] = frc[0, k], frc[1, k], frc[2, k]
            if sample:     # (forces.replica_sums: numpy.add.reduceat over each replica's segment)
                for b in range(b0, b1):
                    lo, hi = offsets[b], ends[b]
                    tau[0, b], tau[1, b] = shear_from_sums(_segment_sum(work[11], lo, hi), _segment_sum(work[12], lo, hi),
                                                           _segment_sum(work[13], lo, hi), V[b])
            if sample == 2:     # every tensor's rows (the totals of the scatter), summed per replica
                pair_tensor_rows(P0, P1, Ci[1], Ci[2], Ci[0], visit_j, pos[0], pos[1], Lx, Ly, mob, active, kys, kxs, dxs,
                                 dys, work[14], work[15], mxs, mys, dFs, tp)
                sphere_tensor_rows(n0, n1, rep_s, pos[0], pos[1], vel[0], vel[1], vel[2], mmi[0], mmi[2], frc[0],
                                   frc[1], frc[2], mob, rate, Lx, Ly, ts)
                tensor_row_sums(b0, b1, N, offsets, ends, tp, ts, tsum)
            if check:
                bad = False
                for b in range(b0, b1):
                    rate_max[b] = _nan_max(rate_max[b], abs(rate[b]))
                    finite = True
                    for k in range(b * N, (b + 1) * N):
                        finite = finite and np.isfinite(pos[0, k]) and np.isfinite(yc[k]) and np.isfinite(vel[0, k]) \
                            and np.isfinite(vel[1, k]) and np.isfinite(vel[2, k])
                        y0[k] = kinetic_term(mmi[0, k], vel[0, k] - yc[k] * rate[b], vel[1, k], mmi[2, k], vel[2, k])
                    ke = 0.5 * _pairwise(y0, b * N, N)        # (guard.verdict: the sum of each replica's row)
                    bnd = energy_bound(N, kk[b], r_mean[b], m_sum[b], rate_max[b], Ly[b]) if max_ke != max_ke \
                        else max_ke
                    code = verdict_code(finite, ke, bnd, verdict[3, b], min_ratio) * guard_on[b]
                    verdict[0, b], verdict[1, b], verdict[2, b] = code, ke, bnd
                    bad = bad or code != 0
                if bad:
                    return _GUARD
            if forces_only:
                return _DONE
            # -- kick (plates follow), damping
            for k in range(n0, n1):
                b = rep_s[k]
                if verlet:        # the half kick the next force phase sees (none in x, y on a plate sphere)
                    half_out[0, k] = half_velocity_change(frc[0, k], mmi[0, k], dt) if mob[k] else 0.0
                    half_out[1, k] = half_velocity_change(frc[1, k], mmi[1, k], dt) if mob[k] else 0.0
                    half_out[2, k] = half_velocity_change(frc[2, k], mmi[2, k], dt)
                vel[0, k] += velocity_change(frc[0, k], mmi[0, k], dt)
                vel[1, k] += velocity_change(frc[1, k], mmi[1, k], dt)
                vel[2, k] += velocity_change(frc[2, k], mmi[2, k], dt)
                frc[0, k] = 0.0
                frc[1, k] = 0.0
                frc[2, k] = 0.0
                if applying and not mob[k]:
                    vel[1, k] = 0.0
                    vel[0, k] = plate_velocity(yc[k], rate[b] * Ly_s[k] / 2)
                vel[0, k] = damped(vel[0, k], yc[k] * rate[b], cool)
                vel[1, k] *= cool
                vel[2, k] *= cool
        if free_mode == 1:            # no ξ without friction and bonds
            start = 2
        # the unit vectors of R = v_i dt − D (a random one at |R| = 0, drawn by the caller), and the ξ
        # rule of each pair in the same pass until the first |R| = 0 (each pair's ξ reads only its own
        # numbers and velocities nothing here changes, so the order of the pairs' updates is free)
        units = False
        last = P1 if start != 2 else P0
        for p in range(P0, last):
            i = Ci[1, p]
            Rx = vel[0, i] * dt - dxs[p]
            Ry = vel[1, i] * dt - dys[p]
            dR = np.sqrt(Rx * Rx + Ry * Ry)
            if free_mode == 2 and free[p]:
                dR = 1.0                  # (no direction drawn for a replica without ξ)
            zero[p] = dR == 0.0
            if zero[p]:
                units = True
            else:
                mx, my = Rx / dR, Ry / dR
                mxs[p], mys[p] = mx, my
                if not units:      # (the ξ rule below, written out: as an inlined helper of the
                    j = Ci[2, p]       # arrays the compiled step took 2.5× as long)
                    kd = dt if active[p] and state_p[p] != 1 else 0.0
                    rvx = vel[0, j] - vel[0, i] + dvxs[p]
                    spin = Cf[_IRI, p] * vel[2, i] + Cf[_IRJ, p] * vel[2, j]
                    inc_ij, inc_ji = xi_rates(rvx, vel[1, j] - vel[1, i], nxs[p], nys[p], mx, my, spin, rvx)
                    xi[0, p] += inc_ij * kd
                    xi[1, p] += inc_ji * kd
        if units:
            return _UNITS
        xi_from = last
    else:       # (the resumption: the ξ rule from the first |R| = 0 on, the pairs before had theirs)
        xi_from = P0
        while xi_from < P1 and not zero[xi_from]:
            xi_from += 1
    # -- the sequential ξ rule (velocities after the kick and damping, geometry of the force phase)
    for p in range(xi_from, P1 if start != 2 else P0):
        i, j = Ci[1, p], Ci[2, p]
        kd = dt if active[p] and state_p[p] != 1 else 0.0
        rvx = vel[0, j] - vel[0, i] + dvxs[p]
        spin = Cf[_IRI, p] * vel[2, i] + Cf[_IRJ, p] * vel[2, j]
        inc_ij, inc_ji = xi_rates(rvx, vel[1, j] - vel[1, i], nxs[p], nys[p], mxs[p], mys[p], spin, rvx)
        xi[0, p] += inc_ij * kd
        xi[1, p] += inc_ji * kd
    # displacement since the lists were built, Verlet bound, drift
    for b in range(b0, b1):
        largest = -math.inf
        for k in range(b * N, (b + 1) * N):
            u[0, k] += (vel[0, k] - yc[k] * (rate[b] * le[b])) * dt
            u[1, k] += vel[1, k] * dt
            largest = _nan_max(largest, u[0, k] * u[0, k] + u[1, k] * u[1, k])
        u_max[b] = _nan_max(u_max[b], np.sqrt(largest))
        strain[b] += abs(rate[b] * le[b]) * dt
        bound[b] = verlet_bound(u_max[b], strain[b], r_max[b])
    for k in range(n0, n1):
        pos[0, k] += vel[0, k] * dt
        pos[1, k] += vel[1, k] * dt
        phi[k] += vel[2, k] * dt
    # strain, wrap (box.wrap element by element: a sphere moved by a period in y takes the flow's
    # velocity difference), clock
    for b in range(b0, b1):
        gamma[b] = gamma[b] + rate[b] * dt * adv[b]
    for k in range(n0, n1):
        b = rep_s[k]
        y0[k] = pos[1, k]
        for q in range(MAX_PASSES + 1):
            if q == MAX_PASSES:
                pos[1, k], up = folded(pos[1, k], Ly_s[k], 0.0, Ly_s[k])
                pos[0, k] -= (Ly[b] * gamma[b] * le[b]) * up
                break
            up = period_count(pos[1, k], Ly_s[k], 0.0)
            if up == 0.0:
                break
            pos[1, k] -= Ly_s[k] * up
            pos[0, k] -= (Ly[b] * gamma[b] * le[b]) * up
        if pos[1, k] != y0[k]:
            vel[0, k] += (pos[1, k] - y0[k]) * (rate[b] * le[b])
    for k in range(n0, n1):
        Lxk = Lx[rep_s[k]]
        for q in range(MAX_PASSES + 1):
            if q == MAX_PASSES:
                pos[0, k], _ = folded(pos[0, k], Lxk, 0.0, Lxk)
                break
            right = period_count(pos[0, k], Lxk, 0.0)
            if right == 0.0:
                break
            pos[0, k] -= Lxk * right
    for b in range(b0, b1):
        t[b] = t[b] + dt
        need[b] = bound[b] >= skin[b]
    return _DONE



def compile_step_kernel(cache=True, say=None):
    """The compiled step (see :func:`run_step`), compiled once per process (or loaded from the cache).

    Every function of the step is a module-level function compiled from its own code object
    (:func:`~.numba_driver.jit_laws`), so Numba's cache finds it again in the next process.

    Parameters
    ----------
    cache : bool, default True
        Keep the compiled code in :func:`~.numba_driver.cache_dir`; False compiles afresh from the
        functions as they are now (a test that edits one).
    say : callable, optional
        ``say(message)``, told before a compile (not before a load from the cache).

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    import numba
    return compile_kernel(True, "_step_kernel", STEP_FUNCTIONS + KERNEL_FUNCTIONS, _signature, cache, say,
                    lambda: f"backend 'numba': compiling the step (first use; kept in {numba.config.CACHE_DIR})")


def compile_kernel(key, name, functions, signature, cache=True, say=None, message=None, parallel=False, linear=False):
    """The compiled function ``name`` of ``functions`` (:func:`~.numba_driver.jit_laws`), compiled for
    ``signature()`` now (or loaded from Numba's cache) and kept per process under ``key``: the one
    compile of every kernel of the step (the engine's steps, blocks and phases, and the documented
    classes' tensor sums, :func:`particleShear.base.compiled_phases.compile_tensor_kernel`).

    Parameters
    ----------
    key : hashable
        The kernel's key in this process's table (a second call with it returns the first's).
    name : str
        The function compiled, one of ``functions``.
    functions : sequence of (module, name)
        Every function it calls, compiled with it (:data:`STEP_FUNCTIONS`, :data:`KERNEL_FUNCTIONS` …).
    signature : callable
        ``signature()``: its Numba signature.
    cache : bool, default True
        As :func:`compile_step_kernel`.
    say, message : callable, optional
        ``say(message())`` before a compile (not before a load from the cache).
    parallel : bool, default False
        Its variant over several threads (``name__parallel``).
    linear : bool, default False
        The history merge's positions by one pass (:func:`_positions_linear`, in place of
        :func:`~particleShear.engine.state._positions`; its functions under their own names in the cache).

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    if cache and key in _kernels:
        return _kernels[key]
    import numba

    if cache:
        numba.config.CACHE_DIR = numba_driver.cache_dir()
    options = {"rename": {name: name + "__parallel"}, "parallel": (name,)} if parallel else {"rename": {}}
    if parallel:
        options["extra"] = {"BORROWED_VIEWS": False}     # (see BORROWED_VIEWS)
    if linear:
        extra, rename = _linear(cache)
        options["extra"] = {**options.get("extra", {}), **extra}
        options["rename"].update(rename)
    compiled = numba_driver.jit_laws(cache, functions, inline=INLINE, **options)[name]
    if say is not None and not numba_driver.on_disk(compiled):
        say(message())
    compiled.compile(signature())          # (or loaded from the cache): before any timing
    if cache:
        _kernels[key] = compiled
    return compiled


def _linear(cache=True):
    """The history merge's positions by one pass (:func:`_positions_linear`) for a compile of the
    merge's functions: ``(extra, rename)`` of :func:`~.numba_driver.jit_laws` (the merge's
    functions under their own names in the cache)."""
    merged = numba_driver.jit_laws(cache, ((sys.modules[__name__], "_positions_linear"),))["_positions_linear"]
    return {"_positions": merged}, {n: n + "__linear" for _, n in MERGE_FUNCTIONS if n != "_positions"}


def _search_signature():
    """The Numba signature of :func:`_search_kernel`."""
    from numba import types
    f1, i1, f, i = types.Array(types.float64, 1, "C"), types.Array(types.int64, 1, "C"), types.float64, types.int64
    return i1(f1, f1, f1, f, f, f, f, i, i, i)


def _block_signature():
    """The Numba signature of :func:`_block_kernel`."""
    from numba import types
    f2, i1, i = types.Array(types.float64, 2, "C"), types.Array(types.int64, 1, "C"), types.int64
    b1, f3 = types.Array(types.boolean, 1, "C"), types.Array(types.float64, 3, "C")
    f1 = types.Array(types.float64, 1, "C")
    i2, b2, s1 = types.Array(types.int64, 2, "C"), types.Array(types.boolean, 2, "C"), types.Array(types.int8, 1, "C")
    return i(i1, i, i1, i1, f2, f2, f2, f2, f2, f2, i, i, i, types.boolean, types.boolean, b1, f3, types.boolean, i1, i1,
             f2, i1, f1, f2, i2, b2, s1, f2, b1, i1, f1, *_signature().args[3:])


def _signature():
    """The Numba signature of :func:`_step_kernel` (:data:`_ARGUMENTS`)."""
    from numba import types
    scalars = {"f": types.float64, "i": types.int64, "b": types.boolean, "i1": types.int8}
    out = []
    for a in _ARGUMENTS:
        name, _, dims = a.partition("[")
        out.append(types.Array(scalars[name], dims.count(":"), "C") if dims else scalars[name])
    return types.int64(*out)


def kernels_of(ws):
    """The compiled step and block of a workspace: the built-in laws', or its run law's variant.

    Parameters
    ----------
    ws : _Workspace
        The workspace (its law, ``ws.law``).

    Returns
    -------
    tuple of numba.core.registry.CPUDispatcher
        ``(step, block)``: :func:`_step_kernel` and :func:`_block_kernel` compiled (or loaded).
    """
    n = threads()
    if n > 1:
        import numba
        numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    if ws.law is None:
        step = _kernels.get(True) or compile_step_kernel()
        return step, _kernels.get(("block", n > 1)) or compile_block_kernel(parallel=n > 1)
    function, m, fingerprint = ws.law
    return _law_kernels(function, m, parallel=n > 1, fingerprint=fingerprint)


def _law_kernels(function, m, say=None, parallel=False, fingerprint=None):
    """The compiled step and block for a run's law ``function(d, a0 … a{m−1})`` (:func:`~.phase_laws.run_law`).

    The law (and every function it calls) is compiled, an adapter ``_central_law(d, a)`` passes it
    the first m numbers of ``a``, and the step's functions are compiled with that adapter under their
    own names (``…__<hash>``: the law's name, m and :func:`~.law_check.law_fingerprint` — its code,
    its helpers', its closure's and its globals' values), so that Numba's cache keeps one entry per
    law and an edited law, a closure with other values or a global set anew gets a new one.

    With ``parallel`` the block is the variant over several threads (:func:`threads`).

    Returns
    -------
    tuple
        ``(step, block)``: the dispatchers of :func:`_step_kernel` and :func:`_block_kernel`.
    """
    import hashlib

    import numba

    fingerprint = fingerprint or law_check.law_fingerprint(function)
    key = ("law", fingerprint, m, parallel)
    if key in _kernels:
        return _kernels[key]
    numba_driver.register_helpers()
    numba.config.CACHE_DIR = numba_driver.cache_dir()
    h = hashlib.sha1(f"{function.__module__}.{function.__qualname__}/{m}{'/parallel' if parallel else ''}".encode())
    h.update(fingerprint.encode())     # (the law's code, helpers, closure and globals: law_check.law_fingerprint)
    suffix = "__" + h.hexdigest()[:12]
    adapter = law_check.law_adapter(function, m, fingerprint)
    names = ("pair_term", "_step_kernel", "_block_kernel")
    extra, rename = _linear()
    L = numba_driver.jit_laws(True, STEP_FUNCTIONS + KERNEL_FUNCTIONS + BLOCK_FUNCTIONS, inline=INLINE,
                              extra={"_central_law": adapter, "PLAIN_STEP": False, **extra},
                              rename={**rename, **{n: n + suffix for n in names}},
                              parallel=("_block_kernel",) if parallel else ())
    step, block = L["_step_kernel"], L["_block_kernel"]
    if say is not None and not numba_driver.on_disk(step):
        say(f"backend 'numba': compiling the step for the law {function.__qualname__} (first use)")
    step.compile(_signature())
    block.compile(_block_signature())
    _kernels[key] = step, block
    return step, block


def compile_kernels(say=None, law=None):
    """Compile (or load from the cache) the compiled loops of the ``"numba"`` backend now: the force
    terms (:func:`~.numba_driver.compile_pair_kernel`), the step (:func:`compile_step_kernel`) and its
    blocks, and the variant of a run's contact law, so that no timing of a run counts them.

    Parameters
    ----------
    say : callable, optional
        ``say(message)``, told once per kernel before it is compiled or loaded.
    law : str or None, optional
        The run's ``contact_law`` (a name of the registry; None or ``"linear"``: the built-in law).
        A law Numba cannot compile is left to the step, which then runs on NumPy with a note.
    """
    numba_driver.compile_pair_kernel(say=say)
    compile_step_kernel(say=say)
    parallel = threads() > 1
    compile_block_kernel(parallel=parallel)
    compile_search_kernel()
    compile_carried_kernel()
    compile_constants_kernel()
    compile_carry_kernel()
    compile_table_kernel()
    for kind in (np.float64, np.int64, np.bool_, np.int8):     # (the copies of a block's candidates, _move)
        _move(np.zeros((1, 1), kind), np.zeros(1, np.int64), np.ones(1, np.int64), np.zeros((1, 1), kind),
              np.zeros(1, np.int64))
    if law is None:
        return
    found = get_law(law)
    if found.name == "linear" and not found.parameters:     # (the built-in law: no variant, phase_laws.run_law)
        return
    values = tuple(float(v) for v in found.parameters.values())
    pair = ((2.0, 1.0, 1.0) if found.radii else (2.0,)) + (1.0, 0.5) + values   # (d0, [r_i, r_j,] k, c, parameters)
    if found.prepared is None:
        function, arguments = found.function, pair
    else:      # (as many constants as the law prepares: its constants of one pair, at its defaults)
        constants, function = found.prepared
        arguments = tuple(constants(*pair))
    m = len(arguments)
    if m <= numba_driver.LAW_SLOTS:
        try:     # (a law outside COMPILED_LAWS is compiled where its bits are NumPy's: law_check.law_bits)
            rows = np.array(arguments, dtype=float).reshape(m, 1)
            if found.name in COMPILED_LAWS or law_check.law_bits(found.name, function, rows, np.array([2.0])) is None:
                _law_kernels(function, m, say, parallel)
        except Exception:      # (the step notes it and runs on NumPy)
            pass


class _Workspace:
    """The compiled step's buffers and constants of one engine for one set of candidates ``C``, and
    the reason the step is not compiled (None: it is), under the key of what that depends on."""

    def __init__(self, engine, key):
        s = engine.s
        C = s.contacts.C
        B, N = s.B, s.N
        self.C, self.key, self.why = C, key, reason(engine)
        self.work = np.empty((16, C.P))
        self.zero = np.zeros(C.P, dtype=np.bool_)
        self.mob = np.ones(B * N, dtype=np.bool_)
        self.yc = np.empty(B * N)
        self.y0 = np.empty(B * N)
        self.tau = np.zeros((2, B))
        self.tsum = np.zeros((TENSOR_SUMS, B))
        self.tp = self.ts = None          # (the rows of every tensor: made at the first step that samples them)
        # the terms a step keeps for a force register (engine.keep_terms)
        self.keep = bool(engine.keep_terms)
        self.kt = np.empty((len(_KEPT), C.P if self.keep else 0))
        self.ktot = np.empty((3, B * N if self.keep else 0))
        self.verdict = np.zeros((4, B))
        self.need = np.zeros(B, dtype=np.bool_)
        per_sphere = lambda a: _copy_of(a, B * N)       # (writable copies)
        per_replica = lambda a: _copy_of(a, B)
        self.Ly_s = per_sphere(engine.Ly_s)
        self.rep_s = np.array(s.rep, dtype=np.int64)
        self.V, self.Lx, self.Ly, self.kk = (per_replica(a) for a in (engine.V, s.Lx, s.Ly, s.k))
        # the factors of the image offset and rate (1 for Lees-Edwards, 0 for a plain periodic replica)
        # and of the strain's advance (0 where it is held): x·1.0 is x, so the products are NumPy's numbers
        self.le, self.adv = (per_replica(1.0 if a is None else a) for a in (engine.lees_edwards, engine.strain_advances))
        self.r_max, self.skin = per_replica(engine.r_max), per_replica(engine.skin)
        self.r_mean = s.r.reshape(B, N).mean(axis=1)
        self.m_sum = s.m.reshape(B, N).sum(axis=1)
        self.guard_on = engine.guard.astype(np.float64)
        self.guarded = bool(engine.guard.any())
        self.max_ke = math.nan if engine.max_kinetic_energy is None else float(engine.max_kinetic_energy)
        self.form = numba_driver.FORMS[C.form]
        # the constants of the visit from j where spheres have parameters of their own (C.Kj)
        Kj = C.Kj
        self.visit_j = Kj is not None
        self.form_j = numba_driver.FORMS[Kj.form] if Kj is not None else self.form
        self.Tj = np.zeros((len(forces.PairConstants.TERM_ROWS), 1)) if Kj is None else np.ascontiguousarray(
            [np.broadcast_to(np.asarray(getattr(Kj, n), dtype=float), (C.P,)) for n in forces.PairConstants.TERM_ROWS])
        self.offsets = np.array(C.offsets, dtype=np.int64)
        self.ends = self.offsets[1:].copy()       # (each replica's candidates end where the next one's start)
        # the phase's law (_phase_law: the run's law or a registered callback): its function and its
        # arguments per candidate, rows of law_rows
        got = _phase_law(s, C) if self.why is None else None
        name, got = (None, None) if got is None else (got[0], got[1:])
        if got is not None and len(got[1]) > numba_driver.LAW_SLOTS:
            self.why, got = f"a contact law of more than {numba_driver.LAW_SLOTS} arguments after d", None
        self.custom = got is not None
        self.law_rows = np.zeros((numba_driver.LAW_SLOTS, C.P if self.custom else 1))
        self.law = None if got is None else got[0]
        if self.custom:
            for k, a in enumerate(got[1]):
                self.law_rows[k] = np.broadcast_to(np.asarray(a, dtype=float), (C.P,))
            known = _held(engine).setdefault("fingerprints", {})   # (once per engine and law: ≈ 26 µs each)
            fingerprint = known.get(got[0]) or known.setdefault(got[0], law_check.law_fingerprint(got[0]))
            self.law = (got[0], len(got[1]), fingerprint)
            try:      # (a law outside COMPILED_LAWS runs compiled only where its bits are NumPy's)
                if name not in COMPILED_LAWS:
                    self.why = law_check.law_bits(name, got[0], self.law_rows[:len(got[1])], C.f[_ID0], fingerprint)
                if self.why is None:
                    _law_kernels(got[0], len(got[1]), say=logging.getLogger(__name__).info,
                                 fingerprint=fingerprint)   # (a first compile, announced)
            except Exception as exc:          # (a law Numba cannot compile: NumPy runs it)
                self.why = f"a contact law Numba cannot compile ({type(exc).__name__})"
        self.no_half = np.zeros((3, 0))

    def tensor_rows(self, tensors):
        """The buffers of the rows of every tensor (:data:`~.stress.SUMMED_ROWS`): ``(tp, ts)``, the
        pair rows (9, P) and the sphere rows (10, B·N) when ``tensors``, else empty ones."""
        if not tensors:
            return _NO_ROWS
        if self.tp is None:
            self.tp = np.empty((9, self.work.shape[1]))
            self.ts = np.empty((10, len(self.mob)))
        return self.tp, self.ts


def _copy_of(a, n):
    """A new float64 array (n,) of ``a``: a number repeated, or a copy of the array (a writable
    buffer of the workspace; ``numpy.broadcast_to`` costs several times a copy on short arrays)."""
    if np.ndim(a) == 0:
        return np.full(n, float(a))
    out = np.array(a, dtype=np.float64)
    return out if out.shape == (n,) else np.array(np.broadcast_to(out, (n,)))


def _key(engine):
    """What :func:`reason` and the workspace depend on besides the candidates and the law callbacks
    (:func:`_laws_key`), compared by identity: the engine's configuration and the run's law."""
    s = engine.s
    return (engine.integrator, engine.keep_terms, engine.lees_edwards, engine.strain_advances, engine.s.contacts.free_p,
            s.law, s.law_params, engine.guard, engine.max_kinetic_energy)


def _laws_key(engine):
    """What the laws of a phase depend on in a state with law callbacks (the ``key()`` of its
    ``callback_laws``: the documented classes' law attributes and a registered law's values, read
    at every phase), compared by equality; None without."""
    key = getattr(getattr(engine.s, "callback_laws", None), "key", None)
    return None if key is None else key()


#: what this module keeps for each engine (its :class:`_Workspace` under "workspace", the block
#: slots' buffers under "slot_buffers"), dropped with the engine: the engine's own attributes stay its own
_HELD = weakref.WeakKeyDictionary()


def _held(engine):
    """The dictionary of what this module keeps for ``engine`` (:data:`_HELD`)."""
    held = _HELD.get(engine)
    if held is None:
        held = _HELD[engine] = {}
    return held


def _workspace(engine):
    """The engine's :class:`_Workspace`, rebuilt at a rebuild of the lists (new ``C``) or when its key changed."""
    ws = _held(engine).get("workspace")
    key, laws = _key(engine), _laws_key(engine)
    if ws is None or ws.C is not engine.s.contacts.C or any(a is not b for a, b in zip(ws.key, key)) or ws.laws != laws:
        ws = _held(engine)["workspace"] = _Workspace(engine, key)
        ws.laws = laws
    return ws


def _array(a):
    """``a`` itself when it is a C-contiguous NumPy array (written in place), else a contiguous copy."""
    if type(a) is np.ndarray and a.flags.c_contiguous:
        return a
    return np.ascontiguousarray(a)


def run_step(engine, cool, dt, sample):
    """One step of ``engine`` in the compiled code, or :data:`NOT_RUN` when it does not cover it.

    The candidate lists are rebuilt first when due (:meth:`~particleShear.engine.step.BatchEngine.neighbours`,
    on NumPy).  A pair at ``d = 0`` (its random normal) and a ``|R| = 0`` of the ξ rule (its random
    direction) get their directions here, from the replica's generator in pair order, as
    :func:`~.forces.normals` draws them, and the step goes on compiled.

    Parameters
    ----------
    engine : BatchEngine
        The engine (backend ``"numba"``).
    cool, dt : float
        Damping factor and time step (s).
    sample : bool or str
        False: no stresses; True: the two shear stresses; ``"tensors"``: also every tensor (their
        rows summed in the compiled step, :func:`~.stress.tensors_from_sums`).

    Returns
    -------
    None, tuple or NOT_RUN
        As :meth:`~particleShear.engine.step.BatchEngine.step`.

    Raises
    ------
    EngineInstability
        When the guard finds a guarded replica unstable (after the force phase, as NumPy).
    """
    got = launch(engine, cool, dt, sample)
    if got is None:
        return NOT_RUN
    ws, kernel, args, held, status = got
    resume_at_units(engine, ws, kernel, args, status)
    hand_back(engine, ws, held, stepped=True)
    engine.step_count += 1
    return step_samples(ws, sample)


def launch(engine, cool, dt, sample, forces_only=False):
    """The start of a compiled step (or of its force phase alone): the lists rebuilt when due, the
    kernel run from the start (the normals at ``d = 0`` drawn and the step run with them), the
    relations, the terms when kept and the guard's record handed back, an unsound verdict reported.

    Parameters
    ----------
    engine : BatchEngine
        The engine (backend ``"numba"``).
    cool, dt : float
        Damping factor and time step (s).
    sample : bool or str
        As :meth:`~particleShear.engine.step.BatchEngine.step`.
    forces_only : bool, default False
        The force phase alone (the kernel stops after it, the forces and torques left in the
        state's ``frc`` and the phase's geometry in the workspace's ``work``).  The kept terms
        (:func:`kept_terms`) are then the rows of the workspace's buffers themselves, not copies:
        a caller that keeps them past the next compiled call gives the workspace new buffers first
        (:func:`force_phase`).

    Returns
    -------
    tuple or None
        ``(workspace, kernel, arguments, held arrays, status)`` (the kernel's arguments after
        ``start, b0, b1``, :func:`step_arguments`; the status of :func:`_step_kernel`), or None
        when the compiled code does not cover the engine's step.

    Raises
    ------
    EngineInstability
        When the guard finds a guarded replica unstable.
    """
    engine.neighbours()
    ws = _prepared(engine)
    if ws is None:
        return None
    kernel, B = kernels_of(ws)[0], engine.s.B
    check = ws.guarded and not engine.step_count % engine.check_interval
    args, held = step_arguments(engine, ws, cool, dt, sample, check, np.full(B, engine.s.predictor.half is not None),
                            forces_only=forces_only)
    status = kernel(0, 0, B, *args)
    if status == _D_ZERO:
        for b in range(B):
            draw_directions(engine, ws, b, ws.work[4] == 0.0, 5)
        status = kernel(3, 0, B, *args)
    hand_back(engine, ws, held)
    if ws.keep:
        engine.terms_to(kept_terms(engine, ws, own_buffers=forces_only))
    if status == _GUARD:
        _report(engine, ws)
    return ws, kernel, args, held, status


def force_phase(engine, sample=False):
    """The force phase of ``engine`` alone in the compiled step
    (:meth:`~particleShear.engine.step.BatchEngine.force_phase` on the ``"numba"`` backend), or None
    where the compiled code does not cover the engine's step (:func:`reason`; the engine then runs
    its NumPy phase, the same numbers).

    The first part of the compiled step (:func:`launch` with ``forces_only``: neighbours when due,
    relations and their history, terms, forces and torques into the state, the guard when due, the
    terms when kept), the acceleration and movement phases then reading the record.  The record's
    rows and the kept terms are the phase's own buffers (no copies): the engine's workspace is
    given new ones (:func:`_take_buffers`), so the engine's later steps and phases leave them as
    they are.

    Parameters
    ----------
    engine : BatchEngine
        The engine (backend ``"numba"``).
    sample : bool or str
        As :meth:`~particleShear.engine.step.BatchEngine.force_phase`.

    Returns
    -------
    tuple or None
        ``(rows, stresses)``: the record's fields but its verdict, in the order of
        :class:`~particleShear.engine.step.ForceRecord` (``dx, dy, nx, ny, dvx, active, yc, mob``;
        the record's ``verdict`` is None: an unsound verdict is reported at once, as on NumPy), and
        the stresses as :meth:`~particleShear.engine.step.BatchEngine.force_phase` returns them;
        or None when the compiled code does not cover the engine's step.

    Raises
    ------
    EngineInstability
        When the guard finds a guarded replica unstable (at once, as the NumPy phase on the host).
    """
    try:
        got = launch(engine, 1.0, 0.0, sample, forces_only=True)
    except BaseException:      # (the terms kept before the guard's report are the workspace's rows)
        _take_buffers(last_workspace(engine))
        raise
    if got is None:
        return None
    ws = got[0]
    w = ws.work
    rows = (w[0], w[1], w[5], w[6], w[7], engine.s.contacts.active.copy(), ws.yc.copy(), ws.mob.copy())
    stresses = step_samples(ws, sample)
    _take_buffers(ws)
    return rows, stresses


def _take_buffers(ws):
    """Give the workspace ``ws`` (or nothing, None) new buffers for the rows a force phase alone hands
    to its caller (its geometry ``work``, the kept terms ``kt`` and totals ``ktot``): those of the
    phase are then the caller's record and terms, which no later compiled call writes into."""
    if ws is None:
        return
    ws.work = np.empty_like(ws.work)
    if ws.keep:
        ws.kt, ws.ktot = np.empty_like(ws.kt), np.empty_like(ws.ktot)


def move(engine, dt, g):
    """The movement of ``engine`` after its force phase ``g`` and its kick in the compiled step
    (:meth:`~particleShear.engine.step.BatchEngine.move` on the ``"numba"`` backend), where ``g`` is
    the record of a compiled force phase (:func:`force_phase`) of the engine's present candidates
    with no verdict left to read; else nothing (the engine then runs its NumPy movement, the same
    numbers).

    The tail of the compiled step from :data:`MOVE_ONLY`: the sequential ξ rule (a random direction
    at ``|R| = 0`` drawn from the replica's generator, :func:`resume_at_units`), the displacement
    since the lists were built, the drift, the strain, the wrap, the clock, the lists due and the
    step count.

    Parameters
    ----------
    engine : BatchEngine
        The engine (backend ``"numba"``), its candidates those of the force phase.
    dt : float
        Time step (s).
    g : ForceRecord or None
        The record of the step's force phase (its pair vectors, normals, image velocity, heights);
        None: a movement without a force phase (not run here).

    Returns
    -------
    bool
        Whether the movement ran here.
    """
    ws = last_workspace(engine) if g is not None else None
    if ws is None or ws.why is not None or ws.C is not engine.s.contacts.C or g.verdict is not None:
        return False
    w = ws.work        # (the phase's geometry: its rows are the record's, the workspace has new ones)
    w[0], w[1], w[5], w[6], w[7] = g.dx, g.dy, g.nx, g.ny, g.dvx
    ws.yc[:] = g.yc
    B = engine.s.B
    kernel = kernels_of(ws)[0]
    args, held = step_arguments(engine, ws, 1.0, dt, False, False, np.zeros(B, dtype=np.bool_))
    resume_at_units(engine, ws, kernel, args, kernel(MOVE_ONLY, 0, B, *args))
    hand_back(engine, ws, held, stepped=True, kicked=False)
    engine.step_count += 1
    return True


def resume_at_units(engine, ws, kernel, args, status):
    """The rest of a step the kernel stopped at the ξ rule (``status`` :data:`UNITS`): the random
    directions at ``|R| = 0`` drawn (:func:`draw_directions`, rows 8, 9 of ``work``) and the kernel
    resumed from there (its start 1); nothing for another status.

    Parameters
    ----------
    engine : BatchEngine
        The engine the kernel stepped (all its replicas).
    ws : _Workspace
        Its workspace (:func:`last_workspace`).
    kernel : numba.core.registry.CPUDispatcher
        The compiled step (:func:`kernels_of`).
    args : tuple
        The kernel's arguments after ``start, b0, b1`` (:func:`step_arguments`).
    status : int
        What the kernel returned.
    """
    if status == UNITS:
        for b in range(engine.s.B):
            draw_directions(engine, ws, b, ws.zero, 8)
        kernel(1, 0, engine.s.B, *args)


def last_workspace(engine):
    """The workspace of the engine's last compiled call, or None before one; unlike
    :func:`_workspace` it makes none (the workspace of a force phase, for its movement).

    Parameters
    ----------
    engine : BatchEngine
        The engine.

    Returns
    -------
    _Workspace or None
        Its buffers, its candidates ``C``, ``why`` (not None where the step is not compiled).
    """
    return _held(engine).get("workspace")


def step_samples(ws, sample):
    """What a step or force phase returns of its samples (:meth:`~particleShear.engine.step.BatchEngine.step`).

    Parameters
    ----------
    ws : _Workspace
        The workspace the kernel sampled into (``tau``, ``tsum``).
    sample : bool or str
        As the step took it.

    Returns
    -------
    None or tuple
        None unless ``sample``; else ``(tau_internal, tau_surface)`` and, for ``"tensors"``, the
        (B, 9, 2, 2) tensors (copies).
    """
    if sample == "tensors":       # (the xy entries are the shear stresses, as the NumPy step returns them)
        T = tensors_from_sums(ws.tsum.copy(), ws.V)
        return -T[:, OVERALL, 0, 1], -T[:, EXTERNAL, 0, 1], T
    return (ws.tau[0].copy(), ws.tau[1].copy()) if sample else None


def _prepared(engine):
    """The engine's workspace when its step runs compiled, else None, with the note: once per engine
    and reason, shown once per process and reason by Python's default filter (the warning is issued
    from this line, so the several engines of one run, the constitution's, the pre-equilibration's
    and the protocol's, print it once)."""
    ws = _workspace(engine)
    if ws.why is None:
        return ws
    if ws.why not in engine.notes:
        engine.notes.add(ws.why)
        warnings.warn(f"backend='numba': this step runs on NumPy ({ws.why})", RuntimeWarning, stacklevel=1)
    return None


def step_arguments(engine, ws, cool, dt, sample, check, pred, half_out=None, tensors=False, forces_only=False,
                   slots=None):
    """The arguments of :func:`_step_kernel` after ``start, b0, b1``, and the arrays to hand back
    (:func:`hand_back`).

    Parameters
    ----------
    engine : BatchEngine
        The engine stepped.
    ws : _Workspace
        Its workspace (:func:`last_workspace`).
    cool, dt : float
        Damping factor and time step (s).
    sample : bool or str
        As :meth:`~particleShear.engine.step.BatchEngine.step` takes it.
    check : bool
        Whether the guard checks this step.
    pred : ndarray of bool (B,)
        Which replicas' force phase sees the Verlet half kick.
    half_out : ndarray (3, B·N), optional
        A block's buffer of the new half kicks, copied into ``half`` (a copy of the state's
        predictor) replica by replica (``half`` is then the one handed back); default a new array
        per step, handed back itself (as ``half_kick`` gives).
    tensors : bool, default False
        A block samples every tensor at some of its steps.
    forces_only : bool, default False
        The force phase alone (:func:`launch`).
    slots : _Slots, optional
        A block's slots, whose ranges of each replica's candidates and buffers the kernel takes (a
        rebuilt replica's candidates are its slot's, handed back by :func:`_settle`).

    Returns
    -------
    args : tuple
        The kernel's arguments after ``start, b0, b1``.
    held : dict
        The arrays the kernel writes that :func:`hand_back` gives to the state and the engine.
    """
    s = engine.s
    c = s.contacts
    C = c.C
    gamma, t, rate = s.gamma.astype(float), s.t.astype(float), s.rate.astype(float)   # (copied back by hand_back)
    next_birth, u, u_max, strain, bound, rate_max = (
        _array(a) for a in (c.next_birth, c.u, c.u_max, c.strain, c.bound, engine.rate_max))
    at = ws if slots is None else slots       # (each replica's columns and the buffers over them)
    Cf, Ci, Cb = C.f, C.i, C.b
    state_p, xi, active, birth = (_array(a) for a in c.history)
    free = c.free_p
    free_mode, free = (0, at.zero) if free is None else (1, at.zero) if free is True else (2, _array(free))
    verlet = engine.integrator == "verlet"
    carried = s.predictor.half
    half = np.array(carried, dtype=float) if carried is not None else np.empty((3, s.B * s.N)) if verlet \
        else ws.no_half
    new_half = ws.no_half if not verlet else np.empty((3, s.B * s.N)) if half_out is None else half_out
    ws.need[:] = c.need             # (a replica a block skips keeps its flag)
    code = 2 if sample == "tensors" else int(bool(sample))
    args = (s.N, float(cool), float(dt), code, bool(check), bool(s.applying_shear), engine.numbers_relations,
            ws.form, ws.custom, ws.law_rows, ws.visit_j, ws.form_j, ws.Tj, free_mode, free, verlet, pred, half,
            new_half, s.pos, s.vel, s.frc, s.phi,
            engine.mmi, s.r, ws.Ly_s, ws.rep_s, rate, gamma, t, ws.Lx, ws.Ly, ws.V, ws.le, ws.adv, Cf, Ci, Cb,
            at.offsets, at.ends, state_p,
            xi, active, birth, next_birth, u, u_max, strain, bound, ws.r_max, ws.skin,
            ws.guard_on, rate_max, ws.kk, ws.r_mean, ws.m_sum, float(engine.min_distance_ratio), ws.max_ke,
            at.work, ws.mob, ws.yc, ws.y0, at.zero, ws.tau, ws.verdict, ws.need,
            *at.tensor_rows(tensors or code == 2), ws.tsum, ws.keep, ws.kt, ws.ktot, forces_only)
    held = dict(state_p=state_p, xi=xi, active=active, birth=birth, next_birth=next_birth, rate_max=rate_max,
                u=u, u_max=u_max, strain=strain, bound=bound, gamma=gamma, t=t, rate=rate,
                half=None if not verlet else new_half if half_out is None else half)
    return args, held


def hand_back(engine, ws, held, stepped=False, kicked=True):
    """Hand the arrays the kernel wrote back to the state and the engine (the arrays themselves, no
    copies, except the rate, strain and clock, which go into the state's own arrays: they may be the
    ensembles' cells): after the force phase the relations and their history (``state.contacts``),
    the rate and the guard's record; after a whole step also the lists' bookkeeping, the clock and
    the Verlet predictor (``state.predictor``).

    Parameters
    ----------
    engine : BatchEngine
        The engine the kernel stepped.
    ws : _Workspace
        Its workspace (the lists due, ``need``).
    held : dict
        The arrays of :func:`step_arguments`.
    stepped : bool, default False
        The kernel ran the movement too: also the displacement, strain since the build, bound,
        the lists due, the strain and the clock.
    kicked : bool, default True
        With ``stepped``: a step of this call reached its kick, so the Verlet predictor too.
    """
    s = engine.s
    c = s.contacts
    c.state_p, c.xi, c.active, c.birth, c.next_birth = (held["state_p"], held["xi"], held["active"], held["birth"],
                                                        held["next_birth"])
    engine.rate_max = held["rate_max"]
    s.rate[...] = held["rate"]      # (into the state's arrays: they may be the ensembles' cells)
    if stepped:
        c.u, c.u_max, c.strain, c.bound = held["u"], held["u_max"], held["strain"], held["bound"]
        if held["half"] is not None and kicked:
            s.predictor.half = held["half"]
        s.gamma[...], s.t[...] = held["gamma"], held["t"]
        c.need = ws.need.copy()


def kept_terms(engine, ws, own_buffers=False):
    """The terms of the last force phase as the NumPy force phase keeps them for a force register
    (what :attr:`~particleShear.engine.step.BatchEngine.terms_to` receives): the rows the step kept (``keep``) and its
    geometry; the torques ``dF·w`` and the contacts ``d < d0`` are the NumPy phase's expressions on them.

    Parameters
    ----------
    engine : BatchEngine
        The engine after its compiled force phase.
    ws : _Workspace
        Its workspace (the rows ``kt``, ``ktot`` and the geometry ``work``).
    own_buffers : bool, default False
        The rows themselves rather than copies (a force phase alone whose caller takes the
        buffers, :func:`launch`).

    Returns
    -------
    dict
        The arrays by name, as the NumPy force phase hands them to
        :attr:`~particleShear.engine.step.BatchEngine.terms_to`.
    """
    c = engine.s.contacts
    C, w, kt, own = c.C, ws.work, ws.kt, ws.visit_j
    if not own_buffers:
        w, kt = w[:11].copy(), kt.copy()
    d, dF = w[4], w[10]
    return dict(C=C, parts=([kt[0], kt[1]], [kt[6], kt[7]] if own else []), F=kt[2:4], dx=w[0], dy=w[1], nx=w[5],
                ny=w[6], d=d, touching=d < C.d0, active=c.active.copy(), shifted=(w[2] != 0) | (w[3] != 0),
                mob=ws.mob.copy(), fx_i=kt[4], fy_i=kt[5], fx_j=kt[8] if own else None, fy_j=kt[9] if own else None,
                dF=dF, tq=dF * C.w, birth=c.birth.copy(), totals=ws.ktot if own_buffers else ws.ktot.copy())


def _report(engine, ws):
    """Raise the guard's EngineInstability of the verdict the kernel wrote."""
    v = ws.verdict
    engine.report_verdict((v[0].astype(np.int64), v[1].copy(), v[2].copy(), v[3].copy()), engine.step_count)


def draw_directions(engine, ws, b, mask, row):
    """Random unit vectors ``(cos 2πu, sin 2πu)`` into ``work`` rows ``row``, ``row + 1`` for replica
    b's candidates where ``mask`` holds: in pair order, from the replica's own generator, as
    :func:`~particleShear.engine.forces.normals` draws them.

    Parameters
    ----------
    engine : BatchEngine
        The engine (its replicas' generators).
    ws : _Workspace or _Slots
        The workspace, or a block's slots (the columns and buffers the kernel read).
    b : int
        The replica.
    mask : ndarray of bool (P,)
        The candidates that get a direction.
    row : int
        5: the normals at ``d = 0`` (rows 5, 6); 8: the directions at ``|R| = 0`` (rows 8, 9).
    """
    lo, hi = ws.offsets[b], ws.ends[b]
    rng = engine.s.rng[b]
    for p in np.flatnonzero(mask[lo:hi]) + lo:
        theta = 2 * np.pi * rng.random()
        ws.work[row, p], ws.work[row + 1, p] = np.cos(theta), np.sin(theta)


def run_block(engine, rates, cool, dt, record=None, row=0, n=None, tensors=None, tensor_out=None):
    """Steps of the engine in compiled blocks: a protocol's steps at the rates ``rates``, recorded
    from row ``row`` on, or ``n`` steps at the state's rate without samples (``rates`` None).

    Each step of a schedule is what :func:`~particleShear.engine.rheometer.shear_record` does for
    it with a sample of the two shear stresses: ``set_rate`` (each sphere keeps its velocity
    relative to the flow, :func:`~particleShear.engine.integrate.flow_shifted`), record the clock,
    strain and rate, the step, record the stresses (and, at the steps ``tensors`` marks, every
    tensor, from its rows summed in the compiled step).  One compiled call runs each replica until the
    block ends (:func:`_block_kernel`), rebuilding its candidate list inside whenever it is due
    (:func:`_rebuild_replica`, in the replica's own columns of a :class:`_Slots`, handed back to the
    engine at the end, :func:`_settle`); a list the block cannot rebuild (no room left in its
    columns, a configuration :func:`_slotted` excludes) ends that replica's call, the list is
    rebuilt by :meth:`~particleShear.engine.step.BatchEngine.neighbours` and the next call goes on.  A pair at ``d = 0`` and a
    ``|R| = 0`` get their random directions here, from the replica's own generator, and the step
    goes on compiled.  The guard's verdict is reported as the step's: the earliest step at which
    a guarded replica failed, the first such replica (each replica runs at least to that step).

    Parameters
    ----------
    engine : BatchEngine
        The engine (backend ``"numba"``).
    rates : ndarray (n, B) or None
        γ̇ of every replica at each of the n steps (1/s); None: ``n`` steps at the state's rate.
    cool, dt : float
        Damping factor and time step (s).
    record : dict of ndarray (n_steps, B), optional
        The protocol's record ("t", "strain", "strain_rate", "stress_internal", "stress_surface"),
        with ``rates``.
    row : int, default 0
        The record's row of the first step.
    n : int, optional
        The number of steps without ``rates``.
    tensors : ndarray (n,) of bool, optional
        With ``rates``: the steps that also sample every tensor of :data:`~.stress.TENSORS`.
    tensor_out : ndarray (n, B, 9, 2, 2), optional
        Where those steps' tensors go (Pa; the other rows are left as they are).

    Returns
    -------
    int
        ``n``, or 0 when the engine's steps do not run compiled (the caller runs them step by step).

    Raises
    ------
    EngineInstability
        When the guard finds a guarded replica unstable: the step and replica of the step-by-step
        loop, but the engine is then left as a failed run leaves it (replicas stepped past that
        step within the block, the records written beyond it): a run stops there.
    """
    scheduled = rates is not None
    if scheduled:
        rates = np.ascontiguousarray(rates, dtype=float)
        n = len(rates)
        rec = tuple(record[name] for name in ("t", "strain", "strain_rate", "stress_internal", "stress_surface"))
    else:
        rates = _NO_RECORD
        rec = (_NO_RECORD,) * 5
    B, step0 = engine.s.B, engine.step_count
    contacts = engine.s.contacts
    want = np.zeros(n, dtype=np.bool_)          # (read at every scheduled step)
    if tensors is not None and scheduled:
        want[:] = tensors
    sums = np.zeros((n, TENSOR_SUMS, B)) if want.any() else _NO_SUMS
    ks, starts, status = np.zeros(B, np.int64), np.zeros(B, np.int64), np.zeros(B, np.int64)
    pred = np.full(B, engine.s.predictor.half is not None)
    # (one buffer of new half kicks for the block: a step resumed in the next call kicked into it)
    half_out = np.empty((3, B * engine.s.N)) if engine.integrator == "verlet" else None
    failed, verdicts = np.full(B, -1, np.int64), np.zeros((4, B))
    end, drawn = n, False
    slots = None          # (the block's candidates with room for rebuilds: _Slots)
    try:
        for _ in range(3 * n * B + 2):       # (each call advances a replica or draws for one: bounded)
            going = (ks < end) & (failed < 0)
            if not going.any():
                break
            if not drawn:     # rebuild the lists due of the replicas still going, and start them anew
                due = contacts.need.copy()
                left = slots is not None and bool((due & going).any())      # (a list the block could not rebuild)
                if left:          # (the block's rebuilt candidates back first; the lists due rebuilt here)
                    slots, held_slots = None, slots
                    _settle(engine, held_slots)
                elif slots is None and contacts.C is not None and _slotted(engine, _workspace(engine)):
                    slots = _Slots.of(engine)      # (the lists due are rebuilt inside the block)
                if slots is None:
                    contacts.need = due & going
                    engine.neighbours()
                    contacts.need = due & ~going
                starts[going & (starts == _SKIP)] = 0
            ws = _prepared(engine)
            if ws is not None and ws.keep and B > 1 and not ks.any():
                return 0          # (a batch keeping its terms steps together: one set of candidates, one record)
            if ws is None:
                if ks.any():
                    raise RuntimeError("run_block: the step stopped running compiled within a block")
                return 0
            starts[~going] = _SKIP
            if slots is None and _slotted(engine, ws):
                slots = _Slots.of(engine)
            at = ws if slots is None else slots
            args, held = step_arguments(engine, ws, cool, dt, scheduled, False, pred, half_out, tensors=want.any(),
                                    slots=slots)
            kernels_of(ws)[1](ks, end, starts, status, rates, *rec, row, step0, engine.check_interval, ws.guarded,
                               scheduled, want, sums, *(_NO_SLOTS if slots is None else slots.arguments()), *args)
            hand_back(engine, ws, held, stepped=True, kicked=bool(pred.any()))
            drawn = False
            for b in np.flatnonzero(going):
                st = status[b]
                starts[b] = _SKIP
                if st == _D_ZERO:        # (nothing of the step changed: its normals at d = 0, then the step)
                    draw_directions(engine, at, b, at.work[4] == 0.0, 5)
                    starts[b], drawn = 3, True
                elif st == _UNITS:       # (the rest of the step, from the ξ rule)
                    draw_directions(engine, at, b, at.zero, 8)
                    starts[b], drawn = 1, True
                elif st == _GUARD:       # (the other replicas run to this step at least: the first failure is reported)
                    failed[b], verdicts[:, b] = ks[b], ws.verdict[:, b]
                    end = min(end, int(ks[b]) + 1)
    finally:
        if slots is not None:
            _settle(engine, slots)
    if ws.keep:        # (the terms of the last step: a batch of one, whose last call stepped it)
        engine.terms_to(kept_terms(engine, ws))
    if want.any():     # (the tensors of the sampled steps at once: each column is one replica's step)
        k = np.flatnonzero(want)
        S = sums[k].transpose(1, 0, 2).reshape(TENSOR_SUMS, -1)
        V = np.broadcast_to(np.asarray(engine.V, dtype=float), (B,))
        tensor_out[k] = tensors_from_sums(S, np.tile(V, len(k))).reshape(len(k), B, *tensor_out.shape[2:])
    if (failed >= 0).any():
        first = int(failed[failed >= 0].min())
        code = np.where(failed == first, verdicts[0], 0).astype(np.int64)
        engine.step_count = step0 + first
        engine.report_verdict((code, verdicts[1], verdicts[2], verdicts[3]), engine.step_count)
    engine.step_count = step0 + n
    return n


_NO_RECORD = np.zeros((0, 0))
_NO_ROWS = np.zeros((9, 0)), np.zeros((10, 0))
_NO_SUMS = np.zeros((0, 0, 0))
#: the slot arguments of :func:`_block_kernel` that rebuild nothing inside (:meth:`_Slots.arguments`)
_NO_SLOTS = (False, np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((11, 0)), np.zeros(0, np.int64), np.zeros(0),
             np.zeros((23, 0)), np.zeros((3, 0), np.int64), np.zeros((2, 0), np.bool_), np.zeros(0, np.int8),
             np.zeros((2, 0)), np.zeros(0, np.bool_), np.zeros(0, np.int64), np.zeros(0))

#: run_block rebuilds the lists due inside its compiled call (:class:`_Slots`); False: every rebuild
#: between calls, by :meth:`~particleShear.engine.step.BatchEngine.neighbours` (the same numbers; a
#: switch for the benchmarks and tests that compare the two)
REBUILD_IN_BLOCK = True
#: the free columns after each replica's candidates in a block (:class:`_Slots`): ``a·P_b + c``,
#: room for the rebuilds of the block; a list that outgrows them is rebuilt between calls
SLACK = (0.25, 16)


def _slotted(engine, ws):
    """Whether :func:`run_block` rebuilds the lists inside its compiled call (:class:`_Slots`): the
    candidates' constants are those of :func:`constant_rows` alone (no visit from j with its own
    constants, no run law's arguments per candidate, no mixed frictionless replicas, no kept terms)."""
    C, free = engine.s.contacts.C, engine.s.contacts.free_p
    return REBUILD_IN_BLOCK and C is not None and ws.why is None and \
        not (ws.keep or ws.visit_j or ws.custom) and (free is None or free is True)


class _Slots:
    """The room of a block's rebuilds inside the compiled block (:func:`_rebuild_replica`): a slot per
    replica, and each replica's present columns.

    Replica b's candidates are the columns ``offsets[b] … ends[b] − 1`` of the engine's
    :class:`~particleShear.engine.forces.PairConstants` blocks and history until the block rebuilds
    its list, then of the slot arrays ``f``, ``i``, ``b``, ``state_p``, ``xi``, ``active``,
    ``birth`` and ``d_eq`` (the equilibrium distances; ``d_eq_c``: the engine candidates', from the
    pair tables): its slot is their columns ``base[b] … cap[b] − 1`` (its candidates and
    :data:`SLACK` more), after the engine's P columns, so that every replica's columns, and those
    of the buffers ``work``, ``zero`` and the tensors' pair rows, are its own.  A rebuild writes only
    its replica's slot: nothing is copied in, and the engine's arrays are written in place until
    :func:`_settle` hands the rebuilt replicas' candidates back.  The slot arrays and buffers are
    scratch between blocks, kept for the engine (``_HELD``) while they are wide enough: new
    ones of this size cost page faults at every block (N = 10,000: blocks 10–40 % slower).

    Parameters
    ----------
    engine : BatchEngine
        The engine (its candidates built, :func:`_slotted`).
    """

    @classmethod
    def of(cls, engine):
        """The slots of a block of ``engine``, or None where its pair tables are not its candidates
        (a table edited since the engine's last rebuild: the engine rebuilds from it)."""
        C = engine.s.contacts.C
        if any(len(p.d_eq) != n for p, n in zip(engine.s.pairs, np.diff(C.offsets))):
            return None
        return cls(engine)

    def __init__(self, engine):
        s = engine.s
        C = s.contacts.C
        P = C.P
        self.offsets, self.ends = np.array(C.offsets[:-1], np.int64), np.array(C.offsets[1:], np.int64)
        count = self.ends - self.offsets
        room = count + (count * SLACK[0]).astype(np.int64) + SLACK[1]
        self.cap = P + np.cumsum(room)
        self.base = self.cap - room
        Q = int(self.cap[-1]) if len(room) else P
        # (the buffers of the engine's last block where they are wide enough: its slots are scratch, and
        # fresh arrays of this size cost page faults at every block; a quarter more room otherwise)
        kept = _held(engine).get("slot_buffers")
        if kept is None or kept["f"].shape != (C.f.shape[0], kept["f"].shape[1]) or kept["f"].shape[1] < Q:
            W = Q + Q // 4
            kept = _held(engine)["slot_buffers"] = dict(
                f=np.empty((C.f.shape[0], W)), i=np.empty((3, W), np.int64), b=np.empty((2, W), np.bool_),
                state_p=np.empty(W, np.int8), xi=np.empty((2, W)), active=np.empty(W, np.bool_),
                birth=np.empty(W, np.int64), d_eq=np.empty(W), work=np.empty((16, W)), zero=np.zeros(W, np.bool_),
                tp=None)
        self._kept = kept
        for name in ("f", "i", "b", "state_p", "xi", "active", "birth", "d_eq", "work", "zero"):
            setattr(self, name, kept[name])
        self.d_eq_c = np.ascontiguousarray(np.concatenate([np.asarray(p.d_eq, dtype=float) for p in s.pairs]))
        self.spheres = s.B * s.N
        self.rebuilt = np.zeros(s.B, np.int64)
        # (the per-replica constants of constant_rows, in the order _constants_kernel takes them)
        self.pc = np.ascontiguousarray(np.stack([np.broadcast_to(np.asarray(a, dtype=float), (s.B,)) for a in
                                                 (s.Lx, s.Ly, s.k, s.nu, s.k_t, s.nu_t, s.mu, s.c, s.prc, s.prt,
                                                  s.keep)]))

    def arguments(self):
        """The slot arguments of :func:`_block_kernel` (``here … s_deq``)."""
        return (True, self.base, self.cap, self.pc, self.rebuilt, self.d_eq_c, self.f, self.i, self.b, self.state_p,
                self.xi, self.active, self.birth, self.d_eq)

    def tensor_rows(self, tensors):
        """As :meth:`_Workspace.tensor_rows`, over these columns."""
        if not tensors:
            return _NO_ROWS
        rows = self._kept["tp"]
        if rows is None or rows[0].shape[1] != self.f.shape[1] or rows[1].shape[1] != self.spheres:
            rows = self._kept["tp"] = np.empty((9, self.f.shape[1])), np.empty((10, self.spheres))
        return rows


def _settle(engine, slots):
    """Hand a block's rebuilt lists back to the engine (:class:`_Slots`), what
    :meth:`~particleShear.engine.step.BatchEngine.neighbours` leaves after the same rebuilds: the
    candidates side by side again (the rebuilt replicas' from their slots, the others' from the
    state's contacts) as the candidates' constants
    (:meth:`~particleShear.engine.forces.PairConstants.from_blocks`) and history, each rebuilt
    replica's pair table made its new list with its history as
    :meth:`~particleShear.engine.contacts.Contacts.sync_down` writes it (written once here, so
    :meth:`~particleShear.engine.step.BatchEngine.adopt_candidates`, which takes the rest, does
    not write these tables again).  Nothing where no list was rebuilt (the kernel wrote the
    history of ``state.contacts`` in place)."""
    rebuilt = np.flatnonzero(slots.rebuilt)
    if not len(rebuilt):
        return
    s = engine.s
    C = s.contacts.C
    kept = np.flatnonzero(slots.rebuilt == 0)
    offsets = np.zeros(s.B + 1, np.int64)
    np.cumsum(slots.ends - slots.offsets, out=offsets[1:])
    P = int(offsets[-1])
    f, i, b = np.empty((slots.f.shape[0], P)), np.empty((3, P), np.intp), np.empty((2, P), np.bool_)
    history = np.empty(P, np.int8), np.empty((2, P)), np.empty(P, np.bool_), np.empty(P, np.int64)
    d_eq = np.empty(P)
    names = ("state_p", "xi", "active", "birth")
    for own, slot, dst in zip((C.f, C.i, C.b) + s.contacts.history + (slots.d_eq_c,),
                              (slots.f, slots.i, slots.b) + tuple(getattr(slots, n) for n in names) + (slots.d_eq,),
                              (f, i, b) + history + (d_eq,)):
        for src, which in ((own, kept), (slot, rebuilt)):
            if len(which):
                _move(src, slots.offsets[which], slots.ends[which], dst, offsets[which])
    C = forces.PairConstants.from_blocks(s, f, i, b, offsets)
    N = s.N
    table = compile_table_kernel()
    for r in rebuilt:      # (each table written once, as sync_down writes it: its own arrays, the kept history)
        key, st, de, act, num, z, pi, pj = table(i, *history, d_eq, offsets[r], offsets[r + 1], r * N)
        s.pairs[r].adopt(key, st, de, act, num, z, i=pi, j=pj)
    engine.adopt_candidates(C, history, slots.rebuilt, written=True)


def _table_columns(i, state_p, xi, active, birth, d_eq, lo, hi, first):
    """A rebuilt replica's pair table from the columns ``lo … hi − 1`` of the handed-back blocks, in
    one pass (compiled; :func:`_settle`): the keys ``i << 32 | j`` and sphere indices (rows less
    ``first``, the replica's first sphere row), and the history as
    :meth:`~particleShear.engine.contacts.Contacts.sync_down` writes it
    (:func:`~particleShear.engine.state.synced_history`), each a new array.

    Returns
    -------
    tuple of ndarray
        ``key, state, d_eq, active, birth, xi, i, j`` (:meth:`~particleShear.engine.state.PairTable.adopt`).
    """
    n = hi - lo
    key, pi, pj = np.empty(n, np.int64), np.empty(n, np.intp), np.empty(n, np.intp)
    st, de, act, num, z = np.empty(n, np.int8), np.empty(n), np.empty(n, np.bool_), np.empty(n, np.int64), \
        np.empty((2, n))
    for q in range(n):
        p = lo + q
        a, c = i[1, p] - first, i[2, p] - first
        pi[q], pj[q], key[q] = a, c, (a << 32) | c
        st[q], z[0, q], num[q] = synced_history(state_p[p], xi[0, p], active[p], birth[p])
        z[1, q] = synced_history(state_p[p], xi[1, p], active[p], birth[p])[1]
        act[q], de[q] = active[p], d_eq[p]
    return key, st, de, act, num, z, pi, pj


def compile_table_kernel(cache=True):
    """:func:`_table_columns` compiled once per process (or loaded from the cache) for the types
    :func:`_settle` passes; :func:`compile_kernels` calls it before a run's timings.

    Parameters
    ----------
    cache : bool, default True
        As :func:`compile_step_kernel`.

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    return compile_kernel("table", "_table_columns", ((state, "synced_history"), (sys.modules[__name__], "_table_columns")),
                          _table_signature, cache)


def _table_signature():
    """The Numba argument types of :func:`_table_columns` (as :func:`_settle` passes them)."""
    from numba import types
    C = lambda t, d: types.Array(t, d, "C")
    return (C(types.intp, 2), C(types.int8, 1), C(types.float64, 2), C(types.boolean, 1), C(types.int64, 1),
            C(types.float64, 1), types.int64, types.int64, types.int64)


def _columns(src, lo, hi, dst, at):
    """Copy the columns ``lo[b] … hi[b] − 1`` of ``src`` to ``dst`` from column ``at[b]`` on, for every b (compiled)."""
    for b in range(lo.shape[0]):
        for row in range(src.shape[0]):       # (a slice's copy: ≈ 30 % faster than a loop over its elements)
            dst[row, at[b]:at[b] + hi[b] - lo[b]] = src[row, lo[b]:hi[b]]
    return 0


def _move(src, lo, hi, dst, at):
    """:func:`_columns` of 1-D or 2-D arrays (the 2-D ones C-contiguous)."""
    kernel = _kernels.get("columns")
    if kernel is None:
        kernel = _kernels["columns"] = numba_driver.jit_laws(True, ((sys.modules[__name__], "_columns"),))["_columns"]
    src, dst = (a.reshape(1, -1) if a.ndim == 1 else a for a in (np.ascontiguousarray(src), dst))
    kernel(src, lo, hi, dst, at)


def _search_kernel(x, y, r, Lx, Ly, shift, skin, nx, ny, scale):
    """The keys ``i·scale + j`` of the pairs ``i < j`` within ``r_i + r_j + skin`` of one replica (compiled).

    The minimum image of :func:`_min_image_pair` and the criterion
    :func:`~particleShear.engine.neighbours.within_reach` on the candidates of an ``nx × ny`` cell
    list (:func:`_cell_pairs`), or on every pair when ``nx`` or ``ny`` is below 3
    (:func:`_all_pairs`).  The keys are found into a buffer of ``8·N`` (once more, into one of the
    size found, where a dense replica has more); unsorted (NumPy's sort of them is the faster:
    :func:`search` sorts them).

    Returns
    -------
    ndarray of int64
        The keys, in the order found (a view of the buffer).
    """
    N = x.shape[0]
    key = np.empty(8 * N + 16, np.int64)
    for _ in range(2):
        n = (_cell_pairs(x, y, r, Lx, Ly, shift, skin, nx, ny, scale, key) if nx >= 3 and ny >= 3
             else _all_pairs(x, y, r, Lx, Ly, shift, skin, scale, key))
        if n <= key.shape[0]:
            break
        key = np.empty(n, np.int64)      # (a dense replica: room for every pair found)
    return key[:n]


def _all_pairs(x, y, r, Lx, Ly, shift, skin, scale, key):
    """The keys ``i·scale + j`` of every pair ``i < j`` within reach into ``key`` while they fit; returns
    how many there are (compiled; the grid of fewer than 3 cells per side)."""
    N, cap, n = x.shape[0], key.shape[0], 0
    for i in range(N):
        for j in range(i + 1, N):
            reach = r[i] + r[j] + skin
            ady = abs(y[j] - y[i])
            if min(ady, Ly - ady) > reach * (1 + 1e-9):      # (out of reach in y through any image: a safe skip)
                continue
            dx, dy, _, _ = _min_image_pair(x[j] - x[i], y[j] - y[i], Lx, Ly, shift)
            if within_reach(dx, dy, reach):
                if n < cap:
                    key[n] = i * scale + j
                n += 1
    return n


def _cell_pairs(x, y, r, Lx, Ly, shift, skin, nx, ny, scale, key):
    """The keys ``i·scale + j`` of the pairs ``i < j`` within reach by an ``nx × ny`` cell list, into
    ``key`` (unordered) while they fit; returns how many there are (compiled).

    The grid, binning and half neighbourhood of
    :func:`~particleShear.engine.neighbours.near_pairs_cells`: the same cell, the cell to the right,
    the three cells of the row above, the row above the top row being the bottom row at
    ``x − shift``.  The spheres' coordinates are copied in cell order first, so that each cell's
    spheres are read from consecutive memory, and the cells are visited in order, each computing
    its neighbours once.  Every pair within reach lies in neighbouring cells, so the pairs found do
    not depend on the order of the visit; each is tested on ``j − i`` (``±1`` times ``b − a``,
    exactly), as the all-pairs search tests it.
    """
    N, cap, n = x.shape[0], key.shape[0], 0
    cw, ch = Lx / nx, Ly / ny
    cell, cu = np.empty(N, np.int64), np.empty(N, np.int64)
    start = np.zeros(nx * ny + 1, np.int64)
    for a in range(N):       # bin: fold into the cell (a y period moves x by the offset)
        ky = np.floor(y[a] / Ly)
        xf = x[a] - shift * ky
        cy = int(cell_index(y[a] - Ly * ky, ch, ny))
        cx = int(cell_index(np.mod(xf, Lx), cw, nx))
        # the column of the row above (the bottom row at x − shift above the top row)
        cu[a] = int(cell_index(np.mod(xf - shift, Lx), cw, nx)) if cy + 1 >= ny else cx
        cell[a] = cy * nx + cx
        start[cell[a] + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(N, np.int64)
    for a in range(N):       # (spheres of a cell in increasing order)
        order[fill[cell[a]]] = a
        fill[cell[a]] += 1
    xs, ys, rs, us = np.empty(N), np.empty(N), np.empty(N), np.empty(N, np.int64)
    for m in range(N):       # (the coordinates in cell order: each cell's spheres side by side)
        a = order[m]
        xs[m], ys[m], rs[m], us[m] = x[a], y[a], r[a], cu[a]
    for cy in range(ny):
        up = (cy + 1 if cy + 1 < ny else 0) * nx
        for cx in range(nx):
            c = cy * nx + cx
            right = c + 1 if cx + 1 < nx else c + 1 - nx
            for m in range(start[c], start[c + 1]):
                a, xa, ya, ra = order[m], xs[m], ys[m], rs[m]
                u = us[m]
                left_up, right_up = (u - 1 if u > 0 else nx - 1), (u + 1 if u + 1 < nx else 0)
                for q in range(5):
                    other = c if q == 0 else right if q == 1 else up + (left_up if q == 2 else u if q == 3 else right_up)
                    for m2 in range(m + 1 if q == 0 else start[other], start[other + 1]):
                        b = order[m2]
                        sign = 1.0 if a < b else -1.0
                        dx, dy, _, _ = _min_image_pair(sign * (xs[m2] - xa), sign * (ys[m2] - ya), Lx, Ly, shift)
                        if within_reach(dx, dy, ra + rs[m2] + skin):
                            if n < cap:
                                key[n] = min(a, b) * scale + max(a, b)
                            n += 1
    return n


def search(x, y, r, Lx, Ly, shift, skin):
    """:func:`~particleShear.engine.neighbours.near_pairs` of the compiled backend: the same pairs, in the
    same order, from the same grid (:func:`~particleShear.engine.neighbours.cell_grid`; every pair
    where it has fewer than 3 cells per side), in compiled code (:func:`_search_kernel`).

    Parameters
    ----------
    x, y, r : ndarray (N,)
        Positions and radii of the replica's spheres (µm).
    Lx, Ly, shift : float
        Box and Lees-Edwards offset ``Ly·γ`` (µm).
    skin : float
        Verlet skin (µm, ≥ 0).

    Returns
    -------
    i, j : ndarray of int
        The pairs, sorted by ``(i, j)``.
    """
    N = len(x)
    if not math.isfinite(float(shift)) or N < 2:   # (an infinite offset: no pair is near, as NumPy's)
        return near_pairs(x, y, r, Lx, Ly, shift, skin)
    kernel = _kernels.get("search") or compile_search_kernel()
    nx, ny = cell_grid(float(Lx), float(Ly), 2 * float(np.max(r)) + float(skin), N)
    key = kernel(np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(y, dtype=float),
                 np.ascontiguousarray(r, dtype=float), float(Lx), float(Ly), float(shift), float(skin), nx, ny, N)
    key = np.sort(key.astype(np.int32) if N * N <= _INT32_MAX else key)   # (as near_pairs_cells sorts)
    return (key // N).astype(np.intp), (key % N).astype(np.intp)


def _constants_kernel(f, flags, idx, r, Lx, Ly, k, nu, k_t, nu_t, mu, c, prc, prt, keep, by_sphere, state, d_eq):
    """Every constant of the candidates in one pass (compiled): column p of the float block ``f`` is
    :func:`~particleShear.engine.forces.pair_rows` of candidate p (replica ``idx[0, p]``, sphere rows
    ``idx[1, p]``, ``idx[2, p]``; ``Lx … mu`` per replica; ``c, prc, prt, keep`` per sphere row where
    ``by_sphere``, else per replica), and ``flags`` rows 0, 1 are ``perm``, ``trans``."""
    for p in range(f.shape[1]):
        b, ai, aj = idx[0, p], idx[1, p], idx[2, p]
        o = ai if by_sphere else b
        perm = state[p] == PERMANENT
        rows = pair_rows(r[ai], r[aj], Lx[b], Ly[b], perm, d_eq[p], k[b], c[o], nu[b], k_t[b], nu_t[b], mu[b], prc[o],
                         prt[o], keep[o])
        # (each row by its literal index: a tuple read at a variable index costs twice the whole pass)
        (f[0, p], f[1, p], f[2, p], f[3, p], f[4, p], f[5, p], f[6, p], f[7, p], f[8, p], f[9, p], f[10, p], f[11, p],
         f[12, p], f[13, p], f[14, p], f[15, p], f[16, p], f[17, p], f[18, p], f[19, p], f[20, p], f[21, p],
         f[22, p]) = rows
        flags[0, p], flags[1, p] = perm, not perm
    return 0


def constant_rows(f, flags, idx, s, state, d_eq):
    """:meth:`~particleShear.engine.forces.PairConstants.set_bonds` of the compiled backend: its
    blocks ``f`` (float, rows :data:`~particleShear.engine.forces.PairConstants.FLOAT_ROWS`) and
    ``flags`` (``perm``, ``trans``) written in one compiled pass (:func:`_constants_kernel`) from the
    same function, :func:`~particleShear.engine.forces.pair_rows`, that the NumPy engine calls on
    arrays (≈ 20 array calls and a gather per parameter there).

    Parameters
    ----------
    f, flags : ndarray (23, P), (2, P)
        The blocks, written in place.
    idx : ndarray of int (3, P)
        Replica and sphere rows i, j of each candidate.
    s : BatchState
        The batch (radii, boxes, per-replica constants, ``visit``).
    state : ndarray of int8 (P,)
        State of each candidate (2: a bond).
    d_eq : ndarray (P,)
        Equilibrium distance of each candidate (µm).
    """
    kernel = _kernels.get("constants") or compile_constants_kernel()
    own = s.visit if s.visit is not None else (s.c, s.prc, s.prt, s.keep)
    kernel(f, flags, _int64(idx), _float(s.r), *(_float(a) for a in (s.Lx, s.Ly, s.k, s.nu, s.k_t, s.nu_t, s.mu)),
           *(_float(a) for a in own), s.visit is not None, np.ascontiguousarray(state, dtype=np.int8), _float(d_eq))


def _float(a):
    """``a`` as a C-contiguous float64 array (itself when it is one)."""
    return np.ascontiguousarray(a, dtype=np.float64)


def _int64(a):
    """``a`` as a C-contiguous int64 array (itself when it is one)."""
    return np.ascontiguousarray(a, dtype=np.int64)


def compile_constants_kernel(cache=True):
    """The compiled constants of a rebuild (:func:`constant_rows`), compiled once per process (or
    loaded from the cache).

    Parameters
    ----------
    cache : bool, default True
        As :func:`compile_step_kernel`.

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    return compile_kernel("constants", "_constants_kernel", CONSTANT_FUNCTIONS, _constants_signature, cache)


def _constants_signature():
    """The Numba signature of :func:`_constants_kernel`."""
    from numba import types
    f2, b2, i2 = (types.Array(t, 2, "C") for t in (types.float64, types.boolean, types.int64))
    f1, i1 = types.Array(types.float64, 1, "C"), types.Array(types.int8, 1, "C")
    return types.int64(f2, b2, i2, *(f1,) * 12, types.boolean, i1, f1)


#: key scale of the pair table (``i << 32 | j``, :class:`~particleShear.engine.state.PairTable`)
_TABLE_SCALE = 1 << 32


def _carry_kernel(old_key, k, state, d_eq, active, birth, xi, merge_min):
    """The history merge of a rebuild in one compiled call: the bonds of the old table kept,
    :func:`~particleShear.engine.state.carried_rows` and :func:`~particleShear.engine.state.carried_fields`
    (the functions :meth:`~particleShear.engine.state.PairTable.replace` calls with
    ``keep_relations=False``, compiled).  Returns the new keys and fields
    (:meth:`~particleShear.engine.state.PairTable.adopt`)."""
    key, src = carried_rows(old_key, old_key[state == PERMANENT], k, merge_min)
    s, d, a, b, z = carried_fields(src, state, d_eq, active, birth, xi)
    return key, s, d, a, b, z


def rebuild(x, y, r, Lx, Ly, shift, skin, table):
    """:func:`~particleShear.engine.neighbours.build_candidates` of the compiled backend (the same
    table) in three calls: the search (:func:`_search_kernel`, the pairs as the table's keys
    ``i << 32 | j``), NumPy's sort of the keys, and the history merge with its gathers
    (:func:`_carry_kernel`): ≈ 40 NumPy calls of :meth:`~particleShear.engine.state.PairTable.replace`
    and :func:`search` fewer, and no key taken apart and put together again.

    Parameters
    ----------
    x, y, r : ndarray (N,)
        Positions and radii of the replica's spheres (µm).
    Lx, Ly, shift : float
        Box and Lees-Edwards offset ``Ly·γ`` (µm).
    skin : float
        Verlet skin (µm, ≥ 0).
    table : PairTable
        The replica's pair list, changed in place.

    Returns
    -------
    PairTable
        ``table``.
    """
    N = len(x)
    if not math.isfinite(float(shift)) or N < 2:     # (an infinite offset: no pair is near, as NumPy's)
        return build_candidates(x, y, r, Lx, Ly, shift, skin, table)
    find = _kernels.get("search") or compile_search_kernel()
    carry = _kernels.get("carry") or compile_carry_kernel()
    nx, ny = cell_grid(float(Lx), float(Ly), 2 * float(np.max(r)) + float(skin), N)
    key = np.sort(find(_float(x), _float(y), _float(r), float(Lx), float(Ly), float(shift), float(skin), nx, ny,
                       _TABLE_SCALE))
    table.adopt(*carry(_int64(table.key), key, *table.fields(), state._MERGE_MIN))
    return table


def compile_carry_kernel(cache=True):
    """The compiled history merge of a rebuild (:func:`rebuild`), compiled once per process (or
    loaded from the cache).

    Parameters
    ----------
    cache : bool, default True
        As :func:`compile_step_kernel`.

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    return compile_kernel("carry", "_carry_kernel", CARRY_FUNCTIONS, _carry_signature, cache, linear=True)


def _carry_signature():
    """The Numba signature of :func:`_carry_kernel`."""
    from numba import types
    f1, i1, i = types.Array(types.float64, 1, "C"), types.Array(types.int64, 1, "C"), types.int64
    s1, b1, f2 = types.Array(types.int8, 1, "C"), types.Array(types.boolean, 1, "C"), types.Array(types.float64, 2, "C")
    return types.Tuple((i1, s1, f1, b1, i1, f2))(i1, i1, s1, f1, b1, i1, f2, i)


def _positions_linear(a, v, merge_min):
    """``numpy.searchsorted(a, v)`` (left side) of the sorted array ``v`` in the sorted array ``a`` by
    one linear pass (compiled): what :func:`~particleShear.engine.state._positions` returns, in
    O(n + m) where compiled code has no run-adaptive sort to merge with and binary searches cost
    O(m log n) (the compiled history merge, :func:`carried`, takes it in place of that function;
    ``merge_min`` is not read)."""
    out = np.empty(len(v), np.int64)
    i, n = 0, len(a)
    for m in range(len(v)):
        while i < n and a[i] < v[m]:
            i += 1
        out[m] = i
    return out


def carried(old_key, kept, k):
    """:func:`~particleShear.engine.state.carried_rows` compiled (the same function, its positions found
    by :func:`_positions_linear`): the keys of a rebuilt candidate list and the old row each carries,
    in O(n) and without NumPy's call overhead (``rows=`` of
    :meth:`~particleShear.engine.state.PairTable.replace`; :func:`rebuild` merges with its gathers
    in :func:`_carry_kernel`).

    Parameters
    ----------
    old_key, kept, k : ndarray of int64
        As :func:`~particleShear.engine.state.carried_rows`.

    Returns
    -------
    key, src : ndarray of int64
    """
    kernel = _kernels.get("carried") or compile_carried_kernel()
    return kernel(*(np.ascontiguousarray(a, dtype=np.int64) for a in (old_key, kept, k)), state._MERGE_MIN)


def compile_carried_kernel(cache=True):
    """The compiled history merge of :func:`carried`, compiled once per process (or loaded from the cache).

    Parameters
    ----------
    cache : bool, default True
        As :func:`compile_step_kernel`.

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    return compile_kernel("carried", "carried_rows", MERGE_FUNCTIONS, _carried_signature, cache, linear=True)


def _carried_signature():
    """The Numba signature of :func:`~particleShear.engine.state.carried_rows`."""
    from numba import types
    i1 = types.Array(types.int64, 1, "C")
    return types.Tuple((i1, i1))(i1, i1, i1, types.int64)


def compile_search_kernel(cache=True):
    """The compiled all-pairs search of :func:`search`, compiled once per process (or loaded from the cache).

    Parameters
    ----------
    cache : bool, default True
        As :func:`compile_step_kernel`.

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    return compile_kernel("search", "_search_kernel", STEP_FUNCTIONS + KERNEL_FUNCTIONS + SEARCH_FUNCTIONS,
                          _search_signature, cache)


def _sorted_keys(key, N):
    """``numpy.sort`` of the keys ``i·2³² + j`` (``0 ≤ i < N``) of a search, compiled: a counting sort
    on i, then each i's few keys in order by insertion.  The same array (a sorted array of numbers is
    one), in O(P + N): Numba's own sort is a quicksort about ten times slower than NumPy's on these
    (2 ms against 0.18 ms at 36,000 keys), which made it a third of a rebuild inside a block."""
    start = np.zeros(N + 1, np.int64)
    for q in range(key.shape[0]):
        start[key[q] // _TABLE_SCALE + 1] += 1
    for i in range(N):
        start[i + 1] += start[i]
    fill = start[:-1].copy()
    out = np.empty_like(key)
    for q in range(key.shape[0]):
        i = key[q] // _TABLE_SCALE
        out[fill[i]] = key[q]
        fill[i] += 1
    for i in range(N):
        for a in range(start[i] + 1, start[i + 1]):
            v, c = out[a], a - 1
            while c >= start[i] and out[c] > v:
                out[c + 1] = out[c]
                c -= 1
            out[c + 1] = v
    return out


def _merged_history(old_key, key, state, d_eq, active, birth, xi, at, b, n0, Si, s_state, s_xi, s_active, s_birth,
                     s_deq):
    """The history merge of a rebuild in one pass (compiled; :func:`_rebuild_replica`): what
    :func:`_carry_kernel` returns (:func:`~particleShear.engine.state.carried_rows` and
    :func:`~particleShear.engine.state.carried_fields` of the bonds kept), written straight into
    the slot's columns ``at …``; with ``at < 0`` nothing is written, only the count.

    ``old_key`` (the old candidates' keys ``i·2³² + j``, sorted and unique, as a pair table keeps
    them) and ``key`` (the search's, sorted) are walked side by side: a new key takes its old row
    where the old list has it and the zeros of a new pair otherwise (inactive, sticking, ξ = 0, no
    number, ``d_eq`` 0); an old key the search missed stays where it is a bond; a repeated new key
    is taken once (``numpy.unique``).  The same keys and fields, copied, as the two functions'
    sorted union and gathers, without their ≈ 25 temporary arrays and passes (about half of a
    rebuild inside a block at N = 150).  The row ``Si`` of a column is ``b`` and the key's sphere
    rows ``i + n0``, ``j + n0``.

    Returns
    -------
    int
        The number of candidates of the new list.
    """
    m, c = old_key.shape[0], key.shape[0]
    q, a, n = 0, 0, 0
    last = -1
    while q < c or a < m:
        if q < c and key[q] == last:        # (a repeated new key)
            q += 1
            continue
        if q < c and (a >= m or key[q] <= old_key[a]):
            k = key[q]
            src = a if a < m and old_key[a] == k else -1
            q += 1
            last = k
        else:
            k, src = old_key[a], a
            if state[a] != PERMANENT:      # (an old key the search missed: kept only as a bond)
                a += 1
                continue
        if src >= 0:
            a += 1
        if at >= 0:
            p = at + n
            Si[0, p], Si[1, p], Si[2, p] = b, k // _TABLE_SCALE + n0, k % _TABLE_SCALE + n0
            if src >= 0:
                s_state[p], s_xi[0, p], s_xi[1, p] = state[src], xi[0, src], xi[1, src]
                s_active[p], s_birth[p], s_deq[p] = active[src], birth[src], d_eq[src]
            else:
                s_state[p], s_xi[0, p], s_xi[1, p], s_active[p], s_birth[p], s_deq[p] = 0, 0.0, 0.0, False, 0, 0.0
        n += 1
    return n


def _rebuild_replica(b, N, pos, r, Lx, Ly, gamma, le, skin, r_max, pc, Cf, Ci, state_p, xi, active, birth, d_eq,
                     Sf, Si, Sb, s_state, s_xi, s_active, s_birth, s_deq, offsets, ends, base, cap, u, u_max, strain,
                     bound):
    """Rebuild replica b's candidate list into its own slot (compiled; :func:`_block_kernel`): what
    :meth:`~particleShear.engine.step.BatchEngine.neighbours` does for it, from the same functions.

    The history of its candidates, the columns ``offsets[b] … ends[b] − 1`` of ``Cf, Ci, state_p, xi,
    active, birth, d_eq`` (the engine's, or its slot's), as the pair table keeps it
    (:func:`~particleShear.engine.state.synced_history`, what the engine writes back before a
    rebuild); the search (:func:`_search_kernel` on the grid of
    :func:`~particleShear.engine.neighbours.cell_grid`, the keys sorted); the history merge
    (:func:`_carry_kernel`); the new candidates with their history and constants
    (:func:`_constants_kernel`; ``pc`` rows ``Lx, Ly, k, nu, k_t, nu_t, mu, c, prc, prt, keep`` per
    replica) written into the slot's columns ``base[b] …`` of ``Sf, Si, Sb, s_state, s_xi,
    s_active, s_birth, s_deq`` (the old columns are read first, so the slot may be the source), and
    ``offsets[b], ends[b]`` made the new ones; the displacement bookkeeping reset.  Returns False,
    having changed nothing, where the new list would pass ``cap[b]`` or the image offset is not
    finite (the caller rebuilds it, :func:`rebuild`)."""
    shift = Ly[b] * gamma[b] * le[b]            # (BatchEngine.image_shift)
    if not math.isfinite(shift) or N < 2:
        return False
    n0, lo, hi = b * N, offsets[b], ends[b]
    nx, ny = cell_grid(Lx[b], Ly[b], 2 * r_max[b] + skin[b], N)
    key = _sorted_keys(_search_kernel(pos[0, n0:n0 + N].copy(), pos[1, n0:n0 + N].copy(), r[n0:n0 + N].copy(), Lx[b],
                                      Ly[b], shift, skin[b], nx, ny, _TABLE_SCALE), N)
    # the old candidates' keys and history as the pair table keeps it (read before the slot is written:
    # it may be their source), then the history merge straight into the slot's columns
    m = hi - lo
    old_key, st, act, num = np.empty(m, np.int64), np.empty(m, np.int8), np.empty(m, np.bool_), np.empty(m, np.int64)
    z, de = np.empty((2, m)), np.empty(m)
    for q in range(m):
        p = lo + q
        old_key[q] = (Ci[1, p] - n0) * _TABLE_SCALE + (Ci[2, p] - n0)
        st[q], z[0, q], num[q] = synced_history(state_p[p], xi[0, p], active[p], birth[p])
        z[1, q] = synced_history(state_p[p], xi[1, p], active[p], birth[p])[1]
        act[q], de[q] = active[p], d_eq[p]
    lo = base[b]
    n = _merged_history(old_key, key, st, de, act, num, z, -1, b, n0, Si, s_state, s_xi, s_active, s_birth, s_deq)
    if lo + n > cap[b]:
        return False
    _merged_history(old_key, key, st, de, act, num, z, lo, b, n0, Si, s_state, s_xi, s_active, s_birth, s_deq)
    _constants_kernel(Sf[:, lo:lo + n], Sb[:, lo:lo + n], Si[:, lo:lo + n], r, pc[0], pc[1], pc[2], pc[3], pc[4],
                      pc[5], pc[6], pc[7], pc[8], pc[9], pc[10], False, s_state[lo:lo + n], s_deq[lo:lo + n])
    offsets[b], ends[b] = lo, lo + n
    for k in range(n0, n0 + N):
        u[0, k] = 0.0
        u[1, k] = 0.0
    u_max[b], strain[b], bound[b] = 0.0, 0.0, 0.0
    return True


#: the compiled block rebinds its arguments as views owning no reference (numba_driver.borrowed);
#: False in its variant on several threads (compile_kernel, parallel=True): there Numba's parfor
#: passes, which cannot see that the views alias the arguments, may remove stores through them as
#: dead, and a parfor's threads take views owning no reference anyway (a global constant, so the
#: branch is removed at compile time)
BORROWED_VIEWS = True

#: :func:`_block_kernel` steps a run without a law of its own, spheres' constants of their own or a force
#: register through a second compile of the step without those flags (≈ 4 % of a block); False in the
#: blocks of a run's law (:func:`_law_kernels`), whose runs always have one: Numba prunes the branch on
#: this constant, so those blocks compile no step they would never call
PLAIN_STEP = True


def _block_kernel(ks, n, starts, status, rates, rec_t, rec_strain, rec_rate, rec_internal, rec_surface, row, step0,
                  interval, guarded, scheduled, want, rec_sums, here, base, cap, pc, rebuilt, d_eq_c, Sf, Si, Sb,
                  s_state, s_xi, s_active, s_birth, s_deq, N, cool, dt, sample, check, applying, numbers, form,
                  custom, A,
                  visit_j, form_j, Tj, free_mode, free, verlet, pred, half, half_out, pos, vel, frc, phi, mmi, r, Ly_s,
                  rep_s, rate, gamma, t, Lx, Ly, V, le, adv, Cf, Ci, Cb, offsets, ends, state_p, xi, active, birth,
                  next_birth, u, u_max, strain, bound, r_max, skin, guard_on, rate_max, kk, r_mean, m_sum, min_ratio, max_ke, work, mob, yc, y0, zero,
                  tau, verdict, need, tp, ts, tsum, keep, kt, ktot, forces_only):
    """Steps of a block, replica by replica, on numbers (compiled; run by :func:`run_block`).

    Replica b runs its steps ``ks[b] … n − 1`` until the block ends, a candidate list of it is due
    that is not rebuilt here (below) or a step of it stops (:func:`_step_kernel`'s statuses); its
    first step here starts as
    ``starts[b]`` says (:data:`_SKIP`: not at all; 0: a new step; 1 or 3: the resumption of a
    step whose random directions the caller drew).  Per step of a schedule (``scheduled``): the
    new rate (:func:`~particleShear.engine.integrate.flow_shifted` on the replica's spheres), the
    record of clock, strain and rate, :func:`_step_kernel` with the two stresses sampled, their
    record, and at the steps ``k`` where ``want[k]`` the sums of every tensor's rows into
    ``rec_sums[k]`` (19, B); otherwise :func:`_step_kernel` alone, at the rate of the state.  The guard checks the
    step ``step0 + k``.  Writes the next step of each replica into ``ks`` and its status into
    ``status`` (:data:`_DONE`, :data:`_NEED` or a status of :func:`_step_kernel`).

    With ``here`` a replica whose candidate list is due before a step of the block (the lists the
    steps before marked, ``need``) rebuilds it here (:func:`_rebuild_replica`: the search, the
    history merge and the new candidates' constants, into its slot: the columns ``base[b] … cap[b] − 1``
    of ``Sf, Si, Sb, s_state, s_xi, s_active, s_birth, s_deq``, whose column indices follow the
    engine's, :class:`_Slots`; ``d_eq_c`` the equilibrium distances of the engine's candidates,
    ``pc`` the constants of :func:`constant_rows` per replica, ``rebuilt[b]`` counts the rebuilds)
    and goes on, its candidates from then on the slot's columns ``offsets[b] … ends[b] − 1``; a
    list that does not fit its slot, or one the compiled search does not take, is left to the
    caller (:data:`_NEED`).

    The replicas share nothing (each reads and writes its own spheres, candidates, slot and
    records), so each runs through the block with its own rebuilds, in any order or on any thread,
    instead of the block ending at the first list due in any replica.

    The arrays are taken as views that own no reference (:func:`~.numba_driver.borrowed`; the
    caller holds them for the call): the ≈ 100 arrays of each replica's call of the step cost no
    atomic reference counts (≈ 6 % of a block at B = 32 before).  Not in the variant on several
    threads (:data:`BORROWED_VIEWS` is False there).
    """
    # (views that own no reference: the ~100 arrays of each step's call, not counted per call, numba_driver.borrowed)
    if BORROWED_VIEWS:
        (ks, starts, status, rates, rec_t, rec_strain, rec_rate, rec_internal, rec_surface, want, rec_sums, base, cap, pc,
         rebuilt, d_eq_c, Sf, Si, Sb, s_state, s_xi, s_active, s_birth, s_deq, A, Tj, free, pred, half, half_out, pos, vel,
         frc, phi, mmi, r, Ly_s, rep_s, rate, gamma, t, Lx, Ly, V, le, adv, Cf, Ci, Cb, offsets, ends, state_p, xi, active,
         birth, next_birth, u, u_max, strain, bound, r_max, skin, guard_on, rate_max, kk, r_mean, m_sum, work, mob, yc, y0,
         zero, tau, verdict, need, tp, ts, tsum, kt, ktot) = borrowed(
            (ks, starts, status, rates, rec_t, rec_strain, rec_rate, rec_internal, rec_surface, want, rec_sums, base, cap,
             pc, rebuilt, d_eq_c, Sf, Si, Sb, s_state, s_xi, s_active, s_birth, s_deq, A, Tj, free, pred, half, half_out,
             pos, vel, frc, phi, mmi, r, Ly_s, rep_s, rate, gamma, t, Lx, Ly, V, le, adv, Cf, Ci, Cb, offsets, ends, state_p,
             xi, active, birth, next_birth, u, u_max, strain, bound, r_max, skin, guard_on, rate_max, kk, r_mean, m_sum,
             work, mob, yc, y0, zero, tau, verdict, need, tp, ts, tsum, kt, ktot))
    B = rate.shape[0]
    # a run without a law of its own, spheres' own constants or a force register (the protocols' runs) steps
    # through the step compiled with those three flags as the constant False (Numba compiles a call with a
    # literal argument for that value): their branches leave the pair loop, ≈ 4 % of a block (docs/performance.md);
    # a run law's block (PLAIN_STEP False, _law_kernels) compiles no such step
    plain = not (custom or visit_j or keep)
    for b in prange(B):
        k, start, st = ks[b], starts[b], _DONE
        while start != _SKIP and k < n:
            if here and need[b] and start == 0:       # (the list due before this step, rebuilt here)
                if rebuilt[b] > 0:        # (its present candidates: its slot's, or the engine's)
                    F, I, S, X, Ac, Bi, D = Sf, Si, s_state, s_xi, s_active, s_birth, s_deq
                else:
                    F, I, S, X, Ac, Bi, D = Cf, Ci, state_p, xi, active, birth, d_eq_c
                if not _rebuild_replica(b, N, pos, r, Lx, Ly, gamma, le, skin, r_max, pc, F, I, S, X, Ac, Bi, D, Sf,
                                        Si, Sb, s_state, s_xi, s_active, s_birth, s_deq, offsets, ends, base, cap, u,
                                        u_max, strain, bound):
                    st = _NEED
                    break
                need[b] = False
                rebuilt[b] += 1
            if scheduled and start == 0:      # (a resumed step has its rate and records)
                for q in range(b * N, (b + 1) * N):
                    vel[0, q], vel[2, q] = flow_shifted(vel[0, q], vel[2, q], pos[1, q] - Ly_s[q] / 2,
                                                        rates[k, b] - rate[b])
                rate[b] = rates[k, b]
                rec_t[row + k, b] = t[b]
                rec_strain[row + k, b] = gamma[b]
                rec_rate[row + k, b] = rate[b]
            due_check = guarded and (step0 + k) % interval == 0
            tensors = scheduled and want[k]
            code = 2 if tensors else 1 if scheduled else 0
            if here and rebuilt[b] > 0:    # (its candidates are its slot's since its first rebuild here)
                F, I, Bf, S, X, Ac, Bi = Sf, Si, Sb, s_state, s_xi, s_active, s_birth
            else:
                F, I, Bf, S, X, Ac, Bi = Cf, Ci, Cb, state_p, xi, active, birth
            # (two calls on purpose: the literal False arguments of the first are what makes Numba compile the
            # step without those flags; one call with the shared arguments packed as *args took 1.05× as long)
            if PLAIN_STEP and plain:     # (custom, visit_j, keep the constant False: the step compiled without them)
                st = _step_kernel(start, b, b + 1, N, cool, dt, code, due_check,
                                  applying, numbers, form, False, A, False, form_j, Tj, free_mode, free, verlet, pred, half,
                                  half_out, pos, vel, frc, phi,
                                  mmi, r, Ly_s, rep_s, rate, gamma, t, Lx, Ly, V, le, adv, F, I, Bf, offsets, ends, S,
                                  X, Ac, Bi, next_birth, u, u_max, strain, bound, r_max, skin, guard_on, rate_max, kk, r_mean,
                                  m_sum, min_ratio, max_ke, work, mob, yc, y0, zero, tau, verdict, need, tp, ts, tsum, False,
                                  kt, ktot, False)
            else:
                st = _step_kernel(start, b, b + 1, N, cool, dt, code, due_check,
                                  applying, numbers, form, custom, A, visit_j, form_j, Tj, free_mode, free, verlet, pred, half,
                                  half_out, pos, vel, frc, phi,
                                  mmi, r, Ly_s, rep_s, rate, gamma, t, Lx, Ly, V, le, adv, F, I, Bf, offsets, ends, S,
                                  X, Ac, Bi, next_birth, u, u_max, strain, bound, r_max, skin, guard_on, rate_max, kk, r_mean,
                                  m_sum, min_ratio, max_ke, work, mob, yc, y0, zero, tau, verdict, need, tp, ts, tsum, keep,
                                  kt, ktot, False)
            start = 0
            if st != _DONE:
                break
            if scheduled:
                rec_internal[row + k, b] = tau[0, b]
                rec_surface[row + k, b] = tau[1, b]
                if tensors:
                    for q in range(tsum.shape[0]):
                        rec_sums[k, q, b] = tsum[q, b]
            if verlet:        # (the half kick the replica's next force phase sees)
                for q in range(b * N, (b + 1) * N):
                    half[0, q], half[1, q], half[2, q] = half_out[0, q], half_out[1, q], half_out[2, q]
                pred[b] = True
            k += 1
            if need[b] and not here:
                st = _NEED
                break
        ks[b], status[b] = k, st
    return 0


def compile_block_kernel(cache=True, parallel=False):
    """The compiled block of :func:`run_block`, compiled once per process (or loaded from the cache).

    Parameters
    ----------
    cache : bool, default True
        As :func:`compile_step_kernel`.
    parallel : bool, default False
        The variant that steps the replicas on several threads (:func:`threads`; its own entry in
        Numba's cache, under the name ``_block_kernel__parallel``).

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    return compile_kernel(("block", bool(parallel)), "_block_kernel", STEP_FUNCTIONS + KERNEL_FUNCTIONS + BLOCK_FUNCTIONS,
                    _block_signature, cache, parallel=bool(parallel))
