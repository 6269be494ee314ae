"""Layer 3: navigation laws (one module each), their registry and ``make_controller``."""

from uvnav.controllers.base import (
    Controller,
    ControllerInfo,
    ControllerParamsError,
    UnknownControllerError,
    available_controllers,
    controller_info,
    make_controller,
    register,
)

__all__ = [
    "Controller",
    "ControllerInfo",
    "ControllerParamsError",
    "UnknownControllerError",
    "available_controllers",
    "controller_info",
    "make_controller",
    "register",
]
