"""Validation of every ``doParticleShearSimulation`` parameter and option before any work (docs/parameters.md).

:func:`validate_run` is the one check of a run's complete argument set; every way to start a
run (the API, a series, a batch, a sweep SPEC, the command line) goes through it, so a value
is refused with the same message whichever way it came.  Each failure raises ``ValueError``
(``TypeError`` for a wrong type) naming the parameter, its value (a huge integer abbreviated:
:func:`show_value`) and the allowed range; integers of any size are compared exactly, never
converted to float first.  Beyond the range of each value on its own, three checks of the whole run come before any work (documented, with
their limits, in ``docs/parameters.md``):

* **resolution** — the protocol resolves the excitation (at least
  :data:`MIN_STEPS_PER_PERIOD` steps per period at the reference time step);
* **constitution** — the ensemble is large enough for its cell (minimum image)
  and for the requested number of particles;
* **cost** — the number of steps and the memory of the run (ensemble, recording,
  cutting, output text) stay within documented limits and the memory available
  on this machine, read when the run is checked (:func:`available_memory`).
"""
__docformat__ = "numpy"
import itertools
import math
import numbers
import os
import tempfile

import numpy as np

from ..checks import as_float as _as_float, in_range, integer as _int, range_text, real_type, show_value
from ..engine.step import BatchEngine
from ..linkable.builders import time_steps_from_model
from ..objects.model import particle_shear_model_parameters
from ..parameters import BY_NAME, PARAMETERS, defaults as _defaults
from ..protocols import PROTOCOLS as _PROTOCOLS
from ..simulation.formats import check_output_format
from .limits import (CELL, MAX_N, MAX_SERIES_RUNS, MAX_TOTAL_STEPS, MIN_SPHERES_PER_PARTICLE,  # noqa: F401 - re-exported
                     MIN_STEPS_PER_PERIOD, MIN_STEPS_PER_PERIOD_COARSENED, SEED_LIMIT, _protocol_room)
from .sessions import _seed_sequence, check_backend, check_run_backend, contact_law_spec
from ..simulation.provenance import run_identity
from ..analysis.measures import warn_few_periods
from .guard import PARAMETER_ALIASES, RUN_PARAMETERS_DOC, UnknownParameterError, close_names
from .rheometer import PROTOCOL_DEFAULTS, _shown, check_protocol, normalize_protocol, protocol_steps

__all__ = ["validate_run", "validated_run", "RunParameters", "checked_point", "CheckedPoint", "RUN_OWN", "validate_simulation_parameters", "validate_series", "show_value", "check_seed",
           "estimate_run_cost", "available_memory", "check_folder_writable", "IMAGE_FILE_TYPES", "RENDERERS",
           "INTEGRATORS", "MIN_STEPS_PER_PERIOD", "MIN_SPHERES_PER_PARTICLE", "MAX_N", "MAX_TOTAL_STEPS",
           "MAX_SERIES_RUNS", "SEED_LIMIT", "contact_law_spec"]

#: accepted ``imageFileType`` values (the reference silently wrote PostScript for anything else)
IMAGE_FILE_TYPES = BY_NAME["imageFileType"].choices
#: accepted ``renderer`` values (None = "auto")
RENDERERS = BY_NAME["renderer"].choices
#: accepted ``integrator`` values (the engine's)
INTEGRATORS = BatchEngine.INTEGRATORS

#: upper and lower limits of the single parameters, from the parameter table
#: (:mod:`particleShear.parameters`, where each limit's reason is stated): the physical ones far
#: beyond any material yet small enough that products of them (k·τ, m·v², …) stay finite double
#: numbers; relative_viscosity, relative_transversal_link_strength and
#: interface_reenforcement_central the largest values the time-step rule integrates stably
#: (benchmarks/stable_ranges.py).  Their combinations: STIFF_VISCOUS.
UPPER = {p.name: p.high for p in PARAMETERS if p.high is not None}
LOWER = {p.name: p.low for p in PARAMETERS if p.low is not None}

#: bounds on the products of the stiffness and viscosity factors that the time-step rule integrates
#: stably (measured as :data:`UPPER`'s): rv·max(1, rts) (rv alone runs to 3.65, rts 39 at rv 0.1
#: runs: 3.9; rv 0.5 with rts 10 runs: 5; rv 3 with rts 30 diverges; 3.5 keeps below the single
#: limits) and, where the viscosities follow the reinforcement, rv·irc (irc 60 at rv 0.1 runs: 6;
#: rv 1 with irc 5 and rv 2 with irc 2.5 run; rv 3 with irc 50 diverges)
STIFF_VISCOUS = {"relative_viscosity*max(1,relative_transversal_link_strength)": 3.5,
                 "relative_viscosity*interface_reenforcement_central": 5.0}

#: memory of one sphere in a running ensemble, bytes (state rows, pair table, relations; measured
#: 6–9 kB peak per sphere at N = 2,000–20,000 with tracemalloc, rounded up)
BYTES_PER_SPHERE = 10_000
#: recording per protocol step: 5 scalars, and the (9, 2, 2) tensor history when it is kept
RECORD_BYTES_PER_STEP = 5 * 8
TENSOR_BYTES_PER_STEP = 9 * 2 * 2 * 8
#: the output table is streamed in blocks of 1,024 rows (42 columns ≈ 3.4 kB of text a row), so
#: writing needs a bounded ~3.5 MB buffer whatever the length of the run
OUTPUT_TEXT_BUFFER_BYTES = 1_024 * 3_500
#: the Voronoi cut holds ~8 float arrays of shape (N, cut_lines)
CUT_BYTES_PER_SPHERE_AND_SEED = 8 * 8
#: fraction of the available memory a run may plan to use
MEMORY_FRACTION = 0.8
#: recording per protocol step of the other protocols (docs/protocols.md): the engine's record of 5 series
#: (6 with N1 for "steady"), 8 bytes each, and as much again for the run's series, its analysis and its
#: file's columns (tracemalloc, growth of the protocol's peak per step: 76 B for creep at 5,600 → 22,400
#: steps); a sweep's steps keep the oscillatory record and its demodulation and join the steps' records
#: (185 B per step of a frequency sweep at 2,518 → 5,542 steps); rounded up.  The whole record is held
#: until the run ends.
#: Each protocol states its own (``record_bytes``, :mod:`particleShear.protocols`).
PROTOCOL_RECORD_BYTES_PER_STEP = {name: p.record_bytes for name, p in _PROTOCOLS.items() if name != "oscillatory"}


# -- single values ---------------------------------------------------------------------------------
def _range(name, v, lo=None, hi=None, lo_open=False, hi_open=False):
    """:func:`~particleShear.checks.in_range` with the run's limits of ``name`` (:data:`UPPER`, :data:`LOWER`)."""
    real_type(name, v)
    if hi is None and name in UPPER:
        hi = UPPER[name]
    if name in LOWER and (lo is None or LOWER[name] > lo):
        lo, lo_open = LOWER[name], False
    return in_range(name, v, lo, hi, lo_open, hi_open)


def _check_stiff_viscous(p):
    """Refuse combinations of viscosity and stiffness factors past :data:`STIFF_VISCOUS` (they diverge)."""
    rv, rts = float(p["relative_viscosity"]), float(p["relative_transversal_link_strength"])
    irc = float(p["interface_reenforcement_central"])
    (name_t, bound_t), (name_c, bound_c) = STIFF_VISCOUS.items()
    if rv * max(1.0, rts) > bound_t:
        raise ValueError(f"relative_viscosity={show_value(p['relative_viscosity'])} with relative_transversal_link_"
                         f"strength={show_value(p['relative_transversal_link_strength'])} is out of range: allowed "
                         f"{name_t} <= {bound_t:g} (the time-step rule diverges beyond; docs/parameters.md, Limits)")
    if not p["keep_viscosity_coefficients_constant"] and rv * irc > bound_c:
        raise ValueError(f"relative_viscosity={show_value(p['relative_viscosity'])} with interface_reenforcement_"
                         f"central={show_value(p['interface_reenforcement_central'])} is out of range: allowed "
                         f"{name_c} <= {bound_c:g} while the viscosities follow the reinforcement "
                         "(keep_viscosity_coefficients_constant=False; the time-step rule diverges beyond; "
                         "docs/parameters.md, Limits)")


def _bool(name, v):
    if not isinstance(v, (bool, np.bool_)):
        raise TypeError(f"{name}={show_value(v)} is invalid: allowed True or False")


def check_seed(name, seed):
    """Raise ValueError unless ``seed`` is None, an integer 0 <= seed < 2**128, or a numpy seed object.

    2**128 bounds the entropy numpy draws itself (``SeedSequence().entropy``); a seed below it is
    recorded (result, results table, output header) as at most 39 digits.

    Parameters
    ----------
    name : str
        The parameter name used in the message (``"seed"``).
    seed : None, int, numpy.random.SeedSequence, numpy.random.Generator or numpy.random.BitGenerator
        The seed to check.

    Raises
    ------
    ValueError
        For anything else (a negative or too large integer, a bool, a float, a string, …).
    """
    if seed is None or isinstance(seed, (np.random.SeedSequence, np.random.Generator, np.random.BitGenerator)):
        return
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, numbers.Integral) or not 0 <= seed < SEED_LIMIT:
        raise ValueError(f"{name}={show_value(seed)} is invalid: allowed None, an integer 0 <= value < 2**128, "
                         "a numpy SeedSequence or Generator")


# -- machine ---------------------------------------------------------------------------------------
def available_memory():
    """Memory (bytes) a new allocation can get now, or None when it cannot be read.

    ``MemAvailable`` of ``/proc/meminfo`` (Linux: free memory plus reclaimable caches), else the
    free physical pages of ``os.sysconf``; read at every call, so the check follows the machine.
    """
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def check_folder_writable(name, folder):
    """Raise ValueError unless ``folder`` is an existing directory in which a file can be created.

    Creates and removes one empty temporary file (``os.access`` is not enough: it says yes to root
    for read-only file systems such as ``/proc``).

    Parameters
    ----------
    name : str
        The parameter name used in the message (e.g. ``"root_folder"``).
    folder : str or os.PathLike
        The folder to probe.

    Raises
    ------
    ValueError
        If ``folder`` is not an existing directory or a file cannot be created there.
    """
    if not os.path.isdir(folder):
        raise ValueError(f"{name}={str(folder)!r} is invalid: needs an existing output folder (no such directory)")
    try:
        fd, path = tempfile.mkstemp(prefix=".particleShear-write-test-", dir=folder)
    except OSError as exc:
        raise ValueError(f"{name}={str(folder)!r} is invalid: the folder is not writable (creating a file "
                         f"there failed: {exc.strerror or exc})") from None
    os.close(fd)
    os.remove(path)


def _bytes(n):
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024
    return f"{n:.3g} PiB"  # pragma: no cover


# -- keyword-only options --------------------------------------------------------------------------
def _check_keyword_options(p):
    """The keyword-only options of one run (``p``: every argument, defaults filled in), in signature order."""
    for name in ("return_result", "verbose"):
        _bool(name, p[name])
    progress = p["progress"]
    if progress is not None and not callable(progress):
        raise TypeError(f"progress={progress!r} is invalid: allowed None or a callable "
                        "progress(phase, step, total, elapsed_s)")
    for name in ("correct_drift_sign", "reference_header"):
        _bool(name, p[name])
    renderer = p["renderer"]
    if renderer is not None and (not isinstance(renderer, str) or renderer.lower() not in RENDERERS):
        raise ValueError(f"renderer={renderer!r} is invalid: allowed one of {RENDERERS} or None")
    time_step_factor = p["time_step_factor"]
    if isinstance(time_step_factor, (bool, np.bool_)) or not isinstance(time_step_factor, numbers.Real):
        raise TypeError(f"time_step_factor={show_value(time_step_factor)} is invalid: allowed a real number")
    x = _as_float(time_step_factor)
    if x is None or not (math.isfinite(x) and x > 0):
        raise ValueError(f"time_step_factor={show_value(time_step_factor)} is out of range: allowed a finite "
                         "value > 0")
    integrator = p["integrator"]
    if not isinstance(integrator, str) or integrator not in INTEGRATORS:
        raise ValueError(f"integrator={integrator!r} is out of range: allowed one of {INTEGRATORS}")
    _bool("stability_guard", p["stability_guard"])
    _bool("stroboscopic", p.get("stroboscopic", False))
    _bool("saveOutputMovie", p["saveOutputMovie"])
    check_output_format(p["output_format"])
    _bool("strict_io", p["strict_io"])
    check_backend(p["backend"])
    contact_law_spec(p)


# -- cost ------------------------------------------------------------------------------------------
def estimate_run_cost(p):
    """Steps and memory a run will need, computed from its parameters without building anything.

    Uses the model constants (eq. S1-8), the time-step rule and the constitution schedule of
    the builder, the protocol length ``(pre + periods + post)/f/dt`` and what is kept or saved.
    The protocol step count is the run's own (``int`` of ``protocol_steps``; for another protocol
    than "oscillatory" its own steps, a sweep's summed over its steps, and their record at
    :data:`PROTOCOL_RECORD_BYTES_PER_STEP`); pre-equilibration and constitution counts are upper
    bounds.

    Parameters
    ----------
    p : dict
        Every argument of ``doParticleShearSimulation`` by name (already range-checked), optionally
        with ``time_step_factor``.

    Returns
    -------
    dict
        ``dt`` (s, protocol time step), ``f`` (Hz), ``steps_per_period`` (at the reference time
        step), ``protocol_steps``, ``pre_equilibration_steps``, ``constitution_steps``,
        ``total_steps``, ``memory``: bytes per item ("ensemble", "recording", "cutting",
        "output_text") and their "total", ``protocol`` and ``protocol_detail`` (the steps of
        :func:`~particleShear.run.rheometer.protocol_steps`; None for "oscillatory").
    """
    N = int(p["N"])
    bf, A, mu = float(p["bimodal_factor"]), float(p["theAmplitude"]), float(p["theMu"])
    rv, rts = float(p["relative_viscosity"]), float(p["relative_transversal_link_strength"])
    factor = float(p.get("time_step_factor", 1.0))
    model = particle_shear_model_parameters(CELL, CELL, N, p["packing_fraction"], p["Young_modulus_spheres"],
                                            p["density"], bimodal_factor=1)
    tau = model.time_constant
    dt_ref, dt_max = time_steps_from_model(tau, bf, mu, rts, A, rv)
    f = float(p["relative_frequency"]) / tau
    steps_per_period = 1.0 / (f * dt_ref)  # = τ/(f·τ·dt): independent of N, E and density
    dt = dt_ref * factor
    n_periods = float(p["pre_periods"]) + float(p["periods"]) + float(p["post_periods"])
    protocol = n_periods * steps_per_period / factor
    proto = p.get("protocol", "oscillatory")
    detail = None
    if proto != "oscillatory":   # the protocol's own steps (a sweep: every step's), not the oscillation's
        detail = protocol_steps(normalize_protocol({**PROTOCOL_DEFAULTS, "time_step_factor": 1.0, **p}))
        protocol = float(sum(detail["segments"]) if "segments" in detail else detail["steps"])
    # fixed-plate pre-equilibration: N/2 steps per halving level from dt_max down to dt, then 3N steps,
    # N = 25·F with the adjustment factor of the simulation, bounded here by its largest value:
    # F ≤ 1.5·2·2 (μ) · 2 (rv) = 24, times (1 − (log10 A + 2))·2 at small amplitudes
    levels = max(0, math.ceil(math.log2(max(dt_max * factor, 1e-300) / dt))) if dt_max * factor > dt else 0
    F = 48.0 * max(1.0, 1 - (math.log10(A) + 2)) if A <= 0.01 else 24.0
    n_pre = 25 * F
    pre = (levels * n_pre / 2 + 3 * n_pre)
    # constitution: at most ~3,600 block steps, each block running (levels + 2) times
    levels_c = max(0, math.ceil(math.log2(0.25 * tau / bf / dt_ref))) if 0.25 * tau / bf > dt_ref else 0
    constitution = 3600 * (levels_c + 2)
    saving = bool(p.get("saveData"))
    tensors = saving and bool(p.get("saveStressTensorData", True))
    cut = int(p["cut_lines"]) if (p.get("do_permanent_links", True) and p.get("doCutByTriangulation", True)) else 0
    memory = {
        "ensemble": N * BYTES_PER_SPHERE,
        "recording": protocol * (PROTOCOL_RECORD_BYTES_PER_STEP[proto] if detail is not None else
                                 RECORD_BYTES_PER_STEP + (TENSOR_BYTES_PER_STEP if tensors else 0)),
        "cutting": float(N) * cut * CUT_BYTES_PER_SPHERE_AND_SEED,
        "output_text": OUTPUT_TEXT_BUFFER_BYTES if tensors and detail is None else 0.0,
    }
    memory["total"] = sum(memory.values())
    return {"dt": dt, "f": f, "steps_per_period": steps_per_period, "protocol_steps": protocol,
            "pre_equilibration_steps": pre, "constitution_steps": constitution,
            "total_steps": protocol + pre + constitution, "memory": memory, "protocol": proto,
            "protocol_detail": detail}


def _protocol_culprit(p, cost, steps_ok):
    """(name, allowed) of the parameter that makes the protocol longer than ``steps_ok`` steps.

    ``time_step_factor`` when the run would fit at factor 1, ``relative_frequency`` when it would fit
    at the default 0.025, else the largest of pre_periods / periods / post_periods.
    """
    if cost.get("protocol_detail") is not None:
        return _protocol_room(p, cost["protocol_detail"], steps_ok)
    factor = float(p.get("time_step_factor", 1.0))
    spp = cost["steps_per_period"]
    n_periods = float(p["pre_periods"]) + float(p["periods"]) + float(p["post_periods"])
    if factor < 1 and n_periods * spp <= steps_ok:
        return "time_step_factor", f"time_step_factor >= {n_periods * spp / steps_ok:.4g}"
    rf = float(p["relative_frequency"])
    if rf < 0.025 and n_periods * spp * rf / 0.025 / factor <= steps_ok:
        return "relative_frequency", f"relative_frequency >= {n_periods * spp * rf / factor / steps_ok:.4g}"
    name = max(("periods", "pre_periods", "post_periods"), key=lambda n: float(p[n]))
    room = max(0.0, steps_ok * factor / spp - (n_periods - float(p[name])))
    return name, f"{name} <= {room:.4g}"


def _check_constitution(p):
    """``N`` and ``cut_lines`` within their ranges, the lower limit of ``N`` set by the cell and the
    upper limit of ``cut_lines`` by ``N``: one range rule per parameter, one message.

    ``N`` is at least 2, and large enough that the largest spheres are smaller than a quarter of
    the cell (minimum image: every pair interacts through one image only); ``cut_lines`` is at
    most :data:`MAX_N`, and with permanent links few enough that each particle holds at least
    :data:`MIN_SPHERES_PER_PARTICLE` spheres.  ``packing_fraction`` and ``bimodal_factor`` are
    checked before.
    """
    phi, bf = float(p["packing_fraction"]), float(p["bimodal_factor"])
    # r_large² = L²·φ·2·max(bf, 1/bf) / (N π (bf + 1/bf)) < L²/16  ⇔  N > 32 φ max(bf, 1/bf) / (π (bf + 1/bf))
    n_min = max(2, math.floor(32 * phi * max(bf, 1 / bf) / (math.pi * (bf + 1 / bf))) + 1)
    why = "" if n_min == 2 else (
        f" for packing_fraction={show_value(p['packing_fraction'])} and bimodal_factor={show_value(p['bimodal_factor'])}: "
        f"the largest spheres must be smaller than a quarter of the {CELL:g} µm cell for each pair to interact "
        "through one image only (or a smaller packing_fraction)")
    N = _int("N", p["N"], n_min, MAX_N, why=why)
    cut_max, why = MAX_N, ""      # never more particles (or cuts) than a run has spheres
    if p["do_permanent_links"]:
        if p["doCutByTriangulation"]:
            kind = "particle (Voronoi cell)"
            cut_max = max(1, N // MIN_SPHERES_PER_PARTICLE)
        else:
            # an arrangement of L lines cuts the plane into at most 1 + L(L+1)/2 pieces
            kind = "piece of the straight cuts (at most 1 + L(L+1)/2 pieces)"
            cut_max = max(1, int((math.sqrt(1 + 8 * (N / MIN_SPHERES_PER_PARTICLE - 1)) - 1) / 2) if N >= 6 else 1)
        why = (f" for N={show_value(p['N'])}: each {kind} must hold at least {MIN_SPHERES_PER_PARTICLE} spheres "
               "(more with a larger N; cut_lines=0: bulk gel)")
    _int("cut_lines", p["cut_lines"], 0, cut_max, why=why)


def _check_cost(p):
    """Resolution, step count and memory of the whole run, before any work."""
    cost = estimate_run_cost(p)
    factor = float(p.get("time_step_factor", 1.0))
    spp = cost["steps_per_period"]
    rf = float(p["relative_frequency"])
    if spp < MIN_STEPS_PER_PERIOD:
        raise ValueError(
            f"relative_frequency={show_value(p['relative_frequency'])} is out of range: the protocol would resolve an "
            f"excitation period with {spp:.3g} steps, fewer than {MIN_STEPS_PER_PERIOD}; allowed "
            f"relative_frequency <= {rf * spp / MIN_STEPS_PER_PERIOD:.3g} for these parameters")
    if spp / factor < MIN_STEPS_PER_PERIOD_COARSENED:
        raise ValueError(
            f"time_step_factor={show_value(p.get('time_step_factor'))} is out of range: it leaves "
            f"{spp / factor:.3g} steps per excitation period, fewer than {MIN_STEPS_PER_PERIOD_COARSENED}; allowed "
            f"time_step_factor <= "
            f"{spp / MIN_STEPS_PER_PERIOD_COARSENED:.3g} at relative_frequency={show_value(p['relative_frequency'])}")
    if cost["total_steps"] > MAX_TOTAL_STEPS:
        other = cost["total_steps"] - cost["protocol_steps"]
        name, allowed = _protocol_culprit(p, cost, MAX_TOTAL_STEPS - other)
        if cost.get("protocol_detail") is not None:
            raise ValueError(
                f"{name}={_shown(p[name])} is out of range: the run would take {cost['total_steps']:.3g} steps, "
                f"more than the limit of {MAX_TOTAL_STEPS:.0e}; allowed {allowed} (flag --{name.replace('_', '-')})")
        raise ValueError(
            f"{name}={show_value(p[name])} is out of range: the run would take {cost['total_steps']:.3g} steps, "
            f"more than the limit of {MAX_TOTAL_STEPS:.0e} ({spp / factor:.4g} steps per excitation period); "
            f"allowed {allowed}")
    avail = available_memory()
    if avail is None:
        return cost
    mem = cost["memory"]
    budget = MEMORY_FRACTION * avail
    if mem["total"] <= budget:
        return cost
    parts = {"ensemble": mem["ensemble"], "cutting": mem["cutting"],
             "recording": mem["recording"] + mem["output_text"]}
    item = max(parts, key=parts.get)
    need = (f"needs ~{_bytes(parts[item])} ({_bytes(mem['total'])} for the whole run), more than "
            f"{MEMORY_FRACTION:.0%} of the {_bytes(avail)} of memory available")
    if item == "ensemble":
        allowed = int(budget / BYTES_PER_SPHERE)
        raise ValueError(f"N={show_value(p['N'])} is out of range: allowed {range_text(2, allowed, integers=True)} "
                         f"on this machine: the ensemble {need} ({_bytes(BYTES_PER_SPHERE)} per sphere)")
    if item == "cutting":
        allowed = int(budget / (int(p["N"]) * CUT_BYTES_PER_SPHERE_AND_SEED))
        raise ValueError(f"cut_lines={show_value(p['cut_lines'])} is out of range: allowed "
                         f"{range_text(0, allowed, integers=True)} for N={show_value(p['N'])} on this machine: the "
                         f"Voronoi cut {need}")
    per_step = mem["recording"] / max(cost["protocol_steps"], 1.0)
    fixed = mem["ensemble"] + mem["cutting"] + mem["output_text"]  # the streamed output's buffer does not grow
    name, allowed = _protocol_culprit(p, cost, max(0.0, (budget - fixed) / per_step))
    hint = " (or saveStressTensorData=False)" if mem["output_text"] else ""
    what, flag = "protocol steps", ""
    if cost.get("protocol_detail") is not None:
        what = f"protocol steps of protocol={p['protocol']!r} ({per_step:.3g} B per step)"
        flag, name_value = f" (flag --{name.replace('_', '-')})", _shown(p[name])
    else:
        name_value = show_value(p[name])
    raise ValueError(f"{name}={name_value} is out of range: recording {cost['protocol_steps']:.3g} "
                     f"{what} {need}; allowed {allowed} on this machine{hint}{flag}")


# -- the whole call --------------------------------------------------------------------------------
def validate_run(params):
    """Check the complete argument set of one ``doParticleShearSimulation`` call before any work.

    The one validation of a run: :func:`~particleShear.run.api.doParticleShearSimulation`, every
    run of :func:`~particleShear.run.api.doParticleShearSimulationSeries` (all of them before the
    first starts), :func:`~particleShear.run.batch.run_batch`, the runs of a sweep SPEC
    (:func:`particleShear.sweep.spec.expand_runs`) and the command line all call it, so a value is
    refused the same way, with the same message, whichever way it came.  In order: the names,
    the keyword-only options (including ``output_format``, ``strict_io``, ``saveOutputMovie`` and
    the usability of ``backend``), every single value (type, range — an integer of any size is
    compared exactly, never converted first), the output folder and ``seed``, then the
    constitution (minimum image, spheres per particle), the resolution, the step count and the
    memory of the run, the writability of the output folder (only when something is saved), the
    movie-needs-snapshots rule and last whether the engine measures a run with a ``backend`` other
    than "numpy".  Limits: ``docs/parameters.md``.

    Parameters
    ----------
    params : dict
        Arguments of one call by name: the reference parameters and the keyword-only options
        (``return_result``, ``verbose``, ``progress``, ``correct_drift_sign``, ``reference_header``,
        ``renderer``, ``time_step_factor``, ``integrator``, ``stability_guard``, ``saveOutputMovie``,
        ``output_format``, ``strict_io``, ``backend``, ``contact_law``, ``plateau_begin``,
        ``plateau_end``, ``plateau_slope``); missing ones take the defaults of the
        signature of ``doParticleShearSimulation``.  Not modified.

    Returns
    -------
    dict
        The cost estimate of :func:`estimate_run_cost` (steps and memory of the run).

    Raises
    ------
    TypeError
        A value of the wrong type (a boolean that is not a bool, a non-callable ``progress``, a
        string for a number, …).
    ValueError
        An unknown parameter name (:class:`~particleShear.run.guard.UnknownParameterError`, naming
        the closest parameters), a value out of range or a run beyond a limit; the message
        names the parameter, its value (a huge integer abbreviated, :func:`show_value`) and what
        would be allowed.
    ImportError
        ``output_format="parquet"`` without pyarrow (the message names the extra to install).

    Warns
    -----
    particleShear.analysis.measures.MeasurementWarning
        When ``periods`` measures fewer than 2 whole excitation periods (no standard error).
    """
    return _checked(params)[1]


def _check_root_folder(p):
    """Check ``p["root_folder"]`` (type; an existing folder where the run writes) and return what writes there.

    The writability probe (:func:`check_folder_writable`) is the caller's, when the list is not empty.
    """
    root = p["root_folder"]
    if not isinstance(root, (str, os.PathLike)):
        raise TypeError(f"root_folder={show_value(root)} is invalid: allowed a path string")
    wants = [n + "=True" for n in ("saveData", "saveOutputImages") if p[n]]
    if wants and not root:
        raise ValueError(f"root_folder={root!r} is invalid: {' and '.join(wants)} needs an existing output folder")
    if wants and not os.path.isdir(root):
        raise ValueError(f"root_folder={root!r} is invalid: {' and '.join(wants)} needs an existing output folder "
                         "(no such directory)")
    return wants


def _checked(params):
    """:func:`validate_run`'s checks; returns ``(p, cost)``: the complete, normalized arguments the
    checks read (defaults filled in, :func:`~particleShear.run.rheometer.normalize_protocol` applied)
    and the cost estimate."""
    defaults = _defaults()
    unknown = sorted(set(params) - set(defaults))
    if unknown:
        near = {n: close_names(n, list(defaults), hints=PARAMETER_ALIASES) for n in unknown}
        guess = "; ".join(f"{n}: did you mean {' or '.join(s)}?" for n, s in near.items() if s)
        raise UnknownParameterError(f"unknown parameters {unknown}{': ' + guess if guess else ''} (allowed the "
                                    f"keywords of doParticleShearSimulation: {RUN_PARAMETERS_DOC})",
                                    name=unknown[0], suggestions=near[unknown[0]])
    p = dict(defaults, **params)
    _check_keyword_options(p)
    for par in PARAMETERS:          # the 1.0.2 booleans (the options' types: _check_keyword_options)
        if par.kind == "bool" and not par.keyword_only:
            _bool(par.name, p[par.name])
    for par in PARAMETERS:          # every single value with a range or a set of choices in the table
        if par.has_range:
            in_range(par.name, p[par.name], par.low, par.high, par.low_open, par.high_open)
        elif par.choices and not par.keyword_only and (not isinstance(p[par.name], str)
                                                        or p[par.name] not in par.choices):
            raise ValueError(f"{par.name}={show_value(p[par.name])} is invalid: allowed one of {par.choices}")
    _check_constitution(p)    # N and cut_lines: ranges that depend on the cell and on N
    _check_stiff_viscous(p)
    wants = _check_root_folder(p)
    check_seed("seed", p["seed"])
    check_protocol(p)             # the protocol's own parameters and steps (docs/protocols.md)
    p = normalize_protocol(p)     # a sweep is constituted for its first value
    cost = _check_cost(p)
    if wants:
        check_folder_writable("root_folder", p["root_folder"])
    if p["saveOutputMovie"] and not p["saveOutputImages"]:
        raise ValueError("saveOutputMovie=True is invalid with saveOutputImages=False: the movie is made of "
                         "the snapshots (set saveOutputImages=True and a root_folder)")
    check_run_backend(p)   # another backend than NumPy only for runs the engine measures
    if p["protocol"] == "oscillatory" or _PROTOCOLS[p["protocol"]].segmented:
        warn_few_periods(p["periods"])   # valid, but fewer than 2 whole periods give no error bar
    return p, cost


class _FrozenArguments(dict):
    """A ``dict`` of checked arguments whose items cannot change (base of :class:`RunParameters` and
    :class:`CheckedPoint`): a value changed after the check would be a value nobody checked."""

    __slots__ = ()

    def _immutable(self, *args, **kwargs):
        """Refused: the checked arguments of a run do not change.

        Parameters
        ----------
        *args, **kwargs
            Those of the ``dict`` method; ignored.

        Raises
        ------
        TypeError
            Always.
        """
        raise TypeError(f"{type(self).__name__} is immutable: the validated arguments of a run do not change "
                        "(change a copy, dict(run), and validate it again)")

    __setitem__ = __delitem__ = __ior__ = clear = pop = popitem = setdefault = update = _immutable


class RunParameters(_FrozenArguments):
    """The complete, validated arguments of one run, immutable: what travels from the check to the engine.

    Made only by :func:`validated_run`, once per run (or, for the runs of a checked sweep point, by
    :meth:`CheckedPoint.run`), so that nothing below the check validates,
    completes, normalizes or hashes the arguments again: the sessions and the simulation object
    read their values from it by the names of the parameter table (:mod:`particleShear.parameters`), the
    constitution from the ensemble's recipe made from it
    (:class:`~particleShear.linkable.builders.EnsembleRecipe`), and the run's identity and seed are the ones computed here.
    A ``dict`` (read like the keyword dict it replaces, ``json``-able, ``dict(run)`` a plain copy)
    whose items cannot change: a value changed after the check would be a value nobody checked.

    Parameters
    ----------
    values : dict
        The complete, normalized arguments (taken as they are).
    run_id : str
        :func:`~particleShear.simulation.provenance.run_identity` of the arguments and the seed.
    seed_sequence : numpy.random.SeedSequence or None
        The run's seed sequence (None when ``seed`` is a Generator or a BitGenerator).
    generator : numpy.random.Generator
        The generator of every random choice of the run, made from ``seed_sequence`` (or ``seed``).
    cost : dict
        The cost estimate of :func:`estimate_run_cost` (steps and memory).
    """

    __slots__ = ("run_id", "seed_sequence", "generator", "cost")

    def __init__(self, values, run_id, seed_sequence, generator, cost):
        dict.__init__(self, values)
        self.run_id, self.seed_sequence, self.generator, self.cost = run_id, seed_sequence, generator, cost

    def __reduce__(self):
        # a plain dict's pickling sets the items one by one (refused here): rebuild from the values
        return type(self), (dict(self), self.run_id, self.seed_sequence, self.generator, self.cost)

    @property
    def seed_entropy(self):
        """``SeedSequence.entropy`` of the run (None without a seed sequence): part of its identity."""
        return None if self.seed_sequence is None else self.seed_sequence.entropy

    @property
    def spawn_key(self):
        """``SeedSequence.spawn_key`` of the run as a tuple (empty without a seed sequence)."""
        return () if self.seed_sequence is None else tuple(self.seed_sequence.spawn_key)


def _identified(p, cost, run_id=None):
    """:class:`RunParameters` of the checked arguments ``p``: seeded from ``p["seed"]`` and identified
    (:func:`~particleShear.simulation.provenance.run_identity`, unless ``run_id`` is given)."""
    ss, rng = _seed_sequence(p["seed"])
    if run_id is None:
        entropy, spawn_key = (None, ()) if ss is None else (ss.entropy, tuple(ss.spawn_key))
        run_id = run_identity(p, entropy, spawn_key)
    return RunParameters(p, run_id, ss, rng, cost)


def validated_run(params):
    """Check one run's arguments (:func:`validate_run`) and return them as :class:`RunParameters`.

    The one place where a run's arguments are checked, completed, normalized, seeded and
    identified: every way to measure (:func:`~particleShear.run.api.doParticleShearSimulation`,
    :func:`~particleShear.run.batch.run_batch`, a series) calls it once per run and hands
    the result down unchanged, so the validation, the run identity and the parameter dict are
    each made once per run.  A sweep checks each point once (:func:`checked_point`) and makes its
    runs from it (:meth:`CheckedPoint.run`).

    Parameters
    ----------
    params : dict
        As for :func:`validate_run`.

    Returns
    -------
    RunParameters
        The complete arguments (defaults filled in, a sweep protocol's first value put in), the
        run id, the seed sequence and generator, and the cost estimate.

    Raises
    ------
    TypeError, ValueError, ImportError
        As :func:`validate_run`.
    """
    return _identified(*_checked(params))


#: the arguments in which the runs of one sweep point differ (where their files go, their seed, the
#: console and the return value): a :class:`CheckedPoint` sets them per run
RUN_OWN = ("root_folder", "seed", "return_result", "verbose")


class CheckedPoint(_FrozenArguments):
    """The complete, validated arguments of a sweep point: every run of it but :data:`RUN_OWN`, immutable.

    Made by :func:`checked_point`, once per point; :meth:`run` makes each run's
    :class:`RunParameters` from it, checking only the values the run sets, so a sweep run is
    validated once (with its point) and its run id is the one the sweep computed.

    Parameters
    ----------
    values : dict
        The complete, normalized arguments (taken as they are).
    cost : dict
        The cost estimate of :func:`estimate_run_cost` (steps and memory): a run's, whatever its
        :data:`RUN_OWN` values.
    """

    __slots__ = ("cost",)

    def __init__(self, values, cost):
        dict.__init__(self, values)
        self.cost = cost

    def __reduce__(self):
        return type(self), (dict(self), self.cost)

    def run(self, root_folder, seed, return_result, verbose, run_id=None):
        """One run of this point: its :class:`RunParameters`, the point's values not checked again.

        ``root_folder``, ``seed``, ``return_result`` and ``verbose`` are checked as
        :func:`validate_run` checks them (the folder exists and is writable where the run writes);
        the result equals ``validated_run(dict(point, root_folder=..., seed=..., ...))``.

        Parameters
        ----------
        root_folder : str or os.PathLike
            Where the run writes ("" when it writes nothing).
        seed : None, int, numpy.random.SeedSequence or numpy.random.Generator
            The run's seed.
        return_result, verbose : bool
            As for :func:`~particleShear.run.api.doParticleShearSimulation`.
        run_id : str, optional
            The run id when the caller has computed it
            (:func:`~particleShear.simulation.provenance.run_identity` of the point and the seed,
            e.g. a sweep's :class:`~particleShear.sweep.spec.SweepRun`); default: computed here.

        Returns
        -------
        RunParameters

        Raises
        ------
        TypeError, ValueError
            As :func:`validate_run`, for one of the values set here.
        """
        p = dict(self, root_folder=root_folder, seed=seed, return_result=return_result, verbose=verbose)
        for name in ("return_result", "verbose"):
            _bool(name, p[name])
        if _check_root_folder(p):
            check_folder_writable("root_folder", root_folder)
        check_seed("seed", seed)
        return _identified(p, self.cost, run_id)


def checked_point(params):
    """Check the arguments of a sweep point (:func:`validate_run`) and return them as :class:`CheckedPoint`.

    Parameters
    ----------
    params : dict
        As for :func:`validate_run` (its :data:`RUN_OWN` values those of the check only: each run
        sets its own, :meth:`CheckedPoint.run`).

    Returns
    -------
    CheckedPoint

    Raises
    ------
    TypeError, ValueError, ImportError
        As :func:`validate_run`.
    """
    p, cost = _checked(params)
    return CheckedPoint(p, cost)


#: the former name of :func:`validate_run` (the same function)
validate_simulation_parameters = validate_run


def validate_series(N_repetitions, amplitudes, mu, do_bulk_control, do_uncrosslinked_control,
                    do_non_frictional_control):
    """Check the grid of a series before any job is built; returns (amplitudes, mu) as lists.

    The series has ``N_repetitions · len(amplitudes) · len(mu) · (1 + controls)`` runs, at most
    :data:`MAX_SERIES_RUNS`.

    Parameters
    ----------
    N_repetitions : int
        Repetitions of each (amplitude, μ) point, 0 … :data:`MAX_SERIES_RUNS`.
    amplitudes : iterable of float
        Strain amplitudes, 1 … :data:`MAX_SERIES_RUNS` values (read at most that many + 1).
    mu : iterable of float
        Friction coefficients, 1 … :data:`MAX_SERIES_RUNS` values.
    do_bulk_control : bool
        Add a crosslinked run without cuts (bulk) per point.
    do_uncrosslinked_control : bool
        Add a run without permanent links per point.
    do_non_frictional_control : bool
        Add a run with μ = 0 per point.

    Returns
    -------
    tuple of list
        ``(amplitudes, mu)`` as lists.

    Raises
    ------
    TypeError, ValueError
        A control flag that is not a bool, ``amplitudes``/``mu`` not a non-empty list, or more
        than :data:`MAX_SERIES_RUNS` runs in all (the message names the parameter).
    """
    for name, v in (("do_bulk_control", do_bulk_control), ("do_uncrosslinked_control", do_uncrosslinked_control),
                    ("do_non_frictional_control", do_non_frictional_control)):
        _bool(name, v)
    n_rep = _int("N_repetitions", N_repetitions, 0, MAX_SERIES_RUNS)
    lists = []
    for name, v in (("amplitudes", amplitudes), ("mu", mu)):
        if isinstance(v, (str, bytes)) or not hasattr(v, "__iter__"):
            raise TypeError(f"{name}={v!r} is invalid: allowed a non-empty list of numbers")
        values = list(itertools.islice(v, MAX_SERIES_RUNS + 1))  # bounded, even for an endless iterator
        if not 1 <= len(values) <= MAX_SERIES_RUNS:
            raise ValueError(f"{name} has {len(values):,}{'+' if len(values) > MAX_SERIES_RUNS else ''} values: "
                             f"allowed 1 <= len({name}) <= {MAX_SERIES_RUNS:,}")
        lists.append(values)
    per_point = 1 + sum(bool(c) for c in (do_bulk_control, do_uncrosslinked_control, do_non_frictional_control))
    runs = n_rep * len(lists[0]) * len(lists[1]) * per_point
    if runs > MAX_SERIES_RUNS:
        raise ValueError(f"N_repetitions={show_value(N_repetitions)} with {len(lists[0])} amplitudes, "
                         f"{len(lists[1])} mu values and {per_point} runs per point is a series of {runs:,} runs: "
                         f"allowed at most "
                         f"{MAX_SERIES_RUNS:,} runs (N_repetitions <= "
                         f"{MAX_SERIES_RUNS // (len(lists[0]) * len(lists[1]) * per_point)})")
    return lists[0], lists[1]
