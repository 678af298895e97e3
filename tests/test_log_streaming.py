"""Logs of any length (issue 24, item 6): read without holding their messages.

``log info`` answers from the MCAP summary; the record walk (a file without
summary) gives the same facts.  ``plot``, ``replay`` and ``recover`` stream: the
reader hands each message over and keeps none.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from swarmnav.models.scenario import load_scenario
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.log.columns import Rows
from swarmnav.log.summary import from_records, read_summary
from swarmnav.log.writer import McapRecorder
from swarmnav.log.records import read_records


@pytest.fixture(scope="module")
def log_with_events(tmp_path_factory) -> Path:
    """gwo-scenario-2 until after its first collisions (events on several chunks)."""
    path = tmp_path_factory.mktemp("stream") / "run.mcap"
    run_episode(EpisodeSpec(load_scenario("gwo-scenario-2")), [McapRecorder(path)], time_limit_s=23.0)
    return path


def test_log_info_from_the_summary_equals_the_record_walk(log_with_events):
    summary, walked = read_summary(log_with_events), from_records(log_with_events)
    assert summary.from_summary and not walked.from_summary
    assert any(kind == "collision_begin" for _, kind, _ in summary.events)  # the fixture has events to find
    assert summary.events == walked.events
    assert summary.counts == walked.counts and summary.schema_names == walked.schema_names
    assert summary.duration_s == walked.duration_s and summary.outcome == walked.outcome
    assert summary.metadata == walked.metadata and summary.complete and walked.complete


def test_a_streamed_read_keeps_no_message_and_counts_them_all(log_with_events):
    seen = []
    raw = read_records(log_with_events, on_message=lambda raw, message: seen.append(message.channel_id))
    assert raw.messages == []
    with log_with_events.open("rb") as stream:
        statistics = make_reader(stream).get_summary().statistics
    assert raw.message_count == len(seen) == statistics.message_count
    assert raw.channel_counts == statistics.channel_message_counts
    assert raw.last_time_ns == statistics.message_end_time


def test_rows_grow_without_losing_a_number():
    rng = np.random.default_rng(0)
    data = rng.normal(size=(1000, 3))
    rows = Rows(3)
    for row in data:
        rows.append(row)
    assert np.array_equal(rows.array(), data) and len(rows) == 1000
    assert Rows().array().shape == (0, 0)


def test_bench_log_measures_every_reader_of_the_log_it_writes():
    import json
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "swarmnav.cli", "bench", "log", "--duration", "2",
                          "--no-video", "--json"], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    figures = json.loads(out.stdout)
    assert not [key for key in figures if key.endswith(": exit")], figures  # every command ran
    readers = ["mcap summary read", "mcap message stream", "swarmnav log info", "swarmnav plot",
               "swarmnav log recover", "swarmnav replay --verify"]
    for name in ["write (swarmnav run)"] + readers:
        assert figures[f"{name}: peak MB"] > 1 and figures[f"{name}: s"] > 0
    assert figures["log_mb"] > 0
