"""The one run composition: seeds that say what they seed, navigators by name, one namespace."""

import json
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from swarmnav.controllers.navigators import NAVIGATORS
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import Seeds, parse_scenario
from swarmnav.cli.main import main
from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode

ROOT = Path(__file__).resolve().parent.parent

RANDOM_WALKS = """
name = "walkers"
seed = 4
time_limit_s = 6.0
arena = { width_m = 4.0, height_m = 4.0 }
start = { x = 0.5, y = 0.5 }
goal = { x = 3.5, y = 3.5 }

[[obstacles]]
x = 2.0
y = 1.0
radius_m = 0.2
motion = { kind = "random_walk", step_m = 0.2, period_s = 0.5 }

[[obstacles]]
x = 1.0
y = 2.5
radius_m = 0.2
motion = { kind = "random_walk", step_m = 0.2, period_s = 0.5 }
"""


def tracks(world_seed, text=RANDOM_WALKS):
    spec = EpisodeSpec(parse_scenario(text), "straight", world_seed=world_seed).resolved()
    times = np.arange(0.0, 6.0, 0.02)
    return np.stack([ob.trajectory().positions_at(times) for ob in spec.scenario.obstacles])


def test_world_seed_changes_the_world_and_only_the_world():
    assert np.array_equal(tracks(1), tracks(1))
    assert not np.array_equal(tracks(1), tracks(2))
    # The planner's seed never moves an obstacle: the default world seed is the file's seed.
    a = EpisodeSpec(parse_scenario(RANDOM_WALKS), "straight", seed=0).resolved()
    b = EpisodeSpec(parse_scenario(RANDOM_WALKS), "straight", seed=9).resolved()
    assert a.world_seed == b.world_seed == 4
    assert np.array_equal(tracks(None), tracks(4))


def test_adding_an_obstacle_does_not_shift_the_others_draws():
    extra = RANDOM_WALKS + ('\n[[obstacles]]\nx = 3.0\ny = 2.0\nradius_m = 0.2\n'
                            'motion = { kind = "random_walk", step_m = 0.2, period_s = 0.5 }\n')
    assert np.array_equal(tracks(7, extra)[:2], tracks(7))


def test_run_gives_other_obstacle_tracks_for_another_world_seed(tmp_path, capsys):
    path = tmp_path / "walkers.toml"
    path.write_text(RANDOM_WALKS)
    outputs = []
    for world_seed in (1, 1, 2):
        out = tmp_path / f"w{len(outputs)}.mcap"
        assert main(["run", str(path), "--planner", "straight", "--world-seed", str(world_seed),
                     "--out", str(out), "--json"]) == 0
        summary = json.loads(capsys.readouterr().out)
        assert summary["world_seed"] == world_seed and summary["navigator"] == "follow"
        outputs.append(out.read_bytes())
    assert outputs[0] == outputs[1]
    assert outputs[0] != outputs[2]


def test_a_scenario_names_its_navigator_and_the_command_line_overrides_it(tmp_path, capsys):
    path = tmp_path / "nav.toml"
    path.write_text(RANDOM_WALKS + '\n[navigator]\nname = "follow"\nparams = {}\n')
    assert main(["plan", str(path), "--planner", "straight", "--json"]) == 0
    capsys.readouterr()
    code = main(["run", str(path), "--planner", "straight", "--navigator", "teleport", "--no-log"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--navigator" in err and "navigator.name" in err
    code = main(["run", str(path), "--planner", "straight", "--navigator-set", "gain=3", "--no-log"])
    err = capsys.readouterr().err
    assert code == 2 and "navigator.params.gain" in err and "--navigator-set" in err
    path.write_text(RANDOM_WALKS + '\n[navigator]\nname = "teleport"\n')
    assert main(["plan", str(path), "--planner", "straight"]) == 2
    assert "navigator.name" in capsys.readouterr().err


def test_scenario_parameters_apply_only_to_the_scenario_s_own_planner():
    scenario = parse_scenario(RANDOM_WALKS + '\n[planner]\nname = "astar"\nparams = { cell_m = 0.1 }\n')
    assert EpisodeSpec(scenario).resolved().planner_params == {"cell_m": 0.1}
    assert EpisodeSpec(scenario, "astar", {"cell_m": 0.2}).resolved().planner_params == {"cell_m": 0.2}
    assert EpisodeSpec(scenario, "theta_star").resolved().planner_params == {}


def crossing_case():
    """A 5 m arena that one obstacle crosses: ``replan`` replans in it."""
    from swarmnav.models.scenario_generator import GeneratorOptions, generate
    return parse_scenario(generate("crossing", 7, GeneratorOptions(obstacles=1, arena_m=5.0, speed_ratio=0.5,
                                                                    range_m=1.0)))


def test_the_navigator_draws_from_its_own_stream(monkeypatch):
    """``replan`` replans with ABC, which draws from the navigator's generator: the same seed gives the same
    run, and another navigator stream under the same seed leaves the plan but changes the replanned drive."""
    from swarmnav.sim import episode as episode_module

    # A small colony (10 x 10): each replan is a whole ABC run, and the stream matters, not the colony's size.
    spec = EpisodeSpec(crossing_case(), "abc", {"population": 10, "iterations": 10}, navigator="replan", seed=3)
    first = run_episode(spec)
    second = run_episode(spec)
    assert first.result.replans >= 1
    assert np.array_equal(first.result.poses, second.result.poses)
    monkeypatch.setattr(episode_module, "NAVIGATOR_STREAM", episode_module.NAVIGATOR_STREAM + 1)
    other = run_episode(spec)
    assert other.path.same_as(first.path)  # the planner's stream is untouched
    assert plan_episode(spec).path.same_as(first.path)
    assert other.result.poses.shape != first.result.poses.shape or \
        not np.array_equal(other.result.poses, first.result.poses)


def test_a_world_seed_set_on_the_scenario_is_kept_and_an_explicit_one_wins():
    scenario = parse_scenario(RANDOM_WALKS).with_world_seed(7)
    spec = EpisodeSpec(scenario, "straight").resolved()
    assert spec.world_seed == 7 and spec.seeds == Seeds(planner=4, world=7)
    times = np.arange(0.0, 6.0, 0.02)
    assert np.array_equal(np.stack([ob.trajectory().positions_at(times) for ob in spec.scenario.obstacles]),
                          tracks(7))
    assert EpisodeSpec(scenario, "straight", seed=1, world_seed=2).seeds == Seeds(planner=1, world=2)
    assert EpisodeSpec(parse_scenario(RANDOM_WALKS)).seeds == parse_scenario(RANDOM_WALKS).seeds == Seeds(4, 4)


def test_one_seed_derives_two_distinct_reproducible_seeds():
    derived = [Seeds.derived(s) for s in range(50)]
    assert derived == [Seeds.derived(s) for s in range(50)]
    assert len({d.planner for d in derived} | {d.world for d in derived}) == 100
    for bad in (-1, 1.5, True):
        with pytest.raises(ConfigError) as info:
            Seeds(0, bad)
        assert info.value.field == "seeds.world"


@pytest.mark.parametrize("name", sorted(NAVIGATORS))
def test_every_navigator_declares_what_it_uses(name, contract_policy):
    """The seam's declarations (controllers.navigator.Navigator) are there, typed, and honest about the
    planner: one that declares it never uses the planner runs with ``setup.planner`` None."""
    from swarmnav.models.scenario import load_scenario

    navigator = NAVIGATORS[name](**NEEDS_PARAMS.get(name, {}))
    assert isinstance(navigator.uses_detections, bool) and isinstance(type(navigator).uses_planner, bool)
    assert navigator.replan_wall_s == 0.0
    spec = EpisodeSpec(load_scenario("gwo-scenario-2"), "astar", navigator=name,
                       navigator_params=NEEDS_PARAMS.get(name))
    result = run_episode(spec, time_limit_s=2.0).result
    assert result.steps > 0 and result.replan_wall_s >= 0.0


def test_the_wheel_installs_one_namespace_and_nothing_named_models(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(tmp_path),
                           str(ROOT)], capture_output=True, text=True)
    if proc.returncode != 0:
        pytest.fail(f"pip wheel failed: {proc.stderr[-2000:]}")
    wheel = next(tmp_path.glob("swarmnav-*.whl"))
    names = zipfile.ZipFile(wheel).namelist()
    tops = {name.split("/")[0] for name in names}
    assert {top for top in tops if not top.endswith(".dist-info")} == {"swarmnav"}
    # Every module and bundled data file (scenarios, maps, studies, MJCF) of a mapped folder ships, at the
    # place pyproject's package-dir gives it (the deepest mapped folder holding it decides).
    import tomllib
    mapping = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"]
    folders = sorted(((ROOT / folder, package) for package, folder in mapping.items()),
                     key=lambda item: len(item[0].parts), reverse=True)
    missing, shipped = [], 0
    for folder, _ in folders:
        for source in folder.rglob("*"):
            if not source.is_file() or "__pycache__" in source.parts or \
                    source.suffix not in (".py", ".toml", ".xml", ".map", ".scen", ".md"):
                continue
            owner, package = next((f, p) for f, p in folders if source.is_relative_to(f))
            if owner != folder:
                continue
            expected = "/".join([*package.split("."), *source.relative_to(folder).parts])
            shipped += expected in names
            if expected not in names:
                missing.append(str(source.relative_to(ROOT)))
    assert shipped > 100 and not missing


NEEDS_PARAMS = {"policy": {"policy": "contract_policy:act"}}


@pytest.fixture
def contract_policy(tmp_path, monkeypatch):
    (tmp_path / "contract_policy.py").write_text("def act(obs):\n    return [0.5, 0.1]\n")
    monkeypatch.syspath_prepend(str(tmp_path))


@pytest.mark.parametrize("name", sorted(NAVIGATORS))
def test_every_navigator_is_deterministic_and_names_a_bad_parameter(name, contract_policy):
    from swarmnav.models.errors import ConfigError
    from swarmnav.models.scenario import load_scenario

    scenario = load_scenario("gwo-scenario-2")
    spec = EpisodeSpec(scenario, "astar", navigator=name, navigator_params=NEEDS_PARAMS.get(name))
    planned = plan_episode(spec)
    first = run_episode(planned, time_limit_s=3.0).result
    again = run_episode(planned, time_limit_s=3.0).result  # the same navigator, reset for its second run
    fresh = run_episode(spec, time_limit_s=3.0).result
    assert first.steps > 0 and np.array_equal(first.poses, again.poses) and np.array_equal(first.poses, fresh.poses)
    with pytest.raises(ConfigError) as info:
        plan_episode(EpisodeSpec(scenario, "astar", navigator=name,
                                 navigator_params={**NEEDS_PARAMS.get(name, {}), "no_such_knob": 1}))
    assert info.value.field == "navigator.params.no_such_knob"


def test_a_navigator_that_does_not_declare_what_it_uses_is_refused_at_registration():
    from swarmnav.controllers.navigators import register
    from swarmnav.controllers.navigators.follow import FollowNavigator

    class Undeclared:
        name = "undeclared"
        uses_detections = False

    with pytest.raises(TypeError, match="uses_planner, replan_wall_s"):
        register(Undeclared)
    assert "undeclared" not in NAVIGATORS

    class HalfDeclared(FollowNavigator):
        name = "half_declared"
        uses_planner = "no"

    with pytest.raises(TypeError, match="does not declare uses_planner"):
        register(HalfDeclared)

    class Stepless:
        name = "stepless"
        uses_detections = False
        uses_planner = False
        replan_wall_s = 0.0

        def reset(self, setup):
            pass

    with pytest.raises(TypeError, match="no step method"):
        register(Stepless)
    assert "stepless" not in NAVIGATORS


def test_only_the_composition_resolves_a_spec_or_builds_an_episode():
    """sim/runtime/episode.py is the one place (compose, plan_episode, given_episode): the CLI, the API, studies,
    given paths and the environment all go through it."""
    import pathlib
    import re
    root = pathlib.Path(__file__).resolve().parents[1]
    sources = [p for folder in ("models", "planners", "controllers", "sim") for p in (root / folder).rglob("*.py")]
    assert len(sources) > 100
    offenders = [str(p.relative_to(root)) for p in sources if p.name != "episode.py"
                 and re.search(r"(?<![\w.])Episode\(|\.resolved\(\)", p.read_text())]
    assert not offenders


def test_a_given_path_is_composed_as_a_planned_run_and_a_path_alone_builds_no_navigator():
    from swarmnav.sim.episode import compose, given_episode
    from swarmnav.models.scenario import load_scenario
    spec = EpisodeSpec(load_scenario("gwo-scenario-1"), "astar", navigator="replan")
    planned = plan_episode(spec)
    given = given_episode(spec, planned.path.waypoints, "test")
    assert given.planner_params == planned.planner_params and "cell_m" in given.planner_params
    assert type(given.navigator) is type(planned.navigator) and given.safety == planned.safety
    assert given.safety.evade and np.array_equal(given.path.waypoints, planned.path.waypoints)
    parts = compose(spec, drive=False)
    assert parts.navigator is None and parts.safety is None
    assert plan_episode(parts).path.same_as(planned.path)
