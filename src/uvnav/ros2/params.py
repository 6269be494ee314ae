"""A law's parameters as ROS 2 parameters: name, ROS 2 type, default and description, and a
parameter file in the layout ``ros2 param dump`` writes (``NODE: {ros__parameters: {...}}``).

The names, defaults and descriptions come from the law's registry entry (its ``Params``
dataclass and the ``Attributes:`` section of that class's docstring); the type is the ROS 2
parameter type of the field's Python type, named as ``ros2 param describe`` names them
(``boolean``, ``integer``, ``double``, ``string`` and their ``array`` forms); a field of any
other type (a nested law's parameters, polygons) is a ``string`` read as YAML.
:func:`law_vehicle` says whether a ``Twist`` can carry a law's commands.  Nothing here needs
``cyclonedds``.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from dataclasses import dataclass
from typing import Any

from uvnav.controllers.base import controller_info
from uvnav.controllers.describe import param_fields

#: the vehicles whose commands a ``Twist`` carries
TWIST_VEHICLES = ("unicycle", "holonomic")
_SCALARS: dict[Any, str] = {bool: "boolean", int: "integer", float: "double", str: "string"}


@dataclass(frozen=True)
class ParamDescriptor:
    """One parameter as ``ros2 param describe`` shows it, with its default."""

    name: str
    type: str
    default: Any
    description: str


def ros_type(hint: Any) -> str:
    """The ROS 2 parameter type of a Python type hint.

    >>> ros_type(float), ros_type(tuple[float, ...]), ros_type(typing.Literal["a", "b"])
    ('double', 'double array', 'string')
    """
    if hint in _SCALARS:
        return _SCALARS[hint]
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin is typing.Literal and args:
        return _SCALARS.get(type(args[0]), "string")
    if origin in (tuple, list) and args and args[0] in _SCALARS:
        return f"{_SCALARS[args[0]]} array"
    if origin in (typing.Union, types.UnionType):
        kinds = {ros_type(a) for a in args if a is not type(None)}
        if len(kinds) == 1:
            return kinds.pop()
    return "string"


def describe(law: str) -> list[ParamDescriptor]:
    """The parameters of the registered law ``law``, in their declaration order.

    Raises:
        UnknownControllerError: ``law`` is not registered.
    """
    ptype = controller_info(law).params_type
    fields = param_fields(ptype)
    hints = typing.get_type_hints(ptype) if fields else {}
    return [ParamDescriptor(f.name, ros_type(hints[f.name]), f.default, f.doc) for f in fields]


def law_vehicle(name: str) -> str:
    """The vehicle of the 2D law ``name``.

    Raises:
        UnknownControllerError: ``name`` is not registered.
        ValueError: the law drives a vehicle a ``Twist`` does not command.
    """
    vehicle = controller_info(name).vehicle
    if vehicle not in TWIST_VEHICLES:
        raise ValueError(
            f"law {name!r} drives the {vehicle} vehicle; the ROS 2 node drives "
            f"{' and '.join(TWIST_VEHICLES)} laws"
        )
    return vehicle


def law_arguments(law: str, values: dict[str, Any]) -> dict[str, Any]:
    """``values`` as the law's parameter dataclass takes them: a list (a ROS 2 array, a YAML
    sequence) given for a tuple field becomes a tuple; everything else is left as it is.

    Raises:
        UnknownControllerError: ``law`` is not registered.
    """
    ptype = controller_info(law).params_type
    if ptype is None or not dataclasses.is_dataclass(ptype):
        return dict(values)
    hints = typing.get_type_hints(ptype)
    return {
        k: tuple(v) if isinstance(v, list) and typing.get_origin(hints.get(k)) is tuple else v
        for k, v in values.items()
    }


def parameter_file(node: str, params: list[ParamDescriptor]) -> dict[str, Any]:
    """The defaults as a ROS 2 parameter file's mapping (``ros2 param dump``'s layout)."""
    return {node: {"ros__parameters": {p.name: plain(p.default) for p in params}}}


def file_parameters(data: Any) -> dict[str, Any]:
    """The parameters of a ROS 2 parameter file's mapping (every node's, in file order).

    Raises:
        ValueError: the mapping is not ``NODE: {ros__parameters: {NAME: VALUE, ...}}``.
    """
    if not isinstance(data, dict) or not data:
        raise ValueError("expected a mapping NODE: {ros__parameters: {...}}")
    out: dict[str, Any] = {}
    for node, body in data.items():
        params = body.get("ros__parameters") if isinstance(body, dict) else None
        if not isinstance(params, dict):
            raise ValueError(f"{node}: expected a mapping with a 'ros__parameters' mapping")
        out.update({str(k): v for k, v in params.items()})
    return out


def plain(value: Any) -> Any:
    """A default as YAML writes it (tuples as lists, dataclasses as mappings)."""
    if isinstance(value, tuple | list):
        return [plain(v) for v in value]
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {k: plain(v) for k, v in dataclasses.asdict(value).items()}
    return value
