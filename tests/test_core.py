"""The navigation contract (``uvnav.core``): the one step loop with a toy world."""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np
import pytest

from uvnav.core import AgentLog, BaseProbe, run_loop


class LineWorld:
    """Agents on a line: position += command * dt; a decision every ``ratio`` steps."""

    vehicle: ClassVar[str] = "unicycle"
    sensing: ClassVar[str] = "exact"

    def __init__(self, n: int, steps: int, ratio: int) -> None:
        self.n_agents = n
        self.x = np.zeros(n)
        self.cmd = np.zeros(n)
        self.steps, self.ratio, self.k = steps, ratio, 0
        self.t, self.dt, self.done = 0.0, 0.1, False
        self.oracles: list[bool] = []

    def law_setup(self, agent: int) -> tuple[Any, np.ndarray, np.random.Generator]:
        return f"spec{agent}", np.array([float(agent)]), np.random.default_rng(agent)

    def start(self, oracles: Sequence[bool]) -> None:
        self.oracles = list(oracles)

    def acting(self) -> Sequence[int]:
        return range(self.n_agents) if self.k % self.ratio == 0 else ()

    def observe(self, agent: int = 0) -> float:
        return float(self.x[agent])

    def apply(self, cmd: float, agent: int = 0) -> float:
        self.cmd[agent] = min(cmd, 1.0)  # saturated
        return float(self.cmd[agent])

    def advance(self) -> None:
        self.x += self.cmd * self.dt
        self.k += 1
        self.t = self.k * self.dt
        self.done = self.k >= self.steps


class Law:
    name: ClassVar[str] = "toy"

    def __init__(self, oracle: bool = False, modes: Sequence[str] = ("M1",)) -> None:
        self.oracle = oracle
        self._modes = list(modes)
        self.mode = self._modes[0]
        self.calls = 0
        self.reset_with: tuple[Any, ...] = ()

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
        self.reset_with = (spec, goal.tolist(), rng.integers(1000))

    def act(self, obs: float) -> float:
        self.mode = self._modes[self.calls % len(self._modes)]
        self.calls += 1
        return 2.0


class Events(BaseProbe):
    def __init__(self) -> None:
        self.events: list[tuple[str, Any]] = []

    def on_start(self, world: Any, laws: Sequence[Any]) -> None:
        self.events.append(("start", world.k))

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
        self.events.append(("decide", (world.k, agent, applied)))

    def on_step(self, world: Any, laws: Sequence[Any]) -> None:
        self.events.append(("step", world.k))

    def on_end(self, world: Any, laws: Sequence[Any]) -> None:
        self.events.append(("end", world.k))


def test_decisions_come_every_ratio_steps_and_probes_see_them_in_order() -> None:
    world = LineWorld(n=2, steps=4, ratio=2)
    laws = [Law(), Law(oracle=True)]
    probe = Events()
    logs = run_loop(world, laws, [probe])
    assert world.oracles == [False, True]
    assert laws[1].reset_with[:2] == ("spec1", [1.0])
    assert probe.events == [
        ("start", 0),
        ("decide", (0, 0, 1.0)), ("decide", (0, 1, 1.0)), ("step", 0), ("step", 1),
        ("decide", (2, 0, 1.0)), ("decide", (2, 1, 1.0)), ("step", 2), ("step", 3),
        ("end", 4),
    ]  # fmt: skip
    assert [len(log.decision_us) for log in logs] == [2, 2]
    assert world.x.tolist() == pytest.approx([0.4, 0.4])  # the saturated command was held


def test_mode_switches_count_changes_between_decisions() -> None:
    law = Law(modes=("M1", "M2", "M2", "M1"))
    (log,) = run_loop(LineWorld(1, 8, 2), [law])
    assert log.mode_switches == 2 and log.last_mode == "M1"


def test_the_number_of_laws_must_match_the_agents() -> None:
    with pytest.raises(ValueError, match="1 law"):
        run_loop(LineWorld(2, 2, 1), [Law()])


def test_decisions_are_timed_in_cpu_time_and_the_first_is_kept_apart() -> None:
    class Sleeper(Law):
        def act(self, obs: float) -> float:
            time.sleep(0.02)  # waits without computing
            return super().act(obs)

    (log,) = run_loop(LineWorld(1, 3, 1), [Sleeper()])
    assert len(log.decision_us) == 3 and log.timed_us == log.decision_us[1:]
    assert min(log.decision_wall_us) >= 20_000.0
    assert max(log.decision_us) < 10_000.0  # CPU time: the sleep is not in it
    assert AgentLog(decision_us=[5.0]).timed_us == [5.0]


class Grouped(Law):
    """A toy law of a group keyed by ``key``: its group decides all members at once."""

    def __init__(self, key: str, made: list[Any]) -> None:
        super().__init__()
        self.group_key = key
        self._made = made

    def make_group(self) -> Any:
        group = Group()
        self._made.append(group)
        return group


class Group:
    def __init__(self) -> None:
        self.calls: list[tuple[float, list[int]]] = []

    def decide(self, world: Any, agents: Sequence[int], laws: Sequence[Any]) -> list[float]:
        self.calls.append((world.t, list(agents)))
        return [0.5 * (i + 1) for i in agents]


def test_a_group_of_laws_decides_once_per_decision_time_before_the_others() -> None:
    made: list[Any] = []
    solo = Law()
    laws = [Grouped("a", made), solo, Grouped("a", made), Grouped("b", made)]
    world = LineWorld(4, steps=6, ratio=2)
    probe = Events()
    logs = run_loop(world, laws, [probe])  # type: ignore[arg-type]
    assert len(made) == 2  # one group per key
    a, b = made
    assert [agents for _, agents in a.calls] == [[0, 2]] * 3
    assert [agents for _, agents in b.calls] == [[3]] * 3
    assert solo.calls == 3
    assert world.cmd.tolist() == [0.5, 1.0, 1.0, 1.0]  # group commands applied, saturated
    assert [len(log.decision_us) for log in logs] == [3, 3, 3, 3]
    first = [e for e in probe.events if e[0] == "decide"][:4]
    assert [agent for _, (_, agent, _) in first] == [0, 2, 3, 1]  # groups first, then the rest
