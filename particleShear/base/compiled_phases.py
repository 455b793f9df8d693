"""The documented classes' tensor sums in the compiled code (Numba, optional).

1.0.2's API steps an ensemble in three calls (``mechanical_simulation_step_calculate_forces``,
``…_acceleration``, ``…_movement``) with the force register and ``StressTensorEvaluation`` read in
between, so the canvas's engine (:class:`~particleShear.base.engine_view.EngineStep`) runs its step
as the engine's phases, :meth:`~particleShear.engine.step.BatchEngine.force_phase`,
:meth:`~particleShear.engine.step.BatchEngine.accelerate` and
:meth:`~particleShear.engine.step.BatchEngine.move` (on the ``"numba"`` backend the force phase and
the movement run in the engine's compiled step kernel, alone). What is left here is the sums of
``StressTensorEvaluation``:

* :func:`tensor_sums`: every tensor's row sums of a force register's phase (:func:`compile_tensor_kernel`,
  the step kernel's own row functions, through the public names of :mod:`particleShear.engine.numba_step`).

It gives NumPy's numbers bit for bit (:meth:`~particleShear.engine.stress.StressInputs.reduce`).
Kept here, beside the classes it serves: the engine's own runs sample whole steps and blocks
(docs/design.md).
"""
__docformat__ = "numpy"

import sys

import numpy as np

from ..engine import numba_step
from ..engine.numba_step import pair_tensor_rows, sphere_tensor_rows, tensor_row_sums

__all__ = ["tensor_sums", "compile_tensor_kernel", "TENSOR_FUNCTIONS"]

#: the functions of the compiled tensor sums (:func:`compile_tensor_kernel`) besides the step's
TENSOR_FUNCTIONS = ((sys.modules[__name__], "_tensor_kernel"),)


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
