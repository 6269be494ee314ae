"""Jobs: what one episode of a campaign is, what comes back, and how tasks are sized.

A :class:`Job` is a small picklable *description* of one episode (a scene: scenario name or file
with section fields to set, or generator name, parameters and seed; law name and parameters; tags;
seed), run by the one scene runner (:func:`uvnav.scenarios.episodes.run_scene`); its
:attr:`Job.key` is the store's resume key.  A worker returns a :class:`JobOutcome`.
:class:`TaskSizer` and :func:`sized_batches` cut the scene groups of a campaign into tasks of
about :data:`TASK_SECONDS` each, for the local pool (:mod:`uvnav.bench.campaign`) and for Ray
(:mod:`uvnav.bench.ray_engine`) alike; running a job is :func:`uvnav.bench.campaign.run_job`.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from uvnav.bench.store import EpisodeKey, canonical_json, params_hash
from uvnav.scenarios.generators import DEFAULT_GENERATOR
from uvnav.sim import Trajectory


def _freeze(
    params: Mapping[str, Any] | Iterable[tuple[str, Any]] | None,
) -> tuple[tuple[str, Any], ...]:
    items = params.items() if isinstance(params, Mapping) else (params or ())
    return tuple(sorted((str(k), v) for k, v in items))


@dataclass(frozen=True)
class Job:
    """One episode to run: where the scene comes from, which controller, which seed.

    Exactly one scene source must be given: ``scenario`` or ``generator_seed``.

    Attributes:
        controller: registry name, e.g. ``"zhang2019-v1"``.
        seed: episode seed (``build_episode(..., seed)`` and ``run_episode``'s generator).
        scenario: built-in scenario name or path to a YAML file.
        generator_seed: seed of the scenario generator named by ``generator``.
        generator: generator name, a key of :data:`uvnav.scenarios.GENERATORS` (default
            :data:`uvnav.scenarios.generators.DEFAULT_GENERATOR`).
        generator_params: keyword arguments of the generator (a mapping is accepted and frozen to
            sorted pairs); they become part of the scenario label, hence of the resume key.
        scene_params: fields of the ``scenario``'s sections to set, ``section.field`` -> value
            (``{"sensing.velocities": "estimated"}``;
            :func:`uvnav.scenarios.catalog.with_fields`); part of the default label.
        label: scenario label stored in the database (defaults from the source).
        family: scenario family reports group by (defaults: scenario name, or generator label).
        params: controller parameters (a mapping is accepted and frozen to sorted pairs).  When the
            scenario names the same controller, these override the scenario's own parameters.
            ``oracle=True`` among them is passed to ``make_controller`` (ground-truth obstacle
            velocities, DESIGN §2) and, being a parameter, keeps oracle runs apart in the store.
        use_scenario_params: start from the scenario's ``controller.params`` when the scenario names
            this controller (default ``True``).
        record: keep the trajectory and store it (for figures; costs memory and disk).
        beyond_assumptions: run the law even where the scene breaks an assumption it declares
            (thesis (2.6)); by default such an episode is stored as ``refused``.
        tags: what identifies the episode beyond the controller parameters (an experiment's
            sensing level, locator, ...): stored with them in the ``params`` column and part of the
            resume key, never passed to the law (a mapping is frozen to sorted pairs).  A tag named
            as a parameter stands for it in the store (``params`` and ``effective_params``): a
            checkpoint's digest for its path.
        probe_factory: a *module-level* (picklable) callable ``job -> list of probes``
            (:class:`uvnav.core.Probe`) that watch the job's episode; a probe with a ``close()``
            is closed after it.  Not part of the resume key;
            :func:`~uvnav.bench.campaign.run_campaign` sets it.
    """

    controller: str
    seed: int
    scenario: str | None = None
    generator_seed: int | None = None
    generator: str = DEFAULT_GENERATOR
    generator_params: Mapping[str, Any] | tuple[tuple[str, Any], ...] = ()
    scene_params: Mapping[str, Any] | tuple[tuple[str, Any], ...] = ()
    label: str | None = None
    family: str | None = None
    params: Mapping[str, Any] | tuple[tuple[str, Any], ...] = ()
    use_scenario_params: bool = True
    record: bool = False
    beyond_assumptions: bool = False
    tags: Mapping[str, Any] | tuple[tuple[str, Any], ...] = ()
    probe_factory: Callable[[Job], Sequence[Any]] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", _freeze(self.params))
        object.__setattr__(self, "generator_params", _freeze(self.generator_params))
        object.__setattr__(self, "scene_params", _freeze(self.scene_params))
        if self.scene_params and self.scenario is None:
            raise ValueError("scene_params need a scenario")
        object.__setattr__(self, "tags", _freeze(self.tags))
        if (self.scenario is None) == (self.generator_seed is None):
            raise ValueError("a Job needs exactly one of scenario, generator_seed")
        if self.generator_seed is not None:
            from uvnav.scenarios.catalog import generators  # layer 5, imported when needed

            known = generators()
            if self.generator not in known:
                raise ValueError(
                    f"unknown generator {self.generator!r}; known: {', '.join(sorted(known))}"
                )
        elif self.generator_params:
            raise ValueError("generator_params need a generator_seed")

    @property
    def params_dict(self) -> dict[str, Any]:
        """The controller parameters as a dict."""
        return dict(self.params)

    @property
    def store_params(self) -> dict[str, Any]:
        """What the store's ``params`` column holds and the resume key hashes: the controller
        parameters and the :attr:`tags`."""
        return {**dict(self.params), **dict(self.tags)}

    @property
    def generator_label(self) -> str:
        """``generator`` or, with parameters, ``generator[k=v,...]`` (values as canonical JSON)."""
        if not self.generator_params:
            return self.generator
        items = dict(self.generator_params).items()
        args = ",".join(f"{k}={canonical_json(v)}" for k, v in items)
        return f"{self.generator}[{args}]"

    @property
    def scenario_label(self) -> str:
        """What the ``scenario`` column stores: the name/path, ``generator/NNNN`` or the label.

        A generator with parameters stores ``generator[k=v,...]/NNNN`` (see
        :attr:`generator_label`).
        """
        if self.label is not None:
            return self.label
        if self.scenario is not None and self.scene_params:
            sets = ",".join(f"{k}={canonical_json(v)}" for k, v in dict(self.scene_params).items())
            return f"{self.scenario}[{sets}]"
        if self.scenario is not None:
            return self.scenario
        return f"{self.generator_label}/{self.generator_seed:04d}"

    @property
    def family_label(self) -> str:
        """Scenario family for reports (the generator label for generated scenes)."""
        if self.family is not None:
            return self.family
        if self.generator_seed is not None:
            return self.generator_label
        return self.scenario_label

    @property
    def key(self) -> EpisodeKey:
        """Resume key ``(scenario, controller, params_hash, seed)``."""
        return (
            self.scenario_label,
            self.controller,
            params_hash(self.store_params),
            int(self.seed),
        )


@dataclass
class JobOutcome:
    """What a worker sends back for one job.

    Attributes:
        job: the job.
        status: ``success``, ``collision``, ``timeout`` or ``error``.
        metrics: metric name → value (``None`` for an error).
        error: ``"ExceptionType: message"`` for an error, else ``None``.
        wall_time: time spent in the worker, building included [s].
        trajectory: recorded trajectory when ``job.record``.
        effective_params: parameters the law was built with (a tag named as a parameter in its
            place) and the scene runner's facts (:attr:`uvnav.scenarios.episodes.Outcome.facts`).
        result: the simulator's own result when ``job.record`` (for figures; never stored).
        cpu_time: CPU time of the worker's thread on the job, building included [s] (never
            stored; what a campaign's engine adds is measured against it, ``bench_ray.py``).
    """

    job: Job
    status: str
    metrics: dict[str, Any] | None
    error: str | None
    wall_time: float
    trajectory: Trajectory | None = None
    effective_params: dict[str, Any] = field(default_factory=dict)
    result: Any = None
    cpu_time: float = 0.0


#: a task (local pool or Ray) runs about this long [s]: enough scene groups are batched into it
#: (:class:`TaskSizer`)
TASK_SECONDS = 0.25
#: at most this many scene groups in one task
MAX_GROUPS_PER_TASK = 16


class TaskSizer:
    """How many scene groups the next task gets, so that a task runs about ``seconds``.

    One group while none has come back; then ``seconds`` over the mean worker time of the groups
    that have (their outcomes' ``wall_time``), between 1 and ``limit``.  A task costs its engine
    a fixed overhead however long it runs (two pickled messages and the bookkeeping of the
    executor's or Ray's driver and workers; Ray's scheduling), so short groups are sent several
    at a time; the size never changes what a job stores.
    """

    def __init__(self, seconds: float = TASK_SECONDS, limit: int = MAX_GROUPS_PER_TASK) -> None:
        self.seconds, self.limit = seconds, limit
        self._groups, self._time = 0, 0.0

    def add(self, outcomes: Sequence[JobOutcome]) -> None:
        """Account for one finished group."""
        self._groups += 1
        self._time += sum(out.wall_time for out in outcomes)

    def size(self) -> int:
        """Groups for the next task."""
        if self._groups == 0 or self._time <= 0.0:
            return 1
        return max(1, min(self.limit, int(self.seconds * self._groups / self._time)))


def sized_batches(queue: deque[list[Job]], sizer: TaskSizer) -> Iterator[list[list[Job]]]:
    """Tasks taken from the front of ``queue`` (scene groups) as they are asked for, each of
    ``sizer.size()`` groups at that moment (fewer at the end)."""
    while queue:
        yield [queue.popleft() for _ in range(min(sizer.size(), len(queue)))]
