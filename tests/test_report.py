"""The report: claims and their verdicts, anytime curves, tables as CSV and LaTeX, figures that fit the page,
and the README's claims table generated from the committed verdicts."""

import csv
import io
import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from swarmnav.cli.main import main
from swarmnav.study.claim_spec import Claim
from swarmnav.study.claims import CONTRADICTED, INCONCLUSIVE, REPRODUCES, a12, verdicts
from swarmnav.study.spec import list_studies, load_study

REPO = Path(__file__).resolve().parents[1]

# optimal is the exact shortest path: every GWO plan (10 wolves, 10 iterations) is longer.  GWO's paper mode
# (Kamil et al.'s weight-1 penalty, no repair) mostly ends in no path here, so B runs Abdulla & Hadi's
# objective with the studies' penalty weight 1000 and 2 cm margin (as gwo-vs-abc does).
SHORTER = """
name = "shorter"
scenarios = ["gwo-scenario-1"]
seeds = 8
[[planners]]
name = "optimal"
label = "A"
[[planners]]
name = "gwo"
label = "B"
params = {{ population = 10, iterations = 10, penalty_weight = 1000.0, penalty_margin_m = 0.02 }}
{claims}
"""
CLAIM = """
[[claims]]
id = "{id}"
statement = "{planner} is shorter than {than}"
source = "synthetic"
scenario = "gwo-scenario-1"
metric = "{metric}"
better = "lower"
planner = "{planner}"
than = ["{than}"]
test = "{test}"
"""


@pytest.fixture(scope="module")
def shorter(tmp_path_factory):
    base = tmp_path_factory.mktemp("shorter")
    claims = (CLAIM.format(id="a-shorter", planner="A", than="B", metric="plan_length_m", test="rank_sum")
              + CLAIM.format(id="b-shorter", planner="B", than="A", metric="plan_length_m", test="rank_sum")
              + CLAIM.format(id="a-shorter-paired", planner="A", than="B", metric="plan_length_m",
                             test="signed_rank"))
    path = base / "shorter.toml"
    path.write_text(SHORTER.format(claims=claims))
    assert main(["study", str(path), "--out", str(base / "out"), "--workers", "2", "--json"]) == 0
    return base / "out"


def test_a_clearly_shorter_planner_reproduces_and_the_reverse_is_contradicted(shorter, capsys):
    capsys.readouterr()
    assert main(["report", str(shorter), "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document == json.loads((shorter / "claims.json").read_text())
    by_id = {c["id"]: c for c in document["claims"]}
    assert by_id["a-shorter"]["verdict"] == REPRODUCES
    assert by_id["b-shorter"]["verdict"] == CONTRADICTED
    assert by_id["a-shorter-paired"]["verdict"] == REPRODUCES
    rows = pd.read_parquet(shorter / "runs.parquet")
    a = rows[rows.label == "A"].plan_length_m.to_numpy()
    b = rows[rows.label == "B"].plan_length_m.to_numpy()
    assert (a < b.min()).all()
    # A (the exact optimum) is deterministic: its eight runs are one plan, counted once, and each claim is the
    # one-sample signed-rank test of B's lengths against it; Holm over the three equal p-values.
    assert len(set(a)) == 1 and all(c["pairs"][0]["test"] == "one_sample" for c in by_id.values())
    expected = 3 * stats.wilcoxon(b - a[0]).pvalue
    assert by_id["a-shorter"]["p_holm"] == pytest.approx(expected) == by_id["b-shorter"]["p_holm"]
    assert by_id["a-shorter"]["a12"] == 1.0 and by_id["b-shorter"]["a12"] == 0.0
    assert by_id["a-shorter"]["pairs"][0]["n"] == [1, 8]
    markdown = (shorter / "report.md").read_text()
    assert "## Claims" in markdown and "| a-shorter | A is shorter than B |" in markdown


def _rows(label, values, scenario="s", navigator="follow", outcome="ok", success=True):
    return [{"scenario": scenario, "label": label, "navigator_label": navigator, "seed": i, "world_seed": None,
             "outcome": outcome, "success": success, "plan_length_m": v if outcome == "ok" else None}
            for i, v in enumerate(values)]


def _claim(**kw):
    base = dict(id="c", statement="s", source="x", scenario="s", metric="plan_length_m", better="lower",
                planner="A", than=("B",), test="rank_sum")
    return Claim(**{**base, **kw})


def test_failed_rows_are_failures_for_success_and_left_out_of_a_metric_with_n_per_side():
    rows = (_rows("A", [1.0] * 10) + _rows("B", [2.0] * 3) + _rows("B", [0.0] * 9, outcome="no_path", success=False))
    [length, success] = verdicts([_claim(id="len"), _claim(id="ok", metric="success", better="higher",
                                                             test="fisher")], rows)
    assert length["pairs"][0]["n"] == [10, 3] and length["pairs"][0]["runs"] == [10, 12]
    assert success["pairs"][0]["successes"] == [10, 3]
    p = stats.fisher_exact([[10, 0], [3, 9]]).pvalue
    assert success["verdict"] == REPRODUCES and success["pairs"][0]["p"] == pytest.approx(p)
    assert success["a12"] == pytest.approx(a12(np.ones(10), np.array([1.0] * 3 + [0.0] * 9)))


def test_every_pair_must_hold_and_one_opposite_pair_contradicts():
    rng = np.random.default_rng(0)
    rows = _rows("A", 10 + rng.random(12)) + _rows("B", 20 + rng.random(12)) + _rows("C", 10 + rng.random(12))
    rows += _rows("D", 5 + rng.random(12))
    [both, opposite] = verdicts([_claim(id="b-and-c", than=("B", "C")), _claim(id="b-and-d", than=("B", "D"))],
                                rows)
    assert both["verdict"] == INCONCLUSIVE and opposite["verdict"] == CONTRADICTED
    assert both["a12"] == min(p["a12"] for p in both["pairs"])
    # higher is better: the same rows turn the verdict around
    [higher] = verdicts([_claim(better="higher")], rows)
    assert higher["verdict"] == CONTRADICTED


BAD_CLAIMS = {
    "unknown planner label": ('planner = "Z"', "claims[0].planner"),
    "unknown than label": ('than = ["Z"]', "claims[0].than[0]"),
    "unknown scenario": ('scenario = "gwo-scenario-9"', "claims[0].scenario"),
    "unknown metric": ('metric = "colour"', "claims[0].metric"),
    "unknown test": ('test = "t_test"', "claims[0].test"),
    "fisher on a length": ('test = "fisher"', "claims[0].test"),
    "unknown navigator": ('navigator = "replan"', "claims[0].navigator"),
    "bad id": ('id = "Not An Id"', "claims[0].id"),
    "unknown key": ('colour = "red"', "claims[0].colour"),
}


@pytest.mark.parametrize("case", list(BAD_CLAIMS))
def test_bad_claims_exit_2_naming_the_file_and_field(case, tmp_path, capsys):
    replacement, field = BAD_CLAIMS[case]
    claim = CLAIM.format(id="a-shorter", planner="A", than="B", metric="plan_length_m", test="rank_sum")
    key = replacement.split(" = ")[0]
    lines = [line for line in claim.splitlines() if not line.startswith(f"{key} =")] + [replacement]
    path = tmp_path / "bad.toml"
    path.write_text(SHORTER.format(claims="\n".join(lines)))
    assert main(["study", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{path}: {field}:" in err


def test_figures_fit_the_page_and_tables_exist_as_csv_and_latex(shorter, tmp_path):
    html_path = tmp_path / "r.html"
    assert main(["report", str(shorter), "--out", str(html_path)]) == 0
    text = html_path.read_text()
    assert re.search(r"img\{max-width:100%;height:auto", text)
    images = re.findall(r"<img [^>]*>", text)
    assert images and all("max-width:100%" in tag and "data:image/svg+xml;base64," in tag for tag in images)
    assert "width=device-width" in text
    files = tmp_path / "r_files"
    svgs = sorted(files.glob("figure-*.svg"))
    assert len(svgs) == len(images) and len(sorted(files.glob("figure-*.png"))) == len(images)
    for svg in svgs:  # no figure wider than 11 inches (792 pt) at its natural size
        width = float(re.search(r'width="([\d.]+)pt"', svg.read_text()).group(1))
        assert width <= 792, svg
    tables = sorted((files / "tables").glob("*.csv"))
    html_tables = text.count("<table>")
    assert len(tables) == html_tables and html_tables >= 5
    for table in tables:
        rows = list(csv.reader(io.StringIO(table.read_text())))
        assert len({len(r) for r in rows}) == 1, table  # every row as wide as the header
        latex = table.with_suffix(".tex").read_text()
        assert latex.index(r"\toprule") < latex.index(r"\midrule") < latex.index(r"\bottomrule")
        body = latex.split(r"\midrule")[1].split(r"\bottomrule")[0].strip().splitlines()
        header = latex.split(r"\toprule")[1].split(r"\midrule")[0]
        columns = re.search(r"\\begin\{tabular\}\{([lr]+)\}", latex).group(1)
        for line in [header.strip()] + body:
            assert len(re.findall(r"(?<!\\)&", line)) == len(columns) - 1, line
            assert not re.search(r"(?<!\\)[_%#]", line.replace(r"\_", "")), line
    # The CSV keeps full precision: the mean of A's lengths is the rows' mean.
    rows = pd.read_parquet(shorter / "runs.parquet")
    mean = next(csv.DictReader(io.StringIO((files / "tables" / "gwo-scenario-1-mean.csv").read_text())))
    assert mean["planner"] == "A"
    assert float(mean["plan length (m) mean"]) == pytest.approx(rows[rows.label == "A"].plan_length_m.mean())
    assert r"\input{tables/claims.tex}" in (files / "tables.tex").read_text()


def test_numbers_have_a_consistent_number_of_significant_digits():
    from swarmnav.study.tables import number, p_value
    assert [number(x) for x in (14.355, 14.2269, 1.885e-05, 0.0001571, 20966.3, 3, 0.0)] == \
        ["14.36", "14.23", "0.00001885", "0.0001571", "20966", "3", "0"]
    assert [p_value(p) for p in (0.36, 0.0123, 1.2e-17)] == ["0.36", "0.012", "1.2e-17"]


def test_anytime_targets_count_every_run_and_the_quartiles_count_unstarted_runs_as_worst():
    from swarmnav.study.anytime import History, first_reached, fixed_target, quartiles
    runs = [History(np.array([20.0, 11.0, 10.2]), np.array([10.0, 20.0, 40.0]), np.array([0.1, 0.2, 0.4]), False),
            History(np.array([30.0, 15.0]), np.array([10.0, 20.0]), np.array([0.1, 0.2]), False)]
    assert first_reached(runs[0].evaluations, runs[0].cost, 11.0) == 20.0
    assert first_reached(runs[1].evaluations, runs[1].cost, 11.0) == float("inf")
    grid, share = fixed_target(runs, total_runs=4, reference=10.0, axis="evaluations")
    # targets 11, 10.3, 10.1, 10.03: run 0 reaches 11 at 20 and 10.3 at 40; run 1 none; two runs had no history
    assert share[np.searchsorted(grid, 20.0)] == pytest.approx(1 / 16)
    assert share[-1] == pytest.approx(2 / 16)
    stack = np.array([[np.nan, 5.0, 4.0], [9.0, 8.0, 7.0], [np.inf, np.inf, 1.0]])
    q1, median, q3 = quartiles(stack)
    assert np.isnan(median[0]) and median[1] == 8.0 and median[2] == 4.0


def test_progress_rows_carry_the_planners_wall_times(shorter):
    progress = pd.read_parquet(shorter / "progress.parquet")
    rows = pd.read_parquet(shorter / "runs.parquet").set_index("config_hash")
    assert len(progress) and progress.wall_s.notna().all()
    for key, group in progress.groupby("config_hash"):
        times = group.sort_values("iteration").wall_s.to_numpy()
        assert (np.diff(times) >= 0).all() and times[-1] <= rows.loc[key, "plan_time_s"]


def test_identical_configurations_are_shown_once():
    from swarmnav.study.report_tables import merge_identical
    def rows(navigator, length):
        return [{"label": "gwo", "navigator_label": navigator, "seed": s, "world_seed": None, "outcome": "ok",
                 "plan_waypoints": "[[0, 0], [1, 1]]", "plan_length_m": length, "plan_time_s": s * 0.1 + len(navigator)}
                for s in range(3)]
    arms = {"gwo": rows("follow", 1.4), "gwo + replan": rows("replan", 1.4), "gwo + other": rows("other", 1.5)}
    merged, sentences = merge_identical(arms)
    assert list(merged) == ["gwo", "gwo + other"] and "gwo + replan as gwo" in sentences[0]


def test_the_readme_claims_table_is_the_one_generated_from_the_committed_verdicts(capsys):
    from swarmnav.study.readme_table import RESULTS_DIR, current_block
    committed = sorted(RESULTS_DIR.glob("*/claims.json"))
    assert main(["report", "--readme-table", str(RESULTS_DIR)]) == 0
    generated = capsys.readouterr().out.strip()
    page = (REPO / "docs" / "reference" / "studies.md").read_text()  # the claims table moved from the README
    assert current_block(page) == generated, "run `make readme-table` (docs/reference/studies.md and verdicts differ)"
    with_claims = [name for name in list_studies() if load_study(name).claims]
    assert sorted(p.parent.name for p in committed) == with_claims, \
        "a bundled study's claims have no committed verdicts (or a study lost its claims); run `make readme-table`"
    for path in committed:  # each committed verdict file is of a bundled study, with its claims as written now
        document = json.loads(path.read_text())
        assert document["study"] == path.parent.name and path.parent.name in list_studies()
        written = {c.id: c.as_dict() for c in load_study(path.parent.name).claims}
        assert sorted(c["id"] for c in document["claims"]) == sorted(written), \
            f"{path}: the study's claims changed; run `make readme-table`"
        for claim in document["claims"]:
            fields = {k: claim[k] for k in written[claim["id"]]}
            assert fields == written[claim["id"]], f"{path}: claim {claim['id']} changed; run `make readme-table`"


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="pdflatex not installed (the LaTeX is checked "
                                                              "structurally above)")
def test_the_latex_tables_compile_with_pdflatex(shorter, tmp_path):
    html_path = tmp_path / "r.html"
    assert main(["report", str(shorter), "--out", str(html_path)]) == 0
    done = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "tables.tex"],
                          cwd=tmp_path / "r_files", capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout[-2000:]


PHYSICS = """
name = "collide"
scenarios = ["gwo-scenario-2"]
mode = "physics"
time_limit_s = 35
seeds = 1
[[planners]]
name = "optimal"
"""


def test_physics_paths_show_the_driven_trajectory_from_logs_and_say_so_without(tmp_path):
    """On gwo-scenario-2 the straight optimal plan driven by follow collides with a moving disc: the outcome
    is a collision, study.json has the moving discs' tracks, and the path figure draws the driven trajectory
    from the kept log (without --logs the report says there is none)."""
    path = tmp_path / "collide.toml"
    path.write_text(PHYSICS)
    for folder, logs in (("with", ["--logs"]), ("without", [])):
        assert main(["study", str(path), "--out", str(tmp_path / folder), "--json", *logs]) == 0
        assert main(["report", str(tmp_path / folder)]) == 0
    geometry = json.loads((tmp_path / "with" / "study.json").read_text())["scenarios"]["gwo-scenario-2"]
    assert len(geometry["disc_tracks"]) == 3 and geometry["optimum_m"] == pytest.approx(np.hypot(10, 10))
    with_logs = (tmp_path / "with" / "report.md").read_text()
    without = (tmp_path / "without" / "report.md").read_text()
    assert "| optimal | 1 | 0 | 1 | 0 | 0 | 0 | 0 |" in with_logs  # runs, success, collision, ...
    assert "the trajectory it drove" in with_logs and "No driven trajectory" not in with_logs
    assert "No driven trajectory for optimal" in without and "--logs" in without


def test_identical_lengths_up_to_rounding_have_no_spread_in_the_paper_table():
    from swarmnav.study.statistics import paper_table
    rows = [{"outcome": "ok", "success": True, "plan_length_m": x} for x in (31.7, 31.700000000000003, 31.7)]
    header, [line] = paper_table({"a": rows})
    assert line[header.index("mean - best (m)")] == 0.0 and line[header.index("std (m)")] == 0.0
    rows[0]["plan_length_m"] = 32.0
    header, [line] = paper_table({"a": rows})
    assert line[header.index("mean - best (m)")] == pytest.approx(0.1)


def test_a12_counts_every_pair_with_ties_half():
    rng = np.random.default_rng(3)
    x, y = rng.integers(0, 5, 40).astype(float), rng.integers(0, 5, 33).astype(float)
    pairs = [(1.0 if a > b else 0.5 if a == b else 0.0) for a in x for b in y]
    assert a12(x, y) == pytest.approx(np.mean(pairs)) and a12(x, y) + a12(y, x) == pytest.approx(1.0)


def test_identical_samples_give_a_rank_sum_p_of_one_and_an_inconclusive_claim(recwarn):
    [claim] = verdicts([_claim()], _rows("A", [3.0] * 5) + _rows("B", [3.0] * 5))
    assert claim["pairs"][0]["p"] == 1.0 and claim["verdict"] == INCONCLUSIVE and claim["a12"] == 0.5
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]
