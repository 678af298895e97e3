"""``swarmnav bench navigation --suite barn``: the 300 BARN worlds (Perille, Truong, Xiao and Stone, "Benchmarking
Metric Ground Navigation", IEEE SSRR 2020) under the BARN challenge's protocol (Daffan/the-barn-challenge,
``run.py`` and ``report_test.py``; ``../shared/benchmarks/barn/README.md``).

The data is read where it lies: ``--barn-dir``, else ``$SWARMNAV_BARN_DIR``, else ``../shared/benchmarks/barn``
beside the repository (never copied into it).  Each (world, run) is one scenario file, written into the
benchmark's folder by :func:`models.world_scenario.scenario_from_world` from the world file: the world's
cylinders, the challenge's start (-2.25, 3.0) facing +y, goal (-2.25, 13.0) within 1 m, 100 s, and a run ends
at the first collision (``stop_on_collision``), as the challenge's does.

**Runs of a world.**  Run 0 starts at the challenge's pose exactly; run ``j >= 1`` starts displaced by
(dx, dy) drawn uniformly in +-:data:`START_JITTER_M` and turned by a heading drawn uniformly in
+-:data:`HEADING_JITTER_DEG`, from ``numpy.random.default_rng([world, j])``; the scenario's seed (its world seed)
is ``j``; the planner and navigator seed is 0 in every run (the study's).  ``--quick``: the challenge's 50 test
worlds 0, 6, ..., 294 with 10 runs each (``report_test.py``); the default: all 300 worlds, run 0 of each;
``--barn-runs N`` and ``--barn-worlds`` choose otherwise.

**Robot, laser and map.**  The protocol asks for the Jackal, a 270-degree laser and no map (issue 33's robot
catalogue, laser and online occupancy grid).  :func:`protocol_tables` uses them when this installation's
scenario format has them (``robot = { model = "jackal" }``, ``sensors.fov_deg``, ``knowledge = { map =
"unknown" }``); until then a stand-in runs and every row says so in ``barn_setup``: a disc robot of the
Jackal's inscribed radius (0.215 m: half its 0.430 m width, so a corner of the real chassis can touch where
the disc does not), top speed 2.0 m/s, the map known, the default 12-ray rangefinder ring.  That stand-in is
*not* the protocol and its figures are not comparable to published ones as equals.

**Score** (the challenge's ``report_test.py``): OT = reference path length / 2 m/s, the path being start ->
``path_N.npy``'s cells (x = 0.15 a - 4.575, y = 0.15 b + 5.075) -> goal; a run scores
``success * OT / clip(AT, 2 OT, 8 OT)`` with AT its time (at most 0.5).  Per navigator ``barn_score`` is the
mean over every run (failures count 0), beside ``success_rate``, ``collision_rate``, ``timeout_rate`` and
``runs`` (:func:`add_scores`).
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass
from pathlib import Path as FilePath
from typing import Any

import numpy as np

from swarmnav.models.errors import ConfigError

WORLD_COUNT = 300
TEST_WORLDS = tuple(range(0, WORLD_COUNT, 6))  # report_test.py's 50 test worlds
QUICK_RUNS = 10                                 # report_test.py's runs per world
REFERENCE_SPEED_M_S = 2.0                       # OT = reference length / 2 m/s
CELL_M = 0.15
CELL_ORIGIN_M = (-4.575, 5.075)                 # path_coord_to_gazebo_coord: x = 0.15 a - 4.575, y = 0.15 b + 5.075
START_JITTER_M = 0.05
HEADING_JITTER_DEG = 3.0
JACKAL_INSCRIBED_RADIUS_M = 0.215               # half the Jackal's 0.430 m width (the data README)
JACKAL_TOP_SPEED_M_S = 2.0
ENV_DIR = "SWARMNAV_BARN_DIR"
PROTOCOL = {"robot": {"model": "jackal"},
            "sensors": {"model": "rangefinder", "count": 270, "fov_deg": 270.0, "range_m": 10.0},
            "knowledge": {"map": "unknown"}}
STAND_IN = {"robot": {"radius_m": JACKAL_INSCRIBED_RADIUS_M, "max_speed_m_s": JACKAL_TOP_SPEED_M_S}}
STAND_IN_TEXT = ("stand-in, not the protocol: disc robot r=0.215 m (the Jackal's inscribed radius), 2 m/s, "
                 "map known, 12-ray rangefinder ring")
PROTOCOL_TEXT = "protocol: jackal, 270-degree laser (270 beams, 10 m), map unknown"
PARTIAL = {k: v for k, v in PROTOCOL.items() if k != "knowledge"}
PARTIAL_TEXT = ("partial, not the protocol: jackal (planned as its circumscribed circle), 270-degree laser "
                "(270 beams, 10 m), map known")
SETUPS = ("auto", "stand-in")


def barn_dir(given: str | None = None) -> FilePath:
    """The BARN data folder: ``given``, else ``$SWARMNAV_BARN_DIR``, else ``../shared/benchmarks/barn`` beside
    the repository (or beside the working directory)."""
    if given:
        candidates, option = [FilePath(given)], "--barn-dir"
    elif os.environ.get(ENV_DIR):
        candidates, option = [FilePath(os.environ[ENV_DIR])], f"${ENV_DIR}"
    else:
        repo = FilePath(__file__).resolve().parents[2]
        candidates = [repo.parent / "shared/benchmarks/barn", FilePath.cwd().parent / "shared/benchmarks/barn"]
        option = "--barn-dir"
    for folder in candidates:
        if (folder / "worlds" / "world_0.world.gz").is_file() and (folder / "paths" / "path_0.npy").is_file():
            return folder
    raise ConfigError(option, f"no BARN data (worlds/world_N.world.gz, paths/path_N.npy) in "
                              f"{', '.join(str(c) for c in candidates)}")


def reference_length_m(folder: FilePath, world: int) -> float:
    """The challenge's reference path length of ``world``: start -> the path's cells -> goal."""
    return cells_length_m(reference_cells(folder, world))


def reference_cells(folder: FilePath, world: int) -> np.ndarray:
    """``paths/path_N.npy``: the (n, 2) cells of the reference path."""
    path = folder / "paths" / f"path_{world}.npy"
    try:
        cells = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise ConfigError("paths", f"cannot read a reference path ({exc})", str(path)) from None
    if cells.ndim != 2 or cells.shape[1] != 2 or not 1 <= len(cells) <= 10_000:
        raise ConfigError("paths", f"expected an (n, 2) array of cells, got shape {cells.shape}", str(path))
    return cells


def cells_length_m(cells: np.ndarray) -> float:
    """The polyline start -> the cells (x = 0.15 a - 4.575, y = 0.15 b + 5.075) -> goal, in metres."""
    from swarmnav.models.world_scenario import BARN_GOAL, BARN_START
    points = cells.astype(float) * CELL_M + np.array(CELL_ORIGIN_M)
    polyline = np.vstack([BARN_START[:2], points, BARN_GOAL[:2]])
    return float(np.linalg.norm(np.diff(polyline, axis=0), axis=1).sum())


def run_score(success: bool, time_s: float | None, optimal_time_s: float) -> float:
    """BARN's score of one run: success x OT / clip(AT, 2 OT, 8 OT)."""
    if not success or time_s is None:
        return 0.0
    return optimal_time_s / float(np.clip(time_s, 2 * optimal_time_s, 8 * optimal_time_s))


def start_jitter(world: int, run: int) -> tuple[float, float, float]:
    """(dx m, dy m, dheading deg) of run ``run`` of ``world``: zero for run 0 (see the module docstring)."""
    if run == 0:
        return 0.0, 0.0, 0.0
    rng = np.random.default_rng([world, run])
    dx, dy = rng.uniform(-START_JITTER_M, START_JITTER_M, 2)
    return float(dx), float(dy), float(rng.uniform(-HEADING_JITTER_DEG, HEADING_JITTER_DEG))


def protocol_tables(setup: str = "auto") -> tuple[dict[str, dict[str, Any]], str]:
    """The scenario tables of the robot, laser and map, and the text that labels the rows: ``auto``, the
    protocol's when this installation has them all; else the Jackal and its laser with the map known when it
    has those (``partial``); else the stand-in.  ``stand-in``: the stand-in whatever is installed."""
    if setup == "stand-in":
        return STAND_IN, STAND_IN_TEXT
    for tables, text in ((PROTOCOL, PROTOCOL_TEXT), (PARTIAL, PARTIAL_TEXT)):
        if _loads(tables):
            return tables, text
    return STAND_IN, STAND_IN_TEXT


def _loads(tables: dict[str, dict[str, Any]]) -> bool:
    from swarmnav.models.scenario import parse_scenario
    from swarmnav.models.world_scenario import _inline
    probe = ("name = \"probe\"\narena = { width_m = 4.0, height_m = 4.0 }\nstart = { x = 1.0, y = 1.0 }\n"
             "goal = { x = 3.0, y = 3.0 }\n" + "".join(f"{k} = {_inline(v)}\n" for k, v in tables.items()))
    try:
        parse_scenario(probe, "<barn protocol probe>")
    except ConfigError:
        return False
    return True


@dataclass(frozen=True)
class BarnRun:
    """One scenario file of the suite: a world, a run of it, and its optimal time OT."""

    name: str
    world: int
    run: int
    reference_length_m: float
    generated: bool = False

    @property
    def optimal_time_s(self) -> float:
        return self.reference_length_m / REFERENCE_SPEED_M_S


def world_source(world: int, generated: bool, barn: str | None = None):
    """A world's obstacles (:class:`models.gazebo_world.GazeboWorld`) and reference path cells: BARN's world
    ``world`` from the data, or the BARN-like world of seed ``world`` (:mod:`swarmnav.benchmarks.barn_like`).
    Each is read (or generated) once per process (the suite's files and its difficulty metrics share it)."""
    return _world_source(world, generated, None if generated else str(barn_dir(barn)))


@functools.lru_cache(maxsize=None)
def _world_source(world: int, generated: bool, folder: str | None):
    if generated:
        from swarmnav.benchmarks.barn_like import generate
        parsed, cells, _ = generate(world)
    else:
        from swarmnav.models.gazebo_world import read_world
        parsed = read_world(FilePath(folder) / "worlds" / f"world_{world}.world.gz")
        cells = reference_cells(FilePath(folder), world)
    cells.setflags(write=False)
    return parsed, cells


MAX_GENERATED_SEED = 10**6


def parse_worlds(text: str | None, generated: bool = False) -> tuple[int, ...] | None:
    """``--barn-worlds``: ``test`` (the 50), ``all``, ``A:B[:STEP]`` or a comma list; None when not given
    (``generated``: seeds of BARN-like worlds, 0 .. 10^6, as ``A:B[:STEP]`` or a list)."""
    if text is None:
        return None
    if generated:
        return _seeds(text)
    if text == "test":
        return TEST_WORLDS
    if text == "all":
        return tuple(range(WORLD_COUNT))
    try:
        if ":" in text:
            parts = [int(p) for p in text.split(":")]
            worlds = tuple(range(*parts)) if len(parts) in (2, 3) else ()
        else:
            worlds = tuple(int(p) for p in text.split(","))
    except ValueError:
        worlds = ()
    if not worlds or not all(0 <= w < WORLD_COUNT for w in worlds) or len(set(worlds)) != len(worlds):
        raise ConfigError("--barn-worlds", f"expected test, all, A:B[:STEP] or distinct worlds 0..299, got {text!r}")
    return worlds


def _seeds(text: str) -> tuple[int, ...]:
    try:
        parts = [int(p) for p in text.split(":" if ":" in text else ",")]
        seeds = tuple(range(*parts)) if ":" in text and len(parts) in (2, 3) else tuple(parts) if ":" not in text else ()
    except ValueError:
        seeds = ()
    if not seeds or not all(0 <= s <= MAX_GENERATED_SEED for s in seeds) or len(set(seeds)) != len(seeds) \
            or len(seeds) > 10_000:
        raise ConfigError("--barn-worlds", f"expected A:B[:STEP] or distinct seeds 0..{MAX_GENERATED_SEED:,} "
                                           f"(at most 10,000) for --suite barn-like, got {text!r}")
    return seeds


GENERATED_DEFAULT = tuple(range(50))  # --suite barn-like: seeds 0..49 (never run before this suite existed)


def parse_planner(text: str | None) -> dict[str, Any] | None:
    """``--barn-planner NAME[:KEY=VALUE,...]``: the known-map track's planner table (checked by building it)."""
    if text is None:
        return None
    from swarmnav.planners.registry import make_planner
    from swarmnav.sim.options import parse_settings
    name, _, settings = text.partition(":")
    params = parse_settings([p for p in settings.split(",") if p.strip()], "--barn-planner")
    try:
        make_planner(name.strip(), params)
    except ConfigError as exc:
        raise ConfigError("--barn-planner", f"{exc.field}: {exc.problem}") from None
    return {"name": name.strip(), "params": params}


def write_barn_suite(folder: str, quick: bool, worlds: tuple[int, ...] | None = None, runs: int | None = None,
                     barn: str | None = None, generated: bool = False, planner: dict[str, Any] | None = None,
                     setup_name: str = "auto") -> tuple[list[str], dict[str, BarnRun], str]:
    """The suite's scenario files under ``folder/scenarios``, their :class:`BarnRun` by scenario name, and the
    setup's label (:func:`protocol_tables`); ``generated``: BARN-like worlds of those seeds; ``planner`` (a
    planner table): the known-map track, every run planned by it on the map given."""
    from swarmnav.models.world_scenario import ImportSettings, scenario_from_world, BARN_START, BARN_GOAL
    if not generated:
        barn_dir(barn)
    worlds = worlds if worlds is not None else GENERATED_DEFAULT if generated else TEST_WORLDS if quick \
        else tuple(range(WORLD_COUNT))
    runs = runs if runs is not None else QUICK_RUNS if quick else 1
    tables, setup = protocol_tables(setup_name)
    if planner is not None:
        tables = {**tables, "planner": planner}
        if "knowledge" in tables:
            tables["knowledge"] = {**tables["knowledge"], "map": "known"}
        params = ", ".join(f"{k}={v}" for k, v in planner["params"].items())
        setup = (f"known-map track: planner {planner['name']}" + (f" ({params})" if params else "")
                 + f"; {setup.replace('map unknown', 'map known')}")
    os.makedirs(os.path.join(folder, "scenarios"), exist_ok=True)
    paths, meta = [], {}
    for world in worlds:
        parsed, cells = world_source(world, generated, barn)
        length_m = cells_length_m(cells)
        for run in range(runs):
            dx, dy, dh = start_jitter(world, run)
            name = f"barnlike-{world}-r{run}" if generated else f"barn-{world:03d}-r{run}"
            start = (BARN_START[0] + dx, BARN_START[1] + dy, BARN_START[2] + dh)
            settings = ImportSettings(
                name=name, start=start, goal=BARN_GOAL, seed=run,
                description=f"{'BARN-like seed' if generated else 'BARN world'} {world}, run {run} (start moved by ({dx:+.4f}, {dy:+.4f}) m, "
                            f"{dh:+.3f} deg); {setup}",
                tables={**tables, "sim": {"stop_on_collision": True}})
            path = os.path.join(folder, "scenarios", f"{name}.toml")
            with open(path, "w", encoding="utf-8") as out:
                out.write(scenario_from_world(parsed, settings).text)
            paths.append(path)
            meta[name] = BarnRun(name, world, run, length_m, generated)
    return paths, meta, setup


def add_scores(table: list[dict[str, Any]], rows: list[dict[str, Any]], meta: dict[str, BarnRun], setup: str,
               with_difficulty: bool = False, barn: str | None = None,
               params: dict[str, dict[str, Any]] | None = None) -> None:
    """BARN's columns on the benchmark's rows: ``barn_score`` (mean over the rows' runs), ``barn_setup``,
    ``navigator_params`` (the parameters the row's navigator was given, ``params`` by row label: a BARN
    configuration such as ``dstar_replan``'s ``footprint=box``; {} for its defaults); a
    per-scenario row (one run) also gets ``world``, ``run``, ``reference_length_m``, ``optimal_time_s``,
    ``time_s`` (AT: the run's simulated time) and, ``with_difficulty``, the world's metrics
    (:mod:`swarmnav.benchmarks.barn_difficulty`) as ``difficulty``."""
    difficulty = None
    if with_difficulty:
        from swarmnav.benchmarks.barn_difficulty import world_metrics
        difficulty = {}
        for world, generated in sorted({(m.world, m.generated) for m in meta.values()}):
            parsed, cells = world_source(world, generated, barn)
            xy = np.array([[c.x_m, c.y_m] for c in parsed.cylinders]).reshape(-1, 2)
            difficulty[world] = world_metrics(xy, cells)
    scores: dict[tuple[str, str], float] = {}
    times: dict[tuple[str, str], float] = {}
    ratios: dict[tuple[str, str], float] = {}
    for r in rows:
        run = meta[r["scenario"]]
        time_s = r.get("sim_time_s")
        scores[(r["navigator_label"], r["scenario"])] = run_score(bool(r["success"]), time_s, run.optimal_time_s)
        times[(r["navigator_label"], r["scenario"])] = time_s
        if r.get("plan_length_m") and r.get("plan_collision_free"):
            ratios[(r["navigator_label"], r["scenario"])] = r["plan_length_m"] / run.reference_length_m
    for row in table:
        label = row["navigator"]
        mine = [s for (lab, scen), s in scores.items() if lab == label and row["scenario"] in (None, scen)]
        row["barn_score"] = sum(mine) / len(mine) if mine else None
        planned = [v for (lab, scen), v in ratios.items() if lab == label and row["scenario"] in (None, scen)]
        # the plan against the reference path (a yardstick): its length over the reference's, collision-free plans
        row["mean_plan_over_reference"] = sum(planned) / len(planned) if planned else None
        row["barn_setup"] = setup
        row["navigator_params"] = dict((params or {}).get(label, {}))
        if row["scenario"] is not None:
            run = meta[row["scenario"]]
            row.update(world=run.world, run=run.run, reference_length_m=run.reference_length_m,
                       optimal_time_s=run.optimal_time_s, time_s=times.get((label, row["scenario"])))
            if difficulty is not None and run.world in difficulty:
                row["difficulty"] = difficulty[run.world]


def print_scores(rows: list[dict[str, Any]]) -> None:
    """BARN's table under the benchmark's: per navigator success, collision, timeout and score."""
    print()
    print(f"BARN ({rows[0]['barn_setup'] if rows else ''})")
    print(f"{'navigator':<18} {'runs':>5} {'success':>7} {'collide':>7} {'timeout':>7} {'barn_score':>10}")
    for r in rows:
        score = "-" if r.get("barn_score") is None else f"{r['barn_score']:.4f}"
        print(f"{r['navigator']:<18} {r['runs']:>5} {r['success_rate']:>7.3f} {r['collision_rate']:>7.3f} "
              f"{r['timeout_rate']:>7.3f} {score:>10}")
