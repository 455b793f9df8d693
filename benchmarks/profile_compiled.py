"""Where the time of a compiled block goes: the compiled steps, the rebuilds inside, the hand-back (not a test).

On the scenes of ``bench_compiled.py`` (``bench_step.build``, seeds 1 … B, ``run_block`` at the
protocol's rates), one core:

1. Blocks of ``numba_step.run_block`` timed whole, with the time of the compiled call (the steps
   and the rebuilds inside), of the hand-back of the rebuilt lists (``numba_step._settle``) and
   the rebuilds per replica-step counted; the rest is the Python of ``run_block``.
2. One rebuild inside a block (``numba_step._rebuild_replica``, replica 0, its list rebuilt from the
   engine's columns into its slot, again and again) and its parts, each in a compiled loop (no
   Python call per rebuild): the search alone (``_search_kernel``), the search with the keys'
   counting sort (``_sorted_keys``), the new candidates' constants alone (``_constants_kernel``);
   the history merge is the rest.
3. One compiled step of the whole batch (``numba_step._step_kernel`` called from Python, as
   ``run_step`` calls it; its call costs a few µs, printed as "empty call"): the force phase alone
   (``forces_only``), the whole step without samples and with the two shear stresses.

Figures are min/median of the timed repetitions; the host's noise is large (alternate the runs
to compare two trees: each process compiles its tree's functions once, from its own cache).

Usage: python benchmarks/profile_compiled.py [N B] (default: 150 32, then 10000 1)
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_step  # noqa: E402

from particleShear.base.engine_adapter import state_from_ensembles  # noqa: E402
from particleShear.engine import numba_driver, numba_step  # noqa: E402
from particleShear.engine.step import BatchEngine  # noqa: E402
from particleShear.run.batch import ENGINE_SKIN_FACTOR  # noqa: E402

COOL = 0.99969060716623

_counts = {"kernel": 0.0, "settle": 0.0, "rebuilds": 0}
_kernels_of, _settle = numba_step.kernels_of, numba_step._settle


def _timed_kernels_of(ws):
    """``numba_step.kernels_of`` whose block kernel adds its time to ``_counts``."""
    step, block = _kernels_of(ws)

    def timed(*args):
        t0 = time.perf_counter()
        out = block(*args)
        _counts["kernel"] += time.perf_counter() - t0
        return out
    return step, timed


def _timed_settle(engine, slots):
    """``numba_step._settle`` counting the lists rebuilt inside the block and timing the hand-back."""
    _counts["rebuilds"] += int(slots.rebuilt.sum())
    t0 = time.perf_counter()
    _settle(engine, slots)
    _counts["settle"] += time.perf_counter() - t0


def block(eng, n):
    """Seconds of ``n`` steps of ``eng`` in ``run_block`` at the protocol's rates (as ``bench_compiled``)."""
    s, B = eng.s, eng.s.B
    w = 2 * math.pi * bench_step.F_EXC
    start = float(s.t[0])
    rates = np.repeat((bench_step.AMPLITUDE * w * np.cos(w * (start + bench_step.DT * np.arange(n))))[:, None], B,
                      axis=1)
    record = {name: np.empty((n, B)) for name in ("t", "strain", "strain_rate", "stress_internal", "stress_surface")}
    t0 = time.perf_counter()
    numba_step.run_block(eng, rates, COOL, bench_step.DT, record, 0)
    return time.perf_counter() - t0


def _stats(values, scale):
    return f"{min(values) * scale:.1f}/{statistics.median(values) * scale:.1f}"


def blocks(eng, steps, repeats, scale):
    """Part 1: the blocks, the compiled call, the hand-back; returns the rebuilds per replica-step."""
    numba_step.kernels_of, numba_step._settle = _timed_kernels_of, _timed_settle
    try:
        block(eng, 5)
        got = {"block": [], "kernel": [], "settle": []}
        rebuilds = 0
        for _ in range(repeats):
            for k in _counts:
                _counts[k] = 0
            got["block"].append(block(eng, steps))
            got["kernel"].append(_counts["kernel"])
            got["settle"].append(_counts["settle"])
            rebuilds += _counts["rebuilds"]
    finally:
        numba_step.kernels_of, numba_step._settle = _kernels_of, _settle
    n = steps * eng.s.B
    print("  blocks of %d steps: whole %s, compiled call %s, hand-back %s; rebuilds per replica-step %.3f"
          % (steps, *(_stats([v / n for v in got[k]], scale) for k in ("block", "kernel", "settle")),
             rebuilds / (n * repeats)))
    return rebuilds / (n * repeats)


def rebuild_parts(eng, repeats):
    """Part 2: µs of one rebuild inside a block of replica 0 and of its parts, in compiled loops."""
    import numba

    f = numba_driver.jit_laws(False, numba_step.STEP_FUNCTIONS + numba_step.KERNEL_FUNCTIONS +
                              numba_step.BLOCK_FUNCTIONS, inline=numba_step.INLINE)
    rebuild, search, order, constants, grid = (f[n] for n in ("_rebuild_replica", "_search_kernel", "_sorted_keys",
                                                              "_constants_kernel", "cell_grid"))
    scale_key = numba_step._TABLE_SCALE

    @numba.njit
    def loop_rebuild(K, b, args):
        offsets, ends = args[25], args[26]
        o, e = offsets[b], ends[b]
        for _ in range(K):
            offsets[b], ends[b] = o, e
            rebuild(b, *args)
        n = ends[b] - offsets[b]          # (the new list, from the slot's first column)
        offsets[b], ends[b] = o, e
        return n

    @numba.njit
    def loop_search(K, sort, b, N, pos, r, Lx, Ly, shift, skin, r_max):
        n0, t = b * N, 0
        nx, ny = grid(Lx, Ly, 2 * r_max + skin, N)
        for _ in range(K):
            key = search(pos[0, n0:n0 + N].copy(), pos[1, n0:n0 + N].copy(), r[n0:n0 + N].copy(), Lx, Ly, shift, skin,
                         nx, ny, scale_key)
            if sort:
                key = order(key, N)
            t += key.shape[0]
        return t

    @numba.njit
    def loop_constants(K, lo, n, Sf, Sb, Si, r, pc, s_state, s_deq):
        for _ in range(K):
            constants(Sf[:, lo:lo + n], Sb[:, lo:lo + n], Si[:, lo:lo + n], r, pc[0], pc[1], pc[2], pc[3], pc[4], pc[5],
                      pc[6], pc[7], pc[8], pc[9], pc[10], False, s_state[lo:lo + n], s_deq[lo:lo + n])
        return 0

    ws, slots = numba_step._workspace(eng), numba_step._Slots.of(eng)
    s, c, b = eng.s, eng.s.contacts, 0
    C = c.C
    args = (s.N, s.pos, s.r, ws.Lx, ws.Ly, s.gamma.astype(float), ws.le, ws.skin, ws.r_max, slots.pc, C.f, C.i,
            c.state_p, c.xi, c.active, c.birth, slots.d_eq_c, slots.f, slots.i, slots.b, slots.state_p,
            slots.xi, slots.active, slots.birth, slots.d_eq, slots.offsets, slots.ends, slots.base, slots.cap,
            c.u.copy(), c.u_max.copy(), c.strain.copy(), c.bound.copy())
    grid_args = (b, s.N, s.pos, s.r, float(ws.Lx[b]), float(ws.Ly[b]), float(ws.Ly[b] * s.gamma[b] * ws.le[b]),
                 float(ws.skin[b]), float(ws.r_max[b]))
    lo, n = int(slots.base[b]), int(loop_rebuild(1, b, args))     # (the rebuilt list, in the slot)
    runs = {"whole": lambda K: loop_rebuild(K, b, args),
            "search": lambda K: loop_search(K, False, *grid_args),
            "search + sort": lambda K: loop_search(K, True, *grid_args),
            "constants": lambda K: loop_constants(K, lo, n, slots.f, slots.b, slots.i, s.r, slots.pc, slots.state_p,
                                                  slots.d_eq)}
    K = max(3, int(300_000 / s.N))
    got = {k: [] for k in runs}
    for k, run in runs.items():
        run(1)
    for _ in range(repeats):
        for k, run in runs.items():
            t0 = time.perf_counter()
            run(K)
            got[k].append((time.perf_counter() - t0) / K)
    print(f"  one rebuild inside a block (replica 0, {n} candidates), µs: "
          + "; ".join(f"{k} {_stats(v, 1e6)}" for k, v in got.items()))
    return {k: statistics.median(v) for k, v in got.items()}


def step_parts(eng, repeats, scale):
    """Part 3: one compiled step of the batch, its force phase alone, without and with samples."""
    ws = numba_step._prepared(eng)
    kernel, B = numba_step.kernels_of(ws)[0], eng.s.B
    pred = np.full(B, eng.s.predictor.half is not None)
    K = max(3, int(300_000 / (eng.s.N * B)))
    got = {}
    for name, sample, forces_only, b1 in (("empty call", False, False, 0), ("force phase", False, True, B),
                                          ("step", False, False, B), ("step sampled", True, False, B)):
        args, _ = numba_step.step_arguments(eng, ws, COOL, bench_step.DT, sample, False, pred, forces_only=forces_only)
        kernel(0, 0, b1, *args)
        got[name] = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            for _ in range(K):
                kernel(0, 0, b1, *args)
            got[name].append((time.perf_counter() - t0) / K)
    print("  one compiled step of the batch (called from Python): "
          + "; ".join(f"{k} {_stats(v, 1e6 if k == 'empty call' else scale)}" for k, v in got.items()))


def main(N, B):
    unit, scale = ("ns per particle-step", 1e9 / N) if N >= 1000 else ("µs per replica-step", 1e6)
    print(f"N = {N}, B = {B} ({unit}; the empty call in µs; min/median)")
    eng = BatchEngine(state_from_ensembles([bench_step.build(N, seed=1 + b) for b in range(B)], backend="numba"),
                      skin_factor=ENGINE_SKIN_FACTOR)
    per = blocks(eng, 40 if N < 1000 else 10, 7 if N < 1000 else 5, scale)
    parts = rebuild_parts(eng, 7)
    print(f"  rebuilds: ≈ {per * parts['whole'] * scale:.1f} {unit} (the rebuild's median × rebuilds per replica-step)")
    step_parts(eng, 7, scale / B)


if __name__ == "__main__":
    if len(sys.argv) == 3:
        main(int(sys.argv[1]), int(sys.argv[2]))
    else:
        main(150, 32)
        main(10_000, 1)
