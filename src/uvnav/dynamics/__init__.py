"""Layer 1: vehicle models as pure ``step(state, command, dt) -> state`` functions, and limits."""

from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec, unicycle_advance, unicycle_step

__all__ = ["UnicycleCommand", "UnicycleSpec", "unicycle_advance", "unicycle_step"]
