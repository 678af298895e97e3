"""The freshness check (issue 31): every committed claims.json records what produced it, and `swarmnav report
--check-fresh` names the stale ones."""

from __future__ import annotations

import json
import shutil

from swarmnav.cli.main import main
from swarmnav.study.readme_table import RESULTS_DIR


def test_check_fresh_passes_on_the_committed_results(capsys):
    code = main(["report", "--check-fresh", str(RESULTS_DIR)])
    out = capsys.readouterr().out
    assert code == 0, f"stale committed verdicts (rerun them: make rerun-stale):\n{out}"
    assert "fresh" in out


def test_check_fresh_names_the_stale_claims_after_a_planner_changes(tmp_path, capsys):
    """A committed claims.json whose recorded hash of planners/grey_wolf.py differs from today's (as after an
    edit of that file) is stale: exit 5, naming the study, its claims and the file; --names gives the study."""
    source = RESULTS_DIR / "gwo-vs-abc" / "claims.json"
    document = json.loads(source.read_text())
    assert "planners/grey_wolf.py" in document["inputs"]["sources"]
    document["inputs"]["sources"]["planners/grey_wolf.py"] = "0" * 64
    (tmp_path / "gwo-vs-abc").mkdir()
    (tmp_path / "gwo-vs-abc" / "claims.json").write_text(json.dumps(document))
    shutil.copytree(RESULTS_DIR / "maco-p0", tmp_path / "maco-p0")  # fresh, not named
    assert main(["report", "--check-fresh", str(tmp_path)]) == 5
    out = capsys.readouterr().out
    assert "stale: gwo-vs-abc" in out and "source planners/grey_wolf.py changed" in out and "maco-p0" not in out
    assert all(c["id"] in out for c in document["claims"])
    assert main(["report", "--check-fresh", str(tmp_path), "--names"]) == 5
    assert capsys.readouterr().out.split() == ["gwo-vs-abc"]
