"""`bench navigation --suite barn` (issue 34, part 2): the challenge's score, reference length and start jitter,
and a real run of one BARN world through the benchmark's study machinery."""

import math
import os
from pathlib import Path

import numpy as np
import pytest

from swarmnav.benchmarks import barn
from swarmnav.benchmarks.navigation import benchmark_navigation
from swarmnav.cli.main import main

DATA = Path(__file__).resolve().parents[2] / "shared/benchmarks/barn"
needs_barn = pytest.mark.skipif(not (DATA / "worlds").is_dir() and not os.environ.get(barn.ENV_DIR),
                                reason="the BARN data (../shared) is not here")


def test_score_clips_time_between_two_and_eight_optimal_times():
    assert barn.run_score(True, 5.0, 5.0) == 0.5          # faster than 2 OT still scores OT / 2 OT
    assert barn.run_score(True, 20.0, 5.0) == 0.25
    assert barn.run_score(True, 100.0, 5.0) == 0.125      # slower than 8 OT scores OT / 8 OT
    assert barn.run_score(False, 20.0, 5.0) == 0.0 and barn.run_score(True, None, 5.0) == 0.0


def test_start_jitter_is_seeded_bounded_and_zero_for_run_zero():
    assert barn.start_jitter(6, 0) == (0.0, 0.0, 0.0)
    draws = [barn.start_jitter(6, j) for j in range(1, 10)]
    assert draws == [barn.start_jitter(6, j) for j in range(1, 10)]
    assert len(set(draws)) == 9 and barn.start_jitter(12, 1) != draws[0]
    assert all(abs(dx) <= 0.05 and abs(dy) <= 0.05 and abs(dh) <= 3.0 for dx, dy, dh in draws)


def test_worlds_option():
    assert barn.parse_worlds("test") == tuple(range(0, 300, 6)) and len(barn.parse_worlds("test")) == 50
    assert barn.parse_worlds("0:12:6") == (0, 6) and barn.parse_worlds("3,5") == (3, 5)
    for bad in ("300", "1,1", "x", "5:5"):
        with pytest.raises(Exception, match="--barn-worlds"):
            barn.parse_worlds(bad)


@needs_barn
def test_reference_length_is_the_polyline_through_the_path_cells():
    cells = np.load(DATA / "paths/path_0.npy")
    points = [(-2.25, 3.0)] + [(0.15 * a - 4.575, 0.15 * b + 5.075) for a, b in cells] + [(-2.25, 13.0)]
    expected = sum(math.dist(p, q) for p, q in zip(points, points[1:]))
    assert math.isclose(barn.reference_length_m(DATA, 0), expected, rel_tol=1e-12)


@needs_barn
def test_one_world_runs_through_the_benchmark(tmp_path):
    rows = benchmark_navigation(navigators=["follow"], suite="barn", by_scenario=True, out_dir=str(tmp_path),
                                barn={"worlds": (294,), "runs": 1, "dir": str(DATA), "setup": "stand-in"})
    overall = {r["navigator"]: r for r in rows if r["scenario"] is None}
    per_run = [r for r in rows if r["scenario"] is not None and r["navigator"] == "follow"]
    assert set(overall) == {"follow"} and overall["follow"]["runs"] == 1 and len(per_run) == 1  # no oracle here
    for r in per_run:  # each run's score is the challenge's, from its own outcome and time
        assert r["world"] == 294 and r["barn_score"] == barn.run_score(r["success_rate"] == 1.0, r["time_s"],
                                                                         r["optimal_time_s"])
        assert set(r["difficulty"]) == {"distance_to_closest_obstacle", "average_visibility", "dispersion",
                                        "characteristic_dimension", "tortuosity"}
    assert overall["follow"]["barn_score"] == per_run[0]["barn_score"]
    assert overall["follow"]["barn_setup"] == barn.STAND_IN_TEXT
    texts = sorted((tmp_path / "scenarios").glob("*.toml"))
    assert [t.name for t in texts] == ["barn-294-r0.toml"]


def test_barn_options_are_checked(tmp_path, capsys):
    assert main(["bench", "navigation", "--barn-runs", "2"]) == 2
    assert "--barn-runs: applies to --suite barn only" in capsys.readouterr().err
    assert main(["bench", "navigation", "--suite", "barn", "--barn-dir", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--barn-dir: no BARN data" in err


def test_barn_like_worlds_are_seeded_passable_and_barn_shaped():
    from swarmnav.benchmarks.barn_difficulty import c_space, field_grid
    from swarmnav.benchmarks.barn_like import FILLS, SMOOTHINGS, generate, parameters
    assert {parameters(s) for s in range(12)} == {(f, k) for f in FILLS for k in SMOOTHINGS}
    world, cells, _ = generate(7)
    again, cells_again, _ = generate(7)
    assert world == again and np.array_equal(cells, cells_again) and generate(8)[0] != world
    xy = np.array([[c.x_m, c.y_m] for c in world.cylinders])
    space = c_space(field_grid(xy))
    assert not space[cells[:, 1], cells[:, 0]].any()      # the reference path runs over free C-space cells
    assert cells[0, 1] == 0 and cells[-1, 1] == 29 and np.abs(np.diff(cells, axis=0)).max() == 1
    assert all(c.radius_m == 0.075 for c in world.cylinders)
    from swarmnav.benchmarks.barn_like import draw_field, clear_passage, passable
    dense = draw_field(np.random.default_rng(0), 0.30, 2)        # BARN's densest pair: a passage is cut
    assert not passable(dense) and passable(clear_passage(dense)) and clear_passage(dense)[:, [0, -1]].all()
    assert {round(c.x_m, 3) for c in world.cylinders if c.y_m < 5} == {-4.425, -0.075} | {
        round(0.15 * k - 4.575, 3) for k in range(2, 30)}  # the entry corridor's walls, as in BARN's files


def test_barn_like_suite_files(tmp_path):
    from swarmnav.models.scenario import load_scenario
    paths, meta, setup = barn.write_barn_suite(str(tmp_path), False, (3, 4), 2, generated=True)
    assert sorted(meta) == ["barnlike-3-r0", "barnlike-3-r1", "barnlike-4-r0", "barnlike-4-r1"]
    first, jittered = load_scenario(paths[0]), load_scenario(paths[1])
    assert first.sim.stop_on_collision and first.time_limit_s == 100.0 and first.goal_tolerance_m == 1.0
    assert len(first.obstacles) == len(jittered.obstacles) and first.start != jittered.start
    assert meta["barnlike-3-r0"].optimal_time_s == meta["barnlike-3-r1"].optimal_time_s > 10.0 / 2.0


def test_known_map_track_planner_is_written_and_checked(tmp_path):
    from swarmnav.models.errors import ConfigError
    from swarmnav.models.scenario import load_scenario
    planner = barn.parse_planner("mmas:cell_m=0.15")
    paths, _, setup = barn.write_barn_suite(str(tmp_path), False, (5,), 1, generated=True, planner=planner)
    scenario = load_scenario(paths[0])
    assert scenario.planner_name == "mmas" and scenario.planner_params == {"cell_m": 0.15}
    assert setup.startswith("known-map track: planner mmas (cell_m=0.15)")
    with pytest.raises(ConfigError, match="--barn-planner"):
        barn.parse_planner("mmas:cell_m=-1")


def test_setup_is_the_most_of_the_protocol_installed_or_the_forced_stand_in():
    tables, text = barn.protocol_tables()
    assert text in (barn.PROTOCOL_TEXT, barn.PARTIAL_TEXT, barn.STAND_IN_TEXT)
    assert barn._loads(tables)  # whatever was chosen loads in this installation
    assert barn.protocol_tables("stand-in") == (barn.STAND_IN, barn.STAND_IN_TEXT)
