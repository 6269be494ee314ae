"""``zhang2019-v2``'s unicycle loop (:mod:`uvnav.controllers.zhang2019_v2_paths`) against the full
evaluation it shortens: every candidate's path rolled out to the horizon and checked against
every disc on every segment, then the least-cost choice.  Branch-and-bound, the per-chunk culls,
the early stops and the lazy braking check must leave the pick exactly as it is."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers import zhang2019_v2_paths as paths
from uvnav.controllers.zhang2019_limits import RampModel
from uvnav.controllers.zhang2019_v2 import Zhang2019V2Params, path_constants
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import numba_available

MODELS = {
    "ideal": RampModel(0.707, 1.414, math.inf, math.inf, 0.25),
    "limited": RampModel(1.0, math.pi, 1.0, 2.0, 0.25),
}

Discs = tuple[FloatArray, FloatArray, FloatArray]


def full_choice(
    pose: FloatArray, now: FloatArray, cand: tuple[FloatArray, FloatArray, FloatArray],
    discs: Discs, prm: FloatArray,
) -> tuple[int, float]:  # fmt: skip
    """The index and first contact of the least-cost candidate, every candidate evaluated in
    full: safe ones (first contact after min_ttc, can brake) first, then those that can brake,
    then all; ties by index."""
    ang, spd, base = cand
    q, w, reach = discs
    n_sub = max(1, math.ceil(prm[paths.M_PERIOD] / prm[paths.M_STEP] - 1e-9))
    h = prm[paths.M_PERIOD] / n_sub
    n = max(1, math.ceil(prm[paths.M_HORIZON] / h - 1e-9))
    times = h * np.arange(n + 1).astype(np.float64)
    rows = []
    for k in range(len(ang)):
        xy, speeds = np.zeros((n + 1, 2)), np.zeros(n + 1)
        xy[0], speeds[0] = pose[:2], now[0]
        state = np.array([pose[2], now[0], now[1], now[0], now[1], 0.0])
        track = np.zeros((n, 8))  # its own heading track: nothing shared
        paths.advance(state, ang[k], spd[k], prm, n_sub, xy, speeds, n, track, np.zeros(1))
        risk = np.array([math.inf, 0.0, 0.0])
        for j in range(len(reach)):
            qw = (q[j, 0], q[j, 1], w[j, 0], w[j, 1])
            paths._disc_along(xy, times, 0, n, qw, reach[j], prm, risk)
        ttc = risk[0]
        cost = base[k] + prm[paths.M_W_TTC] / max(ttc, 1e-3) + prm[paths.M_W_COMFORT] * risk[1]
        brakes = paths._stops(xy, times, speeds, ttc, n_sub, prm)
        rows.append((cost, k, ttc, brakes))
    safe = [r for r in rows if r[3] and r[2] > prm[paths.M_MIN_TTC]]
    pool = safe or [r for r in rows if r[3]] or rows
    best = min(pool, key=lambda r: (r[0], r[1]))
    return best[1], best[2]


def crowd(rng: np.random.Generator, n_bodies: int) -> tuple[Discs, FloatArray]:
    """Walking bodies 0.5-6 m around the origin, nearest first: each a disc or a cluster of
    three discs moving together; the boundary discs (centres, velocities, reaches) and the body
    rows of :func:`uvnav.controllers.zhang2019_v2_paths.choose_on_paths_py`."""
    centres = rng.uniform(-6.0, 6.0, (n_bodies, 2))
    centres = centres[np.argsort(np.hypot(centres[:, 0], centres[:, 1]))]
    q: list[FloatArray] = []
    w: list[FloatArray] = []
    reach: list[float] = []
    rows: list[list[float]] = []
    for c in centres:
        v = rng.uniform(-1.2, 1.2, 2)
        offsets = [np.zeros(2)] if rng.uniform() < 0.6 else list(rng.uniform(-0.5, 0.5, (3, 2)))
        first = len(q)
        for off in offsets:
            q.append(c + off)
            w.append(v)
            reach.append(0.6)
        bound = max(float(np.hypot(*off)) for off in offsets) + 0.6
        rows.append([first, len(q), c[0], c[1], v[0], v[1], bound])
    discs = (np.array(q).reshape(-1, 2), np.array(w).reshape(-1, 2), np.array(reach))
    return discs, np.array(rows, dtype=float).reshape(-1, 7)


def candidates(rng: np.random.Generator, n_c: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Directions, speeds and costs without the risk terms, with ties in the costs."""
    ang = rng.uniform(-math.pi, math.pi, n_c)
    spd = rng.choice([0.0, 0.3, 0.6, 1.0], n_c)
    base = np.round(rng.uniform(0.0, 2.0, n_c), 1)
    return ang, spd, base


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 100_000), n_bodies=st.integers(0, 25), n_c=st.integers(1, 30),
       model=st.sampled_from(sorted(MODELS)))  # fmt: skip
def test_the_loop_picks_what_the_full_evaluation_picks(
    seed: int, n_bodies: int, n_c: int, model: str
) -> None:
    """Over random crowds (the robot boxed in or free), the loop's pick and its first contact
    are the full evaluation's, to the bit, in plain Python and compiled."""
    rng = np.random.default_rng(seed)
    discs, bodies = crowd(rng, n_bodies)
    cand = candidates(rng, n_c)
    pose = np.array([0.0, 0.0, rng.uniform(-math.pi, math.pi)])
    now = np.array([rng.uniform(0.0, 0.7), rng.uniform(-1.0, 1.0)])
    prm = path_constants(MODELS[model], Zhang2019V2Params(), 0.3)
    order = np.argsort(cand[2], kind="mergesort")
    want = full_choice(pose, now, cand, discs, prm)
    loops = [paths.choose_on_paths_py]
    if numba_available():
        paths._compiled_plan()
        loops.append(paths._COMPILED["choose_on_paths_py"])
    for loop in loops:
        out = np.empty(2)
        loop(pose, now, cand, order, discs, bodies, prm, out)
        assert (int(out[0]), out[1]) == want


def test_the_full_evaluation_sees_a_boxed_in_robot() -> None:
    """The reference above is not vacuous: with bodies closing in from all sides no candidate
    is safe, and it falls back to one that can still brake."""
    ring = np.array([[math.cos(a), math.sin(a)] for a in np.linspace(0, 2 * math.pi, 9)[:-1]])
    discs = (1.2 * ring, -0.8 * ring, np.full(8, 0.6))
    rng = np.random.default_rng(3)
    cand = candidates(rng, 12)
    prm = path_constants(MODELS["ideal"], Zhang2019V2Params(), 0.3)
    k, ttc = full_choice(np.zeros(3), np.array([0.3, 0.0]), cand, discs, prm)
    assert ttc <= prm[paths.M_MIN_TTC]
    out = np.empty(2)
    bodies = np.column_stack([np.arange(8), np.arange(8) + 1, discs[0], discs[1], discs[2]])
    paths.choose_on_paths_py(np.zeros(3), np.array([0.3, 0.0]), cand,
                             np.argsort(cand[2], kind="mergesort"), discs, bodies, prm,
                             out)  # fmt: skip
    assert (int(out[0]), out[1]) == (k, ttc)
    assert ttc < 1.0
