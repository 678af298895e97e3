"""Files from elsewhere stay contained (issue 36): inputs are regular files of a bounded size and nesting,
outputs inside a folder are never written through a planted symbolic link, names from files are never paths."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from swarmnav.models.contained_files import loads_json, loads_toml, read_input_text
from swarmnav.models.errors import ConfigError
from swarmnav.cli.main import main
from probe_scenario import PROBE_SCENARIO

DEEP = "[" * 5000 + "]" * 5000


def one_line(capsys, argv: list[str], code: int = 2) -> str:
    status = main(argv)
    err = capsys.readouterr().err.strip()
    assert status == code, (argv, err)
    assert len(err.splitlines()) == 1 and "bug:" not in err, err
    return err


@pytest.fixture
def probe(tmp_path) -> Path:
    path = tmp_path / "probe.toml"
    path.write_text(PROBE_SCENARIO)
    return path


@pytest.fixture
def specials(tmp_path) -> dict[str, str]:
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    (tmp_path / "folder").mkdir()
    return {"a FIFO": str(fifo), "a device": "/dev/zero", "a directory": str(tmp_path / "folder")}


@pytest.mark.parametrize("kind", ["a FIFO", "a device", "a directory"])
def test_every_input_must_be_a_regular_file(capsys, tmp_path, probe, specials, kind):
    path = specials[kind]
    word = {"a FIFO": "FIFO", "a device": "device", "a directory": "directory"}[kind]
    for argv in (["plan", path], ["study", path], ["run", str(probe), "--waypoints", path, "--no-log"],
                 ["scenarios", "info", path], ["log", "info", path], ["plot", path, "-o", str(tmp_path / "p.png")]):
        err = one_line(capsys, argv)
        assert path in err and (word in err or "not a regular file" in err), err


def test_an_input_over_the_size_limit_is_refused_before_it_is_read(tmp_path):
    big = tmp_path / "big.csv"
    big.write_text("x,y\n" + "1,2\n" * 100)
    with pytest.raises(ConfigError, match="404 bytes, more than the maximum 100"):
        read_input_text(big, "--waypoints", max_bytes=100)


@pytest.mark.parametrize("text", [DEEP, "[[" + "9" * 5000 + ", 1], [1, 2]]"])
def test_json_nesting_and_huge_integers_are_bad_input(text):
    with pytest.raises(ConfigError):
        loads_json(text, "f.json")


def test_toml_nesting_is_bad_input_at_any_depth_past_the_limit():
    with pytest.raises(ConfigError, match="MAX_NESTING_DEPTH"):
        loads_toml(f"v = {DEEP}", "f.toml")
    with pytest.raises(ConfigError, match="MAX_NESTING_DEPTH"):
        loads_toml("v = " + "[" * 40 + "]" * 40, "f.toml")  # below Python's recursion limit, above ours
    assert loads_toml("v = [[1], [2]]", "f.toml") == {"v": [[1], [2]]}


def test_deep_and_huge_values_in_every_file_and_setting_are_one_line(capsys, tmp_path, probe):
    deep_scenario = tmp_path / "deep.toml"
    deep_scenario.write_text(PROBE_SCENARIO.replace("params = {}", f"params = {{ x = {DEEP} }}"))
    deep_study = tmp_path / "study.toml"
    deep_study.write_text(f'name = "d"\nscenarios = ["{probe}"]\n[[planners]]\nname = "astar"\n'
                          f'params = {{ cell_m = {DEEP} }}\n')
    (tmp_path / "deep.json").write_text(DEEP)
    (tmp_path / "cell.csv").write_text("x,y\n" + "1" * 140_000 + ",2\n3,4\n")
    for argv in (["plan", str(probe), "--set", f"x={DEEP}"], ["plan", str(probe), "--navigator-set", f"x={DEEP}"],
                 ["bench", "navigation", "--arm", f"a:follow:x={DEEP}"], ["plan", str(deep_scenario)],
                 ["study", str(deep_study), "--out", str(tmp_path / "o")],
                 ["run", str(probe), "--waypoints", str(tmp_path / "deep.json"), "--no-log"],
                 ["run", str(probe), "--waypoints", str(tmp_path / "cell.csv"), "--no-log"],
                 ["plan", str(probe), "--set", "x=" + "y" * 200_000]):
        err = one_line(capsys, argv)
        assert "MAX_" in err or "not a CSV row" in err, err


def small_study(tmp_path: Path, probe: Path, name: str = "contained") -> Path:
    path = tmp_path / f"{name.replace('/', '_')}.toml"
    path.write_text(f'name = "{name}"\nscenarios = ["{probe}"]\nseeds = 1\nmode = "plan"\n'
                    '[[planners]]\nname = "straight"\n')
    return path


def test_a_study_name_is_never_a_path(capsys, tmp_path, probe, monkeypatch):
    monkeypatch.chdir(tmp_path)
    err = one_line(capsys, ["study", str(small_study(tmp_path, probe, "../../escaped-study"))])
    assert "name" in err and "path separator" in err
    assert not (tmp_path.parent / "escaped-study").exists() and not (tmp_path / "studies").exists()


@pytest.mark.parametrize("planted", [".lock", "runs.parquet", "progress.parquet", "study.json", "logs"])
def test_a_link_planted_in_a_study_folder_is_refused_and_its_target_untouched(capsys, tmp_path, probe, planted):
    out, target = tmp_path / "out", tmp_path / "target"
    out.mkdir()
    if planted.endswith(".parquet") or planted == "logs":
        target.mkdir()
    else:
        target.write_text("precious\n")
    (out / planted).symlink_to(target)
    argv = ["study", str(small_study(tmp_path, probe)), "--out", str(out)] + (["--logs"] if planted == "logs" else [])
    err = one_line(capsys, argv)
    assert "symbolic link" in err and str(out / planted) in err
    if target.is_dir():
        assert not any(target.iterdir())
    else:
        assert target.read_text() == "precious\n"


def test_a_damaged_link_is_refused_and_nothing_moves_through_it(capsys, tmp_path, probe):
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    (out / "runs.parquet").mkdir(parents=True)
    (out / "runs.parquet" / "part-0.parquet").write_text("junk")
    elsewhere.mkdir()
    (out / "damaged").symlink_to(elsewhere)
    err = one_line(capsys, ["study", str(small_study(tmp_path, probe)), "--out", str(out)])
    assert "symbolic link" in err and not any(elsewhere.iterdir())


def test_a_log_is_never_written_through_a_link(capsys, tmp_path, probe):
    target = tmp_path / "target.txt"
    target.write_text("precious\n")
    (tmp_path / "run.mcap").symlink_to(target)
    err = one_line(capsys, ["run", str(probe), "--planner", "straight", "--out", str(tmp_path / "run.mcap"),
                            "--overwrite"])
    assert "symbolic link" in err and target.read_text() == "precious\n"


# --- a log from elsewhere ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def probe_log(tmp_path_factory) -> Path:
    from swarmnav.models.scenario import parse_scenario
    from swarmnav.sim.episode import EpisodeSpec, run_episode
    from swarmnav.log.writer import McapRecorder
    path = tmp_path_factory.mktemp("log") / "probe.mcap"
    run_episode(EpisodeSpec(parse_scenario(PROBE_SCENARIO, "probe.toml")), [McapRecorder(path)], time_limit_s=0.2)
    return path


def tampered(source: Path, target: Path, scene=None, run: dict | None = None, drop: str | None = None) -> Path:
    """A copy of ``source`` with its scene.xml rewritten by ``scene`` and ``run`` metadata changed."""
    import json
    from mcap.writer import CompressionType, Writer
    from swarmnav.log.records import read_records
    from swarmnav.log.recover import _Copier
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
