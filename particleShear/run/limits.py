"""The limits a run is checked against (docs/parameters.md): resolution, size, steps and seeds, and the
parameter of another protocol than "oscillatory" that makes it too long.

:mod:`particleShear.run.validation` checks a run against them (and re-exports them); the rheometer's
protocols (:mod:`particleShear.run.rheometer`) check their own steps against the same limits.
"""
__docformat__ = "numpy"

__all__ = ["CELL", "MIN_STEPS_PER_PERIOD", "MIN_STEPS_PER_PERIOD_COARSENED", "MIN_SPHERES_PER_PARTICLE", "MAX_N",
           "MAX_TOTAL_STEPS", "MAX_SERIES_RUNS", "SEED_LIMIT"]

#: cell of every run (µm)
CELL = 500.0
#: fewest protocol steps per excitation period at the reference time step: the demodulation
#: integrates one sine period with the rectangle rule, whose error on G′, G″ is O(1/n²)
#: (~1e-4 relative at n = 100), and the explicit step stays far below the period
MIN_STEPS_PER_PERIOD = 100
#: fewest protocol steps per period that a coarsened time step (``time_step_factor`` > 1) may
#: leave: below 2 samples a period the excitation cannot be represented at all (Nyquist)
MIN_STEPS_PER_PERIOD_COARSENED = 2
#: fewest spheres per particle of a cut gel (mean): fewer than three bonded discs have no area
#: and no shear rigidity of their own
MIN_SPHERES_PER_PARTICLE = 3
#: most spheres of one run (constitution cost grows faster than N; ~10 kB each)
MAX_N = 1_000_000
#: most integration steps of one run (constitution + pre-equilibration + protocol)
MAX_TOTAL_STEPS = 10 ** 9
#: most runs of one series
MAX_SERIES_RUNS = 100_000
#: integer seeds are below this bound (the 128 bits of entropy numpy draws for a fresh SeedSequence)
SEED_LIMIT = 2 ** 128


def _protocol_room(p, detail, steps_ok):
    """(name, allowed) of the parameter of another protocol than "oscillatory" that makes it longer
    than ``steps_ok`` steps: ``total_strain`` (steady), ``hold_time`` (relaxation, creep), the
    largest of pre_periods / periods / post_periods (sweeps)."""
    proto = p["protocol"]
    dtr = detail["dt_over_tau"]
    if proto == "steady":
        name, room = "total_strain", steps_ok * float(p["relative_rate"]) * dtr
    elif proto == "creep":
        name, room = "hold_time", steps_ok * dtr
    elif proto == "relaxation":
        name, room = "hold_time", (steps_ok - 1 - detail["ramp"]) * dtr
        if room <= 0:
            name, room = "ramp_time", (steps_ok - 1) * dtr
    else:
        n_periods = float(p["pre_periods"]) + float(p["periods"]) + float(p["post_periods"])
        per_period = sum(detail["segments"]) / n_periods      # steps of one period of every step
        name = max(("periods", "pre_periods", "post_periods"), key=lambda n: float(p[n]))
        room = steps_ok / max(per_period, 1e-300) - (n_periods - float(p[name]))
        if room <= 0:
            name = "sweep_amplitudes" if proto == "amplitude_sweep" else "sweep_frequencies"
            return name, "fewer or shorter steps"
    return name, f"{name} <= {max(room, 0.0):.4g}"
