"""The documented classes' force phase, movement and tensor sums in the compiled step (Numba, optional).

1.0.2's API steps an ensemble in three calls (``mechanical_simulation_step_calculate_forces``,
``…_acceleration``, ``…_movement``) with the force register and ``StressTensorEvaluation`` read in
between, so the canvas's engine (:class:`~particleShear.base.engine_view.EngineStep`) runs its step
as phases rather than as :meth:`~particleShear.engine.step.BatchEngine.step`.  On the ``"numba"``
backend those phases run here in the engine's compiled step kernel, the same code as the engine's
own steps, through the public names of :mod:`particleShear.engine.numba_step`:

* :func:`force_phase`: the kernel's force phase alone (:func:`~particleShear.engine.numba_step.launch`
  with ``forces_only``);
* :func:`move`: the kernel from its movement alone (:data:`~particleShear.engine.numba_step.MOVE_ONLY`:
  the ξ rule, displacement, drift, strain, wrap, clock) after the phase and the NumPy kick;
* :func:`tensor_sums`: every tensor's row sums of a force register's phase (:func:`compile_tensor_kernel`,
  the step kernel's own row functions).

Each gives the NumPy phase's numbers bit for bit, and falls back to it
(:meth:`~particleShear.engine.step.BatchEngine.force_phase`, :meth:`~particleShear.engine.step.BatchEngine.move`,
:meth:`~particleShear.engine.stress.StressInputs.reduce`) where the compiled step does not cover the
engine (:func:`~particleShear.engine.numba_step.reason`) or the backend is NumPy.  Kept here, beside
the classes they serve: the engine's own runs step whole steps and blocks (docs/design.md).
"""
__docformat__ = "numpy"

import sys

import numpy as np

from ..engine import numba_step
from ..engine.numba_step import pair_tensor_rows, sphere_tensor_rows, tensor_row_sums
from ..engine.step import ForceRecord

__all__ = ["force_phase", "move", "tensor_sums", "compile_tensor_kernel", "TENSOR_FUNCTIONS"]

#: the functions of the compiled tensor sums (:func:`compile_tensor_kernel`) besides the step's
TENSOR_FUNCTIONS = ((sys.modules[__name__], "_tensor_kernel"),)


def force_phase(engine, sample=False):
    """The force phase of ``engine``: compiled on the ``"numba"`` backend where the step kernel covers
    it, else :meth:`~particleShear.engine.step.BatchEngine.force_phase` (the same numbers).

    Compiled: the first part of the compiled step (neighbours when due, relations and their
    history, terms, forces and torques into the state, the guard when due, the terms when kept),
    the acceleration and movement phases then reading the record.  The record's rows and the kept
    terms are the phase's own buffers (no copies): the engine's workspace is given new ones, so
    the engine's later steps and phases leave them as they are.

    Parameters
    ----------
    engine : BatchEngine
        The engine (a documented canvas's; any engine).
    sample : bool or str
        As :meth:`~particleShear.engine.step.BatchEngine.force_phase`.

    Returns
    -------
    record : ForceRecord
        What the acceleration and the movement of the step read (``verdict`` None: the compiled
        phase reports an unsound verdict at once).
    stresses : None or tuple
        As :meth:`~particleShear.engine.step.BatchEngine.force_phase` returns them.

    Raises
    ------
    EngineInstability
        When the guard finds a guarded replica unstable.
    """
    if not engine.backend.compiled:
        return engine.force_phase(sample)
    try:
        got = numba_step.launch(engine, 1.0, 0.0, sample, forces_only=True)
    except BaseException:      # (the terms kept before the guard's report are the workspace's rows)
        _take_buffers(numba_step.last_workspace(engine))
        raise
    if got is None:
        return engine.force_phase(sample)
    ws = got[0]
    w = ws.work
    record = ForceRecord(w[0], w[1], w[5], w[6], w[7], engine.s.contacts.active.copy(), ws.yc.copy(), ws.mob.copy(),
                         None)
    stresses = numba_step.step_samples(ws, sample)
    _take_buffers(ws)
    return record, stresses


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
    """The movement of ``engine`` after its force phase ``g`` and its kick: compiled on the ``"numba"``
    backend where ``g`` is the record of a compiled phase (:func:`force_phase`) of the engine's
    present candidates, else :meth:`~particleShear.engine.step.BatchEngine.move` (the same numbers).

    Compiled: the tail of the compiled step from :data:`~particleShear.engine.numba_step.MOVE_ONLY`,
    the sequential ξ rule (a random direction at ``|R| = 0`` drawn from the replica's generator,
    :func:`~particleShear.engine.numba_step.resume_at_units`), the displacement since the lists were
    built, the drift, the strain, the wrap, the clock and the lists due.

    Parameters
    ----------
    engine : BatchEngine
        The engine, its candidates those of the force phase.
    dt : float
        Time step (s).
    g : ForceRecord or None
        The record of the step's force phase (its pair vectors, normals, image velocity, heights);
        None: a movement without a force phase (:meth:`~particleShear.engine.step.BatchEngine.move`).
    """
    ws = numba_step.last_workspace(engine) if engine.backend.compiled and g is not None else None
    if ws is None or ws.why is not None or ws.C is not engine.s.contacts.C or g.verdict is not None:
        engine.move(dt, g)
        return
    w = ws.work        # (the phase's geometry: its rows are the record's, the workspace has new ones)
    w[0], w[1], w[5], w[6], w[7] = g.dx, g.dy, g.nx, g.ny, g.dvx
    ws.yc[:] = g.yc
    B = engine.s.B
    kernel = numba_step.kernels_of(ws)[0]
    args, held = numba_step.step_arguments(engine, ws, 1.0, dt, False, False, np.zeros(B, dtype=np.bool_))
    numba_step.resume_at_units(engine, ws, kernel, args, kernel(numba_step.MOVE_ONLY, 0, B, *args))
    numba_step.hand_back(engine, ws, held, stepped=True, kicked=False)
    engine.step_count += 1


def tensor_sums(q):
    """The per-replica sums of every tensor's rows (:data:`~particleShear.engine.stress.SUMMED_ROWS`)
    of one force phase's inputs, in the compiled code: what
    :meth:`~particleShear.engine.stress.StressInputs.reduce` sums on NumPy, the same bits (the rows
    from the same entry functions, the sums in NumPy's order); the tensors are then
    :func:`~particleShear.engine.stress.tensors_from_sums` of them.  ``StressTensorEvaluation``'s
    sums of a force register's phase on the ``"numba"`` backend.

    Parameters
    ----------
    q : StressInputs
        Every input of the rows (one force phase of a batch whose spheres are ``B·N`` rows; host arrays).

    Returns
    -------
    ndarray (TENSOR_SUMS, B)
        The sums (:data:`~particleShear.engine.numba_step.TENSOR_SUMS` rows, 19).
    """
    C, B = q.C, q.B
    n, P = len(q.x), len(q.dx)
    own = q.fx_j is not None
    tsum = np.zeros((numba_step.TENSOR_SUMS, B))
    arrays = [C.ai, C.aj, C.rep, C.offsets, q.rep, q.x, q.y, q.vx, q.vy, q.omega, q.m, q.inertia, q.Lx, q.Ly, q.rate,
              q.mob, q.active, q.shifted, q.dx, q.dy, q.fx_i, q.fy_i, q.fx_j if own else q.fx_i,
              q.fy_j if own else q.fy_i, q.dF, q.fx, q.fy, q.torque]
    kernel = compile_tensor_kernel()
    try:            # (the inputs as they are: the arrays of a force phase have the kernel's types)
        kernel(B, n // B if B else 0, *arrays[:5], own, *arrays[5:], np.empty((9, P)), np.empty((10, n)), tsum)
    except TypeError:
        sizes = [None] * 5 + [n] * 7 + [B] * 3 + [None, None] + [P] * 8 + [n] * 3
        kinds = [np.int64] * 5 + [float] * 10 + [np.bool_] * 3 + [float] * 10
        arrays = [np.ascontiguousarray(np.asarray(a, dtype=t) if k is None else
                                       np.broadcast_to(np.asarray(a, dtype=t), (k,))) for a, k, t in zip(arrays, sizes, kinds)]
        kernel(B, n // B if B else 0, *arrays[:5], own, *arrays[5:], np.empty((9, P)), np.empty((10, n)), tsum)
    return tsum


def _tensor_kernel(B, N, ai, aj, rep_p, offsets, rep_s, own_j, x, y, vx, vy, omega, m, inertia, Lx, Ly, rate, mob,
                   active, shifted, dx, dy, fx_i, fy_i, fx_j, fy_j, dF, fx, fy, torque, tp, ts, tsum):
    """Every tensor's row sums of one force phase's inputs into ``tsum`` (TENSOR_SUMS, B), ``tp``
    (9, P) and ``ts`` (10, B·N) their rows (compiled; :func:`compile_tensor_kernel`): the rows and
    sums of the compiled step's sampling steps, over the whole batch."""
    pair_tensor_rows(offsets[0], offsets[B], ai, aj, rep_p, own_j, x, y, Lx, Ly, mob, active, shifted, shifted, dx, dy,
                     fx_i, fy_i, fx_j, fy_j, dF, tp)
    sphere_tensor_rows(0, B * N, rep_s, x, y, vx, vy, omega, m, inertia, fx, fy, torque, mob, rate, Lx, Ly, ts)
    tensor_row_sums(0, B, N, offsets, offsets[1:], tp, ts, tsum)
    return 0


def compile_tensor_kernel(cache=True):
    """The compiled :func:`_tensor_kernel` of :func:`tensor_sums`, compiled once per process (or loaded
    from Numba's cache) with the step's functions
    (:func:`~particleShear.engine.numba_step.compile_kernel`).

    Parameters
    ----------
    cache : bool, default True
        As :func:`~particleShear.engine.numba_step.compile_step_kernel`.

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    return numba_step.compile_kernel("tensors", "_tensor_kernel",
                                     numba_step.STEP_FUNCTIONS + numba_step.KERNEL_FUNCTIONS + TENSOR_FUNCTIONS,
                                     _tensor_signature, cache)


def _tensor_signature():
    """The Numba signature of :func:`_tensor_kernel`."""
    from numba import types
    f1, i1, f2 = (types.Array(types.float64, 1, "C"), types.Array(types.int64, 1, "C"),
                  types.Array(types.float64, 2, "C"))
    b1 = types.Array(types.boolean, 1, "C")
    return types.int64(types.int64, types.int64, i1, i1, i1, i1, i1, types.boolean, *(f1,) * 10, b1, b1, b1,
                       *(f1,) * 10, f2, f2, f2)
