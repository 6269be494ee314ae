"""Planar UUV (thesis (4.1)-(4.7)): box bound, sqrt(2) V_max, bounded turn, exact steps."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.dynamics.holonomic import (
    HolonomicCommand,
    HolonomicSpec,
    holonomic_step,
    max_speed_along,
    velocity_toward,
)

SPEC = HolonomicSpec(v_max=1.0, u_max=1.0, radius=0.2)


def test_diagonal_speed_is_sqrt2_vmax() -> None:
    assert math.isclose(max_speed_along(math.pi / 4, 1.0), math.sqrt(2))
    assert math.isclose(max_speed_along(0.0, 1.0), 1.0)
    cmd = velocity_toward(math.pi / 4, 10.0, SPEC, math.pi / 4, 0.2)
    assert math.isclose(cmd.speed, math.sqrt(2)) and not cmd.violates(SPEC, math.pi / 4, 0.2)


@settings(max_examples=60, deadline=None)
@given(
    direction=st.floats(-math.pi, math.pi),
    heading=st.floats(-math.pi, math.pi),
    speed=st.floats(0.0, 5.0),
    period=st.floats(0.01, 1.0),
)
def test_velocity_toward_is_always_within_the_limits(
    direction: float, heading: float, speed: float, period: float
) -> None:
    cmd = velocity_toward(direction, speed, SPEC, heading, period)
    assert not cmd.violates(SPEC, heading, period)
    assert cmd.speed <= math.sqrt(2) * SPEC.v_max + 1e-12  # (4.7)


@settings(max_examples=60, deadline=None)
@given(
    vx=st.floats(-3, 3),
    vy=st.floats(-3, 3),
    heading=st.floats(-math.pi, math.pi),
    period=st.floats(0.01, 1.0),
)
def test_clipping_restores_the_limits(vx: float, vy: float, heading: float, period: float) -> None:
    c = HolonomicCommand(vx, vy).clipped(SPEC, heading, period)
    assert not c.violates(SPEC, heading, period, tol=1e-9)


def test_step_is_exact_and_orientation_follows_the_velocity() -> None:
    s = holonomic_step(np.array([1.0, 2.0, 0.0]), HolonomicCommand(0.5, -0.5), 2.0)
    assert np.allclose(s, [2.0, 1.0, -math.pi / 4])
    still = holonomic_step(s, HolonomicCommand(0.0, 0.0), 1.0)
    assert np.allclose(still, s)
    assert HolonomicCommand(0.0, 1.0).violates(SPEC, 0.0, 0.5)  # turn pi/2 > U_max * 0.5
    assert HolonomicCommand(1.2, 0.0).violates(SPEC, 0.0, 0.5)  # box
