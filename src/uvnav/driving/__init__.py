"""Driving (DESIGN §1, layer 6): thesis Chapter 6's data, simulator, expert and evaluator.

Udacity-layout datasets (``driving_log.csv`` + ``IMG/``), steering balancing and the 8:2 split
(:mod:`uvnav.driving.dataset`), the CarRacing-v3 simulator with a forward camera
(:mod:`uvnav.driving.sim`), the pure-pursuit expert (:mod:`uvnav.driving.expert`) and the
closed-loop evaluator (:mod:`uvnav.driving.evaluate`), and the pipeline that trains and evaluates
the network on them (:mod:`uvnav.driving.pipeline`).  Torch is imported only by the pipeline's
functions that train or run the network (it lives in :mod:`uvnav.learning`); gymnasium is
imported lazily by the simulator.
"""

from __future__ import annotations
