"""Grid planners (A*, Dijkstra, Theta*, D* Lite, IMMAS, IACO, M-ACO), maps and Moving AI checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from swarmnav.models.scenario import list_scenarios, load_scenario, parse_scenario
import json

from swarmnav.planners.registry import PLANNERS, make_planner
from swarmnav.cli import main as cli
from swarmnav.models.errors import ConfigError
from swarmnav.planners.errors import NoPathFound
from swarmnav.models.geometry import segment_box_distance, segment_box_distances
from swarmnav.planners.dstar_lite import DStarLite
from swarmnav.planners.grid_graph import grid_line_of_sight, move_masks
from swarmnav.planners.grid_search import astar_cells, dijkstra_cells
from swarmnav.planners.theta_star import theta_star_cells
from swarmnav.planners.grid_shortcut import box_line_of_sight
from swarmnav.planners.colony_walk import GridGraph, walk_colony
from swarmnav.planners.improved_ant_colony import (adaptive_parameters, feature_cells, iaco_heuristic, pheromone_intensity,
                                          prune_length)
from swarmnav.models.world import Box, OccupancyGrid, Pose2D, Rect
from swarmnav.planners.problem import Problem
from swarmnav.planners.pheromone_propagation import analyse_environment
from swarmnav.planners.problem import map_problem
from swarmnav.models.grid_map import benchmark_sets, format_map, map_to_grid, merge_boxes, parse_map, read_map, read_scenarios
from swarmnav.planners.problem import scenario_problem

# Every planner that avoids obstacles on a grid map (``straight`` does not avoid them).
MAP_PLANNERS = sorted(name for name, cls in PLANNERS.items() if "boxes" in cls.supports and name != "straight")
MAP_SCENARIOS = [n for n in list_scenarios() if n.startswith(("immas-", "iaco-")) and "dynamic" not in n]
FAST = {"iaco": {"ants": 20, "iterations": 15}}


def draw(rows: list[str]) -> np.ndarray:
    """A world grid from text drawn top row first ('#' blocked)."""
    return np.array([[ch == "#" for ch in row] for row in rows], dtype=bool)[::-1]


# -- maps ----------------------------------------------------------------------

def test_map_reader_flips_rows_and_merged_boxes_cover_exactly_the_occupied_cells():
    text = format_map(np.array([[1, 0, 0], [1, 1, 0]], dtype=bool))
    occ = parse_map(text)
    assert occ.tolist() == [[True, False, False], [True, True, False]]
    grid = map_to_grid(occ, 0.5)
    assert grid.occupied[0].tolist() == [True, True, False]       # the file's last row is y = 0
    rng = np.random.default_rng(3)
    world = rng.random((20, 30)) < 0.3
    boxes = merge_boxes(world, 0.25)
    covered = np.zeros_like(world, dtype=int)
    for b in boxes:
        c0, c1 = round(b.x_min_m / 0.25), round(b.x_max_m / 0.25)
        r0, r1 = round(b.y_min_m / 0.25), round(b.y_max_m / 0.25)
        covered[r0:r1, c0:c1] += 1
    assert np.array_equal(covered, world.astype(int))             # disjoint and exact
    assert len(boxes) < world.sum()


def test_bad_map_text_is_a_config_error():
    with pytest.raises(ConfigError):
        parse_map("type octile\nheight 2\nwidth 2\nmap\n..\n.x\n")


def test_segment_box_distance_matches_dense_sampling():
    rng = np.random.default_rng(0)
    a, b = rng.uniform(-2, 2, (60, 2)), rng.uniform(-2, 2, (60, 2))
    lo = rng.uniform(-1, 0.5, (5, 2))
    boxes = np.hstack([lo, lo + rng.uniform(0.1, 1, (5, 2))])
    d = segment_box_distances(a, b, boxes)
    t = np.linspace(0, 1, 4001)[:, None, None]
    p = a[None] * (1 - t) + b[None] * t
    gap = np.maximum(np.maximum(boxes[None, None, :, :2] - p[:, :, None], p[:, :, None] - boxes[None, None, :, 2:]), 0)
    assert np.allclose(np.hypot(gap[..., 0], gap[..., 1]).min(axis=0), d, atol=2e-3)


@pytest.mark.parametrize("snap", [False, True])
def test_scalar_and_vectorised_segment_box_distances_agree(snap):
    rng = np.random.default_rng(11)
    a, b = rng.uniform(-2, 2, (300, 2)), rng.uniform(-2, 2, (300, 2))
    lo = rng.uniform(-1, 0.5, (6, 2))
    boxes = np.hstack([lo, lo + rng.uniform(0.1, 1, (6, 2))])
    if snap:       # on a 0.5 lattice: axis-parallel, zero-length, touching and grazing segments
        a, b, boxes = np.round(a * 2) / 2, np.round(b * 2) / 2, np.round(boxes * 2) / 2
    scalar = [[segment_box_distance(*a[i], *b[i], *box) for box in boxes] for i in range(len(a))]
    assert np.allclose(scalar, segment_box_distances(a, b, boxes), rtol=0, atol=1e-12)


def off_lattice_boxes_problem() -> Problem:
    """Boxes off the cell edges, inflation wider than a cell, and an all-free grid: the box test decides alone."""
    rng = np.random.default_rng(2)
    lo = rng.uniform(0.5, 5.0, (8, 2))
    hi = lo + rng.uniform(0.05, 1.0, (8, 2))
    boxes = tuple(Box(x0, y0, x1, y1) for (x0, y0), (x1, y1) in zip(lo.tolist(), hi.tolist()))
    grid = OccupancyGrid(np.zeros((120, 120), dtype=bool), 0.05, (0.0, 0.0))
    return Problem(Pose2D(0.1, 0.1), Pose2D(5.9, 5.9), Rect(0.0, 0.0, 6.0, 6.0), (), robot_radius_m=0.37,
                   clearance_m=0.0, boxes=boxes, cell_m=0.05, grid_override=grid)


@pytest.mark.parametrize("scenario_name", ["iaco-complex", "immas-env2-rings", "off-lattice"])
def test_box_line_of_sight_equals_the_test_against_every_box(scenario_name):
    if scenario_name == "off-lattice":
        problem = off_lattice_boxes_problem()
    else:
        problem = scenario_problem(load_scenario(scenario_name))
    grid = problem.grid
    los = box_line_of_sight(problem, grid)
    free = (~grid.occupied).tolist()
    free_cells = np.argwhere(~grid.occupied)
    rng = np.random.default_rng(5)
    pairs = free_cells[rng.integers(len(free_cells), size=(300, 2))]
    # Short segments too: most of Theta*'s questions are local, near obstacles.
    near = np.clip(pairs[:, 0] + rng.integers(-4, 5, (300, 2)), 0, np.array(grid.shape) - 1)
    pairs = np.concatenate([pairs, np.stack([pairs[:, 0], near], axis=1)])
    answers = []
    for p, q in pairs:
        p, q = tuple(p.tolist()), tuple(q.tolist())
        centres = grid.centres_m(np.array([p, q]))
        d = segment_box_distances(centres[:1], centres[1:], problem.box_array_m)
        expected = grid_line_of_sight(free, p, q) and bool(np.all(d - problem.inflation_m >= -1e-9))
        assert los(p, q) == expected, (p, q)
        answers.append(expected)
    assert 0 < sum(answers) < len(answers)


def test_map_scenarios_load_with_boxes_and_a_grid_at_map_resolution():
    assert len(MAP_SCENARIOS) == 10
    scenario = load_scenario("immas-env1-scattered")
    problem = scenario_problem(scenario)
    assert problem.grid.shape == (50, 50) and problem.grid.cell_m == pytest.approx(0.4)
    assert 0 < len(scenario.boxes) < problem.grid.occupied.sum()


def test_a_map_that_does_not_span_the_arena_is_rejected():
    text = load_scenario("iaco-simple").source_text.replace("cell_m = 0.4", "cell_m = 0.3")
    with pytest.raises(ConfigError) as err:
        parse_scenario(text, str(load_scenario("iaco-simple").source_path))
    assert err.value.field == "map.cell_m"


def test_shortcut_off_keeps_the_raw_cells():
    problem = scenario_problem(load_scenario("iaco-simple"))
    raw = make_planner("astar", {"shortcut": False}).plan(problem, np.random.default_rng(0))
    assert len(raw.waypoints) == len(raw.stats.extra["raw_cells"])
    short = make_planner("astar").plan(problem, np.random.default_rng(0))
    assert short.stats.length_m <= raw.stats.length_m + 1e-9


# -- searches ------------------------------------------------------------------

def test_no_corner_cutting_and_octile_costs():
    occ = draw(["...",
                ".#.",
                "..."])
    # Corner to corner: every diagonal move passes the blocked centre, so 4 straight moves
    # (with corner cutting it would be 2 + sqrt 2).
    cells, cost, _ = astar_cells(occ, (0, 0), (2, 2))
    assert cost == pytest.approx(4.0)
    assert dijkstra_cells(occ, (0, 0), (2, 2))[1] == pytest.approx(4.0)
    free = (~occ).tolist()
    assert not grid_line_of_sight(free, (0, 0), (2, 2))
    assert theta_star_cells(occ, (0, 0), (0, 2))[1] == pytest.approx(2.0)
    squeeze = draw([".#",
                    "#."])
    with pytest.raises(NoPathFound):
        astar_cells(squeeze, (1, 0), (0, 1))


@pytest.mark.parametrize("planner_name", MAP_PLANNERS)
def test_unreachable_goal_raises_no_path_found(planner_name):
    occ = draw(["....#....",
                "....#....",
                "....#...."])
    problem = map_problem(occ, 0.4, (1, 0), (1, 8))
    with pytest.raises(NoPathFound):
        make_planner(planner_name, FAST.get(planner_name, {})).plan(problem, np.random.default_rng(0))


def test_dstar_lite_replans_after_cells_change():
    rng = np.random.default_rng(5)
    occ = rng.random((30, 30)) < 0.2
    start, goal = (0, 0), (29, 29)
    occ[start] = occ[goal] = False
    planner = DStarLite(occ, start, goal)
    cells = planner.plan()
    assert planner.cost_cells == pytest.approx(astar_cells(occ, start, goal)[1])
    # Block part of the current path, move the robot a few cells, and replan.
    robot = cells[3]
    blocked = {cells[k]: True for k in (8, 9, 10)}
    for cell in blocked:
        occ[cell] = True
    planner.move_start(robot)
    planner.update_cells(blocked)
    replanned = planner.plan()
    assert replanned[0] == robot and replanned[-1] == goal
    assert not any(occ[c] for c in replanned)
    assert planner.cost_cells == pytest.approx(astar_cells(occ, robot, goal)[1])
    # Freeing them again restores the old cost-to-go.
    for cell in blocked:
        occ[cell] = False
    planner.update_cells({cell: False for cell in blocked})
    planner.plan()
    assert planner.cost_cells == pytest.approx(astar_cells(occ, robot, goal)[1])


# -- Moving AI -----------------------------------------------------------------

SETS = benchmark_sets()


@pytest.mark.skipif(not SETS, reason="Moving AI benchmark folder not found (set SWARMNAV_MOVINGAI_DIR)")
@pytest.mark.parametrize("search", [astar_cells, dijkstra_cells], ids=["astar", "dijkstra"])
def test_movingai_optimal_lengths_on_a_sample(search):
    checked = 0
    for map_path, scen_path in SETS:
        occ = read_map(map_path)
        scenarios = [s for s in read_scenarios(scen_path) if s.map_name.endswith(map_path.name)]
        for s in scenarios[::7]:
            _, cost, _ = search(occ, s.start_cell(), s.goal_cell())
            assert abs(cost - s.optimal_length) < 1e-4, s
            checked += 1
    assert checked > 50


# -- IMMAS ---------------------------------------------------------------------

def test_gate_raise_closes_a_cell_between_two_diagonal_obstacles():
    occ = draw(["#####",
                "...#.",
                ".....",
                ".#...",
                "....."])
    # Cell (2, 2) in world rows (middle row) has NE (3, 3) and SW (1, 1) blocked.
    assert not occ[0, 0] and not occ[2, 4]
    analysis = analyse_environment(occ, start=(0, 0), goal=(2, 4))
    assert (2, 2) in analysis.gates
    assert analysis.blocked[2, 2]


def test_tight_tunnel_entrance_is_closed_and_the_wide_way_is_taken():
    occ = draw([".........",
                ".........",
                "##.###...",
                ".........",
                "........."])
    # The one-cell gap at world row 2, column 2 is flanked by obstacles left and right.
    start, goal = (0, 0), (4, 0)
    analysis = analyse_environment(occ, start, goal)
    assert (2, 2) in analysis.tunnels and analysis.blocked[2, 2]
    assert not analysis.closing_reverted
    problem = map_problem(occ, 0.4, start, goal)
    assert [2, 2] in make_planner("astar").plan(problem, np.random.default_rng(0)).stats.extra["raw_cells"]
    wide = make_planner("immas").plan(problem, np.random.default_rng(0))
    assert [2, 2] not in wide.stats.extra["raw_cells"]
    assert wide.stats.extra["tunnels_closed"] >= 1
    assert problem.is_collision_free(wide.waypoints)


def test_closing_is_reverted_when_it_would_disconnect_start_and_goal():
    occ = draw(["....",
                "##.#",
                "...."])
    analysis = analyse_environment(occ, (0, 0), (2, 0))
    assert analysis.closing_reverted and not analysis.gates and not analysis.tunnels


def test_immas_reports_table_1_quantities():
    """Gates, tunnels and the arc cost agree with the environment analysis computed here."""
    scenario = load_scenario("immas-env1-scattered")
    problem = scenario_problem(scenario)
    planner = make_planner("immas", scenario.planner_params)
    path = planner.plan(problem, np.random.default_rng(0))
    extra = path.stats.extra
    grid = problem.grid
    start = grid.cell_of(problem.start.x_m, problem.start.y_m)
    goal = grid.cell_of(problem.goal.x_m, problem.goal.y_m)
    analysis = analyse_environment(grid.occupied, start, goal, planner.rho, planner.clean_weight,
                                   planner.diagonal_factor)
    assert extra["gates_raised"] == len(analysis.gates) and extra["tunnels_closed"] == len(analysis.tunnels)
    cells = [tuple(c) for c in extra["raw_cells"]]
    assert cells[0] == start and cells[-1] == goal
    assert extra["moves"] == len(cells) - 1
    # Every move made is an iteration; loops cut out of the tour make the moves fewer.
    assert path.stats.iterations >= extra["moves"]
    if path.stats.iterations == extra["moves"]:
        assert extra["total_arc_cost"] == pytest.approx(sum(analysis.route_cost[c] for c in cells[1:]))
    assert not any(analysis.blocked[c] for c in cells)


# -- IACO ----------------------------------------------------------------------

def test_iaco_heuristic_eq6_hand_computed():
    # From (0, 0) with the goal at (3, 4) (d_ig = 5), moving to (1, 1) (d_ij = sqrt 2, d_jg = sqrt 13),
    # straight on from the previous move (omega = 0, factor 2).
    eta = iaco_heuristic(5.0, math.sqrt(2.0), math.sqrt(13.0), 1.0)
    assert eta == pytest.approx(5.0 / (math.sqrt(2.0) + math.sqrt(13.0)) * 2.0)
    # A right-angle turn halves it; a U-turn gives zero.
    assert iaco_heuristic(5.0, 1.0, 4.0, 0.0) == pytest.approx(1.0)
    assert iaco_heuristic(5.0, 1.0, 4.0, -1.0) == pytest.approx(0.0)


def test_iaco_adaptive_parameters_eqs_9_to_11_hand_computed():
    # Nc / N = 0.5 and L_GL / (LF_best + L_GL) = 10 / (10 + 10) = 0.5, so x = 0.5.
    alpha, beta, rho = adaptive_parameters(1.0, 5.0, 2.0, 0.7, 50, 100, 10.0, 10.0, 0.3)
    assert alpha == pytest.approx(1.0 + 2.0 * math.sin(0.5 * math.pi))
    assert beta == pytest.approx(5.0 * math.exp(-2.0 * 0.25))
    assert rho == pytest.approx(0.7 * 0.5)
    # Before any best length: ratio 0, rho keeps its initial value.
    alpha, beta, rho = adaptive_parameters(1.0, 5.0, 2.0, 0.7, 1, 100, 10.0, None, 0.3)
    assert alpha == pytest.approx(1.0 + 2.0 * math.sin(0.005 * math.pi))
    assert rho == 0.3
    # Eq. (7): a path 1 cell longer than the collar line gets Q * t_c ** -1.
    assert pheromone_intensity(100.0, 1.5, 10.0, np.array([11.0]))[0] == pytest.approx(100.0 / 1.5)


def test_iaco_eq7_is_capped_above_only_and_prunes_where_deposits_vanish():
    q_m = pheromone_intensity(100.0, 1.5, 10.0, np.array([5.0, 13.0, 30.0]), exponent_limit=3.0)
    assert q_m[0] == pytest.approx(100.0 * 1.5 ** 3)              # 5 ** 3 capped at 3
    assert q_m[1] == pytest.approx(100.0 * 1.5 ** -27)             # 3 cells longer: not capped below
    assert q_m[2] == 0.0                                           # underflows: deposits nothing
    limit = prune_length(100.0, 1.5, 10.0, 1e-12)
    assert pheromone_intensity(100.0, 1.5, 10.0, np.array([limit]), 3.0)[0] == pytest.approx(1e-12)
    assert prune_length(100.0, 1.0, 10.0, 1e-12) == math.inf


def test_colony_walk_tours_are_legal_moves_and_dead_ends_are_backed_out_of():
    occ = draw(["......",
                ".####.",
                ".#..#.",
                ".#.##.",
                "......"])
    graph = GridGraph.of(OccupancyGrid(occupied=occ, cell_m=1.0, origin_m=(0.0, 0.0)))
    start, goal = graph.index((2, 2)), graph.index((4, 5))        # start in a pocket open at the bottom
    weights = np.where(graph.table >= 0, 1.0, 0.0)
    walk = walk_colony(graph, start, goal, 40, weights, None, np.random.default_rng(0), 400)
    assert walk.reached.all()
    for a in range(40):
        tour = walk.tour(a)
        assert tour[0] == start and tour[-1] == goal and len(set(tour.tolist())) == len(tour)
        for u, v in zip(tour[:-1], tour[1:]):
            assert v in graph.table[u]
        moves = np.diff(graph.cells(tour), axis=0)
        assert walk.length_cells[a] == pytest.approx(np.sum(np.hypot(*moves.T)))


def test_feature_points_are_outside_convex_corners_only():
    occ = np.zeros((6, 6), dtype=bool)
    occ[2:4, 2:4] = True                   # a 2 x 2 block: 4 convex corners, no concave one
    cells, labels, _ = feature_cells(occ)
    assert sorted(map(tuple, cells.tolist())) == [(1, 1), (1, 4), (4, 1), (4, 4)]
    assert set(labels.tolist()) == {1}


def test_iaco_reports_table_3_quantities():
    """The best tour's length, bends and convergence iteration agree with its cells and history."""
    problem = scenario_problem(load_scenario("iaco-simple"))
    path = make_planner("iaco", FAST["iaco"]).plan(problem, np.random.default_rng(1))
    extra = path.stats.extra
    cells = np.array(extra["raw_cells"])
    steps = np.diff(cells, axis=0)
    assert np.all(np.abs(steps).max(axis=1) == 1)                       # legal moves only
    assert extra["raw_length_m"] == pytest.approx(np.sum(np.hypot(*steps.T)) * problem.grid.cell_m)
    assert extra["bends"] == int(np.count_nonzero(np.any(steps[1:] != steps[:-1], axis=1)))
    # The best of all iterations is no longer than the last iteration's mean (nan when no ant
    # of the last iteration arrived).
    assert not extra["raw_length_m"] > extra["mean_length_m"] + 1e-9
    history = path.stats.cost_history
    k = extra["convergence_iteration"]
    assert history[k] == pytest.approx(extra["raw_length_m"]) and history[k - 1] > history[k]
    assert all(h == history[k] for h in history[k:])


# -- M-ACO ---------------------------------------------------------------------

def test_maco_route_is_collision_free_and_baseline_links_are_checked():
    scenario = load_scenario("restaurant-table-2")
    problem = scenario_problem(scenario)
    path = make_planner("maco", scenario.planner_params).plan(problem, np.random.default_rng(0))
    assert problem.is_collision_free(path.waypoints)
    extra = path.stats.extra
    nodes = np.array(extra["nodes_m"])
    assert extra["route"][0] == 0 and extra["route"][-1] == len(nodes) - 1
    assert problem.is_collision_free(nodes[extra["route"]])
    for label in ("dijkstra", "astar"):
        route = extra[f"{label}_route"]
        assert route[0] == 0 and route[-1] == len(nodes) - 1
        assert extra[f"{label}_length_m"] == pytest.approx(np.sum(np.hypot(*np.diff(nodes[route], axis=0).T)))
        # A link is listed as colliding exactly when the exact check rejects it.
        links = list(zip(route[:-1], route[1:]))
        colliding = [[a, b] for a, b in links if not problem.is_collision_free(nodes[[a, b]])]
        assert extra[f"{label}_colliding_links"] == colliding
    # Both baselines are optimal on the same graph.
    assert extra["astar_length_m"] == pytest.approx(extra["dijkstra_length_m"])
    # The unchecked baseline can only be as short as or shorter than the checked colony's route.
    assert extra["dijkstra_length_m"] <= extra["raw_length_m"] + 1e-9


# -- CLI -----------------------------------------------------------------------

def _walled_scenario(tmp_path, planner: str) -> str:
    rows = ["....#....", "....#....", "....#....", "....#...."]
    (tmp_path / "walled.map").write_text(format_map(np.array([[ch == "#" for ch in r] for r in rows])))
    toml = f'''name = "walled"
arena = {{ width_m = 3.6, height_m = 1.6 }}
robot = {{ radius_m = 0.15, clearance_m = 0.05 }}
start = {{ x = 0.2, y = 0.2 }}
goal = {{ x = 3.4, y = 1.4 }}
planner = {{ name = "{planner}" }}

[map]
file = "walled.map"
cell_m = 0.4
'''
    path = tmp_path / "walled.toml"
    path.write_text(toml)
    return str(path)


@pytest.mark.parametrize("planner_name", ["astar", "immas"])
def test_cli_exits_3_when_the_goal_is_unreachable(tmp_path, capsys, planner_name):
    assert cli.main(["plan", _walled_scenario(tmp_path, planner_name), "--json"]) == 3


def test_cli_plans_a_map_scenario(capsys):
    assert cli.main(["plan", "immas-env2-rings", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["planner"] == "immas" and out["collision_free"] is True


def test_dstar_lite_penalties_steer_the_path_and_their_repair_matches_a_fresh_search():
    rng = np.random.default_rng(11)
    occ = rng.random((24, 24)) < 0.15
    start, goal = (0, 0), (23, 23)
    occ[start] = occ[goal] = False
    penalty = np.zeros(occ.shape)
    penalty[:, 10:14] = 5.0  # a costly band every path must cross
    planner = DStarLite(occ, start, goal, penalty=penalty)
    cells = planner.plan()
    assert planner.cost_cells > astar_cells(occ, start, goal)[1]  # the band costs more than its length
    assert sum(10 <= c < 14 for _, c in cells) <= 6  # it is crossed as briefly as the cells allow
    # New penalties after the robot moved: the incremental repair's cost equals a fresh search's.
    robot = cells[4]
    penalty2 = penalty.copy()
    penalty2[:12, 10:14] = 0.0
    planner.move_start(robot)
    changed = planner.update_penalty(penalty2)
    assert changed == 12 * 4
    planner.plan()
    fresh = DStarLite(occ, robot, goal, penalty=penalty2)
    fresh.plan()
    assert planner.cost_cells == pytest.approx(fresh.cost_cells)
    with pytest.raises(ValueError, match="penalty"):
        planner.update_penalty(-penalty2)


def test_dstar_lite_repairs_match_a_fresh_search_over_many_changes_with_and_without_penalties():
    # Each cell's move mask is kept between repairs and recomputed over the changed cells' 3 x 3 blocks only: a
    # stale mask would show as a cost or a path through a blocked cell after some of these changes.
    rng = np.random.default_rng(3)
    for penalised in (False, True):
        occ = rng.random((25, 25)) < 0.2
        start, goal = (0, 0), (24, 24)
        occ[start] = occ[goal] = False
        penalty = rng.random(occ.shape) * 2 if penalised else None
        planner = DStarLite(occ, start, goal, penalty=penalty)
        for _ in range(15):
            changes = {(int(r), int(c)): bool(rng.random() < 0.5) for r, c in rng.integers(0, 25, (30, 2))}
            changes.pop(planner.start, None), changes.pop(goal, None)
            for cell, blocked in changes.items():
                occ[cell] = blocked
            planner.update_cells(changes)
            assert planner.masks == move_masks(occ).tolist()  # refreshed over the changed cells' blocks only
            if penalised:
                penalty = penalty.copy()
                penalty[rng.integers(0, 25)] = rng.random(25) * 2
                planner.update_penalty(penalty)
            fresh = DStarLite(occ, planner.start, goal, penalty=penalty)
            try:
                cells = planner.plan()
            except NoPathFound:
                with pytest.raises(NoPathFound):
                    fresh.plan()
                continue
            fresh.plan()
            assert planner.cost_cells == pytest.approx(fresh.cost_cells)
            assert not any(occ[c] for c in cells) and cells[-1] == goal
            planner.move_start(cells[min(2, len(cells) - 1)])
