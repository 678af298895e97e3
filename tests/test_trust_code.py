"""Data is not code: a scenario file, a study file or a log never makes swarmnav import and call code,
unless the user passes ``--trust-code`` on that invocation (or names the code on the command line).

Each path is tried with a policy whose module writes a marker file when imported: without the opt-in
the marker never appears and the command exits 2 with one line naming ``--trust-code``.
"""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

SCENARIO = """
name = "trust"
seed = 0
time_limit_s = 1.0
arena = { width_m = 3.0, height_m = 3.0, walls = false }
robot = { radius_m = 0.15, max_speed_m_s = 0.2 }
start = { x = 0.5, y = 0.5, heading_deg = 45.0 }
goal = { x = 2.5, y = 2.5, tolerance_m = 0.1 }
sensors = { count = 8, range_m = 0.4 }
planner = { name = "straight", params = {} }
"""

MARKER_MODULE = """
from pathlib import Path
Path(__file__).with_name("marker.txt").write_text("imported")

def act(obs):
    return [1.0, 0.0]
"""


@pytest.fixture
def marker(tmp_path, monkeypatch):
    """A module ``marker_policy`` importable by subprocesses, and the file its import writes."""
    (tmp_path / "marker_policy.py").write_text(MARKER_MODULE)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")]))
    monkeypatch.chdir(tmp_path)
    return tmp_path / "marker.txt"


def swarmnav(*args):
    return subprocess.run([sys.executable, "-m", "swarmnav.cli", *args], capture_output=True, text=True,
                          timeout=300)


def refused(out, marker: Path, field: str) -> bool:
    lines = out.stderr.strip().splitlines()
    return (out.returncode == 2 and len(lines) == 1 and field in lines[0] and "--trust-code" in lines[0]
            and "Traceback" not in out.stderr and not marker.exists())


def policy_scenario(tmp_path: Path) -> Path:
    path = tmp_path / "trust.toml"
    path.write_text(SCENARIO + 'navigator = { name = "policy", params = { policy = "marker_policy:act" } }\n')
    return path


def test_a_scenario_file_naming_a_policy_runs_it_only_with_trust_code(marker, tmp_path):
    scenario = policy_scenario(tmp_path)
    for command in ("plan", "run"):
        out = swarmnav(command, str(scenario), "--no-log" if command == "run" else "--json")
        assert refused(out, marker, "navigator.params.policy"), out.stderr
        assert str(scenario) in out.stderr
    ran = swarmnav("run", str(scenario), "--no-log", "--json", "--trust-code")
    assert ran.returncode == 0, ran.stderr
    assert marker.read_text() == "imported" and json.loads(ran.stdout)["navigator"] == "policy"


def test_the_command_line_may_name_the_policy_a_scenario_file_names(marker, tmp_path):
    # The user's own --navigator-set replaces the file's value: that is code the user put there.
    out = swarmnav("run", str(policy_scenario(tmp_path)), "--no-log", "--navigator-set",
                   "policy=marker_policy:act")
    assert out.returncode == 0, out.stderr
    assert marker.exists()


def test_a_study_naming_a_policy_runs_it_only_with_trust_code(marker, tmp_path):
    (tmp_path / "plain.toml").write_text(SCENARIO)
    study = tmp_path / "study.toml"
    study.write_text(textwrap.dedent('''
        scenarios = ["plain.toml"]
        mode = "physics"
        seeds = 1

        [[planners]]
        name = "straight"

        [[navigators]]
        name = "policy"
        params = { policy = "marker_policy:act" }
    '''))
    out = swarmnav("study", str(study), "--out", str(tmp_path / "rows"), "--workers", "1", "--json")
    assert refused(out, marker, "navigators[0].params.policy"), out.stderr
    assert not (tmp_path / "rows").exists()
    ran = swarmnav("study", str(study), "--out", str(tmp_path / "rows"), "--workers", "1", "--json",
                   "--trust-code")
    assert ran.returncode == 0, ran.stderr
    summary = json.loads(ran.stdout)
    assert summary["ran"] == 1 and summary["failed"] == 0, summary
    assert marker.exists()


def test_replay_verify_reruns_a_logged_policy_only_when_named_or_trusted(marker, tmp_path):
    scenario = tmp_path / "plain.toml"
    scenario.write_text(SCENARIO)
    log = tmp_path / "run.mcap"
    recorded = swarmnav("run", str(scenario), "--navigator", "policy", "--navigator-set",
                        "policy=marker_policy:act", "--out", str(log))
    assert recorded.returncode == 0, recorded.stderr
    marker.unlink()

    out = swarmnav("replay", str(log), "--verify")
    assert refused(out, marker, "navigator.params.policy"), out.stderr
    assert "--navigator-set policy=" in out.stderr and str(log) in out.stderr

    named = swarmnav("replay", str(log), "--verify", "--navigator-set", "policy=marker_policy:act")
    assert named.returncode == 0, named.stderr
    assert "named on the command line" in named.stdout and marker.exists()
    marker.unlink()

    trusted = swarmnav("replay", str(log), "--verify", "--trust-code", "--json")
    assert trusted.returncode == 0, trusted.stderr
    assert json.loads(trusted.stdout)["verify"]["passed"] is True and marker.exists()


def test_replay_takes_only_code_parameters_on_its_command_line(marker, tmp_path):
    scenario = tmp_path / "plain.toml"
    scenario.write_text(SCENARIO)
    log = tmp_path / "run.mcap"
    assert swarmnav("run", str(scenario), "--out", str(log)).returncode == 0
    out = swarmnav("replay", str(log), "--verify", "--navigator-set", "lookahead_m=2")
    lines = out.stderr.strip().splitlines()
    assert out.returncode == 2 and len(lines) == 1 and "--navigator-set" in lines[0]


def test_the_python_api_takes_a_policy_and_a_trusted_file(tmp_path, monkeypatch):
    from swarmnav.models.errors import ConfigError
    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.episode import EpisodeSpec, plan_episode

    (tmp_path / "marker_policy.py").write_text(MARKER_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "marker_policy", raising=False)  # imported afresh: its marker is this test's
    path = policy_scenario(tmp_path)
    with pytest.raises(ConfigError, match="--trust-code"):
        plan_episode(EpisodeSpec(load_scenario(str(path))))
    assert not (tmp_path / "marker.txt").exists()
    assert plan_episode(EpisodeSpec(load_scenario(str(path), trust_code=True))).spec.navigator == "policy"
    assert (tmp_path / "marker.txt").exists()


def test_the_public_api_refuses_a_files_policy_unless_trusted(tmp_path, monkeypatch):
    import swarmnav

    (tmp_path / "marker_policy.py").write_text(MARKER_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "marker_policy", raising=False)  # imported afresh: its marker is this test's
    path = policy_scenario(tmp_path)
    with pytest.raises(swarmnav.ConfigError, match="navigator.params.policy.*--trust-code"):
        swarmnav.run(str(path), log=False)
    assert not (tmp_path / "marker.txt").exists()
    result = swarmnav.run(swarmnav.load_scenario(str(path), trust_code=True), log=False)
    assert result.to_dict()["navigator"] == "policy" and (tmp_path / "marker.txt").exists()
