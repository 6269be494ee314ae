"""Campaign files: a YAML description of scenarios × controllers × seeds, expanded into jobs.

Example (``uvnav bench crowds.yaml``)::

    name: crowd-baselines          # campaign name in the results database (the resume identity)
    description: optional text
    scenarios:
      - generator: crowdnav-circle # a seed generator of any kind (uvnav scenarios list)
        seeds: [0, 200]            # two integers: the range [start, stop)
        params: {n_humans: 3}      # optional generator keyword arguments
      - builtin: open-field        # a built-in scene of any kind
        seeds: {values: [0, 7]}    # explicit seeds (any list that is not two integers is too)
      - file: scenes/corridor.yaml # a scenario YAML file of any kind, relative to this file
        seeds: [0, 5]
      - scene: antipodal:8         # anything `uvnav simulate` takes (8 robots here)
        seeds: [0, 3]
    controllers:
      - name: zhang2019-v1
        params: {alpha0: 0.1}                 # fixed parameters
        grid: {switch_distance: [1.0, 1.5]}   # cartesian product of parameter values
        oracle: false                         # true: ground-truth obstacle velocities
      - name: savkin-wang2013-v1
    record: false                  # store trajectories (figures; costs disk)

Expansion (:meth:`CampaignSpec.jobs`): every scenario entry × every controller entry that can
drive it (same vehicle and sensing, :mod:`uvnav.scenarios.episodes`) × every grid point × every
seed is one :class:`~uvnav.bench.campaign.Job`; the episode seed is the scenario seed (for a
generator, the same number draws the scene and seeds the episode).  When the file is loaded,
controller parameters are checked against the controller's ``Params``, generator parameters by
drawing the entry's first scene (names, types and ranges, as the generator checks them), and every
controller must fit at least one scenario entry and every entry at least one controller, so a typo
stops the campaign before it starts rather than filling the database with ``error`` rows.  An
episode whose scene breaks an assumption the law declares (thesis (2.6)), or whose generated
scene cannot place the bodies it drew (a first seed refused so does not stop the campaign), is
stored as ``refused`` with the reason, not run.

The schema is pydantic v2 with ``extra="forbid"`` (DESIGN §3); :func:`load_campaign` turns every
problem into one :class:`CampaignError` line ``FILE: FIELD: PROBLEM``.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    StrictBool,
    ValidationError,
    ValidationInfo,
    model_validator,
)

from uvnav.bench.campaign import CampaignRun, Job, run_campaign
from uvnav.bench.store import ResultsStore
from uvnav.controllers import ControllerParamsError, available_controllers
from uvnav.controllers.base import controller_info, make_law
from uvnav.scenarios import ScenarioError
from uvnav.scenarios.errors import FieldError, from_validation_error
from uvnav.scenarios.limits import MAX_CAMPAIGN_EPISODES, MAX_GRID_POINTS
from uvnav.scenarios.loader import parse_yaml


class CampaignError(ScenarioError):
    """A campaign file that cannot be loaded or run: ``source: field: problem`` on one line.

    A subclass of :class:`~uvnav.scenarios.ScenarioError` (same attributes ``source``, ``path``,
    ``problem``), so callers that report scenario errors report these the same way.
    """


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class SeedValues(_Strict):
    """Explicit seeds, for when two seeds must not read as a range: ``{values: [3, 7]}``."""

    values: list[int] = Field(min_length=1)


def _seed_list(seeds: list[int] | SeedValues) -> list[int]:
    """The seeds a ``seeds`` field means (raises :class:`FieldError` for a bad one)."""
    if isinstance(seeds, SeedValues):
        values = list(seeds.values)
    elif len(seeds) == 2:
        start, stop = seeds
        if start >= stop:
            raise FieldError(
                "seeds",
                f"[{start}, {stop}] is read as the range [start, stop) and needs start < stop "
                "(write {values: [a, b]} for two explicit seeds)",
            )
        if stop - start > MAX_CAMPAIGN_EPISODES:
            raise FieldError(
                "seeds",
                f"[{start}, {stop}) is {stop - start} seeds, more than the limit of "
                f"{MAX_CAMPAIGN_EPISODES} episodes of a campaign "
                "(uvnav.scenarios.limits.MAX_CAMPAIGN_EPISODES)",
            )
        values = list(range(start, stop))
    elif not seeds:
        raise FieldError("seeds", "needs [start, stop) or a list of seeds (got an empty list)")
    else:
        values = list(seeds)
    if min(values) < 0:
        raise FieldError("seeds", f"seeds must be >= 0 (got {min(values)})")
    if len(set(values)) != len(values):
        dup = sorted({s for s in values if values.count(s) > 1})
        raise FieldError("seeds", f"duplicate seed(s) {dup}")
    return values


class ScenarioEntry(_Strict):
    """Where episodes come from: exactly one of ``generator``, ``builtin``, ``file``; and seeds.

    Attributes:
        generator: seed generator of any scene kind (``uvnav scenarios list``).
        builtin: built-in scene name of any kind (``uvnav scenarios list``).
        file: scenario YAML file of any kind, relative to the campaign file.
        scene: anything ``uvnav simulate`` takes (built-in, file, ``antipodal:8``).
        seeds: ``[start, stop]`` (a range), or any other list of seeds, or ``{values: [...]}``.
        params: generator keyword arguments (generator entries only).
    """

    generator: str | None = None
    builtin: str | None = None
    file: str | None = None
    scene: str | None = None
    seeds: list[int] | SeedValues
    params: dict[str, Any] = Field(default_factory=dict)

    _path: Path | None = PrivateAttr(default=None)
    _kind: Any = PrivateAttr(default=None)

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> ScenarioEntry:
        from uvnav.scenarios.catalog import builtin_names, generate, generators, resolve
        from uvnav.scenarios.errors import PlacementError

        sources = ("generator", "builtin", "file", "scene")
        given = [k for k in sources if getattr(self, k) is not None]
        if len(given) != 1:
            got = ", ".join(given) if given else "none"
            raise FieldError("", f"needs exactly one of {', '.join(sources)} (got {got})")
        seeds = _seed_list(self.seeds)
        if self.generator is not None:
            try:  # names, types and ranges, as the generator itself checks them
                self._kind = generate(self.generator, seeds[0], self.params).kind
            except PlacementError:  # valid parameters; that seed's episodes are stored refused
                self._kind = generators()[self.generator]
            except ScenarioError as exc:
                if exc.path in ("generator", "params") or exc.path.startswith("params."):
                    raise FieldError(exc.path, exc.problem) from None
                problem = f"{self.generator}: {exc.path}: {exc.problem}"
                raise FieldError("params", problem) from None
            return self
        if self.params:
            raise FieldError("params", "only generator entries take params")
        if self.builtin is not None:
            names = [n for n, _ in builtin_names()]
            if self.builtin not in names:
                raise FieldError(
                    "builtin",
                    f"unknown built-in scenario {self.builtin!r} (known: {', '.join(names)}; "
                    "for a YAML file use file:)",
                )
            self._kind = resolve(self.builtin).kind
        spec = self.scene
        if self.file is not None:
            base = (info.context or {}).get("base_dir") or Path.cwd()
            path = Path(self.file).expanduser()
            self._path = path if path.is_absolute() else Path(base) / path
            if not self._path.is_file():
                raise FieldError("file", f"no such scenario file {str(self._path)!r}")
            spec = str(self._path)
        if spec is not None:
            try:
                resolved = resolve(spec)
            except ScenarioError as exc:
                raise FieldError("file" if self.file else "scene", str(exc)) from None
            if resolved.seed is not None:
                raise FieldError(
                    "scene",
                    f"{spec} fixes its seed; write generator: {spec.partition(':')[0]} with seeds",
                )
            self._kind = resolved.kind
        return self

    def fits(self, info: Any) -> bool:
        """Whether the law of registry entry ``info`` can drive this entry's scenes."""
        return bool(self._kind.fits(info))

    def seed_list(self) -> list[int]:
        """The seeds of this entry, in order."""
        return _seed_list(self.seeds)

    def job(
        self, controller: str, params: Mapping[str, Any], seed: int, record: bool, beyond: bool
    ) -> Job:
        """The job of one controller parameter set and one seed on this scenario entry."""
        return dataclasses.replace(
            self._job(controller, params, seed, record), beyond_assumptions=beyond
        )

    def _job(self, controller: str, params: Mapping[str, Any], seed: int, record: bool) -> Job:
        if self.generator is not None:
            return Job(
                controller=controller,
                params=params,
                seed=seed,
                generator_seed=seed,
                generator=self.generator,
                generator_params=self.params,
                record=record,
            )
        if self.builtin is not None or self.scene is not None:
            return Job(
                controller=controller,
                params=params,
                seed=seed,
                scenario=self.builtin or self.scene,
                record=record,
            )
        assert self.file is not None and self._path is not None
        return Job(
            controller=controller,
            params=params,
            seed=seed,
            scenario=str(self._path),
            label=self.file,  # the key keeps the path as written, so a moved tree still resumes
            record=record,
        )


class ControllerEntry(_Strict):
    """A controller with fixed parameters and an optional parameter grid.

    Attributes:
        name: registered controller name (``uvnav controllers list``).
        params: fixed parameters (fields of the controller's ``Params``).
        grid: parameter → list of values; the campaign runs the cartesian product (in the order
            written), each point merged over ``params``.
        oracle: give the controller ground-truth obstacle velocities (DESIGN §2); stored as the
            parameter ``oracle: true``, so oracle and sensing runs of one law stay apart.
    """

    name: str
    params: dict[str, Any] = Field(default_factory=dict)
    grid: dict[str, list[Any]] = Field(default_factory=dict)
    oracle: StrictBool = False

    @model_validator(mode="after")
    def _check(self) -> ControllerEntry:
        known = available_controllers(None)
        if self.name not in known:
            raise FieldError(
                "name", f"unknown controller {self.name!r} (known: {', '.join(sorted(known))})"
            )
        if "oracle" in self.params or "oracle" in self.grid:
            raise FieldError("params", "set oracle with the entry's own oracle: field")
        for key, values in self.grid.items():
            if not values:
                raise FieldError(f"grid.{key}", "needs at least one value")
            if key in self.params:
                raise FieldError(f"grid.{key}", "is also in params (give it in one place)")
        points = math.prod(len(values) for values in self.grid.values())
        if points > MAX_GRID_POINTS:
            counts = " x ".join(str(len(values)) for values in self.grid.values())
            raise FieldError(
                "grid",
                f"{counts} = {points:.3g} parameter sets, more than the limit of "
                f"{MAX_GRID_POINTS} (uvnav.scenarios.limits.MAX_GRID_POINTS); split the grid",
            )
        for point in self.param_sets():
            try:
                make_law(self.name, **point)
            except ControllerParamsError as exc:
                where = "grid" if set(point) & set(self.grid) else "params"
                raise FieldError(where, f"{self.name}: {exc}") from None
        return self

    def param_sets(self) -> list[dict[str, Any]]:
        """Every parameter set of this entry (the grid's cartesian product over ``params``)."""
        keys = list(self.grid)
        sets = []
        for values in itertools.product(*(self.grid[k] for k in keys)):
            point = {**self.params, **dict(zip(keys, values, strict=True))}
            if self.oracle:
                point["oracle"] = True
            sets.append(point)
        return sets


class CampaignSpec(_Strict):
    """A campaign file (see the module docstring).

    Attributes:
        name: campaign name in the results database; running the file again resumes it.
        description: free text.
        scenarios: scenario entries.
        controllers: controller entries.
        record: store every episode's trajectory.
        beyond_assumptions: run every law even on scenes that break an assumption it declares
            (thesis (2.6)), to measure it there; by default those episodes are ``refused``.
    """

    name: str = Field(min_length=1, pattern=r"^\S(.*\S)?$")
    description: str = ""
    scenarios: list[ScenarioEntry] = Field(min_length=1)
    controllers: list[ControllerEntry] = Field(min_length=1)
    record: StrictBool = False
    beyond_assumptions: StrictBool = False

    @model_validator(mode="after")
    def _bounded(self) -> CampaignSpec:
        sets = sum(len(ctrl.param_sets()) for ctrl in self.controllers)
        n = sets * sum(len(sc.seed_list()) for sc in self.scenarios)
        if n > MAX_CAMPAIGN_EPISODES:
            raise FieldError(
                "scenarios",
                f"the campaign has {n} episodes, more than the limit of {MAX_CAMPAIGN_EPISODES} "
                "(uvnav.scenarios.limits.MAX_CAMPAIGN_EPISODES); split it into several campaigns",
            )
        return self

    def jobs(self) -> list[Job]:
        """The campaign's jobs: scenario entries × seeds × controller entries × grid points.

        Seeds come before controllers so that the jobs of one generated scene run close together
        and a worker generates the scene once for all of them (see
        :func:`uvnav.bench.campaign.scene_groups`).
        """
        sets = [
            (ctrl.name, params, controller_info(ctrl.name))
            for ctrl in self.controllers
            for params in ctrl.param_sets()
        ]
        return [
            sc.job(name, params, seed, self.record, self.beyond_assumptions)
            for sc in self.scenarios
            for seed in sc.seed_list()
            for name, params, info in sets
            if sc.fits(info)
        ]

    @model_validator(mode="after")
    def _pairs(self) -> CampaignSpec:
        infos = [controller_info(c.name) for c in self.controllers]
        for j, info in enumerate(infos):
            if not any(sc.fits(info) for sc in self.scenarios):
                kinds = ", ".join(sorted({sc._kind.name for sc in self.scenarios}))
                raise FieldError(
                    f"controllers.{j}.name",
                    f"{info.name} drives a {info.vehicle} with {info.sensing} sensing: no "
                    f"scenario entry fits it (their kinds: {kinds})",
                )
        for i, sc in enumerate(self.scenarios):
            if not any(sc.fits(info) for info in infos):
                raise FieldError(
                    f"scenarios.{i}",
                    f"no controller entry can drive its {sc._kind.name} scenes "
                    f"({sc._kind.describe()})",
                )
        return self

    def config(self) -> dict[str, Any]:
        """What the store keeps with the campaign: the file's content, defaults filled in."""
        return self.model_dump(mode="json")


def _allowed_fields(loc: tuple[str | int, ...]) -> list[str] | None:
    model: Any = CampaignSpec
    for part in loc:
        if isinstance(part, int):
            continue
        if model is CampaignSpec and part == "scenarios":
            model = ScenarioEntry
        elif model is CampaignSpec and part == "controllers":
            model = ControllerEntry
        elif model is ScenarioEntry and part == "seeds":
            model = SeedValues
        elif part == "SeedValues":
            continue
        else:
            return None
    return list(model.model_fields)


def campaign_from_dict(
    data: Any, source: str = "<dict>", *, base_dir: str | Path | None = None
) -> CampaignSpec:
    """Validate a mapping as a :class:`CampaignSpec`.

    Args:
        data: the parsed YAML.
        source: what to call the origin in error messages.
        base_dir: directory that ``file:`` entries are relative to (default: the working directory).

    Raises:
        CampaignError: one line naming ``source``, the field and the problem.
    """
    if not isinstance(data, dict):
        raise CampaignError(
            source, "<root>", f"expected a mapping of campaign fields (got {type(data).__name__})"
        )
    try:
        return CampaignSpec.model_validate(data, context={"base_dir": base_dir})
    except ValidationError as exc:
        err = from_validation_error(exc, source, allowed_fields=_allowed_fields)
        raise CampaignError(source, _drop_union_tags(err.path), err.problem) from None


def _drop_union_tags(path: str) -> str:
    # ``seeds`` is ``list[int] | SeedValues``: pydantic names the failing branch in the location
    parts = [p for p in path.split(".") if p not in ("list[int]", "SeedValues")]
    return ".".join(parts)


def load_campaign(path: str | Path) -> CampaignSpec:
    """Read and validate a campaign file; ``file:`` scenarios are checked to load.

    Raises:
        CampaignError: missing file, malformed YAML, a schema violation, or a bad scenario file.
    """
    path = Path(path)
    source = str(path)
    try:
        if path.is_dir():
            raise CampaignError(source, "", "is a directory, not a campaign file")
        if path.exists() and not path.is_file():  # a FIFO or /dev/zero would never end
            raise CampaignError(source, "", "is not a regular file")
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise CampaignError(source, "", "no such campaign file") from None
    except UnicodeDecodeError as exc:
        raise CampaignError(source, "", f"cannot read: {exc}") from None
    except OSError as exc:
        raise CampaignError(source, "", f"cannot read: {exc.strerror or exc}") from None
    data = parse_yaml(text, source, kind="campaign", error=CampaignError)
    spec = campaign_from_dict(data, source, base_dir=path.parent)
    return spec


def run_campaign_spec(
    store: ResultsStore,
    spec: CampaignSpec,
    *,
    resume: bool = False,
    engine: str = "local",
    workers: int = 1,
    address: str | None = None,
    progress: bool = False,
    retry_errors: bool = False,
    probe_factory: Callable[[Job], Sequence[Any]] | None = None,
) -> CampaignRun:
    """Run a campaign file's jobs into ``store`` (see :func:`~uvnav.bench.campaign.run_campaign`).

    Args:
        store: results store.
        spec: the campaign.
        resume: continue a campaign of the same name already in the store (skipping stored keys);
            without it such a campaign is an error, so two different campaigns that share a name
            never mix in one database.
        engine: ``"local"`` or ``"ray"``.
        workers: worker processes / Ray CPUs.
        address: Ray cluster address.
        progress: rich progress bar on stderr.
        retry_errors: run again the episodes stored with status ``error``.
        probe_factory: probes that watch each episode run (``run_campaign``'s).

    Raises:
        CampaignError: the campaign exists and ``resume`` is false.
        uvnav.bench.store.StoreInUseError: another process runs a campaign into this database.
    """
    with store.writer_lease():  # before the check below: another writer may be creating it
        if not resume and store.campaign_id(spec.name) is not None:
            raise CampaignError(
                str(store.path),
                "",
                f"campaign {spec.name!r} is already in this database: pass --resume to continue "
                "it, or --db for another database",
            )
        return run_campaign(
            store,
            spec.name,
            spec.jobs(),
            config=spec.config(),
            workers=workers,
            progress=progress,
            retry_errors=retry_errors,
            engine=engine,
            address=address,
            probe_factory=probe_factory,
        )
