"""Imported by the campaign pool's fork server only (:func:`uvnav.bench.campaign.default_mp_context`
preloads it): one short episode is run there, so that every worker forked from the server starts
with what a process's first episode otherwise pays for itself — the lazy imports of the scene,
episode and metric code and the loading of the compiled kernels (numba's target context and its
cache), about 0.65 CPU-s — instead of each worker paying it again (:func:`warm_up`).
"""

from __future__ import annotations

from uvnav.bench.campaign import warm_up

warm_up()
