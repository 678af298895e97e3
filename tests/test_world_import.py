"""`swarmnav scenarios import`: a Gazebo world's static cylinders and boxes as a scenario (issue 34, part 1).

Three BARN worlds are imported and compared cylinder by cylinder with the file, read here with a regular
expression (not the importer's parser); hostile files (an entity bomb, a truncated gzip, a missing file, a
gzip bomb) are one line on stderr and exit 2 in bounded time."""

import gzip
import math
import os
import re
import time
from pathlib import Path

import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.world_scenario import ImportSettings, import_world
from swarmnav.cli.main import main

BARN = Path(os.environ.get("SWARMNAV_BARN_DIR", Path(__file__).resolve().parents[2] / "shared/benchmarks/barn"))
needs_barn = pytest.mark.skipif(not (BARN / "worlds").is_dir(), reason="the BARN data (../shared) is not here")
MODEL = re.compile(r"<model name='(unit_cylinder_\d+)'>\s*<static>1</static>\s*<pose frame=''>(\S+) (\S+) ")


def run_cli(capsys, *argv):
    started = time.perf_counter()
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err, time.perf_counter() - started


def one_line_exit_2(capsys, path, needle):
    code, out, err, wall_s = run_cli(capsys, "scenarios", "import", str(path))
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and str(path) in err and needle in err, err
    assert wall_s < 10.0


@needs_barn
@pytest.mark.parametrize("index", [0, 150, 299])
def test_barn_world_imported_cylinder_by_cylinder(index, tmp_path, capsys):
    path = BARN / "worlds" / f"world_{index}.world.gz"
    text = gzip.decompress(path.read_bytes()).decode()
    world_part = text.split("<state")[0]  # the <state> section repeats the poses: the models' own are these
    expected = [(name, float(x), float(y)) for name, x, y in MODEL.findall(world_part)]
    assert len(expected) > 100
    out = tmp_path / f"w{index}.toml"
    code, printed, _, _ = run_cli(capsys, "scenarios", "import", str(path), "--out", str(out))
    assert code == 0 and f"{len(expected)} cylinders" in printed
    scenario = parse_scenario(out.read_text(), str(out))
    origin = re.search(r"world frame = arena frame \+ \((\S+), (\S+)\)", out.read_text())
    ox, oy = float(origin.group(1)), float(origin.group(2))
    assert len(scenario.obstacles) == len(expected)
    for ob, (name, x, y) in zip(scenario.obstacles, expected):
        assert math.isclose(ob.x_m + ox, x, abs_tol=1e-12) and math.isclose(ob.y_m + oy, y, abs_tol=1e-12), name
        assert ob.radius_m == 0.075 and ob.height_m == 1.0 and not ob.moving
    # the challenge's start and goal, in the arena's frame
    assert (scenario.start.x_m + ox, scenario.start.y_m + oy) == (-2.25, 3.0)
    assert (scenario.goal.x_m + ox, scenario.goal.y_m + oy, scenario.goal_tolerance_m) == (-2.25, 13.0, 1.0)


SDF = """<?xml version='1.0'?>
<sdf version='1.6'><world name='w'>
  <model name='shelf'><static>1</static><pose>2 3 0 0 0 1.5707963267948966</pose>
    <link name='l'><pose>1 0 0 0 0 0</pose>
      <collision name='c'><geometry><box><size>2 0.5 1</size></box></geometry></collision></link></model>
  <model name='post'><static>true</static><pose>0 0 0 0 0 0.7</pose>
    <link name='l'><collision name='c'><pose>1 0 0 0 0 0</pose>
      <geometry><cylinder><radius>0.2</radius><length>0.8</length></cylinder></geometry></collision></link></model>
  <model name='cart'><static>0</static><link name='l'><collision name='c'>
      <geometry><box><size>1 1 1</size></box></geometry></collision></link></model>
</world></sdf>
"""


def test_poses_compose_with_yaw_boxes_and_cylinders(tmp_path):
    path = tmp_path / "shelf.world"
    path.write_text(SDF)
    imported = import_world(path, ImportSettings(name="shelf", start=(-1.0, -1.0, 0.0), goal=(5.0, 5.0, 0.5)))
    ox, oy = imported.origin_m
    (post,) = imported.world.cylinders
    assert math.isclose(post.x_m, math.cos(0.7)) and math.isclose(post.y_m, math.sin(0.7))
    (shelf,) = imported.world.blocks  # the link 1 m along the model's x, turned 90 degrees: at (2, 4), 0.5 x 2
    assert [round(v, 9) for v in (shelf.x_min_m, shelf.y_min_m, shelf.x_max_m, shelf.y_max_m)] == [1.75, 3, 2.25, 5]
    assert imported.world.skipped == {"non-static model": 1}
    scenario = parse_scenario(imported.text, "shelf")
    (box,) = scenario.boxes
    assert math.isclose(box.x_min_m + ox, 1.75) and math.isclose(box.y_max_m + oy, 5.0)


def test_a_box_turned_off_the_axes_is_refused(tmp_path, capsys):
    path = tmp_path / "turned.world"
    path.write_text(SDF.replace("1.5707963267948966", "0.5"))
    one_line_exit_2(capsys, path, "box turned by")


def test_entity_bomb_is_refused(tmp_path, capsys):
    lol = "".join(f'<!ENTITY lol{k} "{f"&lol{k - 1};" * 10}">' for k in range(1, 10))
    path = tmp_path / "bomb.world"
    path.write_text(f'<?xml version="1.0"?><!DOCTYPE sdf [<!ENTITY lol0 "lol">{lol}]><sdf><world>&lol9;</world></sdf>')
    one_line_exit_2(capsys, path, "refused")


def test_truncated_gzip_and_gzip_bomb(tmp_path, capsys):
    path = tmp_path / "cut.world.gz"
    path.write_bytes(gzip.compress(SDF.encode() * 20)[:200])
    one_line_exit_2(capsys, path, "broken gzip")
    bomb = tmp_path / "bomb.world.gz"
    bomb.write_bytes(gzip.compress(b"<sdf>" + b" " * (40 * 1024 * 1024)))  # 40 MB of XML in ~40 kB
    one_line_exit_2(capsys, bomb, "decompresses to more than")


def test_missing_file_and_not_a_world(tmp_path, capsys):
    one_line_exit_2(capsys, tmp_path / "nowhere.world", "does not exist")
    path = tmp_path / "other.world"
    path.write_text("<robot name='r'/>")
    one_line_exit_2(capsys, path, "expected <sdf><world>")


def test_endpoint_in_an_obstacle_names_the_field(tmp_path):
    path = tmp_path / "shelf.world"
    path.write_text(SDF)
    with pytest.raises(ConfigError, match="start"):
        import_world(path, ImportSettings(name="s", start=(2.0, 4.0, 0.0), goal=(5.0, 5.0, 0.5)))
