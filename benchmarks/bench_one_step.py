"""The issue-20 performance rows, current tree against a baseline tree in one run (not a test).

Each row is measured in two worker processes, one per tree (``PYTHONPATH`` set to the tree, one
thread: ``OMP_NUM_THREADS = OPENBLAS_NUM_THREADS = MKL_NUM_THREADS = 1``, pinned to one CPU while
timed, like ``taskset -c 0``).  Both workers build their scene first; then the parent asks them
for timed blocks in turn, baseline / current / baseline / current …, and takes the median of each
tree's samples, so a busy spell of a shared host hits both.  Rows:

(a) the documented step loop of README.md ("Scripts of particleShear 1.0.2 …") on the
    ``bench_step.build(150, seed=2)`` scene (EnsembleLinkable, N = 150, frictional, crosslinked,
    plates on): per step ``setShearRate``, ``mechanical_simulation_step_calculate_forces``,
    ``record_total_particle_forces``, ``ev.evaluate_stress_tensors(ens.force_register,
    ens.movableSphereList(), ens.shear_rate)`` (every tensor every step), acceleration, movement;
    µs per step (median of single steps).  Target: current ≤ 0.6 × baseline.
(b) µs per replica-step of the protocol at B = 32: ``doParticleShearSimulationSeries(N_repetitions=32,
    batch_size=32)`` of default-scene runs in this process (an inline executor), the sum of the runs'
    ``timings["protocol"]`` over the sum of their ``N_steps``.  Target: no slower (≤ 1.05 × baseline,
    the scatter of medians on a shared host).
(c) the single default run ``doParticleShearSimulation(doDrawing=False, plotStress=False, saveData=False,
    seed=s)``, wall time of the whole call.  Target: no slower (≤ 1.05 ×).
(d) plateau law: a batch of 32 runs (the series above) against single runs, wall time per run of the
    whole call (constitution, pre-equilibration, protocol; the protocol part is printed too), the law
    set the 1.0.2 way (``CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau``,
    both trees) and as ``contact_law="plateau"`` (where the tree accepts it).  Short runs
    (``relative_frequency`` 0.5: 671 protocol steps).  Target: batch per run ≤ 1/2.5 of a single run.
(e) the same for ``integrator="verlet"``.
(f) N = 10,000 and 100,000 (``bench_step.build(N)``) through the engine: ``BatchEngine.set_rate`` +
    ``step(cool, dt, sample=True)`` on a ``BatchState`` of one (the skin of a run's engine) where the
    tree has an ensemble-to-state conversion (``state_from_ensembles``), else the documented step of
    the ensemble (forces, totals, acceleration, movement, reset); ns per particle-step (median of block means).  Targets: ≤ 600 /
    ≤ 1,000 ns (current tree).

A row a tree cannot run prints "n/a".  ``--quick`` uses B = 8, shorter runs and fewer blocks
(indicative figures, ≈ 3 min); the full run takes ≈ 8 min on a 2-core host.

Usage: python benchmarks/bench_one_step.py [--baseline PATH] [--current PATH] [--quick] [--rows a b c d e f]
"""
import argparse
import concurrent.futures
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

#: the NumPy engine's figures (docs/performance.md); PARTICLESHEAR_BACKEND=numba times the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_BASELINE = os.path.normpath(os.path.join(HERE, "..", "..", "baseline-e45c1fa"))   # beside the repo
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


# ----------------------------------------------------------------------------------------- worker side
class InlineExecutor(concurrent.futures.Executor):
    """An executor that runs each task at once in this process (no pool: the law set here applies)."""

    def submit(self, fn, /, *args, **kwargs):
        fut = concurrent.futures.Future()
        try:
            fut.set_result(fn(*args, **kwargs))
        except Exception as exc:  # handed to the caller through the future
            fut.set_exception(exc)
        return fut


class Worker:
    """State of one worker process: the scene of its row and the commands that time it."""

    def __init__(self, tree):
        import particleShear
        where = os.path.realpath(particleShear.__file__)
        if not where.startswith(os.path.realpath(tree) + os.sep):
            raise RuntimeError(f"particleShear imported from {where}, not from the tree {tree}")
        self.kw = {}

    # -- set-up commands
    def setup_loop(self, N, seed, warm):
        import bench_step
        from particleShear import StressTensorEvaluation
        self.ens = bench_step.build(N, seed=seed)
        self.ev = StressTensorEvaluation(self.ens.size_x, self.ens.size_y)
        bench_step.documented_steps(self.ens, self.ev, warm)
        return {}

    def setup_engine(self, N, warm):
        import numpy as np

        import bench_step
        ens = bench_step.build(N)
        w = 2 * math.pi * bench_step.F_EXC
        cool, dt, amp = 0.99969060716623, bench_step.DT, bench_step.AMPLITUDE
        try:
            from particleShear.engine.step import BatchEngine
            try:
                from particleShear.base.engine_adapter import state_from_ensembles as make
            except ImportError:         # an older tree: the conversion was BatchState's
                from particleShear.engine.state import BatchState
                make = BatchState.from_ensembles
        except (ImportError, AttributeError):
            make = None
        if make is not None:
            try:
                from particleShear.run.batch import ENGINE_SKIN_FACTOR as skin
            except ImportError:
                skin = 0.2
            eng = BatchEngine(make([ens]), skin_factor=skin)
            s = eng.s

            def block(n):
                t0 = time.perf_counter()
                for _ in range(n):
                    eng.set_rate(np.array([amp * w * math.cos(w * float(s.t[0]))]))
                    eng.step(cool, dt, sample=True)
                return time.perf_counter() - t0
            path = f"BatchEngine of a BatchState copy, skin {skin} r_max"
        else:
            def block(n):
                t0 = time.perf_counter()
                for _ in range(n):
                    ens.setShearRate(amp * w * math.cos(w * ens.t))
                    ens.mechanical_simulation_step_calculate_forces()
                    ens.record_total_particle_forces()
                    ens.mechanical_simulation_step_calculate_acceleration(cool, dt)
                    ens.mechanical_simulation_step_calculate_movement(dt)
                    ens.reset_force()
                return time.perf_counter() - t0
            path = "the ensemble's documented step (no ensemble-to-state conversion in this tree)"
        block(warm)
        self.block = block
        return {"path": path}

    def setup_runs(self, law=None, integrator=None):
        import inspect

        from particleShear import doParticleShearSimulation
        self.kw = {}
        if law == "attr":
            from particleShear import CircleBasicElasticity, elastic_force_law_plateau
            CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
        elif law == "param":
            if "contact_law" not in inspect.signature(doParticleShearSimulation).parameters:
                return {"na": "doParticleShearSimulation has no contact_law parameter"}
            self.kw["contact_law"] = "plateau"
        if integrator is not None:
            self.kw["integrator"] = integrator
        return {}

    # -- timed commands
    def loop(self, steps):
        import bench_step
        return {"samples": bench_step.documented_steps(self.ens, self.ev, steps)}

    def engine(self, steps):
        return {"value": self.block(steps) / steps}

    def single(self, seed, kw):
        from particleShear import doParticleShearSimulation
        t0 = time.perf_counter()
        res = doParticleShearSimulation(doDrawing=False, plotStress=False, saveData=False, seed=seed,
                                        verbose=False, return_result=True, **dict(self.kw, **kw))
        wall = time.perf_counter() - t0
        return {"wall": wall, "protocol": res.timings.get("protocol", math.nan), "steps": res.N_steps}

    def series(self, B, seed, kw):
        from particleShear import doParticleShearSimulationSeries
        t0 = time.perf_counter()
        res = doParticleShearSimulationSeries(N_repetitions=B, batch_size=B, executor=InlineExecutor(), max_workers=1,
                                              seed=seed, doDrawing=False, plotStress=False, saveData=False,
                                              **dict(self.kw, **kw))
        wall = time.perf_counter() - t0
        prot = sum(r.timings.get("protocol", math.nan) for r in res)
        return {"wall": wall / len(res), "protocol": prot / len(res),
                "replica_step": prot / sum(r.N_steps for r in res)}


def worker_main(tree, cpu):
    """Serve JSON commands from stdin, one reply line each on the original stdout."""
    import warnings
    warnings.simplefilter("ignore")
    proto = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)                              # the package's prints go to the log, not the protocol
    sys.path.insert(0, HERE)
    w = None
    for line in sys.stdin:
        msg = json.loads(line)
        try:
            if msg["cmd"] == "init":
                w = Worker(tree)
                out = {}
            elif msg["cmd"] == "pin":
                if cpu is not None and hasattr(os, "sched_setaffinity"):
                    os.sched_setaffinity(0, {cpu})
                out = {}
            else:
                out = getattr(w, msg["cmd"])(**msg.get("args", {}))
        except Exception as exc:  # reported to the parent, which prints n/a or the error
            out = {"error": f"{type(exc).__name__}: {exc}"}
        proto.write(json.dumps(out) + "\n")
        proto.flush()


# ----------------------------------------------------------------------------------------- parent side
class Proc:
    """A worker process for one tree."""

    def __init__(self, label, tree, cpu):
        self.label, self.tree = label, tree
        env = dict(os.environ, PYTHONPATH=tree, PARTICLESHEAR_BENCH_WORKER="1")
        for v in THREAD_VARS:
            env[v] = "1"
        self.log = tempfile.TemporaryFile(mode="w+")
        self.p = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--worker", tree,
                                   "--cpu", "" if cpu is None else str(cpu)],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.log, text=True,
                                  env=env, cwd=tempfile.gettempdir())
        self.send("init")

    def send(self, cmd, **args):
        self.p.stdin.write(json.dumps({"cmd": cmd, "args": args}) + "\n")
        self.p.stdin.flush()

    def recv(self):
        line = self.p.stdout.readline()
        if not line:
            self.log.seek(0)
            tail = self.log.read()[-2000:]
            raise RuntimeError(f"worker of {self.label} ({self.tree}) ended:\n{tail}")
        return json.loads(line)

    def call(self, cmd, **args):
        self.send(cmd, **args)
        return self.recv()

    def close(self):
        try:
            self.p.stdin.close()
            self.p.wait(timeout=60)
        except (OSError, subprocess.TimeoutExpired):
            self.p.kill()
        self.log.close()


def pick_cpu():
    if not hasattr(os, "sched_getaffinity"):
        return None
    return min(os.sched_getaffinity(0))


class Row:
    def __init__(self, key, label, unit, target, kind):
        self.key, self.label, self.unit, self.target, self.kind = key, label, unit, target, kind
        self.value = {"baseline": None, "current": None}
        self.ratio = None


def measure(trees, cpu, setup, blocks):
    """Start one worker per tree, set both up, pin them, run ``blocks`` (list of (cmd, args)) alternately.

    Returns {tree label: list of (cmd, reply), or {"na"/"error": text}} and the set-up replies; a worker
    that dies makes the row an error for both trees (the script goes on with the next row)."""
    try:
        return _measure(trees, cpu, setup, blocks)
    except (RuntimeError, OSError, ValueError) as exc:
        return {lab: {"error": str(exc)} for lab in trees}, {lab: {} for lab in trees}


def _measure(trees, cpu, setup, blocks):
    procs = {lab: Proc(lab, path, cpu) for lab, path in trees.items()}
    try:
        for pr in procs.values():
            pr.recv()                                        # init
        for pr in procs.values():                             # both set up at once (untimed)
            pr.send(setup[0], **setup[1])
        ready = {lab: pr.recv() for lab, pr in procs.items()}
        for pr in procs.values():
            pr.call("pin")
        out = {lab: (ready[lab] if ("na" in ready[lab] or "error" in ready[lab]) else []) for lab in procs}
        for cmd, args in blocks:
            for lab, pr in procs.items():
                if isinstance(out[lab], dict):
                    continue
                rep = pr.call(cmd, **args)
                out[lab] = rep if "error" in rep else out[lab] + [(cmd, rep)]
        return out, ready
    finally:
        for pr in procs.values():
            pr.close()


def fmt(v, unit):
    if v is None:
        return "n/a"
    if unit in ("s/run",):
        return f"{v:.3f}"
    if unit == "ratio":
        return f"{v:.3f}"
    return f"{v:,.1f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default=DEFAULT_BASELINE, help=f"baseline tree (default {DEFAULT_BASELINE})")
    ap.add_argument("--current", default=os.path.dirname(HERE), help="current tree (default: this script's repo)")
    ap.add_argument("--quick", action="store_true", help="B = 8, shorter runs, fewer blocks (≈ 3 min)")
    ap.add_argument("--rows", nargs="+", default=list("abcdef"), choices=list("abcdef"))
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    ap.add_argument("--cpu", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker_main(args.worker, int(args.cpu) if args.cpu else None)
        return
    trees = {"baseline": os.path.abspath(args.baseline), "current": os.path.abspath(args.current)}
    for lab, path in trees.items():
        if not os.path.isdir(os.path.join(path, "particleShear")):
            ap.error(f"--{lab} {path!r} is not a tree with a particleShear package")
    q = args.quick
    cpu = pick_cpu()
    B = 8 if q else 32
    short = {"relative_frequency": 0.5}                  # 671 protocol steps (default 0.025: 13,439)
    print(f"issue-20 benchmark ({'quick' if q else 'full'}): baseline {trees['baseline']}, current "
          f"{trees['current']}; one thread, workers pinned to CPU {cpu}; alternating blocks, medians", flush=True)
    rows = []
    t_start = time.perf_counter()

    def report(r):
        b, c = r.value["baseline"], r.value["current"]
        ratio = (c / b) if (b and c) else None
        r.ratio = ratio
        print(f"  {r.label}: baseline {fmt(b, r.unit)} {r.unit}, current "
              f"{fmt(c, r.unit)} {r.unit}, current/baseline "
              f"{'n/a' if ratio is None else f'{ratio:.3f}'}  [{time.perf_counter() - t_start:.0f} s]", flush=True)
        rows.append(r)

    def fill(r, out, fn, quiet=False):
        for lab, res in out.items():
            if not isinstance(res, dict):
                r.value[lab] = fn(res)
            elif not quiet:
                print(f"    {lab}: n/a ({res.get('na') or res.get('error')})", flush=True)

    if "a" in args.rows:
        r = Row("a", "(a) documented step loop, N = 150", "µs/step", ("ratio", 0.6), "loop")
        nb, steps = (3, 100) if q else (6, 200)
        out, _ = measure(trees, cpu, ("setup_loop", {"N": 150, "seed": 2, "warm": 20}),
                         [("loop", {"steps": steps})] * nb)
        fill(r, out, lambda res: 1e6 * statistics.median([t for _, rep in res for t in rep["samples"]]))
        report(r)
    if "b" in args.rows:
        r = Row("b", f"(b) protocol per replica-step, B = {B}", "µs", ("ratio", 1.05), "series")
        kw = {"relative_frequency": 0.5 if q else 0.25}
        out, _ = measure(trees, cpu, ("setup_runs", {}),
                         [("series", {"B": B, "seed": 100 + i, "kw": kw}) for i in range(1 if q else 2)])
        fill(r, out, lambda res: 1e6 * statistics.median([rep["replica_step"] for _, rep in res]))
        report(r)
    if "c" in args.rows:
        kw = short if q else {}
        r = Row("c", "(c) single default run" + (" (relative_frequency 0.5)" if q else ""), "s/run",
                ("ratio", 1.05), "single")
        out, _ = measure(trees, cpu, ("setup_runs", {}),
                         [("single", {"seed": 1 + i, "kw": kw}) for i in range(1 if q else 4)])
        fill(r, out, lambda res: statistics.median([rep["wall"] for _, rep in res]))
        report(r)
    for key, name, setup in (("d", "plateau law (class attribute)", {"law": "attr"}),
                             ("d", 'plateau law (contact_law="plateau")', {"law": "param"}),
                             ("e", 'velocity Verlet (integrator="verlet")', {"integrator": "verlet"})):
        if key not in args.rows:
            continue
        n_single = 1 if q else 2
        blocks = [("single", {"seed": 1 + i, "kw": short}) for i in range(n_single)]
        blocks.append(("series", {"B": B, "seed": 200, "kw": short}))
        out, _ = measure(trees, cpu, ("setup_runs", setup), blocks)
        r1 = Row(key, f"({key}) {name}, single run", "s/run", None, "single")
        r2 = Row(key, f"({key}) {name}, batch of {B}, per run", "s/run", None, "series")
        r3 = Row(key, f"({key}) {name}, batch per run / single run", "ratio", ("abs", 0.4), "ratio")
        r4 = Row(key, f"({key}) {name}, same, protocol part only", "ratio", None, "ratio")
        def med(res, cmd, key):
            return statistics.median([rep[key] for c, rep in res if c == cmd])
        fill(r1, out, lambda res: med(res, "single", "wall"))
        fill(r2, out, quiet=True, fn=lambda res: med(res, "series", "wall"))
        fill(r3, out, quiet=True, fn=lambda res: med(res, "series", "wall") / med(res, "single", "wall"))
        fill(r4, out, quiet=True, fn=lambda res: med(res, "series", "protocol") / med(res, "single", "protocol"))
        for r in (r1, r2, r3, r4):
            report(r)
    if "f" in args.rows:
        for n, target in ((10000, 600.0), (100000, 1000.0)):
            nb, steps = ((3, 20) if q else (6, 50)) if n == 10000 else ((2, 8) if q else (4, 25))
            r = Row("f", f"(f) engine, N = {n:,}", "ns/particle-step", ("abs", target), "engine")
            out, ready = measure(trees, cpu, ("setup_engine", {"N": n, "warm": 5}),
                                 [("engine", {"steps": steps})] * nb)
            fill(r, out, lambda res, n=n: 1e9 * statistics.median([rep["value"] for _, rep in res]) / n)
            for lab in trees:
                if "path" in ready[lab]:
                    print(f"    {lab}: {ready[lab]['path']}")
            report(r)

    print(f"\nsummary ({'quick: B = 8, short runs, indicative' if q else 'full'}; "
          f"{time.perf_counter() - t_start:.0f} s)")
    print("| row | baseline | current | current / baseline | target | result |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        b, c = r.value["baseline"], r.value["current"]
        if r.target is None:
            tgt, res = "", ""
        elif r.target[0] == "ratio":
            tgt = f"current ≤ {r.target[1]} × baseline"
            res = "n/a" if r.ratio is None else ("PASS" if r.ratio <= r.target[1] else "FAIL")
        else:
            tgt = f"current ≤ {r.target[1]:g}"
            res = "n/a" if c is None else ("PASS" if c <= r.target[1] else "FAIL")
        ratio = "n/a" if r.ratio is None else f"{r.ratio:.3f}"
        print(f"| {r.label} [{r.unit}] | {fmt(b, r.unit)} | {fmt(c, r.unit)} | {ratio} | {tgt} | {res} |")


if __name__ == "__main__":
    main()
