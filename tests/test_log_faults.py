"""Run logs under hostile input and faults (issue 9): cut files, full disks, bad paths.

Every case goes through the CLI's ``main`` in-process, as a user would type it,
and checks the exit code and the one line on stderr.  Real files, a real full
device (/dev/full), a real file-size limit, a real busy port.
"""

from __future__ import annotations

import errno
import os
import shutil
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.records import Chunk, Message
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import Writer

from swarmnav.models.scenario import load_scenario
from swarmnav.cli.main import main
from swarmnav.log.writer import McapRecorder
from swarmnav.log.records import LogError, read_records
from swarmnav.sim.episode import EpisodeSpec, run_episode

REPO = Path(__file__).resolve().parent.parent
SCENARIO = "gwo-scenario-2"  # moving obstacles: every channel has traffic


@pytest.fixture(scope="module")
def small_log(tmp_path_factory) -> Path:
    """One short run, flushed every 0.1 s so that it has several chunks to lose."""
    path = tmp_path_factory.mktemp("small") / "small.mcap"
    run_episode(EpisodeSpec(load_scenario(SCENARIO)), [McapRecorder(path, flush_interval_s=0.1)], time_limit_s=0.4)
    return path


def chunk_ends_and_messages(path: Path) -> list[tuple[int, list[tuple[str, int, bytes]]]]:
    """(byte offset where each chunk ends, its messages as (topic, log time, data)), read with
    mcap's own reader on the intact file."""
    topics: dict[int, str] = {}
    out = []
    with path.open("rb") as stream:
        for record in StreamReader(stream, emit_chunks=True).records:
            if isinstance(record, Chunk):
                end = stream.tell()
                inner = list(breakup_chunk(record))
                topics.update({r.id: r.topic for r in inner if hasattr(r, "topic")})
                out.append((end, [(topics[m.channel_id], m.log_time, m.data) for m in inner
                                  if isinstance(m, Message)]))
    return out


def messages_of(path: Path) -> list[tuple[str, int, bytes]]:
    with path.open("rb") as stream:
        return [(c.topic, m.log_time, m.data)
                for _, c, m in make_reader(stream).iter_messages(log_time_order=False)]


def one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err
    return err


def cut_offsets(size: int) -> tuple[list[int], set[int]]:
    """Every offset in the last 4 kB plus 200 spread over the rest (descending), and the
    subset that also goes through the CLI: every 16th of the tail and the spread ones."""
    tail = list(range(max(0, size - 4096), size + 1))
    spread = {int(k) for k in np.linspace(0, max(size - 4096, 0), 200)}
    return sorted(set(tail) | spread, reverse=True), spread | set(tail[::16]) | {size}


def test_every_cut_is_read_cleanly_or_refused_with_exit_2(small_log, tmp_path, capsys):
    chunks = chunk_ends_and_messages(small_log)
    assert len(chunks) >= 4  # the run flushed several times: cuts can lose some of them
    cut, recovered = tmp_path / "cut.mcap", tmp_path / "recovered.mcap"
    shutil.copyfile(small_log, cut)
    size = small_log.stat().st_size
    offsets, through_cli = cut_offsets(size)
    seen: dict[int, int] = {}  # messages kept -> a cut that kept that many
    for offset in offsets:  # descending: each cut is a truncation of the previous one
        os.truncate(cut, offset)
        expected = [m for end, messages in chunks if end <= offset for m in messages]
        try:
            raw = read_records(cut)
        except LogError:
            assert not expected, offset
        else:
            assert [(raw.topic_of(m), m.log_time, m.data) for m in raw.messages] == expected, offset
            assert raw.complete == (offset == size)
        if offset not in through_cli and len(expected) in seen:
            continue
        seen.setdefault(len(expected), offset)
        info = main(["log", "info", str(cut)])
        captured = capsys.readouterr()
        assert info in (0, 2) and "Traceback" not in captured.err, offset
        if info == 2:  # nothing readable at all
            assert len(captured.err.strip().splitlines()) == 1 and str(cut) in captured.err, offset
            assert not expected, offset
        elif offset < size:  # read as plot reads it: what was recovered, one warning line, exit 0
            assert len(captured.err.strip().splitlines()) == 1 and captured.err.startswith(f"warning: {cut}:")
            assert f"recovered {len(expected)} messages" in captured.err and "log recover" in captured.err
            assert f"{len(expected)} messages" in captured.out
        else:
            assert not captured.err, offset
        status = main(["log", "recover", str(cut), str(recovered)])
        captured = capsys.readouterr()
        assert status in (0, 2), offset
        if status == 2:
            assert not expected, f"cut at {offset} lost complete chunks: {captured.err}"
            assert len(captured.err.strip().splitlines()) == 1 and str(cut) in captured.err
        else:
            assert messages_of(recovered) == expected, offset
    assert len(seen) >= len(chunks)  # every salvage level was reached by some cut

    # Replay, verify and plot take what a cut leaves: one cut per salvage level.
    for count, offset in sorted(seen.items()):
        shutil.copyfile(small_log, cut)
        os.truncate(cut, offset)
        for argv in (["replay", str(cut), "--verify"],
                     ["replay", str(cut), "--video", str(tmp_path / "v.mp4"), "--width", "32",
                      "--height", "32", "--fps", "5"],
                     ["plot", str(cut), "-o", str(tmp_path / "p.png"), "--dpi", "20"]):
            status = main(argv)
            captured = capsys.readouterr()
            assert status in (0, 2), (argv, offset, captured.err)
            assert "Traceback" not in captured.err
            if status == 2:
                assert len(captured.err.strip().splitlines()) == 1 and str(cut) in captured.err


def test_a_damaged_chunk_ends_the_read_and_keeps_the_chunks_before_it(small_log, tmp_path, capsys):
    chunks = chunk_ends_and_messages(small_log)
    data = bytearray(small_log.read_bytes())
    data[chunks[2][0] - 40] ^= 0xFF  # inside the third chunk's compressed bytes
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    raw = read_records(damaged)
    assert not raw.complete and raw.problem.startswith("corrupt record")
    assert [(raw.topic_of(m), m.log_time, m.data) for m in raw.messages] == chunks[0][1] + chunks[1][1]
    # log info answers from the intact summary (it decompresses no chunk but those with events);
    # reading the messages finds the damage: what was recovered, one warning line, exit 0.
    assert main(["log", "info", str(damaged)]) == 0
    capsys.readouterr()
    assert main(["plot", str(damaged), "-o", str(tmp_path / "p.png"), "--dpi", "20"]) == 0
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and "corrupt record" in captured.err
    assert f"recovered {len(chunks[0][1] + chunks[1][1])} messages" in captured.err


@pytest.mark.parametrize("size", range(0, 9))
def test_tiny_files_are_refused_in_one_line(small_log, tmp_path, capsys, size):
    tiny = tmp_path / "tiny.mcap"
    tiny.write_bytes(small_log.read_bytes()[:size])
    for argv in (["log", "info", str(tiny)], ["log", "recover", str(tiny), str(tmp_path / "r.mcap")],
                 ["replay", str(tiny), "--verify"], ["plot", str(tiny), "-o", str(tmp_path / "p.png")]):
        assert main(argv) == 2, argv
        err = one_error_line(capsys)
        assert str(tiny) in err
        assert ("truncated" in err or "empty" in err), err
    assert not (tmp_path / "r.mcap").exists() and not (tmp_path / "p.png").exists()


@pytest.mark.parametrize("target,problem", [("DIR", "is a directory"), ("/dev/null", "not a regular file"),
                                            ("missing.mcap", "no such file")])
def test_log_info_names_the_path_and_the_real_problem(tmp_path, capsys, target, problem):
    path = {"DIR": str(tmp_path), "missing.mcap": str(tmp_path / "missing.mcap")}.get(target, target)
    assert main(["log", "info", path]) == 2
    err = one_error_line(capsys)
    assert path in err and problem in err


def test_a_json_tf_channel_from_another_tool_is_refused(tmp_path, capsys):
    other = tmp_path / "other.mcap"
    with other.open("wb") as stream:
        writer = Writer(stream)
        writer.start(profile="", library="another tool")
        schema = writer.register_schema(name="tf", encoding="jsonschema", data=b"{}")
        channel = writer.register_channel(topic="/tf", message_encoding="json", schema_id=schema)
        writer.add_message(channel_id=channel, log_time=0, publish_time=0, data=b'{"x": 1}')
        writer.finish()
    for argv in (["log", "info", str(other)], ["plot", str(other), "-o", str(tmp_path / "p.png")]):
        assert main(argv) == 2
        err = one_error_line(capsys)
        assert str(other) in err and "/tf" in err and "foxglove.FrameTransform" in err


# -- writing: full disk, refused paths, busy port --------------------------------------


def test_full_disk_is_one_line_with_the_path_and_exit_2(capsys):
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full on this system")
    # The CLI writes no log onto a device (issue 36: --out is a regular file or a new one), one line, exit 2 ...
    with pytest.raises(SystemExit) as info:
        main(["run", "gwo-scenario-1", "--out", "/dev/full", "--overwrite"])
    err = one_error_line(capsys)
    assert info.value.code == 2 and "/dev/full" in err and "device" in err
    # ... and a disk that fills under the log file is kept as the OSError naming it (the CLI's one line)
    from swarmnav.log.file import LogFile
    log = LogFile("/dev/full", overwrite=True)
    with pytest.raises(OSError) as full:
        log.write(b"x" * 4096)
    log.close()
    assert full.value.errno == errno.ENOSPC and log.error.filename == "/dev/full"


FILE_SIZE_LIMITED_RUN = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG instead
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[2]), int(sys.argv[2])))
from swarmnav.cli.main import main
sys.exit(main(["run", "gwo-scenario-2", "--out", sys.argv[1], "--seed", "0"]))
"""


def test_a_write_that_fails_midway_keeps_what_was_written_recoverable(tmp_path, capsys):
    """A file-size limit fails a write the way a full disk does: the run stops with one
    line, and every chunk written before the failure is recovered byte for byte."""
    limited, reference = tmp_path / "limited.mcap", tmp_path / "reference.mcap"
    limit_bytes = 120_000
    process = subprocess.run([sys.executable, "-c", FILE_SIZE_LIMITED_RUN, str(limited), str(limit_bytes)],
                             cwd=REPO, capture_output=True, text=True, timeout=120)
    assert process.returncode == 2, process.stderr[-2000:]
    assert process.stderr.strip().splitlines() == [
        f"swarmnav: error: {limited}: {os.strerror(errno.EFBIG)}"]
    assert 0 < limited.stat().st_size <= limit_bytes
    assert main(["run", "gwo-scenario-2", "--out", str(reference), "--seed", "0"]) == 0
    recovered = tmp_path / "recovered.mcap"
    assert main(["log", "recover", str(limited), str(recovered)]) == 0
    capsys.readouterr()
    kept = messages_of(recovered)
    full = messages_of(reference)
    assert 0 < len(kept) < len(full)
    last_ns = max(t for _, t, _ in kept)
    assert kept == [m for m in full if m[1] <= last_ns]


def test_out_paths_the_file_system_refuses_name_the_path(tmp_path, capsys):
    for out, problem in (("/sys/x.mcap", os.strerror(errno.EACCES)), (str(tmp_path), os.strerror(errno.EISDIR))):
        if out.startswith("/sys") and os.access("/sys", os.W_OK) and not Path("/sys/kernel").is_dir():
            continue
        assert main(["run", "gwo-scenario-1", "--out", out, "--overwrite"]) == 2
        err = one_error_line(capsys)
        assert out in err and problem in err, err


def test_a_busy_live_port_leaves_no_file_behind(tmp_path):
    from swarmnav.models.errors import ConfigError

    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        path = tmp_path / "live.mcap"
        recorder = McapRecorder(path, live=True, live_port=port)
        with pytest.raises(ConfigError, match=f"127.0.0.1:{port}"):
            run_episode(EpisodeSpec(load_scenario("gwo-scenario-1")), [recorder], time_limit_s=0.1)
    assert not path.exists()


def test_the_recorder_never_prints_and_announces_the_live_url(tmp_path, capsys):
    urls = []
    recorder = McapRecorder(tmp_path / "quiet.mcap", live=True, live_port=0, live_speed=None,
                            on_live=urls.append)
    run_episode(EpisodeSpec(load_scenario("gwo-scenario-1")), [recorder], time_limit_s=0.2)
    captured = capsys.readouterr()
    assert captured.out == captured.err == ""
    assert len(urls) == 1 and urls[0].startswith("ws://127.0.0.1:") and not urls[0].endswith(":0")


# -- replay --verify on logs that end early, and with the range scans in the verdict ----


def test_verify_passes_a_recovered_log_as_an_equal_prefix(small_log, tmp_path, capsys):
    chunks = chunk_ends_and_messages(small_log)
    cut, recovered = tmp_path / "cut.mcap", tmp_path / "recovered.mcap"
    cut.write_bytes(small_log.read_bytes()[:chunks[2][0] + 5])  # three chunks and a bit
    assert main(["log", "recover", str(cut), str(recovered)]) == 0
    last_ns = max(t for _, t, _ in messages_of(recovered))
    capsys.readouterr()
    assert main(["replay", str(recovered), "--verify"]) == 0
    out = capsys.readouterr().out
    assert f"prefix bitwise equal, the log ends at t = {last_ns * 1e-9:.3f} s" in out
    assert "range scans: bitwise equal" in out


class _Interrupt(McapRecorder):
    def step(self, frame):
        super().step(frame)
        if frame.time_s >= 0.2:
            raise KeyboardInterrupt


def test_verify_passes_an_interrupted_log_as_an_equal_prefix(tmp_path, capsys):
    path = tmp_path / "interrupted.mcap"
    with pytest.raises(KeyboardInterrupt):
        run_episode(EpisodeSpec(load_scenario("gwo-scenario-1")), [_Interrupt(path)])
    assert main(["replay", str(path), "--verify", "--json"]) == 0
    verify = __import__("json").loads(capsys.readouterr().out)["verify"]
    assert verify["passed"] and verify["log_is_prefix"]
    assert verify["logged_steps"] == 11 < verify["simulated_steps"]
    assert verify["verdict"] == "prefix bitwise equal, the log ends at t = 0.200 s"


class _OneBeamOff(McapRecorder):
    """Logs one range reading a micrometre off, at one step: only the scans differ."""

    def step(self, frame):
        if abs(frame.time_s - 0.1) < 1e-9:
            hit = np.flatnonzero(np.isfinite(frame.range_m))
            frame.range_m = frame.range_m.copy()
            frame.range_m[hit[0] if hit.size else 0] = 1e-6 + (frame.range_m[hit[0]] if hit.size else 0.5)
        super().step(frame)


def test_verify_fails_when_only_a_range_scan_differs(tmp_path, capsys):
    path = tmp_path / "beam.mcap"
    run_episode(EpisodeSpec(load_scenario(SCENARIO)), [_OneBeamOff(path)], time_limit_s=0.4)
    assert main(["replay", str(path), "--verify"]) == 4
    out = capsys.readouterr().out
    assert "DIFFERENT" in out and "range scans: differ" in out
    assert "max position deviation:   0.000e+00 m" in out


# -- plot -o writes exactly the path given, or says why not ------------------------------


@pytest.mark.parametrize("out,dpi,field", [("run.xyz", "120", "-o"), ("run", "120", "-o"), ("DIR", "120", "-o"),
                                           ("run.png", "0", "--dpi"), ("run.png", "100000", "--dpi")])
def test_plot_refuses_outputs_it_cannot_write_exactly(small_log, tmp_path, capsys, out, dpi, field):
    target = tmp_path if out == "DIR" else tmp_path / out
    before = sorted(tmp_path.iterdir())
    assert main(["plot", str(small_log), "-o", str(target), "--dpi", dpi]) == 2
    err = one_error_line(capsys)
    assert field in err
    assert sorted(tmp_path.iterdir()) == before  # nothing written anywhere


def test_plot_to_a_full_device_is_one_line(small_log, tmp_path, capsys):
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full on this system")
    link = tmp_path / "full.png"
    link.symlink_to("/dev/full")
    assert main(["plot", str(small_log), "-o", str(link)]) == 2
    err = one_error_line(capsys)
    assert str(link) in err and os.strerror(errno.ENOSPC) in err


@pytest.mark.parametrize("suffix,magic", [(".png", b"\x89PNG"), (".svg", b"<?xml"), (".pdf", b"%PDF")])
def test_plot_writes_exactly_the_path_given(small_log, tmp_path, capsys, suffix, magic):
    out = tmp_path / f"run{suffix}"
    assert main(["plot", str(small_log), "-o", str(out), "--dpi", "30"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]
    assert out.read_bytes().startswith(magic)


# -- replay --video names the file ffmpeg could not write -----------------------------------


def test_replay_video_to_a_refused_path_is_one_line(small_log, tmp_path, capsys):
    for target, problem in ((tmp_path, os.strerror(errno.EISDIR)), ("/sys/v.mp4", os.strerror(errno.EACCES))):
        if str(target).startswith("/sys") and not Path("/sys/kernel").is_dir():
            continue
        assert main(["replay", str(small_log), "--video", str(target), "--width", "32", "--height", "32"]) == 2
        err = one_error_line(capsys)
        assert str(target) in err and problem in err


# -- a writer stops when its consumer fails ------------------------------------------------------


def _children(pid: int) -> list[int]:
    out = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            out += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            pass
    return out


def test_a_run_whose_encoder_dies_ends_with_one_line_and_a_finished_log(tmp_path):
    """ffmpeg killed mid-run: the run stops at the next frame, exit 2, one line, the log closed."""
    import time

    from swarmnav.log.reader import read_log
    log, video = tmp_path / "run.mcap", tmp_path / "run.mp4"
    process = subprocess.Popen([sys.executable, "-m", "swarmnav.cli", "run", SCENARIO, "--out", str(log),
                                "--video", str(video), "--width", "64", "--height", "48", "--fps", "30"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    killed = False
    while not killed and process.poll() is None and time.monotonic() < deadline:
        for child in _children(process.pid):
            try:
                if "ffmpeg" in Path(f"/proc/{child}/comm").read_text() and video.stat().st_size > 0:
                    os.kill(child, 9)
                    killed = True
            except OSError:
                pass
        time.sleep(0.05)
    assert killed, "ffmpeg never started (or the run ended first)"
    out, err = process.communicate(timeout=60)
    lines = err.strip().splitlines()
    assert process.returncode == 2 and len(lines) == 1, err
    assert str(video) in lines[0] and "ffmpeg" in lines[0] and "Traceback" not in err
    written = read_log(log)
    assert written.complete and written.outcome["outcome"] == "error"


@pytest.mark.parametrize("fps", ["1e9", "241", "0", "nan", "inf", "0.01"])
def test_a_frame_rate_out_of_range_is_one_line_before_anything_runs(tmp_path, capsys, fps):
    status = main(["run", SCENARIO, "--no-log", "--video", str(tmp_path / "v.mp4"), f"--fps={fps}"])
    err = capsys.readouterr().err
    assert status == 2 and len(err.strip().splitlines()) == 1 and "--fps" in err
    assert not (tmp_path / "v.mp4").exists()
