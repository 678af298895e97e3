"""Studies: the grid runs through the one episode function, rows resume, failures are rows, the report agrees."""

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from swarmnav.models.scenario import load_scenario
from swarmnav.planners.errors import PlanningError
from swarmnav.cli.main import main
from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode
from swarmnav.study.grid import expand
from swarmnav.study.spec import list_studies, load_study

TINY = """
name = "tiny"
scenarios = ["gwo-scenario-1", "restaurant-table-2"]
mode = "physics"
time_limit_s = {time_limit_s}
seeds = 3
[[planners]]
name = "astar"
[[planners]]
name = "gwo"
params = {{ population = 10, iterations = 10, mode = "robust" }}   # the paper mode ends inside a disc here
"""
TINY_TIME_LIMIT_S = 4.0


def write(tmp_path: Path, text: str, name: str = "study.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """The tiny study (2 scenarios x 2 planners x 3 seeds, physics, 4 s simulated) run on 2 local workers."""
    base = tmp_path_factory.mktemp("tiny")
    path = write(base, TINY.format(time_limit_s=TINY_TIME_LIMIT_S))
    assert main(["study", str(path), "--out", str(base / "out"), "--workers", "2", "--json"]) == 0
    return path, base / "out"


@pytest.fixture(scope="module")
def tiny_report(tiny, tmp_path_factory):
    """The tiny study's report, written once for the tests that read it: (HTML path, Markdown text)."""
    _, out = tiny
    html = tmp_path_factory.mktemp("tiny-report") / "r.html"
    assert main(["report", str(out), "--out", str(html)]) == 0
    return html, html.with_suffix(".md").read_text()


def test_tiny_study_rows_equal_the_same_episodes(tiny):
    path, out = tiny
    rows = pd.read_parquet(out / "runs.parquet")
    assert len(rows) == 12 and rows["config_hash"].is_unique
    for row in rows.to_dict("records"):
        spec = EpisodeSpec(load_scenario(row["scenario"]), row["planner"], json.loads(row["planner_params"]),
                           seed=int(row["seed"]))
        try:
            planned = plan_episode(spec)
        except PlanningError as exc:
            assert row["outcome"] == "no_path" and type(exc).__name__ in row["error"]
            continue
        summary = run_episode(planned, time_limit_s=TINY_TIME_LIMIT_S).summary()
        assert row["outcome"] == "ok"
        for key in ("reached", "collisions", "sim_time_s", "path_length_m", "min_clearance_m"):
            assert row[key] == summary[key], key
        assert row["run_outcome"] == summary["outcome"]
        plan = summary["plan"]
        assert row["plan_length_m"] == plan["length_m"] and row["plan_iterations"] == plan["iterations"]
        assert row["plan_evaluations"] == plan["evaluations"]
        assert json.loads(row["plan_waypoints"]) == plan["waypoints"]
        assert row["navigator"] == summary["navigator"] and row["world_seed"] is None or math.isnan(row["world_seed"])
    progress = pd.read_parquet(out / "progress.parquet")
    gwo = rows[(rows.planner == "gwo") & (rows.outcome == "ok")]
    assert set(gwo.config_hash) <= set(progress.config_hash)
    one = progress[progress.config_hash == gwo.config_hash.iloc[0]].sort_values("iteration")
    assert len(one) == gwo.plan_iterations.iloc[0] + 1 and np.all(np.diff(one.best_cost) <= 0)


def test_running_again_skips_every_cell(tiny, capsys):
    path, out = tiny
    assert main(["study", str(path), "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["skipped"] == 12 and summary["ran"] == 0
    assert len(pd.read_parquet(out / "runs.parquet")) == 12


def test_resume_after_a_kill_runs_each_cell_once(tmp_path):
    path = write(tmp_path, 'name = "resume"\nscenarios = ["gwo-scenario-1"]\nseeds = 40\n'
                           '[[planners]]\nname = "gwo"\nparams = { population = 20, iterations = 40 }\n')
    out = tmp_path / "out"
    command = [sys.executable, "-m", "swarmnav.cli", "study", str(path), "--out", str(out), "--workers", "1",
               "--json"]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not list((out / "runs.parquet").glob("part-*.parquet")) and time.monotonic() < deadline:
        time.sleep(0.05)
    process.send_signal(signal.SIGKILL)
    process.wait()
    before = pd.read_parquet(out / "runs.parquet")
    assert 0 < len(before) < 40  # killed part-way, with its flushed rows readable
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, timeout=120)
    after = pd.read_parquet(out / "runs.parquet")
    assert len(after) == 40 and after["config_hash"].is_unique
    assert set(after.config_hash) == {c.config_hash for c in expand(load_study(str(path)))}
    assert set(after.seed) == set(range(40))


def test_a_raising_planner_and_a_run_past_the_wall_limit_are_rows(tmp_path, capsys):
    # gwo raises on a grid map (it plans among discs only); 20000 iterations outlast a 1 s wall limit.
    path = write(tmp_path, 'name = "failing"\nscenarios = ["iaco-simple", "gwo-scenario-1"]\nwall_limit_s = 1.0\n'
                           '[[planners]]\nname = "gwo"\nparams = { population = 50, iterations = 20000 }\n')
    assert main(["study", str(path), "--out", str(tmp_path / "out"), "--workers", "2"]) == 0
    assert "2 failed" in capsys.readouterr().out
    rows = pd.read_parquet(tmp_path / "out" / "runs.parquet").set_index("scenario")
    assert rows.loc["iaco-simple", "outcome"] == "error"
    assert rows.loc["iaco-simple", "error"].startswith("ConfigError: ") and "planner.name: gwo" in rows.loc["iaco-simple", "error"]
    assert rows.loc["gwo-scenario-1", "outcome"] == "timeout"
    assert rows.loc["gwo-scenario-1", "cell_wall_s"] < 10
    assert not rows.success.any()
    assert main(["report", str(tmp_path / "out")]) == 0  # a report of failures only still counts them
    report = (tmp_path / "out" / "report.md").read_text()
    # runs, success, collision, left arena, timeout, no path, error, success %
    assert "| gwo | 1 | 0 | 0 | 0 | 0 | 0 | 1 | 0 |" in report and "| gwo | 1 | 0 | 0 | 0 | 1 | 0 | 0 | 0 |" in report


def _markdown_table(text: str, first_header: str) -> list[list[str]]:
    lines = text.splitlines()
    out = []
    for i, line in enumerate(lines):
        if line.startswith(f"| {first_header} |"):
            j = i + 2
            while j < len(lines) and lines[j].startswith("|"):
                out.append([c.strip() for c in lines[j].strip("|").split(" | ")])
                j += 1
    return out


def test_the_report_is_in_the_study_order_whatever_order_the_rows_finished_in(tiny, tiny_report, tmp_path):
    """The same rows give the same report: written from the rows reversed, the Markdown is identical, and the
    scenarios and planners appear in the study file's order."""
    import shutil

    import pyarrow as pa
    import pyarrow.parquet as pq

    _, out = tiny
    copy = tmp_path / "copy"
    (copy / "runs.parquet").mkdir(parents=True)
    shutil.copytree(out / "progress.parquet", copy / "progress.parquet")
    shutil.copy(out / "study.json", copy / "study.json")
    table = pq.read_table(out / "runs.parquet")
    pq.write_table(table.take(pa.array(range(table.num_rows - 1, -1, -1))), copy / "runs.parquet" / "part-0.parquet")
    html = tmp_path / "copy-report" / "r.html"
    assert main(["report", str(copy), "--out", str(html)]) == 0
    texts = [tiny_report[1], html.with_suffix(".md").read_text()]
    assert texts[0] == texts[1]
    assert texts[0].index("## Scenario gwo-scenario-1") < texts[0].index("## Scenario restaurant-table-2")
    counts = texts[0].split("## Scenario gwo-scenario-1")[1]
    assert counts.index("| astar |") < counts.index("| gwo |")


def test_report_tables_and_wilcoxon_agree_with_the_rows(tiny, tiny_report):
    _, out = tiny
    html, text = tiny_report
    assert "data:image/svg+xml;base64," in html.read_text() and "src='http" not in html.read_text()
    rows = pd.read_parquet(out / "runs.parquet")
    checked = 0
    for scenario, group in rows.groupby("scenario"):
        section = text.split(f"## Scenario {scenario}")[1].split("## Scenario")[0]
        counts = {r[0]: r for r in _markdown_table(section, "planner | runs | success")}
        means = _markdown_table(section, "planner | n | plan length (m)")
        mean_header = next(line for line in section.splitlines() if line.startswith("| planner | n | plan length"))
        columns = [c.strip() for c in mean_header.strip("|").split(" | ")]
        mean_rows, median_rows = ({r[0]: dict(zip(columns, r)) for r in means[:2]},
                                  {r[0]: dict(zip(columns, r)) for r in means[2:4]})
        for label, runs in group.groupby("label"):
            assert int(counts[label][1]) == len(runs)
            assert int(counts[label][2]) == int(runs.success.sum())
            assert float(counts[label][-1]) == pytest.approx(100 * runs.success.mean(), abs=0.05)
            lengths = runs.loc[runs.outcome == "ok", "plan_length_m"].to_numpy()
            assert int(mean_rows[label]["n"]) == lengths.size
            mean, _, std = mean_rows[label]["plan length (m)"].partition(" ± ")
            assert float(mean) == pytest.approx(lengths.mean(), rel=1e-3)
            if np.ptp(lengths) > 1e-9:
                assert float(std) == pytest.approx(lengths.std(ddof=1), rel=1e-3)
            assert float(median_rows[label]["plan length (m)"]) == pytest.approx(np.median(lengths), rel=1e-3)
            checked += 1
        ok = group[group.outcome == "ok"]
        tests = {r[1]: r for r in _markdown_table(section, "against | metric")}
        for metric, header in (("plan_length_m", "plan length (m)"), ("plan_time_s", "plan time (s)"),
                               ("path_length_m", "driven length (m)"), ("min_clearance_m", "min clearance (m)")):
            p = stats.ranksums(ok[ok.label == "astar"][metric], ok[ok.label == "gwo"][metric]).pvalue
            assert tests[header][0] == "gwo" and float(tests[header][4]) == pytest.approx(p, rel=0.06), metric
        success = _markdown_table(section, "against | ref successes")[0]
        counts_of = [(int(g.success.sum()), len(g)) for g in (group[group.label == "astar"], group[group.label == "gwo"])]
        assert success[1:3] == [f"{s}/{n}" for s, n in counts_of]
        (a_s, a_n), (g_s, g_n) = counts_of
        assert float(success[3]) == pytest.approx(stats.fisher_exact([[a_s, a_n - a_s], [g_s, g_n - g_s]]).pvalue,
                                                  rel=0.06)
        header = next(line for line in section.splitlines() if line.startswith("| planner | runs | successes"))
        columns = [c.strip() for c in header.strip("|").split(" | ")]
        paper = {r[0]: dict(zip(columns, r)) for r in _markdown_table(section, "planner | runs | successes")}
        for label, runs in group.groupby("label"):
            lengths = runs.loc[runs.outcome == "ok", "plan_length_m"].to_numpy()
            assert float(paper[label]["best length (m)"]) == pytest.approx(lengths.min(), rel=1e-3)
            assert float(paper[label]["mean - best (m)"]) == pytest.approx(lengths.mean() - lengths.min(), abs=1e-3)
    assert checked == 4


BAD_STUDIES = {
    "unknown planner": ('scenarios = ["gwo-scenario-1"]\n[[planners]]\nname = "nope"\n', "planners[0].name"),
    "unknown key": ('scenarios = ["gwo-scenario-1"]\ncolour = 1\n[[planners]]\nname = "astar"\n', "colour"),
    "empty grid": ('scenarios = ["gwo-scenario-1"]\nseeds = []\n[[planners]]\nname = "astar"\n', "seeds"),
    "empty sweep": ('scenarios = ["gwo-scenario-1"]\n[[planners]]\nname = "gwo"\nparams = { iterations = [] }\n',
                    "planners[0].params.iterations"),
    "sweep over a missing parameter": ('scenarios = ["gwo-scenario-1"]\n[[planners]]\nname = "astar"\n'
                                       'params = { wolves = [10, 20] }\n', "planners[0].params.wolves"),
    "quick seeds beyond the seeds": ('scenarios = ["gwo-scenario-1"]\nseeds = 3\nquick_seeds = 4\n'
                                     '[[planners]]\nname = "astar"\n', "quick_seeds"),
    "no scenario matches": ('scenarios = ["nothing-*"]\n[[planners]]\nname = "astar"\n', "scenarios[0]"),
    "paired seeds of different counts": ('scenarios = ["gwo-scenario-1"]\nseeds = 3\nworld_seeds = [0, 1]\n'
                                         'paired_seeds = true\n[[planners]]\nname = "astar"\n', "paired_seeds"),
    "negative clearance": ('scenarios = ["gwo-scenario-1"]\nclearance_m = -0.1\n[[planners]]\nname = "astar"\n',
                           "clearance_m"),
    "infinite clearance": ('scenarios = ["gwo-scenario-1"]\nclearance_m = inf\n[[planners]]\nname = "astar"\n',
                           "clearance_m"),
    "clearance of a pre-inflated map": ('scenarios = ["immas-env1-dynamic"]\nclearance_m = 0.0\n'
                                        '[[planners]]\nname = "astar"\n', "clearance_m"),
}


@pytest.mark.parametrize("case", list(BAD_STUDIES))
def test_bad_study_files_exit_2_naming_the_field(case, tmp_path, capsys):
    text, field = BAD_STUDIES[case]
    path = write(tmp_path, text)
    assert main(["study", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{path}: {field}:" in err
    assert not (tmp_path / "out").exists()


def test_studies_lists_every_bundled_study(capsys):
    assert main(["studies", "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert [s["name"] for s in listed] == list_studies() and len(listed) >= 5
    for entry in listed:
        assert entry["cells"] == len(expand(load_study(entry["name"]))) > 0


def test_paper_values_are_flagged_where_impossible():
    from swarmnav.study.statistics import impossible
    rows = [{"planner": "gwo", "outcome": "ok", "plan_length_m": 14.3, "straight_line_m": 14.142},
            {"planner": "optimal", "outcome": "ok", "plan_length_m": 14.2, "straight_line_m": 14.142}]
    assert "straight line" in impossible("plan_length_m", 14.0, rows)
    assert "exact optimum" in impossible("plan_length_m", 14.15, rows)
    assert impossible("plan_length_m", 14.25, rows) is None
    rows[1].update(outcome="no_path", plan_length_m=None)
    assert "no collision-free path" in impossible("plan_length_m", 14.25, rows)


def test_a_copied_results_folder_reports_without_the_scenario_files(tmp_path):
    """The path plot draws what study.json recorded at run time; the report opens no scenario file.
    Also: the IMMAS quantities a paper prints are columns of their own, equal to the planner's stats."""
    bundled = Path(load_scenario("immas-env1-scattered").source_path)
    work = tmp_path / "work"
    work.mkdir()
    for name in (bundled.name, "immas-env1-scattered.map"):
        source = bundled.parent / name if name.endswith(".toml") else bundled.parent.parent / "maps" / name
        (work / name).write_bytes(source.read_bytes())
    scenario = load_scenario(str(work / bundled.name))
    (work / "study.toml").write_text('name = "copied"\nscenarios = ["immas-env1-scattered.toml"]\nseeds = 2\n'
                                     '[[planners]]\nname = "immas"\n[[planners]]\nname = "astar"\n')
    assert main(["study", str(work / "study.toml"), "--out", str(work / "out"), "--workers", "2", "--json"]) == 0
    (tmp_path / "copy").mkdir()
    os.rename(work / "out", tmp_path / "copy" / "out")
    for path in work.iterdir():
        path.unlink()
    work.rmdir()
    folder = tmp_path / "copy" / "out"
    geometry = json.loads((folder / "study.json").read_text())["scenarios"]["immas-env1-scattered"]
    assert geometry["arena_m"] == [scenario.arena_width_m, scenario.arena_height_m]
    assert geometry["boxes"] == [[b.x_min_m, b.y_min_m, b.x_max_m, b.y_max_m] for b in scenario.boxes]
    assert len(geometry["boxes"]) > 0 and geometry["goal"] == [scenario.goal.x_m, scenario.goal.y_m]
    assert main(["report", str(folder)]) == 0
    report = (folder / "report.md").read_text()
    assert "immas-env1-scattered: the plan of one seed per planner" in report
    rows = pd.read_parquet(folder / "runs.parquet")
    immas = rows[rows.planner == "immas"]
    assert len(immas) == 2 and (immas.outcome == "ok").all()
    for row in immas.to_dict("records"):
        extra = json.loads(row["plan_extra"])
        assert (row["plan_gates_raised"], row["plan_tunnels_closed"]) == (extra["gates_raised"],
                                                                          extra["tunnels_closed"])
        assert row["plan_arc_cost"] == extra["total_arc_cost"]
    assert rows[rows.planner == "astar"].plan_gates_raised.isna().all()
    paper_header = next(line for line in report.splitlines() if line.startswith("| planner | runs | successes"))
    assert "gates" in paper_header and "tunnels" in paper_header


def test_logs_keep_one_mcap_per_run_that_replays(tmp_path):
    path = write(tmp_path, 'name = "logged"\nscenarios = ["restaurant-table-2", "gwo-scenario-1"]\n'
                           'mode = "physics"\ntime_limit_s = 2.0\nseeds = [0]\n[[planners]]\nname = "astar"\n')
    assert main(["study", str(path), "--out", str(tmp_path / "out"), "--workers", "2", "--logs", "--json"]) == 0
    rows = pd.read_parquet(tmp_path / "out" / "runs.parquet")
    assert len(rows) == 2 and rows.log.notna().all()
    for row in rows.to_dict("records"):
        assert Path(row["log"]).parent == (tmp_path / "out" / "logs").resolve()
        assert main(["replay", row["log"], "--verify", "--json"]) == 0


def test_paired_seeds_run_the_kth_seed_with_the_kth_world_seed(tmp_path):
    from swarmnav.study.spec import parse_study
    text = 'scenarios = ["gwo-scenario-2"]\nseeds = [3, 4, 5]\nworld_seeds = [7, 8, 9]\n{}[[planners]]\nname = "astar"\n'
    paired = expand(parse_study(text.format("paired_seeds = true\n")))
    crossed = expand(parse_study(text.format("")))
    assert [(c.seed, c.world_seed) for c in paired] == [(3, 7), (4, 8), (5, 9)]
    assert len(crossed) == 9 and {c.config_hash for c in paired} <= {c.config_hash for c in crossed}
    quick = parse_study(text.format("paired_seeds = true\nquick_seeds = 2\n")).quick()
    assert [(c.seed, c.world_seed) for c in expand(quick)] == [(3, 7), (4, 8)]


def test_a_clearance_override_plans_and_simulates_with_it_and_replays(tmp_path):
    """``clearance_m = 0`` (the papers' convention): the rows are the episodes with that clearance, the exact
    optimum is shorter than with the scenario's own 0.05 m, and the logged run re-simulates bit for bit."""
    path = write(tmp_path, 'name = "bare"\nscenarios = ["gwo-scenario-1"]\nmode = "physics"\ntime_limit_s = 2.0\n'
                           'clearance_m = 0.0\nseeds = [0]\n[[planners]]\nname = "optimal"\n')
    assert main(["study", str(path), "--out", str(tmp_path / "out"), "--workers", "1", "--logs", "--json"]) == 0
    row = pd.read_parquet(tmp_path / "out" / "runs.parquet").to_dict("records")[0]
    scenario = load_scenario("gwo-scenario-1")
    bare = plan_episode(EpisodeSpec(scenario, "optimal", clearance_m=0.0))
    own = plan_episode(EpisodeSpec(scenario, "optimal"))
    assert row["clearance_m"] == 0.0 and bare.problem.clearance_m == 0.0
    assert row["plan_length_m"] == bare.path.stats.length_m < own.path.stats.length_m
    assert main(["replay", row["log"], "--verify", "--json"]) == 0


PLAN_ONLY = 'name = "bar"\nscenarios = ["gwo-scenario-1"]\nseeds = 2\n[[planners]]\nname = "astar"\n'


def test_the_progress_bar_appears_only_on_a_terminal(tmp_path, capsys):
    import pty
    path = write(tmp_path, PLAN_ONLY)
    assert main(["study", str(path), "--workers", "1", "--out", str(tmp_path / "piped")]) == 0
    assert capsys.readouterr().err == ""  # stderr is not a terminal here
    command = [sys.executable, "-m", "swarmnav.cli", "study", str(path), "--workers", "1"]
    leader, follower = pty.openpty()
    try:
        on_terminal = subprocess.run(command + ["--out", str(tmp_path / "tty")], stdout=subprocess.PIPE,
                                     stderr=follower, timeout=120)
        os.close(follower)
        err = b""
        while True:
            try:
                chunk = os.read(leader, 4096)
            except OSError:  # EIO once the child's end is closed and drained
                break
            if not chunk:
                break
            err += chunk
    finally:
        os.close(leader)
    assert on_terminal.returncode == 0
    text = err.decode()
    assert "\r[" in text and "2/2" in text and "failed 0" in text


def test_off_the_main_thread_the_wall_limit_is_checked_after_the_run():
    import threading
    from swarmnav.study.cell import run_cell
    from swarmnav.study.spec import parse_study
    cell = expand(parse_study(PLAN_ONLY.replace("seeds = 2\n", "seeds = 1\nwall_limit_s = 0.0001\n")))[0]
    result = {}
    thread = threading.Thread(target=lambda: result.update(row=run_cell(cell)[0]))
    thread.start()
    thread.join()
    row = result["row"]
    assert row["outcome"] == "timeout" and "checked after the run" in row["error"]
    assert row["cell_wall_s"] > 0.0001 and row["plan_length_m"] > 0  # the run finished, then was judged


def test_a_quick_run_is_the_first_seeds_of_the_full_one():
    full = load_study("iaco-vs-grid")
    quick = full.quick()
    assert quick.seeds == full.seeds[:full.quick_seeds] and len(quick.seeds) < len(full.seeds)
    full_cells = {c.config_hash: c for c in expand(full)}
    quick_cells = expand(quick)
    assert len(quick_cells) * len(full.seeds) == len(full_cells) * len(quick.seeds)
    assert all(c.config_hash in full_cells and c.seed in quick.seeds for c in quick_cells)


def test_an_unreachable_ray_address_is_one_line_naming_the_option(tmp_path):
    import socket

    from swarmnav.models.errors import ConfigError
    from swarmnav.study.ray_engine import check_reachable

    with socket.socket() as listener:  # a port that surely refuses: bound, never listening
        listener.bind(("127.0.0.1", 0))
        port = listener.getsockname()[1]
        with pytest.raises(ConfigError) as info:
            check_reachable(f"ray://127.0.0.1:{port}")
        assert info.value.field == "--address" and str(port) in info.value.problem
        study = write(tmp_path, PLAN_ONLY)
        assert main(["study", str(study), "--out", str(tmp_path / "out"), "--engine", "ray",
                     "--address", f"127.0.0.1:{port}"]) == 2
    assert not (tmp_path / "out").exists()  # refused before anything was written


ABC_PLAN_ONLY = ('name = "abc-progress"\nscenarios = ["restaurant-table-2"]\nseeds = 2\n'
                 '[[planners]]\nname = "abc"\nparams = { population = 10, iterations = 12, limit = 6, mode = "robust", '
                 'stall_evaluations = 0 }\n')


def test_progress_rows_are_the_planners_own_evaluation_history():
    """A study's progress rows for a cell equal the history the planner records for the same seed, and
    ABC's evaluations per iteration differ (scouts), so they are no even spread."""
    from swarmnav.study.cell import run_cell
    from swarmnav.study.spec import parse_study
    for cell in expand(parse_study(ABC_PLAN_ONLY)):
        row, progress = run_cell(cell)
        assert row["outcome"] == "ok", row.get("error")
        stats = plan_episode(EpisodeSpec(load_scenario(cell.scenario), cell.planner, cell.planner_params,
                                         seed=cell.seed)).path.stats
        assert [p["iteration"] for p in progress] == list(range(len(stats.cost_history)))
        assert [p["best_cost"] for p in progress] == list(stats.cost_history)
        assert [p["evaluations"] for p in progress] == list(stats.evaluation_history)
        assert not any(p["evaluations_estimated"] for p in progress)
        assert len(set(np.diff([p["evaluations"] for p in progress]).tolist())) > 1


def test_a_planner_without_an_evaluation_history_gets_an_even_spread_marked_estimated():
    import dataclasses

    from swarmnav.planners.problem import Path as PlannedPath
    from swarmnav.study.cell import _progress_rows
    from swarmnav.study.spec import parse_study
    cell = expand(parse_study(ABC_PLAN_ONLY))[0]
    episode = plan_episode(EpisodeSpec(load_scenario(cell.scenario), cell.planner, cell.planner_params,
                                       seed=cell.seed))
    stats = dataclasses.replace(episode.path.stats, evaluation_history=())
    episode.path = PlannedPath(episode.path.waypoints, stats)
    progress = _progress_rows(cell, episode)
    assert all(p["evaluations_estimated"] for p in progress)
    evaluations = [p["evaluations"] for p in progress]
    assert evaluations[0] == 0 and evaluations[-1] == stats.evaluations
    assert np.ptp(np.diff(evaluations)) <= 1  # even, up to rounding


def test_the_convergence_curve_by_evaluations_is_the_recorded_step_function():
    from swarmnav.study.anytime import on_grid
    costs = on_grid(np.array([20, 61, 101, 150]), np.array([9.0, 7.0, 7.0, 4.0]),
                    np.array([0, 19, 20, 60, 61, 149, 150, 400]))
    assert np.isnan(costs[:2]).all()  # nothing was scored before the first population
    assert costs[2:].tolist() == [9.0, 9.0, 7.0, 7.0, 4.0, 4.0]


def test_the_maps_and_poses_axes_run_each_value_and_rows_carry_it(tmp_path, capsys):
    path = write(tmp_path, 'name = "knowledge"\nscenarios = ["gwo-scenario-1"]\nmode = "physics"\ntime_limit_s = 2.0\n'
                           'seeds = [0]\nmaps = ["known", "unknown"]\nposes = ["odometry"]\n'
                           '[[planners]]\nname = "astar"\n[[navigators]]\nname = "replan"\n')
    assert main(["study", str(path), "--out", str(tmp_path / "out"), "--workers", "1", "--json"]) == 0
    rows = pd.read_parquet(tmp_path / "out" / "runs.parquet")
    assert sorted(rows.map_knowledge) == ["known", "unknown"] and set(rows.pose_source) == {"odometry"}
    assert rows.config_hash.nunique() == 2 and (rows.outcome != "error").all(), rows.error.tolist()
    bad = write(tmp_path, path.read_text().replace('"unknown"]', '"blurry"]'), "bad.toml")
    capsys.readouterr()
    assert main(["study", str(bad), "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "maps" in err and "blurry" in err, err
