"""Learning (DESIGN §1, layer 6): the only package that imports torch.

Torch is imported lazily inside :mod:`uvnav.learning.pilotnet` and its siblings; importing
:mod:`uvnav.learning` itself is cheap and works without the ``learning`` extra.
"""

from __future__ import annotations

from uvnav.learning.config import PilotNetConfig, TrainConfig

__all__ = ["PilotNetConfig", "TrainConfig"]
