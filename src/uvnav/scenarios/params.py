"""Typed, range-checked parameters of the seeded scene generators.

A generator declares its keyword parameters once, in its signature, as
``Annotated[type, Field(ge=..., lt=..., description=...)]`` with a default; :func:`typed_generator`
checks every call against that signature (pydantic's ``validate_call``: names, types, ranges) and
turns a refusal into one :class:`~uvnav.scenarios.errors.ScenarioError` line
``GENERATOR:SEED: params.NAME: PROBLEM``, and :func:`describe_params` reads the same signature back
for ``uvnav scenarios show GENERATOR`` (name, type, default, range, description).  A parameter's
default is the family's own value, so a ``GENERATOR:SEED`` scene without ``params`` is the
family's scene bit for bit.
"""

from __future__ import annotations

import functools
import inspect
import types
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

from annotated_types import Ge, Gt, Le, Lt
from pydantic import ConfigDict, ValidationError, validate_call
from pydantic.fields import FieldInfo

from uvnav.scenarios.errors import ScenarioError, from_validation_error

F = TypeVar("F", bound=Callable[..., Any])

_CONFIG = ConfigDict(arbitrary_types_allowed=True)


def typed_generator(name: str) -> Callable[[F], F]:
    """Check a generator's keyword arguments against its annotated signature (module docstring).

    Args:
        name: the generator's registry name (the ``GENERATOR`` of the error line).
    """

    def wrap(fn: F) -> F:
        checked = validate_call(config=_CONFIG)(fn)
        fixed = set(fn.keywords) if isinstance(fn, functools.partial) else set()

        @functools.wraps(fn)
        def run(seed: int, **params: Any) -> Any:
            if fixed & set(params):  # a partial's keywords (crowd-eth's dataset) are not params
                raise _unknown_param(name, seed, fn, min(fixed & set(params)))
            try:
                return checked(seed, **params)
            except ValidationError as exc:
                raise _params_error(name, seed, fn, exc) from None

        return typing.cast(F, run)

    return wrap


def generator_variant(name: str, fn: Callable[..., Any], **defaults: Any) -> Callable[..., Any]:
    """The generator ``name``: ``fn`` with other ``defaults`` (each still a parameter, checked as
    ``fn`` checks it); its errors name ``name``."""
    part = functools.partial(fn, **defaults)

    @functools.wraps(fn)
    def run(seed: int, **params: Any) -> Any:
        try:
            return part(seed, **params)
        except ScenarioError as exc:
            exc.source = f"{name}:{seed}"
            raise

    run.__signature__ = inspect.signature(part)  # type: ignore[attr-defined]
    run.variant_of = part  # type: ignore[attr-defined]
    return run


def _unknown_param(name: str, seed: int, fn: Callable[..., Any], key: str) -> ScenarioError:
    """One line: ``key`` is not a parameter of generator ``name``; the ones that are."""
    fixed = set(fn.keywords) if isinstance(fn, functools.partial) else set()
    known = ", ".join(p for p in list(inspect.signature(fn).parameters)[1:] if p not in fixed)
    return ScenarioError(
        f"{name}:{seed}", "params", f"{name}: unknown parameter {key!r} (known: {known})"
    )


def _params_error(
    name: str, seed: int, fn: Callable[..., Any], exc: ValidationError
) -> ScenarioError:
    """One line: an unknown parameter with the known ones, else the first refused value."""
    source = f"{name}:{seed}"
    unknown = [e for e in exc.errors() if e.get("type") == "unexpected_keyword_argument"]
    if unknown:
        return _unknown_param(name, seed, fn, str(unknown[0]["loc"][-1]))
    err = from_validation_error(exc, source)
    return ScenarioError(source, f"params.{err.path}", err.problem)


@dataclass(frozen=True)
class ParamInfo:
    """One generator parameter: ``name``, ``type`` (as written), ``default``, ``bounds`` (e.g.
    ``>= 0.1, < 1``; empty when unbounded) and ``description``."""

    name: str
    type: str
    default: Any
    bounds: str
    description: str


_BOUND_TEXT = ((Ge, "ge", ">="), (Gt, "gt", ">"), (Le, "le", "<="), (Lt, "lt", "<"))


def _bounds(info: FieldInfo | None) -> str:
    if info is None:
        return ""
    parts = []
    for meta in info.metadata:
        for cls, attr, sign in _BOUND_TEXT:
            if isinstance(meta, cls):
                parts.append(f"{sign} {getattr(meta, attr):g}")
    return ", ".join(parts)


def _type_text(hint: Any) -> str:
    """``float``, ``int | None``, ``tuple[float, float]``, ``'polygon' | 'disc'``."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin is typing.Annotated:
        return _type_text(args[0])
    if origin is typing.Literal:
        return " | ".join(repr(a) for a in args)
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_type_text(a) for a in args)
    if origin is not None and args:
        name = getattr(origin, "__name__", str(origin))
        return f"{name}[{', '.join(_type_text(a) for a in args)}]"
    if hint is type(None):
        return "None"
    return str(getattr(hint, "__name__", hint)).replace("typing.", "")


def describe_params(fn: Callable[..., Any]) -> list[ParamInfo]:
    """The parameters of generator ``fn`` after its seed, in signature order: of a function, of a
    :func:`generator_variant` (its defaults), or of a ``functools.partial`` (less the keywords it
    fixes: ``crowd-eth`` is the ETH walkway)."""
    variant = getattr(fn, "variant_of", None)
    inner = inspect.unwrap(fn)  # a typed_generator's function, or partial
    fixed = set(inner.keywords) if isinstance(inner, functools.partial) else set()
    fn = variant if variant is not None else inner
    base = fn.func if isinstance(fn, functools.partial) else fn
    hints = typing.get_type_hints(inspect.unwrap(base), include_extras=True)
    out: list[ParamInfo] = []
    named = (inspect.Parameter.KEYWORD_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    for p in list(inspect.signature(fn).parameters.values())[1:]:
        if p.kind not in named or p.name in fixed:
            continue
        hint = hints.get(p.name, Any)
        info = None
        if typing.get_origin(hint) is typing.Annotated:
            args = typing.get_args(hint)
            hint = args[0]
            info = next((a for a in args[1:] if isinstance(a, FieldInfo)), None)
        default = p.default if p.default is not inspect.Parameter.empty else None
        out.append(
            ParamInfo(
                p.name, _type_text(hint), default, _bounds(info),
                (info.description or "") if info is not None else "",
            )
        )  # fmt: skip
    return out
