"""A log from elsewhere (issue 36): its attached scene is compiled with nothing beyond itself, and its run
metadata is checked once, so every reader refuses the same bad log in one line (exit 2)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from mcap.writer import CompressionType, Writer

from swarmnav.models.scenario import parse_scenario
from swarmnav.cli.main import main
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.log.records import read_records
from swarmnav.log.recover import _Copier
from swarmnav.log.writer import McapRecorder
from probe_scenario import PROBE_SCENARIO


def one_line(capsys, argv: list[str], code: int = 2) -> str:
    status = main(argv)
    err = capsys.readouterr().err.strip()
    assert status == code, (argv, err)
    assert len(err.splitlines()) == 1 and "bug:" not in err, err
    return err


@pytest.fixture(scope="module")
def probe_log(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("log") / "probe.mcap"
    run_episode(EpisodeSpec(parse_scenario(PROBE_SCENARIO, "probe.toml")), [McapRecorder(path)], time_limit_s=0.2)
    return path


def tampered(source: Path, target: Path, scene=None, run: dict | None = None, drop: str | None = None) -> Path:
    """A copy of ``source`` with its scene.xml rewritten by ``scene`` and its ``run`` metadata changed."""
    with target.open("wb") as stream:
        writer = Writer(stream, compression=CompressionType.ZSTD)
        copier = _Copier(writer)
        raw = read_records(source, on_message=copier.message)
        copier.start(raw)
        for name, values in raw.metadata.items():
            values = dict(values)
            if name == "run":
                values.update(run or {})
                if drop:
                    obstacles = json.loads(values["obstacles"])
                    for entry in obstacles:
                        entry.pop(drop)
                    values["obstacles"] = json.dumps(obstacles)
            writer.add_metadata(name, values)
        for a in raw.attachments.values():
            data = a.data if scene is None else scene(a.data.decode()).encode()
            writer.add_attachment(create_time=a.create_time, log_time=a.log_time, name=a.name,
                                  media_type=a.media_type, data=data)
        writer.finish()
    return target


SCENES = {
    "garbage": (lambda xml: "<<<not xml", "not XML"),
    "size memory": (lambda xml: xml.replace(">", "><size memory='900G'/>", 1), "<size>"),
    "include": (lambda xml: xml.replace(">", "><include file='/etc/passwd'/>", 1), "<include>"),
    "mesh file": (lambda xml: xml.replace("<asset>", "<asset><mesh name='m' file='/etc/passwd'/>", 1), "file"),
    "asset folder": (lambda xml: xml.replace("<compiler", "<compiler meshdir='/etc'", 1), "folder"),
    "huge texture": (lambda xml: xml.replace("<asset>", "<asset><texture name='t' type='2d' builtin='flat' "
                                                         "width='100000' height='100000'/>", 1), "width"),
    "not compilable": (lambda xml: xml.replace("<worldbody>", "<worldbody><geom type='nosuch'/>", 1), "compile"),
}


def test_the_tampering_changes_the_scene(probe_log, tmp_path):
    for rewrite, _ in SCENES.values():
        original = read_records(probe_log).attachments["scene.xml"].data.decode()
        changed = read_records(tampered(probe_log, tmp_path / "t.mcap", scene=rewrite)).attachments["scene.xml"]
        assert changed.data.decode() == rewrite(original) != original


@pytest.mark.parametrize("kind", sorted(SCENES))
def test_a_log_scene_reaching_beyond_itself_is_refused_by_replay(capsys, tmp_path, probe_log, kind):
    rewrite, word = SCENES[kind]
    log = tampered(probe_log, tmp_path / "t.mcap", scene=rewrite)
    for argv in (["replay", str(log), "--verify"],
                 ["replay", str(log), "--video", str(tmp_path / "v.mp4"), "--width", "32", "--height", "32"]):
        err = one_line(capsys, argv)
        assert str(log) in err and word in err, err


@pytest.mark.parametrize("run, drop, field", [({"seed": '"nan"'}, None, "run.seed"),
                                              ({"world_seed": "-1"}, None, "run.world_seed"),
                                              ({"arena_size_m": '"wide"'}, None, "run.arena_size_m"),
                                              ({"obstacles": "[" * 5000}, None, "run.obstacles"),
                                              (None, "size_m", "run.obstacles"),
                                              (None, "entity_id", "run.obstacles")])
def test_bad_run_metadata_is_one_line_for_every_reader(capsys, tmp_path, probe_log, run, drop, field):
    log = tampered(probe_log, tmp_path / "t.mcap", run=run, drop=drop)
    for argv in (["replay", str(log), "--verify"], ["plot", str(log), "-o", str(tmp_path / "p.png")],
                 ["log", "info", str(log)],
                 ["replay", str(log), "--video", str(tmp_path / "v.mp4"), "--width", "32", "--height", "32"]):
        err = one_line(capsys, argv)
        assert f"metadata {field}" in err, (argv, err)
