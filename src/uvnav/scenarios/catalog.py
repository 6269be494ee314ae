"""One scenario model for every vehicle: scene kinds, one name resolver, one generator registry.

A scene is one of five **kinds** (:data:`KINDS`), each with its vehicle and sensing (the
contract of :mod:`uvnav.core`), its pydantic model, its built-ins and its generators:

=========  ============  ===========  ==============================================
kind       vehicle       sensing      what
=========  ============  ===========  ==============================================
nav2d      unicycle      exact        Ch. 2 unicycle among moving bodies, crowds
           (holonomic)                (or the holonomic disc robot of crowd benchmarks)
nav3d      vehicle3d     exact        Ch. 3 flyer among moving 3D bodies
uuv2d      uuv2d         sonar-fan    Ch. 4 planar UUV, viewing-cone sonar, AMAPS
uuv3d      vehicle3d     sonar-array  Ch. 5 UUV, nine sonars, deforming bodies
multi2d    unicycle      exact        Ch. 8 N unicycles in one world
=========  ============  ===========  ==============================================

:func:`resolve` turns what a user types into a scene: a built-in name, a YAML file (its kind is
read from its content: ``kind:``, ``robots:``, ``dim: 3`` with ``sonar:``, ``dim: 3``, else
2D) or ``generator:seed``.  ``generator:seed`` is scene number ``seed`` of the generator *and*
episode seed ``seed``, in ``uvnav simulate``, ``uvnav bench`` and the API alike (the multi-robot
generators' number is the number of robots: ``antipodal:8``).

:data:`SceneFile` is the discriminated union of the five models (for ``uvnav scenarios schema``):
the discriminator is :func:`infer_kind`, the same rule as the resolver's.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Union

import numpy as np
from pydantic import Discriminator, Tag, TypeAdapter

from uvnav.core import load_plugins
from uvnav.dynamics.vehicles import vehicles_2d
from uvnav.scenarios.errors import ScenarioError


@dataclass(frozen=True)
class SceneKind:
    """A kind of scene.

    Attributes:
        name: the kind's name (:data:`KINDS`).
        vehicles: the vehicles its laws may drive (the first is the scene's own; a 2D scene
            holds every planar vehicle: the holonomic robot and the plug-ins'
            (:func:`~uvnav.dynamics.vehicles.vehicles_2d`)).
        sensing: the observation of :data:`uvnav.core.SENSINGS` its world makes.
        summary: one line for listings.
        model: the pydantic model of its files.
        load: built-in name, path or ``generator:seed`` -> validated model.
        builtins: names of its built-in scenes.
        generators: generator names (``name:seed`` specs).
        episode_rng: the episode generator of seed ``s`` (the stream the chapter's reproduction
            uses, so that a seed reproduces the reproduction's episode).
        spec_is_seed: the number of ``generator:N`` is the scene's seed (else a size, as the
            number of robots of ``antipodal:N``).
    """

    name: str
    vehicles: tuple[str, ...]
    sensing: str
    summary: str
    model: type
    load: Callable[[str], Any]
    builtins: Callable[[], list[str]]
    generators: tuple[str, ...]
    episode_rng: Callable[[int], np.random.Generator]
    spec_is_seed: bool = True

    @property
    def vehicle(self) -> str:
        """The scene's own vehicle."""
        return self.vehicles[0]

    def fits(self, info: Any) -> bool:
        """Whether a law (its registry entry) can drive this kind's scenes: one of its vehicles,
        its sensing."""
        return bool(info.vehicle in self.vehicles and info.sensing == self.sensing)

    def describe(self) -> str:
        """``a unicycle or holonomic with exact sensing``."""
        return f"a {' or '.join(self.vehicles)} with {self.sensing} sensing"


@dataclass(frozen=True)
class Resolved:
    """A resolved scene: its kind, the validated model, the text typed, and the episode seed a
    ``generator:seed`` spec fixes (``None`` for a built-in or a file)."""

    kind: SceneKind
    scenario: Any
    spec: str
    seed: int | None

    @property
    def name(self) -> str:
        """The scene's name for output: a ``generator:N`` spec as typed (so that it resolves
        again, where some generators name their scenes ``generator-N``), else the model's."""
        gen, sep, _ = self.spec.partition(":")
        if sep and gen in generators():
            return self.spec
        return str(getattr(self.scenario, "name", self.spec))


def _run_rng(seed: int) -> np.random.Generator:
    from uvnav.sim.seeding import run_rng

    return run_rng(seed)


def _plain_rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def _nav2d_load(spec: str) -> Any:
    from uvnav.scenarios.loader import load_scenario

    sc = load_scenario(spec)
    if getattr(sc, "dim", 2) != 2:
        raise ScenarioError(spec, "dim", "is a 3D scene (kind nav3d), not a 2D one")
    return sc


def _nav3d_load(spec: str) -> Any:
    from uvnav.scenarios.loader import load_scenario

    sc = load_scenario(spec)
    if getattr(sc, "dim", 2) != 3:
        raise ScenarioError(spec, "dim", "is a 2D scene (kind nav2d), not a 3D one")
    return sc


@functools.lru_cache(maxsize=2)
def _builtins_of_dim(dim: int) -> tuple[str, ...]:
    """The top-level built-ins of dimension ``dim`` (read by :func:`infer_kind`'s rule)."""
    from uvnav.scenarios.loader import builtin_yaml_files, list_builtin, parse_yaml

    files = builtin_yaml_files()
    want = "nav3d" if dim == 3 else "nav2d"
    return tuple(
        name
        for name in list_builtin()
        if infer_kind(parse_yaml(files[name].read_text(), name)) == want
    )


def _uuv2d_load(spec: str) -> Any:
    from uvnav.scenarios.uuv2d import UUV2D_GENERATORS, load_uuv2d_scenario

    gen, sep, number = spec.partition(":")
    if sep and gen in UUV2D_GENERATORS:
        return UUV2D_GENERATORS[gen](_seed_of(spec, number))
    return load_uuv2d_scenario(spec)


def _generate(name: str, seed: int, params: Mapping[str, Any]) -> Any:
    """Scene ``seed`` of the seed generator ``name`` with keyword ``params`` (any kind)."""
    return generator_function(name)(seed, **params)


def generator_function(name: str) -> Callable[..., Any]:
    """The callable ``f(seed, **params)`` of the seed generator ``name`` (any kind).

    Raises:
        KeyError: ``name`` is not a seed generator.
    """
    from uvnav.scenarios.ch5 import CH5_GENERATORS
    from uvnav.scenarios.generators import GENERATORS
    from uvnav.scenarios.uuv2d import UUV2D_GENERATORS

    table = {**GENERATORS, **UUV2D_GENERATORS, **CH5_GENERATORS, **plugin_generators()}
    return table[name]


#: one line on each built-in generator, for listings (a plug-in's: its ``summary`` attribute)
GENERATOR_SUMMARIES: dict[str, str] = {
    "random-ch2": "Ch. 2: 1-6 moving, rotating non-convex bodies across I -> T, (2.6)-(2.8) kept",
    "random-ch2-edge": "Ch. 2 at the edge of (2.6)-(2.7): 8 fast, fast-turning discs",
    "crowd-eth": "crossing the ETH 'eth' walkway among its recorded pedestrians",
    "crowd-hotel": "crossing the ETH 'hotel' walkway among its recorded pedestrians",
    "crowd-file": "crossing the crowd of any trajectory file (path=...)",
    "random-ch3": "Ch. 3: 2-4 moving, rotating 3D bodies (AR motion) between S and E",
    "random-ch3-periodic": "random-ch3 with weaving / circling bodies",
    "crowdnav-circle": "CrowdNav's circle-crossing test case (5 ORCA humans)",
    "crowdnav-square": "CrowdNav's square-crossing test case (5 ORCA humans)",
    "crowd-dynamic": "20 ORCA humans of random size and speed who change goals; 5 m sensing",
    "random-ch4": "Ch. 4: deforming bodies within the chapter's assumptions",
    "random-ch4-hard": "Ch. 4, harder: faster, translating bodies, narrow gaps",
    "random-ch5": "Ch. 5: deforming 3D bodies between A and B, within the assumptions",
    "random-ch5-dense": "Ch. 5 beyond the assumptions: bodies closer than the law needs",
    "antipodal": "N robots on a circle swap to the opposite points",
    "crossing": "two perpendicular flows of N/2 robots each",
    "thesis-ch2-multi": "the Fig. 2.8 six-obstacle scene with N <= 8 robots",
}


def generator_summary(name: str) -> str:
    """One line on generator ``name`` (``""`` for a plug-in without a ``summary``)."""
    if name in GENERATOR_SUMMARIES:
        return GENERATOR_SUMMARIES[name]
    return str(getattr(plugin_generators().get(name), "summary", "") or "")


def generator_params(name: str) -> list[Any]:
    """The keyword parameters of seed generator ``name``
    (:class:`uvnav.scenarios.params.ParamInfo`: name, type, default, bounds, description)."""
    from uvnav.scenarios.params import describe_params

    return describe_params(generator_function(name))


def _uuv3d_load(spec: str) -> Any:
    from uvnav.scenarios.ch5 import load_ch5_scenario

    return load_ch5_scenario(spec)


def _multi_load(spec: str) -> Any:
    from uvnav.scenarios.multi import load_multi_scenario

    return load_multi_scenario(spec)


def _models() -> dict[str, type]:
    from uvnav.scenarios.ch5 import Scenario5
    from uvnav.scenarios.multi import MultiScenario
    from uvnav.scenarios.schema import Scenario
    from uvnav.scenarios.schema3d import Scenario3D
    from uvnav.scenarios.uuv2d import Uuv2dScenario

    return {
        "nav2d": Scenario,
        "nav3d": Scenario3D,
        "uuv2d": Uuv2dScenario,
        "uuv3d": Scenario5,
        "multi2d": MultiScenario,
    }


def _kinds() -> dict[str, SceneKind]:
    from uvnav.scenarios.ch5 import GENERATOR_CH5, GENERATOR_CH5_DENSE, list_ch5_builtin
    from uvnav.scenarios.generators import GENERATORS
    from uvnav.scenarios.multi import MULTI_GENERATORS
    from uvnav.scenarios.uuv2d import UUV2D_GENERATORS, list_uuv2d_builtin

    models = _models()
    gen2d, gen3d = (
        tuple(g for g, fn in GENERATORS.items() if getattr(fn, "scene_kind", "nav2d") == kind)
        for kind in ("nav2d", "nav3d")
    )
    return {
        k.name: k
        for k in (
            SceneKind(
                "nav2d", tuple(vehicles_2d()), "exact",
                "Ch. 2 unicycle among moving bodies and crowds",
                models["nav2d"], _nav2d_load, lambda: list(_builtins_of_dim(2)), gen2d, _run_rng,
            ),
            SceneKind(
                "nav3d", ("vehicle3d",), "exact", "Ch. 3 flying robot among moving 3D bodies",
                models["nav3d"], _nav3d_load, lambda: list(_builtins_of_dim(3)), gen3d,
                _plain_rng,
            ),
            SceneKind(
                "uuv2d", ("uuv2d",), "sonar-fan", "Ch. 4 planar UUV, sonar only, deforming bodies",
                models["uuv2d"], _uuv2d_load, list_uuv2d_builtin, tuple(UUV2D_GENERATORS),
                _plain_rng,
            ),
            SceneKind(
                "uuv3d", ("vehicle3d",), "sonar-array", "Ch. 5 UUV with nine sonars among "
                "deforming bodies", models["uuv3d"], _uuv3d_load, list_ch5_builtin,
                (GENERATOR_CH5, GENERATOR_CH5_DENSE), _plain_rng,
            ),
            SceneKind(
                "multi2d", ("unicycle",), "exact", "N unicycles in one world (Ch. 8)",
                models["multi2d"], _multi_load, list, tuple(MULTI_GENERATORS), _run_rng,
                spec_is_seed=False,
            ),
        )
    }  # fmt: skip


_KINDS: dict[str, SceneKind] | None = None


def kinds() -> Mapping[str, SceneKind]:
    """Every scene kind by name (:data:`KINDS` order)."""
    global _KINDS
    if _KINDS is None:
        _KINDS = _kinds()
    return _KINDS


#: Scene kinds, in the order of the thesis's chapters.
KINDS: tuple[str, ...] = ("nav2d", "nav3d", "uuv2d", "uuv3d", "multi2d")


#: Entry-point group of third-party scene generators.  An entry point's name is the generator's;
#: it loads a callable ``f(seed, **params)`` returning a scenario model of one kind, whose
#: ``scene_kind`` attribute names that kind (``nav2d`` when absent).  A name already taken is
#: refused.
GENERATOR_GROUP = "uvnav.generators"


def plugin_generators() -> dict[str, Callable[..., Any]]:
    """The generators of the :data:`GENERATOR_GROUP` entry points (loaded once).

    Raises:
        RuntimeError: a plug-in takes a taken name, or names an unknown ``scene_kind``.
    """
    builtin = frozenset(g for k in kinds().values() for g in k.generators)
    plugins = load_plugins(GENERATOR_GROUP, builtin, "scene generator")
    for name, fn in plugins.items():
        kind = getattr(fn, "scene_kind", "nav2d")
        if kind not in KINDS:
            raise RuntimeError(
                f"scene generator {name!r}: unknown scene_kind {kind!r}; known: {', '.join(KINDS)}"
            )
    return plugins


def generators() -> dict[str, SceneKind]:
    """Every generator name and the kind of scene it makes (one registry: the built-in kinds'
    and :data:`GENERATOR_GROUP`'s; duplicates refused)."""
    out: dict[str, SceneKind] = {}
    for k in kinds().values():
        for g in k.generators:
            if g in out:
                raise RuntimeError(f"generator {g!r} is registered by {out[g].name} and {k.name}")
            out[g] = k
    for name, fn in plugin_generators().items():
        out[name] = kinds()[getattr(fn, "scene_kind", "nav2d")]
    return out


def _plugin_scene(name: str, seed: int, params: Mapping[str, Any]) -> Any:
    spec = f"{name}:{seed}"
    kind = generators()[name]
    try:
        scenario = plugin_generators()[name](seed, **params)
    except ScenarioError:
        raise
    except (TypeError, ValueError, OverflowError) as exc:
        raise ScenarioError(spec, "params", f"{name}: {exc}") from None
    if not isinstance(scenario, kind.model):
        raise ScenarioError(
            spec, "generator", f"{name} returned a {type(scenario).__name__}, not a "
            f"{kind.model.__name__} ({kind.name} scene)"
        )  # fmt: skip
    return scenario


def infer_kind(data: Any) -> str:
    """The kind of a scene file's mapping: its ``kind``; else ``robots`` -> multi2d; ``dim: 3``
    with ``sonar`` -> uuv3d; ``dim: 3`` -> nav3d; else nav2d."""
    if isinstance(data, Mapping):
        kind = data.get("kind")
        if isinstance(kind, str) and kind in KINDS:
            return kind
        if "robots" in data:
            return "multi2d"
        if data.get("dim") == 3:
            return "uuv3d" if "sonar" in data else "nav3d"
        return "nav2d"
    # a validated model
    for name, model in _models().items():
        if isinstance(data, model):
            return name
    return "nav2d"


def _seed_of(spec: str, text: str) -> int:
    if not text.isdigit():
        raise ScenarioError(spec, "seed", f"must be a non-negative integer (got {text!r})")
    seed = int(text)
    if seed >= 2**63:
        raise ScenarioError(spec, "seed", f"must be below 2**63 (got {text})")
    return seed


def _file_kind(path: Path) -> str:
    from uvnav.scenarios.loader import parse_yaml

    try:
        text = path.read_text()
    except UnicodeDecodeError:
        raise ScenarioError(str(path), "", "is not a text (YAML) file") from None
    except OSError as exc:
        raise ScenarioError(str(path), "", f"cannot be read ({exc.strerror or exc})") from None
    return infer_kind(parse_yaml(text, str(path)))


def resolve(spec: str) -> Resolved:
    """The scene ``spec`` names: ``generator:seed``, a built-in name or a YAML file.

    Raises:
        ScenarioError: unknown name, unreadable or invalid file, bad seed (one line).
    """
    gen, sep, number = spec.partition(":")
    by_gen = generators()
    if sep and gen in by_gen:
        seed = _seed_of(spec, number)
        kind = by_gen[gen]
        if gen in plugin_generators():
            return Resolved(kind, _plugin_scene(gen, seed, {}), spec, seed)
        return Resolved(kind, kind.load(spec), spec, seed if kind.spec_is_seed else None)
    for kind in kinds().values():
        if spec in kind.builtins():
            return Resolved(kind, kind.load(spec), spec, None)
    path = Path(spec)
    if path.is_dir():
        raise ScenarioError(spec, "", "is a directory, not a scenario file")
    if path.is_file():
        kind = kinds()[_file_kind(path)]
        return Resolved(kind, kind.load(spec), spec, None)
    raise ScenarioError(
        spec,
        "",
        "no such file or built-in scene, nor a GENERATOR:N spec (see 'uvnav scenarios list')",
    )


def generate(name: str, seed: int, params: Mapping[str, Any] | None = None) -> Resolved:
    """Scene ``seed`` of the seed generator ``name`` (any kind) with keyword ``params``; the
    episode seed is ``seed``, as for ``name:seed``.

    Raises:
        ScenarioError: unknown generator, a size generator (``antipodal``: write ``antipodal:N``
            as a scene), or parameters the generator refuses (one line).
    """
    by_gen = generators()
    spec = f"{name}:{seed}"
    if name not in by_gen:
        raise ScenarioError(
            spec,
            "generator",
            f"unknown generator {name!r}; known: "
            f"{', '.join(g for g, k in by_gen.items() if k.spec_is_seed)}",
        )
    kind = by_gen[name]
    if not kind.spec_is_seed:
        raise ScenarioError(
            spec,
            "generator",
            f"{name}:N makes a scene of N robots; give it as a scene "
            f"('{name}:8'), with episode seeds",
        )
    if name in plugin_generators():
        return Resolved(kind, _plugin_scene(name, seed, params or {}), spec, seed)
    if not params:
        return Resolved(kind, kind.load(spec), spec, seed)
    try:
        scenario = _generate(name, seed, params)
    except ScenarioError:
        raise
    except (TypeError, ValueError, OverflowError) as exc:
        values = ", ".join(f"{k}={v!r}" for k, v in params.items())
        raise ScenarioError(spec, "params", f"{name} with {values}: {exc}") from None
    return Resolved(kind, scenario, spec, seed)


def with_fields(resolved: Resolved, fields: Mapping[str, Any]) -> Resolved:
    """``resolved`` with the section fields ``fields`` set, each named ``section.field``
    (``sensing.velocities`` of a 3D scene, ``sonar.noise_std`` of a sonar scene); every section
    changed is validated again by its own model (the scene's other checks are not rerun).

    Raises:
        ScenarioError: no such section or field, or a value the section refuses (one line).
    """
    from pydantic import BaseModel, ValidationError

    sections: dict[str, dict[str, Any]] = {}
    for path, value in fields.items():
        section, _, name = str(path).partition(".")
        sections.setdefault(section, {})[name] = value
    update: dict[str, Any] = {}
    for section, values in sections.items():
        part = getattr(resolved.scenario, section, None)
        unknown = [
            n for n in values if not isinstance(part, BaseModel) or n not in type(part).model_fields
        ]
        if unknown or not isinstance(part, BaseModel):
            where = f"{section}.{unknown[0] if unknown else ''}"
            raise ScenarioError(resolved.spec, where, "is no field of the scene's sections")
        try:
            update[section] = type(part).model_validate({**part.model_dump(), **values})
        except ValidationError as exc:
            err = exc.errors(include_url=False)[0]
            where = ".".join((section, *(str(x) for x in err["loc"])))
            raise ScenarioError(resolved.spec, where, str(err["msg"])) from None
    scenario = resolved.scenario.model_copy(update=update)
    return Resolved(resolved.kind, scenario, resolved.spec, resolved.seed)


def builtin_names() -> list[tuple[str, SceneKind]]:
    """Every built-in scene with its kind, in :data:`KINDS` order."""
    return [(name, k) for k in kinds().values() for name in k.builtins()]


def scene_file_adapter() -> TypeAdapter[Any]:
    """A pydantic adapter of :data:`SceneFile` (validation and JSON Schema of every kind)."""
    members = tuple(Annotated[model, Tag(name)] for name, model in _models().items())
    union: Any = Annotated[Union[members], Discriminator(infer_kind)]  # noqa: UP007
    return TypeAdapter(union)
