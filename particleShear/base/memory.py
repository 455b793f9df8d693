"""Allocator tuning of the classes' step: :func:`particleShear.engine.memory.tune_allocator` (kept here by name)."""
__docformat__ = "numpy"

from ..engine.memory import tune_allocator

__all__ = ["tune_allocator"]
