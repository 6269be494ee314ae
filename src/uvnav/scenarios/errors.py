"""One-line scenario errors (DESIGN §3: one clear line naming the file, the field and the problem).

Every problem found while reading a scenario — malformed YAML, an unknown or mistyped field, a
value out of range, an inconsistent scene — is raised as :class:`ScenarioError`, whose ``str()``
is a single line ``<file>: <field path>: <problem>``, e.g.
``thesis.yaml: robot.v_max: must be > 0 (got -1)``; a source longer than 200 characters is cut
with ``...`` so that the line stays readable.
Pydantic's structured errors are translated here, so that the command line can print them verbatim
and exit with status 2 instead of showing a traceback.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from pydantic import ValidationError

from uvnav.validation import clip, describe_error, one_line


class ScenarioError(ValueError):
    """A scenario that cannot be loaded or does not make sense.

    Attributes:
        source: the file (or ``"<dict>"``, or a built-in name) the scenario came from.
        path: dotted field path (``obstacles.0.motion.speed``), ``"line N"`` for YAML syntax
            errors, or ``""`` for a problem with the whole file.
        problem: what is wrong, in one line.
    """

    def __init__(self, source: str, path: str, problem: str) -> None:
        self.source = str(source)
        self.path = str(path)
        self.problem = one_line(problem)
        super().__init__(str(self))

    def __str__(self) -> str:
        parts = [p for p in (clip(self.source, 200), self.path, self.problem) if p]
        return ": ".join(parts)


class FieldError(ValueError):
    """Raised inside model validators to point at a sub-field (``path`` relative to the model)."""

    def __init__(self, path: str, problem: str) -> None:
        self.path = path
        self.problem = problem
        super().__init__(problem)


def format_loc(loc: Sequence[str | int], tags: Sequence[str] = ()) -> str:
    """Dotted field path of a pydantic ``loc``, without discriminated-union tag segments."""
    parts: list[str] = []
    for i, part in enumerate(loc):
        if isinstance(part, str) and part in tags and i > 0 and loc[i - 1] == "motion":
            continue
        parts.append(str(part))
    return ".".join(parts)


def from_validation_error(
    exc: ValidationError,
    source: str,
    *,
    tags: Sequence[str] = (),
    allowed_fields: Any = None,
) -> ScenarioError:
    """The first error of ``exc`` as a :class:`ScenarioError` (with a count of the others).

    Args:
        exc: pydantic's error.
        source: the file name to report.
        tags: discriminator values that pydantic inserts into ``loc`` and we hide.
        allowed_fields: optional callable ``loc -> list[str] | None`` naming the fields allowed at
            the location of an ``extra_forbidden`` error.
    """
    errors = exc.errors(include_url=False)
    if not errors:  # pragma: no cover - pydantic always reports at least one
        return ScenarioError(source, "", str(exc))
    # an unknown field is usually the cause of the other errors (a misspelt required field)
    errors = sorted(errors, key=lambda e: e.get("type") != "extra_forbidden")
    first = errors[0]
    loc = tuple(first.get("loc", ()))
    ctx = first.get("ctx") or {}
    extra_path = ""
    if first.get("type") == "value_error" and isinstance(ctx.get("error"), FieldError):
        extra_path = ctx["error"].path
    path = format_loc(loc, tags)
    if extra_path:
        path = f"{path}.{extra_path}" if path else extra_path
    allowed = None
    if first.get("type") == "extra_forbidden" and allowed_fields is not None:
        allowed = allowed_fields(loc[:-1])
    problem = describe_error(first, allowed)
    if len(errors) > 1:
        problem += f" (and {len(errors) - 1} more error{'s' if len(errors) > 2 else ''})"
    return ScenarioError(source, path or "<root>", problem)


class PlacementError(ScenarioError):
    """A generator could not place the bodies it drew: the scene is refused, not built short.

    ``str()`` is one line ``GENERATOR:SEED: placement: placed K of N bodies (...)``; a campaign
    stores the episode as ``refused`` with that line, the command line exits 2.

    Attributes:
        placed: bodies placed.
        wanted: bodies drawn (or asked for).
    """

    def __init__(self, source: str, placed: int, wanted: int, why: str = "") -> None:
        self.placed = int(placed)
        self.wanted = int(wanted)
        detail = f" ({why})" if why else ""
        super().__init__(source, "placement", f"placed {placed} of {wanted} bodies{detail}")
