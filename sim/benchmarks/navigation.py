"""``swarmnav bench navigation``: every navigator on the bundled dynamic suite, the way navigation
benchmarks report it (BARN, Nav2, CrowdNav): success, collisions, timeouts, SPL, danger, cost.

Every navigator x every scenario of the suite (the bundled ``dyn-*`` files,
made by ``swarmnav scenarios generate``) x N world seeds (run k uses world
seed k and planner seed k), run as a physics study (the study machinery, in this
process; ``--out DIR`` keeps its rows for ``swarmnav report``).  One row per navigator; every run counts in every
rate (failures are never dropped from the denominators).  ``mean_time_to_goal_s``
averages the successful runs only.  ``navigator_us_per_step`` is the wall time
measured around the navigator's ``step`` call per control step;
``realtime_factor`` is simulated over wall time of whole runs (physics, sensing,
navigator).  Scenarios whose obstacles all move on fixed lines give the same run
for every world seed; they are still counted once per seed.  ``--by-scenario``
adds one row per navigator and scenario (the same columns plus ``scenario``), to
see where the failures are.

**Against the clairvoyant oracle** (:mod:`controllers.navigators.oracle`): every scenario and world seed is
also run by ``oracle``, whose verdict (solvable at its lattice's resolution or not, T*) each contender's run
is read against, so that an unsolvable scene never counts against a navigator: ``oracle_solvable_runs``,
``solved_share`` (successes among the oracle-solvable runs), ``time_score`` (BARN's, Perille et al. 2020:
0 on failure, else T* / T clipped to 1, averaged over the oracle-solvable runs) and ``mean_spl_solvable``.
The ``oracle`` row itself is the yardstick's validation: ``success_on_solvable`` is its physics success on
the runs it called solvable (target: at least 0.95), ``solvable_share`` the share it called solvable.

``--suite dyn300``: the 300 generated scenes of ``models/suites/dyn300.toml`` (each with its own world
seed, ``--seeds`` ignored), in order of difficulty; ``--quick`` a stratified sample (2 per group), ``--per-group
N`` one of N per group;
``--sensor-model detector|rangefinder`` (12 rangefinders at 1 m) overrides their sensing; with
``--by-scenario`` each scenario's rows carry its shipped ``difficulty`` metrics (to set success against them).  Where the
shipped verdicts (``dyn300-verdicts.json``) disagree with this run's oracle, ``verdict_mismatches`` says how
often (the oracle row).

**Speed** (:mod:`swarmnav.benchmarks.navigation_speed`; figures printed after the table, never asserted):
``realtime_factor_cpu`` (simulated time over the runs' own CPU time, ``run_cpu_s``); the oracle row's
``oracle_search`` (its search timed on every scene run: median and max, wall and CPU); the ``mppi`` row's
``mppi_every_step`` (its control step at 1,000 x 30 optimising every step); each with the load average.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import re
import sys
import tempfile
from typing import Any

from swarmnav.controllers.navigators import NAVIGATORS
from swarmnav.models.scenario import list_scenarios, load_scenario

SUITE_PREFIX = "dyn-"
ORACLE = "oracle"  # the clairvoyant yardstick, run beside every contender
# A generated suite's per-scenario rows carry these shipped difficulty metrics (sim/runtime/difficulty.py).
DIFFICULTY_KEYS = ("difficulty_rank", "static_density", "dispersion", "survivability", "dynamic_traversability",
                   "t_star_ratio")


def default_navigators(settings: dict[str, dict[str, Any]] | None = None) -> list[str]:
    """Every registered navigator that runs with its default parameters, or with its share of ``settings``
    (``policy`` needs a callable: it joins when ``--navigator-set policy=module:function`` names one)."""
    from swarmnav.controllers.navigators import make_navigator
    from swarmnav.models.errors import ConfigError
    names = []
    for name in NAVIGATORS:
        try:
            make_navigator(name, (settings or {}).get(name))
        except ConfigError:
            if name in (settings or {}):
                raise  # asked for with a bad value: say so rather than leave it out
            continue
        names.append(name)
    return names


def navigator_settings(pairs: dict[str, Any], navigators: list[str]) -> dict[str, dict[str, Any]]:
    """``--navigator-set KEY=VALUE``: each navigator gets the keys it has as parameters; a key none has is an error."""
    from swarmnav.controllers.navigators import navigator_parameters
    from swarmnav.models.errors import ConfigError
    out: dict[str, dict[str, Any]] = {}
    for key, value in pairs.items():
        takers = [n for n in navigators if key in navigator_parameters(n)]
        if not takers:
            raise ConfigError("--navigator-set", f"no navigator of this benchmark has a parameter {key!r}")
        for name in takers:
            out.setdefault(name, {})[key] = value
    return out


def suite_names() -> list[str]:
    """The bundled dynamic suite: scenarios named ``dyn-*``."""
    return [name for name in list_scenarios() if name.startswith(SUITE_PREFIX)]


@dataclasses.dataclass(frozen=True)
class Arm:
    """One row of the benchmark: a navigator under a label with its parameters (a default row: label = name)."""
    label: str
    navigator: str
    params: dict[str, Any]


def parse_arm(text: str) -> Arm:
    """``--arm LABEL:NAVIGATOR[:KEY=VALUE,KEY=VALUE...]``: a navigator under its own label with its own
    parameters, a row of the table beside the defaults (e.g. ``iaco_local+evade:iaco_local:evade=true``)."""
    from swarmnav.controllers.navigators import make_navigator
    from swarmnav.models.errors import ConfigError
    from swarmnav.sim.options import parse_settings
    label, sep, rest = text.partition(":")
    name, _, settings = rest.partition(":")
    label, name = label.strip(), name.strip()
    if not sep or not label or not name:
        raise ConfigError("--arm", f"expected LABEL:NAVIGATOR[:KEY=VALUE,...], got {text!r}")
    if name not in NAVIGATORS:
        raise ConfigError("--arm", f"unknown navigator {name!r} in {text!r} (known: {', '.join(sorted(NAVIGATORS))})")
    if is_clairvoyant(name):
        raise ConfigError("--arm", f"{name!r} is the yardstick, run beside every contender already")
    # a comma starts a new KEY=VALUE only before a key, so a TOML array value keeps its commas
    pairs = re.split(r",(?=\s*[A-Za-z_][A-Za-z0-9_]*\s*=)", settings) if settings else []
    params = parse_settings([p.strip().rstrip(",") for p in pairs if p.strip(" ,")], "--arm")
    try:
        make_navigator(name, params)  # a bad key or value is refused here, naming the navigator's field
    except ConfigError as exc:
        raise ConfigError(f"--arm {label}: {exc.field}", exc.problem) from None
    return Arm(label, name, params)


def read_arms(path: str) -> list[Arm]:
    """``--arms FILE.toml``: rows from a data file, each ``[[navigators]]`` entry written as a study file writes
    it (``name``, ``label``, ``params``), one value per parameter (a list, a study's sweep, is refused here: one
    row is one configuration). A parameter that names code is refused (data is not code: ``--arm`` on the
    command line is the way to opt in). Every problem is one ConfigError naming the file and the field."""
    from swarmnav.controllers.navigators import make_navigator
    from swarmnav.models.contained_files import name_problem
    from swarmnav.models.toml_table import parse_toml, read_text
    from swarmnav.study.spec_sections import read_components
    top = parse_toml(read_text(path, "--arms"), str(path))
    top.only({"navigators", "description"})
    if top.has("description"):
        top.string("description")
    components = read_components(top, "navigators", "navigator", make_navigator, False)
    arms = []
    for i, component in enumerate(components):
        if component.swept:
            top.fail(f"navigators[{i}].params.{component.swept[0]}",
                     "a list (a study's sweep): an arm takes one value per parameter")
        if is_clairvoyant(component.name):
            top.fail(f"navigators[{i}].name", f"{component.name!r} is the yardstick, run beside every contender already")
        problem = name_problem(component.label)  # a row's label is a name: bounded, printable, never a path
        if problem:
            top.fail(f"navigators[{i}].label", problem)
        arms.append(Arm(component.label, component.name, dict(component.params)))
    return arms


def check_arms(contenders: list[str], arms: list[Arm]) -> None:
    """Each row's label is its own: an arm's label is neither a default row's name, the oracle's, nor another
    arm's."""
    from swarmnav.models.errors import ConfigError
    taken = set(contenders) | {ORACLE}
    for arm in arms:
        if arm.label in taken:
            raise ConfigError("--arm", f"label {arm.label!r} is already a row of this benchmark (give it its own)")
        taken.add(arm.label)


def navigation_study(seeds: int | None, navigators: list[str], scenarios: list[str],
                     navigator_params: dict[str, dict[str, Any]], arms: list[Arm] = ()) -> dict[str, Any]:
    """The benchmark as a physics study: each scenario with its own planner, every navigator (and each arm
    under its label), run ``k`` with world seed ``k`` and planner seed ``k`` (paired); ``seeds`` None: one run,
    the scenario's world seed."""
    planners = list(dict.fromkeys(load_scenario(name).planner_name for name in scenarios))
    runs = ({"seeds": seeds, "world_seeds": list(range(seeds)), "paired_seeds": True} if seeds is not None
            else {"seeds": [0]})
    return {"name": "bench-navigation", "scenarios": scenarios, "mode": "physics", **runs,
            "planners": [{"name": p} for p in planners],
            "navigators": [{"name": n, "params": navigator_params.get(n, {})} for n in navigators]
            + [{"name": a.navigator, "label": a.label, "params": a.params} for a in arms]}


def is_clairvoyant(name: str) -> bool:
    return bool(getattr(NAVIGATORS[name], "clairvoyant", False))


def oracle_verdicts(rows: list[dict[str, Any]]) -> dict[tuple[str, int], dict[str, Any]]:
    """(scenario, world seed) -> the oracle's verdict (its ``oracle`` event), from the oracle's runs."""
    out = {}
    for r in rows:
        if r["navigator"] == ORACLE and r.get("run_events"):
            verdict = json.loads(r["run_events"])["last"].get("oracle")
            if verdict is not None:
                out[(r["scenario"], r["world_seed"])] = verdict
    return out


def write_suite(suite_name: str, quick: bool, sensor_model: str | None, folder: str,
                per_group: int | tuple[int, int] | None = None, seed_offset: int = 0) -> tuple[list[str], Any]:
    """The suite's scenes as TOML files under ``folder`` (paths, in order of difficulty) and the suite;
    ``quick``: a stratified sample of 2 scenes per group, ``per_group``: of that many (or, ``(first, end)``, each
    group's scenes first to end - 1 in seed order: :func:`models.suites.stratified_sample`); ``seed_offset``: the
    held-out scenes of the same groups (:func:`models.suites.load_suite`)."""
    import os
    from swarmnav.models.suites import load_suite, stratified_sample
    suite = load_suite(suite_name, sensor_model, seed_offset)
    scenes = (stratified_sample(suite, per_group) if per_group is not None
              else stratified_sample(suite) if quick else suite.scenes)
    if not scenes and isinstance(per_group, tuple):
        from swarmnav.models.errors import ConfigError
        largest = max(sum(s.group == g for s in suite.scenes) for g in {s.group for s in suite.scenes})
        raise ConfigError("--per-group", f"{per_group[0]}:{per_group[1]} selects no scene (a group of "
                                         f"{suite_name} has at most {largest:,})")
    os.makedirs(os.path.join(folder, "scenarios"), exist_ok=True)
    paths = []
    for scene in scenes:
        path = os.path.join(folder, "scenarios", f"{scene.name}.toml")
        with open(path, "w", encoding="utf-8") as out:
            out.write(scene.text())
        paths.append(path)
    return paths, suite


def benchmark_navigation(seeds: int = 5, navigators: list[str] | None = None, scenarios: list[str] | None = None,
                         progress: bool = False, navigator_params: dict[str, dict[str, Any]] | None = None,
                         by_scenario: bool = False, out_dir: str | None = None, suite: str | None = None,
                         quick: bool = False, sensor_model: str | None = None,
                         workers: int = 1, speed: bool = True, per_group: int | tuple[int, int] | None = None,
                         arms: list[Arm] = (), engine: str = "local", address: str | None = None,
                         seed_offset: int = 0, barn: dict[str, Any] | None = None,
                         knowledge: dict[str, Any] | None = None) -> list[dict[str, Any]]:
    """One row per navigator and the oracle's (see the module docstring); ``navigator_params``: per navigator
    name.  With ``by_scenario`` one row per navigator and scenario after them (each with a ``scenario`` key;
    the overall rows have ``scenario`` None).  The runs are a study's rows, kept in ``out_dir`` when given;
    ``suite`` (e.g. ``dyn300``) runs a generated suite instead of ``scenarios``; ``arms``: more rows, each a
    navigator under its own label with its own parameters (the rows are keyed by label; with arms and no
    ``navigators`` only the arms run); ``engine="ray"``:
    the runs on Ray (a local instance of ``workers`` CPUs, or the cluster at ``address``); ``suite="barn"``: the
    BARN worlds (:mod:`swarmnav.benchmarks.barn`; ``barn``: its ``worlds``, ``runs`` and ``dir``), with its score;
    ``knowledge``: the study axes ``maps`` / ``poses`` (``--map`` / ``--pose``), every row says its values."""
    if out_dir is None:
        with tempfile.TemporaryDirectory(prefix="swarmnav-bench-navigation-") as folder:
            return benchmark_navigation(seeds, navigators, scenarios, progress, navigator_params, by_scenario,
                                        folder, suite, quick, sensor_model, workers, speed, per_group, arms,
                                        engine, address, seed_offset, barn, knowledge)
    from swarmnav.study.execute import run_study_tables

    navigator_params = navigator_params or {}
    # arms alone (no navigator named) run alone: the default navigators only when neither was given
    named = navigators if navigators is not None or arms else default_navigators(navigator_params)
    contenders = [n for n in (named or []) if not is_clairvoyant(n)]
    check_arms(contenders, list(arms))
    shipped: dict[str, dict[str, Any]] = {}
    barn_meta = None
    if suite in ("barn", "barn-like"):
        from swarmnav.benchmarks import barn as barn_suite
        names, barn_meta, barn_setup = barn_suite.write_barn_suite(out_dir, quick, (barn or {}).get("worlds"),
                                                                   (barn or {}).get("runs"), (barn or {}).get("dir"),
                                                                   generated=suite == "barn-like",
                                                                   planner=(barn or {}).get("planner"),
                                                                   setup_name=(barn or {}).get("setup") or "auto")
        run_seeds, speed = None, False  # the speed figures re-run every scene's oracle search: not here
    elif suite is not None:
        names, loaded = write_suite(suite, quick, sensor_model, out_dir, per_group, seed_offset)
        shipped = loaded.verdicts
        run_seeds = None
    else:
        names, run_seeds = scenarios or suite_names(), seeds
    # the BARN suites run no oracle unless asked: on BARN's 50 test worlds (stand-in) it succeeded in 7 of 50 runs
    # (18 collisions, 25 timeouts: models/suites/results/barn-test50.json), so it is no yardstick there
    yardstick = [ORACLE] if barn_meta is None or (barn or {}).get("oracle") else []
    tables = {**navigation_study(run_seeds, contenders + yardstick, names, navigator_params, list(arms)),
              **(knowledge or {})}
    rows = run_study_tables(tables, out_dir, show_progress=progress, workers=workers, engine=engine,
                            address=address)
    verdicts = oracle_verdicts(rows)
    labels = contenders + [a.label for a in arms] + yardstick
    runs = {label: [r for r in rows if r["navigator_label"] == label] for label in labels}
    settings = {a.label: {"arm_of": a.navigator, "arm_params": a.params} for a in arms}
    sensing = "+".join(sorted({load_scenario(name).sensor_model for name in names}))
    from swarmnav.benchmarks.crowd_rows import crowd_rows, robot_visible
    visible = robot_visible(names)
    if visible:  # scenes among agents: one table per setting (CrowdNav's invisible and visible robot)
        table = crowd_rows(runs, visible, verdicts, shipped, sensing, settings, _row, ORACLE)
    else:
        table = [{"scenario": None, **_row(nav, arm, verdicts, shipped), "sensor_model": sensing,
                  **settings.get(nav, {})} for nav, arm in runs.items()]
    if speed:
        _add_speed(table, rows)
        if visible:  # the agents' own cost (navigation_speed.crowd_step_cost), on the oracle's row
            from swarmnav.benchmarks.navigation_speed import crowd_step_cost
            next(r for r in table if r["navigator"] == ORACLE)["crowd_step"] = crowd_step_cost()
    if by_scenario:
        for name in dict.fromkeys(r["scenario"] for r in rows):
            extra = {"difficulty": {k: shipped[name][k] for k in DIFFICULTY_KEYS}} if name in shipped else {}
            for nav, arm in runs.items():
                table.append({"scenario": name, **_row(nav, [r for r in arm if r["scenario"] == name], verdicts,
                                                       shipped), **extra})
    given = {key: "+".join(sorted({str(r[key]) for r in rows})) for key in ("map_knowledge", "pose_source")}
    for row in table:  # what the runs were given (the oracle keeps the true map: controllers.world_map)
        row.update(given)
    if barn_meta is not None:
        barn_suite.add_scores(table, rows, barn_meta, barn_setup, by_scenario, (barn or {}).get("dir"),
                              {**navigator_params, **{a.label: a.params for a in arms}})
    return table


def _add_speed(table: list[dict[str, Any]], rows: list[dict[str, Any]]) -> None:
    """The oracle's search times on every scene run (its row's ``oracle_search``) and MPPI's cost per control
    step optimising every step (its row's ``mppi_every_step``): :mod:`swarmnav.benchmarks.navigation_speed`."""
    from swarmnav.benchmarks.navigation_speed import mppi_step_cost, oracle_search_times
    scenes = list(dict.fromkeys((r["scenario_ref"], r["world_seed"]) for r in rows if r["navigator"] == ORACLE))
    for row in table:
        if row["navigator"] == ORACLE:
            row["oracle_search"] = oracle_search_times(scenes)
        elif row["navigator"] == "mppi":
            row["mppi_every_step"] = mppi_step_cost()


def _mean(values: list[float]) -> float | None:
    return sum(values) / len(values) if values else None


def _row(navigator: str, rows: list[dict[str, Any]], verdicts: dict[tuple[str, int], dict[str, Any]],
         shipped: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """Rates over every run (a run that raised, or found no path, counts as a failure in each rate's
    denominator); means over the runs that drove; the oracle's columns over the runs it called solvable."""
    out = _plain_row(navigator, rows)
    solvable = [r for r in rows if verdicts.get((r["scenario"], r["world_seed"]), {}).get("solvable")]
    out["oracle_solvable_runs"] = len(solvable)
    out["solved_share"] = (sum(bool(r["success"]) for r in solvable) / len(solvable)) if solvable else None
    scores = []
    for r in solvable:
        t_star = verdicts[(r["scenario"], r["world_seed"])]["arrival_s"]
        scores.append(min(1.0, t_star / r["time_to_goal_s"]) if r["success"] and r["time_to_goal_s"] else 0.0)
    out["time_score"] = _mean(scores)
    out["mean_spl_solvable"] = _mean([r["spl"] or 0.0 for r in solvable])
    if navigator == ORACLE:
        out["solvable_share"] = len(solvable) / len(rows) if rows else None
        out["success_on_solvable"] = out.pop("solved_share")
        out["verdict_mismatches"] = sum(
            1 for r in rows if r["scenario"] in shipped and (r["scenario"], r["world_seed"]) in verdicts
            and bool(shipped[r["scenario"]]["oracle"]["solvable"])
            != bool(verdicts[(r["scenario"], r["world_seed"])]["solvable"]))
    return out


def _plain_row(navigator: str, rows: list[dict[str, Any]]) -> dict[str, Any]:
    n = len(rows)
    drove = [r for r in rows if r["outcome"] == "ok"]
    reached = [r["time_to_goal_s"] for r in rows if r["success"]]
    steps = sum(r["control_steps"] for r in drove)
    return {
        "navigator": navigator, "runs": n, "failed_runs": n - len(drove),
        "success_rate": sum(bool(r["success"]) for r in rows) / n,
        "collision_rate": sum(bool(r["collisions"]) for r in drove) / n,
        "timeout_rate": sum(r["run_outcome"] == "timeout" for r in drove) / n,
        "left_arena_rate": sum(r["run_outcome"] == "left_arena" for r in drove) / n,
        "mean_time_to_goal_s": _mean(reached),
        "mean_spl": _mean([r["spl"] or 0.0 for r in drove]),
        "mean_time_in_danger_s": _mean([r["time_in_danger_s"] for r in drove]),
        "mean_replans": _mean([r["replans"] for r in drove]),
        "navigator_us_per_step": 1e6 * sum(r["navigator_wall_s"] for r in drove) / max(steps, 1),
        "realtime_factor": sum(r["sim_time_s"] for r in drove) / max(sum(r["wall_time_s"] for r in drove), 1e-9),
        "realtime_factor_cpu": (sum(r["sim_time_s"] for r in drove) / max(sum(r["run_cpu_s"] for r in drove), 1e-9)
                                if drove and all(r.get("run_cpu_s") is not None for r in drove) else None),
        "cpu_s_per_run": (_mean([r["run_cpu_s"] for r in drove])
                          if drove and all(r.get("run_cpu_s") is not None for r in drove) else None),
    }


def knowledge_axes(args: argparse.Namespace) -> dict[str, list[str]]:
    """``--map`` / ``--pose`` as the study axes ``maps`` / ``poses`` (absent: each scenario's [knowledge])."""
    return {key: [value] for key, value in (("maps", getattr(args, "map", None)), ("poses", getattr(args, "pose", None)))
            if value is not None}


def run(args: argparse.Namespace) -> int:
    from swarmnav.models.errors import ConfigError
    if args.seeds < 1:
        raise ConfigError("--seeds", f"must be at least 1, got {args.seeds}")
    for name in args.navigator or []:
        if name not in NAVIGATORS:
            raise ConfigError("--navigator", f"unknown navigator {name!r} (known: {', '.join(sorted(NAVIGATORS))})")
    if args.suite == "papers":
        if getattr(args, "engine", "local") == "ray":
            raise ConfigError("--engine", "ray applies to the dyn and dyn300 suites (papers runs in this process)")
        from swarmnav.benchmarks.paper_navigation import (PAPER_SUITE, benchmark_paper_navigation,
                                                              print_table)
        paper_rows = benchmark_paper_navigation(args.seeds, tuple(args.scenario or PAPER_SUITE), args.out,
                                                knowledge_axes(args))
        print(json.dumps(paper_rows)) if args.json else print_table(paper_rows)
        return 0
    from swarmnav.sim.options import parse_settings
    settings = navigator_settings(parse_settings(args.navigator_set, "--navigator-set"),
                                  args.navigator or list(NAVIGATORS))
    suite = None if args.suite == "dyn" else args.suite
    barn = _barn_options(args, suite)
    if suite is None and getattr(args, "sensor_model", None):
        raise ConfigError("--sensor-model", "applies to a generated suite (--suite dyn300, crowdnav) only")
    if getattr(args, "address", None) and getattr(args, "engine", "local") != "ray":
        raise ConfigError("--address", "applies to --engine ray only")
    if suite is None and getattr(args, "seed_offset", 0):
        raise ConfigError("--seed-offset", "applies to a generated suite (--suite dyn300, crowdnav) only")
    if suite is None and getattr(args, "per_group", None):
        raise ConfigError("--per-group", "applies to a generated suite (--suite dyn300, crowdnav) only")
    arms = [parse_arm(text) for text in getattr(args, "arm", None) or []]
    if getattr(args, "arms", None):
        arms += read_arms(args.arms)
    rows = benchmark_navigation(args.seeds, args.navigator, args.scenario,
                                progress=not args.json and sys.stderr.isatty(), navigator_params=settings,
                                by_scenario=args.by_scenario, out_dir=args.out, suite=suite,
                                quick=bool(getattr(args, "quick", False)) and suite is not None,
                                sensor_model=getattr(args, "sensor_model", None),
                                workers=getattr(args, "workers", 1) or 1, per_group=getattr(args, "per_group", None),
                                arms=arms, engine=getattr(args, "engine", "local"),
                                address=getattr(args, "address", None),
                                seed_offset=getattr(args, "seed_offset", 0) or 0, barn=barn,
                                knowledge=knowledge_axes(args))
    if args.json:
        print(json.dumps(rows))
        return 0
    overall = [r for r in rows if r["scenario"] is None]
    if any("robot_visible" in r for r in overall):  # among agents: CrowdNav's two settings apart
        from swarmnav.benchmarks.crowd_rows import print_crowd_lines
        for seen in (False, True):
            part = [r for r in overall if r.get("robot_visible") is seen]
            if part:
                _print_table(part, f"robot {'visible' if seen else 'invisible'} to the humans"
                             + (" (no clairvoyant yardstick)" if seen else ""))
                print_crowd_lines(part)
                print()
    else:
        _print_table(overall, "")
    if suite in ("barn", "barn-like"):
        from swarmnav.benchmarks.barn import print_scores
        print_scores(overall)
    if args.by_scenario:
        for name in dict.fromkeys(r["scenario"] for r in rows if r["scenario"] is not None):
            print()
            _print_table([r for r in rows if r["scenario"] == name], name)
    from swarmnav.benchmarks.navigation_speed import speed_lines
    print()
    oracle = next((r.get("oracle_search") for r in overall if r["navigator"] == ORACLE), None)
    mppi = next((r.get("mppi_every_step") for r in overall if r["navigator"] == "mppi"), None)
    for line in speed_lines(overall, oracle or {}, mppi):
        print(line)
    crowd = next((r["crowd_step"] for r in overall if r.get("crowd_step")), None)
    if crowd:
        from swarmnav.benchmarks.navigation_speed import crowd_line
        print(crowd_line(crowd))
    return 0


def _barn_options(args: argparse.Namespace, suite: str | None) -> dict[str, Any] | None:
    """``--barn-dir``, ``--barn-runs``, ``--barn-worlds`` (``--suite barn`` and ``barn-like`` only; the dyn300
    options refused there)."""
    from swarmnav.models.errors import ConfigError
    given = {k: getattr(args, f"barn_{k}", None) for k in ("dir", "runs", "worlds", "planner", "setup", "oracle")}
    if suite not in ("barn", "barn-like"):
        for key, value in given.items():
            if value is not None:
                raise ConfigError(f"--barn-{key}", "applies to --suite barn only")
        return None
    for option in ("sensor_model", "per_group", "seed_offset"):
        if getattr(args, option, None):
            raise ConfigError(f"--{option.replace('_', '-')}", "applies to a generated suite (--suite dyn300, crowdnav) only")
    from swarmnav.benchmarks.barn import barn_dir, parse_planner, parse_worlds
    if suite == "barn":
        barn_dir(given["dir"])  # no data: one line before anything runs
    return {"dir": given["dir"], "runs": given["runs"], "worlds": parse_worlds(given["worlds"], suite == "barn-like"),
            "planner": parse_planner(given["planner"]), "setup": given["setup"], "oracle": given["oracle"]}


def _print_table(rows: list[dict[str, Any]], title: str) -> None:
    if title:
        print(title)
    header = (f"{'navigator':<18} {'runs':>4} {'success':>7} {'collide':>7} {'timeout':>7} {'t_goal_s':>8} "
              f"{'SPL':>5} {'danger_s':>8} {'replans':>7} {'us/step':>8} {'x_realtime':>10} {'solvable':>8} "
              f"{'solved':>6} {'t_score':>7}")
    print(header)

    def cell(value: Any, width: int, spec: str) -> str:
        return f"{'-' if value is None else format(value, spec):>{width}}"

    for r in rows:
        solved = r["success_on_solvable"] if r["navigator"] == ORACLE else r["solved_share"]
        print(f"{r['navigator']:<18} {r['runs']:>4} {r['success_rate']:>7.2f} {r['collision_rate']:>7.2f} "
              f"{r['timeout_rate']:>7.2f} {cell(r['mean_time_to_goal_s'], 8, '.1f')} {cell(r['mean_spl'], 5, '.2f')} "
              f"{cell(r['mean_time_in_danger_s'], 8, '.2f')} {cell(r['mean_replans'], 7, '.1f')} "
              f"{r['navigator_us_per_step']:>8.0f} {r['realtime_factor']:>10.1f} {r['oracle_solvable_runs']:>8} "
              f"{cell(solved, 6, '.2f')} {cell(r['time_score'], 7, '.2f')}")
    oracle = [r for r in rows if r["navigator"] == ORACLE]
    for r in oracle:
        print(f"oracle (clairvoyant): called {r['oracle_solvable_runs']} of {r['runs']} runs solvable; succeeded in "
              f"physics on {cell(r['success_on_solvable'], 4, '.2f').strip()} of them (target >= 0.95)"
              + (f"; {r['verdict_mismatches']} verdicts differ from the shipped ones" if r["verdict_mismatches"]
                 else ""))
