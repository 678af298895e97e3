"""The BARN block of the docs (docs/barn.md, moved from the README) is generated from the committed results (models/suites/results/barn*.json): it
fails when either drifts from the other, and checks that the figures are the rows' own."""

import json
from pathlib import Path

from swarmnav.benchmarks import barn_table
from swarmnav.benchmarks.barn_difficulty import success_against_difficulty

README = Path(__file__).resolve().parent.parent / "docs" / "barn.md"  # the page that holds the block


def test_readme_block_is_generated_from_the_committed_results():
    assert barn_table.current_block(README.read_text(encoding="utf-8")) == barn_table.block()


def test_committed_results_are_barn_runs_with_their_scores():
    present = [p for p in barn_table.RESULTS if p.is_file()]
    assert present, "no committed BARN result"
    for path in present:
        rows = json.loads(path.read_text(encoding="utf-8"))
        overall = {r["navigator"]: r for r in rows if r["scenario"] is None}
        for name, row in overall.items():
            runs = [r for r in rows if r["scenario"] is not None and r["navigator"] == name]
            assert len(runs) == row["runs"]  # one per-run row for every run counted
            assert abs(sum(r["barn_score"] for r in runs) / len(runs) - row["barn_score"]) < 1e-12
            assert abs(sum(r["success_rate"] for r in runs) / len(runs) - row["success_rate"]) < 1e-12
            assert all(0.0 <= r["barn_score"] <= 0.5 and (r["barn_score"] > 0) == (r["success_rate"] == 1.0)
                       for r in runs)


def test_success_against_difficulty_reads_the_rows():
    rows = [{"navigator": "n", "world": w, "success_rate": float(w < 2),
             "difficulty": {k: float(w) for k in ("distance_to_closest_obstacle", "average_visibility",
                                                  "dispersion", "characteristic_dimension", "tortuosity")}}
            for w in range(4)]
    table = success_against_difficulty(rows, "n")
    assert table["dispersion"] == {"spearman": -0.8944, "success_low_half": 1.0, "success_high_half": 0.0}
