"""Campaigns: resumable parameter sweeps with a results table (docs/sweeps.md).

``run_sweep(SPEC, DIR)`` / ``python -m particleShear sweep SPEC --out DIR`` run every
combination of a SPEC's [grid] and [[zip]] lists × [seeds] repetitions, one results row per
run in ``DIR/results.csv``, resumable after any interruption; ``load_results(DIR)`` reads it back
typed by its schema (``DIR/results.schema.json``).
"""
__docformat__ = "numpy"
from ..simulation.provenance import run_identity
from .spec import SweepRun, SweepSpec, expand_runs, load_spec, parse_spec
from .runner import Sweep, SweepOutcome, run_sweep
from .schema import load_results

__all__ = ["run_sweep", "load_results", "Sweep", "SweepOutcome", "SweepSpec", "SweepRun", "load_spec", "parse_spec",
           "expand_runs", "run_identity"]
