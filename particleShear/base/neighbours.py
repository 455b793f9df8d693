"""Pair table and O(N) neighbour search, the engine's (re-exported for the classes; docs/classes.md):
``candidate_pairs`` is :func:`~particleShear.engine.neighbours.near_pairs`.

A pair of the table is *active* (a relation) while it touches or is a permanent link.
"""
__docformat__ = "numpy"

from ..engine.neighbours import all_pairs, near_pairs as candidate_pairs
from ..engine.state import PERMANENT, SLIP, STICK, PairTable

__all__ = ["PairTable", "STICK", "SLIP", "PERMANENT", "STATE_NAMES", "candidate_pairs", "all_pairs"]

STATE_NAMES = ("stick", "slip", "permanent")
STATE_CODES = {"stick": STICK, "slip": SLIP, "permanent": PERMANENT}

