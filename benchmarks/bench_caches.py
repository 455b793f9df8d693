"""What each cache of the canvas classes buys per step (not a test).

For every cache the classes keep between steps, the step is timed with the cache disabled (the
value recomputed where it is used, by an instance-level patch of the method that keeps it) and
enabled, in alternating blocks in one process on the same scene, and the median µs per step of
each is printed with the saving (the median over block pairs of disabled − enabled) in µs and as a fraction of
the enabled step.

The step is what a run does (docs/design.md, "Caching"): ``setShearRate``, the force phase, the
register totals, the σ_xy-only evaluation on every other step (what the experiment samples), the
acceleration and the movement — on the crosslinked, frictional, sheared scenes of ``bench_step.py``
at N = 150 and N = 10,000.

Usage: python benchmarks/bench_caches.py [--sizes 150,10000] [--blocks K] [--only NAME,...]
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import types  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from bench_step import AMPLITUDE, DT, F_EXC, build  # noqa: E402

from particleShear import StressTensorEvaluation  # noqa: E402
from particleShear.base import canvas as C  # noqa: E402
from particleShear.base.register import SphereSelection  # noqa: E402
from particleShear.engine import laws as engine_laws  # noqa: E402

COOL = 0.99969060716623


def run_steps(ens, ev, n_steps):
    """Wall time (s) of each of n_steps run-like steps."""
    times = []
    w = 2 * math.pi * F_EXC
    for k in range(n_steps):
        t0 = time.perf_counter()
        ens.setShearRate(AMPLITUDE * w * math.cos(w * ens.t))
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        if k % 2 == 0:
            ev.evaluate_shear_stresses(ens.force_register, ens._mobile_selection())
        ens.mechanical_simulation_step_calculate_acceleration(COOL, DT)
        ens.mechanical_simulation_step_calculate_movement(DT)
        times.append(time.perf_counter() - t0)
    return times


# -- the patches that disable one cache each (instance attributes shadow the class's methods) --------
def _wrap_tnr(ens, before):
    """test_neighbor_relation preceded by ``before(ens)`` (drops a cache kept across steps)."""
    orig = type(ens).test_neighbor_relation

    def tnr(self):
        before(self)
        return orig(self)
    return {"test_neighbor_relation": types.MethodType(tnr, ens)}


def _struct_attr(name):
    def before(self):
        S = self._struct
        if S is not None:
            setattr(S, name, None if name != "mob" else C._UNSET)
    return before


def _bond_attr(name):
    def before(self):
        S = self._struct
        if S is not None and S.bond is not None:
            setattr(S.bond, name, None)
    return before


def no_yc(ens):
    return {"_y_centred": types.MethodType(lambda self: self._pos[1] - self.size_y / 2, ens)}


def no_u(ens):
    return {"_affine_vx": types.MethodType(lambda self, rate: self._y_centred() * rate, ens)}


def no_mob(ens):
    def mob(self):
        if not self.applyingShear:
            return None
        y, r = self._pos[1], self._a["r"]
        m = r < y
        m &= y < self.size_y - r
        return m
    return {"_mobile_mask": types.MethodType(mob, ens)}


def no_mob_limits(ens):
    def before(self):
        self._mob_limits = None
    orig = type(ens)._mobile_mask

    def mob(self):
        before(self)
        return orig(self)
    return {"_mobile_mask": types.MethodType(mob, ens)}


def no_selection(ens):
    return {"_mobile_selection": types.MethodType(lambda self: SphereSelection(self, self._mobile_mask()), ens)}


def no_kw(ens):
    return {"_kick_weights": types.MethodType(lambda self: self._st.take(C._MASS_ROWS, axis=0), ens)}


def no_on_relations(ens):
    return {"_on_relations": types.MethodType(lambda self, value, g: value * g.active, ens)}


def no_uniform(ens):
    def param(self, name):
        arr = self._a[name]
        return float(arr[0]) if len(arr) and (arr == arr[0]).all() else None
    return {"_param": types.MethodType(param, ens)}


def no_law(ens):
    def inside(d, d0, k, c, holder):
        return engine_laws.central_inside(d, d0, *engine_laws.central_constants(d0, k, c),
                                          form=engine_laws.central_form(c))
    return {"_builtin_law_inside": inside}


def no_flush(ens):
    orig = type(ens)._flush_pair_forces
    return {"_flush_pair_forces": types.MethodType(lambda self, reuse=False: orig(self, False), ens)}


def no_cand(ens):
    def before(self):
        self._cand_key = None
    return _wrap_tnr(ens, before)


def no_struct(ens):
    def before(self):
        self._struct = None
    return _wrap_tnr(ens, before)


CACHES = {
    "_yc (_y_centred)": no_yc,
    "_u (_affine_vx)": no_u,
    "_mob (_mobile_mask, whole)": no_mob,
    "_mob_limits (r, Ly - r)": no_mob_limits,
    "_selection (_mobile_selection)": no_selection,
    "_kw (_kick_weights)": no_kw,
    "_rel_factors (_on_relations)": no_on_relations,
    "_uniform (_param)": no_uniform,
    "_cand_* (rsum, perm, ji)": no_cand,
    "_struct (pair structure, all on it)": no_struct,
    "S.mob (internal flags)": lambda ens: _wrap_tnr(ens, _struct_attr("mob")),
    "S.flush (flush arrays)": no_flush,
    "holder.law (law constants)": no_law,
    "S.bond (bond constants, all)": lambda ens: _wrap_tnr(ens, _struct_attr("bond")),
    "B.params": lambda ens: _wrap_tnr(ens, _bond_attr("params")),
    "B.tensile": lambda ens: _wrap_tnr(ens, _bond_attr("tensile")),
    "B.tangential": lambda ens: _wrap_tnr(ens, _bond_attr("tangential")),
    "B.viscous": lambda ens: _wrap_tnr(ens, _bond_attr("viscous")),
}


def measure(ens, ev, patch, blocks, steps):
    """(disabled, enabled, saved) s per step: the medians over all steps of each state, and the median
    over block pairs of the difference of their block medians (adjacent blocks see the same load)."""
    off, on, saved = [], [], []
    patches = patch(ens)
    for b in range(blocks):
        med = {}
        for state in ((0, 1) if b % 2 == 0 else (1, 0)):
            if state == 0:
                ens.__dict__.update(patches)
                t = run_steps(ens, ev, steps)
                off += t
                for name in patches:
                    del ens.__dict__[name]
            else:
                t = run_steps(ens, ev, steps)
                on += t
            med[state] = statistics.median(t)
        saved.append(med[0] - med[1])
    return statistics.median(off), statistics.median(on), statistics.median(saved)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="150,10000")
    ap.add_argument("--blocks", type=int, default=20)
    ap.add_argument("--only", default="")
    args = ap.parse_args()
    only = [s for s in args.only.split(",") if s]
    for n in [int(s) for s in args.sizes.split(",")]:
        ens = build(n)
        ev = StressTensorEvaluation(ens.size_x, ens.size_y)
        run_steps(ens, ev, 20)
        steps = 40 if n <= 1000 else 6
        print(f"\nN = {n}: {args.blocks} alternating blocks of {steps} steps per state; median µs per step")
        print(f"{'cache':40s} {'disabled':>10s} {'enabled':>10s} {'saved':>9s} {'saved %':>8s}")
        for name, patch in CACHES.items():
            if only and not any(o in name for o in only):
                continue
            t_off, t_on, dt = measure(ens, ev, patch, args.blocks, steps)
            print(f"{name:40s} {t_off * 1e6:10.1f} {t_on * 1e6:10.1f} {dt * 1e6:9.1f} "
                  f"{100 * dt / t_on:7.1f}%", flush=True)


if __name__ == "__main__":
    main()
