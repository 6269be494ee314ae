"""Campaign files: schema, one-line errors, expansion into jobs; same results on 1 and 2 workers."""

from __future__ import annotations

from pathlib import Path

import pytest

from uvnav.bench.campaign import Job
from uvnav.bench.spec import CampaignError, campaign_from_dict, load_campaign, run_campaign_spec
from uvnav.bench.store import ResultsStore
from uvnav.bench.summary import TIMING_COLUMNS, controller_summary
from uvnav.scenarios import GENERATORS
from uvnav.sim import METRIC_NAMES

DETERMINISTIC = [m for m in METRIC_NAMES if not m.startswith("decision_us")]

EXAMPLE = """\
name: ch2-baselines
scenarios:
  - generator: random-ch2
    seeds: [0, 4]
    params: {}
  - builtin: thesis-ch2-one-obstacle
    seeds: [0, 2]
controllers:
  - name: zhang2019-v1
    params: {alpha0: 0.1}
    grid: {switch_distance: [1.0, 1.5]}
    oracle: false
  - name: savkin-wang2013-v1
record: false
"""

SMALL = {
    "name": "small",
    "scenarios": [{"generator": "random-ch2", "seeds": [0, 3]}],
    "controllers": [{"name": "straight-v1"}, {"name": "zhang2019-v1"}],
}


def write(tmp_path: Path, text: str, name: str = "c.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_example_expands_to_the_cartesian_product(tmp_path: Path) -> None:
    spec = load_campaign(write(tmp_path, EXAMPLE))
    jobs = spec.jobs()
    # (4 + 2 seeds) x (2 grid points + 1 plain controller)
    assert len(jobs) == 6 * 3 == len({j.key for j in jobs})
    zhang = {j.params for j in jobs if j.controller == "zhang2019-v1"}
    assert zhang == {
        (("alpha0", 0.1), ("switch_distance", 1.0)),
        (("alpha0", 0.1), ("switch_distance", 1.5)),
    }
    generated = [j for j in jobs if j.generator_seed is not None]
    assert {j.seed for j in generated} == {0, 1, 2, 3}
    assert all(j.seed == j.generator_seed for j in generated)  # episode seed = scenario seed
    assert {j.scenario_label for j in jobs if j.scenario} == {"thesis-ch2-one-obstacle"}
    assert spec.config()["controllers"][0]["grid"] == {"switch_distance": [1.0, 1.5]}


def test_seed_forms() -> None:
    def seeds(value: object) -> list[int]:
        data = {**SMALL, "scenarios": [{"generator": "random-ch2", "seeds": value}]}
        return campaign_from_dict(data).scenarios[0].seed_list()

    assert seeds([3, 6]) == [3, 4, 5]  # two integers: the range [start, stop)
    assert seeds([9]) == [9]
    assert seeds([5, 1, 7]) == [5, 1, 7]
    assert seeds({"values": [7, 3]}) == [7, 3]  # two explicit seeds
    for bad, fragment in [
        ([6, 3], "needs start < stop"),
        ([1, 2, 2], "duplicate seed"),
        ([-1], ">= 0"),
        ([], "empty"),
    ]:
        with pytest.raises(CampaignError, match=fragment):
            seeds(bad)


def test_generator_params_oracle_and_file_entries(tmp_path: Path) -> None:
    scene = write(
        tmp_path,
        "name: lane\nrobot: {start: [0, 0], goal: [4, 0], v_max: 1.0, u_max: 1.0}\n",
        "lane.yaml",
    )
    spec = campaign_from_dict(
        {
            "name": "mixed",
            "scenarios": [
                {"generator": "random-ch2", "seeds": {"values": [7]}, "params": {"n_obstacles": 2}},
                {"file": scene.name, "seeds": [0, 1]},
            ],
            "controllers": [{"name": "straight-v1", "oracle": True}],
        },
        base_dir=tmp_path,
    )
    gen, from_file = spec.jobs()
    assert gen.scenario_label == "random-ch2[n_obstacles=2]/0007"
    assert gen.family_label == "random-ch2[n_obstacles=2]"
    assert gen.params == (("oracle", True),)
    assert from_file.scenario_label == "lane.yaml" and from_file.scenario == str(scene)
    # a plain generator job keeps the label (and resume key) campaigns stored before
    assert Job(controller="c", seed=7, generator_seed=7).scenario_label == "random-ch2/0007"
    assert "random-ch2" in GENERATORS


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("name: x\nscenarios: []\ncontrollers: [{name: straight-v1}]\n", ["scenarios", "at least"]),
        (
            "name: x\nscenarios: [{generator: nope, seeds: [0, 2]}]\ncontrollers: [{name: z}]\n",
            ["scenarios.0.generator", "unknown generator 'nope'", "random-ch2"],
        ),
        (
            "name: x\nscenarios: [{generator: random-ch2, seeds: [0, 2], param: {}}]\n"
            "controllers: [{name: straight-v1}]\n",
            ["scenarios.0.param", "unknown field", "allowed: generator, builtin, file"],
        ),
        (
            "name: x\nscenarios: [{generator: random-ch2, seeds: [0, 2], params: {n: 1}}]\n"
            "controllers: [{name: straight-v1}]\n",
            ["scenarios.0.params", "random-ch2", "'n'"],
        ),
        (
            "name: x\nscenarios: [{builtin: nowhere, seeds: [0, 2]}]\n"
            "controllers: [{name: straight-v1}]\n",
            ["scenarios.0.builtin", "unknown built-in scenario 'nowhere'", "file:"],
        ),
        (
            "name: x\nscenarios: [{generator: random-ch2, builtin: open-field, seeds: [0, 2]}]\n"
            "controllers: [{name: straight-v1}]\n",
            ["scenarios.0", "exactly one of generator, builtin, file"],
        ),
        (
            "name: x\nscenarios: [{generator: random-ch2, seeds: [0, 2]}]\n"
            "controllers: [{name: no-such-law-v1}]\n",
            ["controllers.0.name", "unknown controller 'no-such-law-v1'"],
        ),
        (
            "name: x\nscenarios: [{generator: random-ch2, seeds: [0, 2]}]\n"
            "controllers: [{name: zhang2019-v1, grid: {alpha00: [1, 2]}}]\n",
            ["controllers.0.grid", "alpha00"],
        ),
        (
            "name: x\nscenarios: [{generator: random-ch2, seeds: [2, 0]}]\n"
            "controllers: [{name: straight-v1}]\n",
            ["scenarios.0.seeds", "start < stop"],
        ),
        (
            "name: x\nscenarios: [{file: missing.yaml, seeds: [0, 1]}]\n"
            "controllers: [{name: straight-v1}]\n",
            ["scenarios.0.file", "no such scenario file"],
        ),
        ("name: x\nname: y\n", ["line 2", "duplicate key 'name'"]),
        ("- just\n- a list\n", ["<root>", "mapping"]),
    ],
)
def test_bad_files_give_one_line_naming_file_and_field(
    tmp_path: Path, text: str, fragments: list[str]
) -> None:
    path = write(tmp_path, text)
    with pytest.raises(CampaignError) as info:
        load_campaign(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{path}: ")
    for fragment in fragments:
        assert fragment in message


def test_bad_scenario_file_is_reported_through_the_campaign(tmp_path: Path) -> None:
    write(tmp_path, "name: lane\nrobot: {start: [0, 0], goal: [4, 0], v_max: -1}\n", "bad.yaml")
    path = write(
        tmp_path,
        "name: x\nscenarios: [{file: bad.yaml, seeds: [0, 1]}]\n"
        "controllers: [{name: straight-v1}]\n",
    )
    with pytest.raises(CampaignError, match=r"scenarios\.0\.file: .*bad\.yaml: robot\.v_max"):
        load_campaign(path)
    assert not Path("bad.yaml").exists()  # resolved against the campaign file, not the cwd


def test_existing_campaign_needs_resume(tmp_path: Path) -> None:
    spec = campaign_from_dict({**SMALL, "controllers": [{"name": "straight-v1"}]})
    with ResultsStore(tmp_path / "r.sqlite") as store:
        assert run_campaign_spec(store, spec).ran == 3
        with pytest.raises(CampaignError, match="--resume"):
            run_campaign_spec(store, spec)
        again = run_campaign_spec(store, spec, resume=True)
        assert (again.ran, again.skipped) == (0, 3)


def test_one_and_two_workers_store_identical_metrics(tmp_path: Path) -> None:
    spec = campaign_from_dict(SMALL)  # 6 episodes: straight-v1 and zhang2019-v1 on random-ch2
    frames, tables = [], []
    for workers in (1, 2):
        with ResultsStore(tmp_path / f"w{workers}.sqlite") as store:
            run = run_campaign_spec(store, spec, workers=workers)
            assert (run.ran, run.errors) == (6, 0)
            df = store.episodes_frame("small")
            frames.append(df.sort_values(["controller", "seed"]).reset_index(drop=True))
            tables.append(controller_summary(store, "small"))
    cols = ["scenario", "controller", "params_hash", "seed", "status", *DETERMINISTIC]
    assert frames[0][cols].equals(frames[1][cols])
    for row in tables[0] + tables[1]:
        for col in TIMING_COLUMNS:
            row.pop(col)
    assert tables[0] == tables[1]
    assert {r["controller"] for r in tables[0]} == {"straight-v1", "zhang2019-v1"}
    zhang = next(r for r in tables[0] if r["controller"] == "zhang2019-v1")
    assert zhang["episodes"] == 3 and zhang["success_rate"] == 1.0


@pytest.mark.parametrize(
    ("where", "field", "value"),
    [
        ("controller", "oracle", "yes"),
        ("controller", "oracle", 1),
        ("campaign", "record", "true"),
        ("campaign", "beyond_assumptions", "no"),
    ],
)
def test_a_switch_is_true_or_false_not_a_word_or_a_number(
    where: str, field: str, value: object
) -> None:
    controller: dict[str, object] = {"name": "zhang2019-v1"}
    data: dict[str, object] = {
        "name": "switches",
        "scenarios": [{"generator": "random-ch2", "seeds": [0, 1]}],
        "controllers": [controller],
    }
    (controller if where == "controller" else data)[field] = value
    with pytest.raises(CampaignError, match=f"{field}: expected true or false") as info:
        campaign_from_dict(data, "switches.yaml")
    assert "\n" not in str(info.value)
    (controller if where == "controller" else data)[field] = True
    assert campaign_from_dict(data, "switches.yaml").name == "switches"


def test_a_grid_of_more_parameter_sets_than_the_limit_is_refused_before_expanding() -> None:
    grid = {f"k{i}": list(range(20)) for i in range(9)}  # 20^9 sets: expanding them never ends
    data = {
        "name": "huge-grid",
        "scenarios": [{"generator": "random-ch2", "seeds": [0, 2]}],
        "controllers": [{"name": "dwa-v1", "grid": grid}],
    }
    with pytest.raises(CampaignError, match=r"controllers\.0\.grid: 20 x 20 .* = 5\.12e\+11 "):
        campaign_from_dict(data, "huge.yaml")
    data["controllers"] = [{"name": "dwa-v1", "grid": {"safety_margin": [0.2, 0.3]}}]
    assert len(campaign_from_dict(data, "small.yaml").jobs()) == 4
