"""The smaller items of issue 36, each a test that failed before the fix."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from swarmnav.cli.main import main
from probe_scenario import PROBE_SCENARIO


def outcome(capsys, argv):
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert len(err.splitlines()) <= 1 and "bug:" not in err, err
    return code, err, captured.out


def test_run_out_empty_is_refused_not_the_default_log(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "probe.toml").write_text(PROBE_SCENARIO)
    code, err, _ = outcome(capsys, ["run", "probe.toml", "--out", "", "--planner", "straight"])
    assert code == 2 and "--out" in err and not (tmp_path / "logs").exists()


def test_the_planner_grid_refusal_names_the_file_and_both_maxima(capsys, tmp_path):
    path = tmp_path / "wide.toml"
    path.write_text(PROBE_SCENARIO.replace("width_m = 5.0, height_m = 5.0", "width_m = 200.0, height_m = 200.0"))
    code, err, _ = outcome(capsys, ["plan", str(path)])
    assert code == 2 and str(path) in err and "5,000,000" in err and "16,000,000" in err


@pytest.mark.parametrize("argv", [["log", "recover", "LOG", "SPECIAL"], ["foxglove-layout", "-o", "SPECIAL"],
                                  ["plot", "LOG", "-o", "SPECIAL"], ["run", "SCENARIO", "--out", "SPECIAL"]])
def test_an_output_is_never_a_fifo_or_a_device(capsys, tmp_path, argv):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    (tmp_path / "probe.toml").write_text(PROBE_SCENARIO)
    argv = [{"SPECIAL": str(fifo), "LOG": str(tmp_path / "x.mcap"), "SCENARIO": str(tmp_path / "probe.toml")}.get(a, a)
            for a in argv]
    code, err, _ = outcome(capsys, argv)
    assert code == 2 and "FIFO" in err and fifo.is_fifo()


def test_bench_log_reports_a_failed_write_on_stderr_with_exit_2(capsys, monkeypatch):
    from swarmnav.benchmarks import log as bench_log
    monkeypatch.setattr(bench_log, "measure", lambda argv: {"s": 0.1, "cpu_s": 0.1, "peak_mb": 1.0, "exit": 2,
                                                            "error": "swarmnav: error: time_limit_s: too long"})
    code, err, out = outcome(capsys, ["bench", "log", "--duration", "10", "--no-video"])
    assert code == 2 and "too long" in err and "too long" not in out


def test_a_scenario_name_given_by_a_path_that_is_a_device_says_so(capsys):
    code, err, _ = outcome(capsys, ["plan", "/dev/null"])
    assert code == 2 and "device" in err and "does not exist" not in err
