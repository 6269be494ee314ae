"""A law's parameters as ROS 2 parameters, parameter files, and which laws a ``Twist`` can
carry (no DDS needed)."""

from __future__ import annotations

import typing
from dataclasses import dataclass

import pytest

from uvnav.controllers.describe import attribute_docs
from uvnav.ros2.params import (
    describe,
    file_parameters,
    law_arguments,
    law_vehicle,
    parameter_file,
    ros_type,
)


@pytest.mark.parametrize(
    ("hint", "expected"),
    [
        (bool, "boolean"),
        (int, "integer"),
        (float, "double"),
        (str, "string"),
        (tuple[float, ...], "double array"),
        (list[int], "integer array"),
        (tuple[str, ...], "string array"),
        (typing.Literal["a", "b"], "string"),
        (typing.Literal[1, 2], "integer"),
        (float | None, "double"),
        (dict[str, float], "string"),
        (tuple[tuple[float, float], ...], "string"),
    ],
)
def test_ros_types_of_python_hints(hint: object, expected: str) -> None:
    assert ros_type(hint) == expected


@dataclass(frozen=True)
class _Params:
    """Parameters of a test law.

    Attributes:
        gain: how hard it pushes [1/s], over
            two lines.
        levels: fractions of V_max.

    Notes: not a field.
    """

    gain: float = 1.5
    levels: tuple[float, ...] = (1.0, 0.5)


def test_field_docs_read_the_attributes_section() -> None:
    assert attribute_docs(_Params) == {
        "gain": "how hard it pushes [1/s], over two lines.",
        "levels": "fractions of V_max.",
    }


def test_describe_and_the_parameter_file_of_a_registered_law() -> None:
    params = {p.name: p for p in describe("zhang2019-v2")}
    assert params["horizon"].type == "double" and params["horizon"].default == 4.0
    assert params["horizon"].description.startswith("H [s]")
    assert params["speed_levels"].default == (1.0, 0.6, 0.3)
    data = parameter_file("uvnav", list(params.values()))
    assert data["uvnav"]["ros__parameters"]["speed_levels"] == [1.0, 0.6, 0.3]
    assert file_parameters(data)["speed_levels"] == [1.0, 0.6, 0.3]
    assert describe("straight-holonomic-v1") == []


def test_arrays_become_the_laws_tuples() -> None:
    got = law_arguments("zhang2019-v2", {"speed_levels": [1.0, 0.5], "horizon": 3.0})
    assert got == {"speed_levels": (1.0, 0.5), "horizon": 3.0}


@pytest.mark.parametrize("data", [None, [], {}, {"n": 3}, {"n": {"parameters": {}}}])
def test_a_malformed_parameter_file_is_refused(data: object) -> None:
    with pytest.raises(ValueError, match="ros__parameters"):
        file_parameters(data)


def test_laws_of_other_vehicles_are_refused() -> None:
    assert law_vehicle("zhang2019-v2") == "unicycle"
    assert law_vehicle("zhang2019-holonomic-v2") == "holonomic"
    with pytest.raises(ValueError, match="drives the vehicle3d vehicle"):
        law_vehicle("zhang2020-3d-v1")
