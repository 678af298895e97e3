"""One truncation rule (issue 36): ``log info``, ``plot``, ``replay --video`` and ``replay --verify`` agree on
every cut of a log: each reads what the cut kept (exit 0, one warning line) or each refuses it (exit 2, one
line), and they refuse exactly the cuts that keep no step."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from swarmnav.models.scenario import parse_scenario
from swarmnav.cli.main import main
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.log.records import LogError, read_records
from swarmnav.log.writer import McapRecorder
from probe_scenario import PROBE_SCENARIO


@pytest.fixture(scope="module")
def chunked_log(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("cuts") / "probe.mcap"
    run_episode(EpisodeSpec(parse_scenario(PROBE_SCENARIO, "probe.toml")),
                [McapRecorder(path, flush_interval_s=0.05)], time_limit_s=0.3)
    return path


def steps_kept(path: Path) -> int:
    try:
        raw = read_records(path)
    except LogError:
        return 0
    return sum(1 for m in raw.messages if raw.topic_of(m) == "/tf")


def test_every_reader_agrees_on_every_cut(chunked_log, tmp_path, capsys):
    cut = tmp_path / "cut.mcap"
    size = chunked_log.stat().st_size
    offsets = sorted({int(k) for k in np.linspace(0, size, 12)} | {size - 1, 40})
    verdicts = {}
    for offset in offsets:
        shutil.copyfile(chunked_log, cut)
        with open(cut, "r+b") as stream:
            stream.truncate(offset)
        steps = steps_kept(cut)
        codes = []
        for argv in (["log", "info", str(cut)], ["plot", str(cut), "-o", str(tmp_path / "p.png"), "--dpi", "20"],
                     ["replay", str(cut), "--verify"],
                     ["replay", str(cut), "--video", str(tmp_path / "v.mp4"), "--width", "32", "--height", "32",
                      "--fps", "5"]):
            code = main(argv)
            err = capsys.readouterr().err.strip()
            assert code in (0, 2) and "bug:" not in err and len(err.splitlines()) <= 1, (offset, argv, err)
            if code == 2:
                assert str(cut) in err, (offset, argv, err)
            codes.append(code)
        assert len(set(codes)) == 1, f"cut at byte {offset} of {size}: exit codes {codes} ({steps} steps kept)"
        assert codes[0] == (2 if steps == 0 else 0), (offset, steps, codes)
        verdicts[offset] = codes[0]
    assert set(verdicts.values()) == {0, 2}  # both outcomes met: the cuts span the first step
    print(f"\n{len(offsets)} cuts x 4 readers: {sum(v == 0 for v in verdicts.values())} read, "
          f"{sum(v == 2 for v in verdicts.values())} refused, all in agreement")
