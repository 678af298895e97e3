"""What a video frame shows: the caption, the follow camera, no black background, the palette.

Real MuJoCo rendering offscreen with EGL (MUJOCO_GL=egl) on the compiled scene of a bundled scenario.
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from swarmnav.models.scenario import load_scenario  # noqa: E402
from swarmnav.video.caption import FrameCaption, run_title  # noqa: E402
from swarmnav.sim.scene import compile_scene  # noqa: E402

WIDTH, HEIGHT = 320, 240


def _frame(camera: str, xy_m=(5.0, 5.0), yaw_rad: float = 0.0, scenario: str = "gwo-scenario-2") -> np.ndarray:
    import mujoco

    from swarmnav.video.render import ScenePoser, SceneRenderer

    loaded = load_scenario(scenario)
    model = mujoco.MjModel.from_xml_string(compile_scene(loaded).xml)
    poser = ScenePoser(model)
    renderer = SceneRenderer(model, WIDTH, HEIGHT, camera, grid_m=(loaded.arena_width_m, loaded.arena_height_m))
    try:
        position = np.array([xy_m[0], xy_m[1], 0.0])
        poser.apply(position, np.array([np.cos(yaw_rad / 2), 0.0, 0.0, np.sin(yaw_rad / 2)]), None)
        return renderer.render(poser.data, follow_xy_m=position)
    finally:
        renderer.close()


def _blob_pixels(image: np.ndarray, tolerance: int = 24) -> int:
    """Pixels of the colour at the frame's centre (where the robot is posed)."""
    centre = image[HEIGHT // 2, WIDTH // 2].astype(int)
    return int((np.abs(image.astype(int) - centre).max(axis=2) <= tolerance).sum())


def test_follow_camera_keeps_the_robot_a_readable_size():
    follow, top = _frame("follow"), _frame("top")
    # The chassis (0.15 m radius) is a tenth of the 3 m the follow view spans: its disc is wider
    # than a twelfth of the frame's height, many times what the whole-arena top view gives it.
    robot_follow = _blob_pixels(follow)
    assert robot_follow > np.pi * (HEIGHT / 24) ** 2
    assert robot_follow > 8 * _blob_pixels(top)


@pytest.mark.parametrize("xy_m, yaw_rad", [((9.8, 9.8), np.pi / 4), ((0.2, 0.2), -3 * np.pi / 4),
                                           ((9.8, 0.2), 0.0)])
def test_chase_view_has_no_black_background(xy_m, yaw_rad):
    """At the arena's corners the chase camera looks past the floor's edge: ground, not black."""
    image = _frame("chase", xy_m, yaw_rad)
    black = (image.max(axis=2) < 25).mean()
    assert black < 0.01, f"{black:.1%} of the frame is black"


@pytest.mark.parametrize("scenario", ["gwo-scenario-2", "immas-env1-scattered"])
def test_top_view_has_no_black_side_bands(scenario):
    """The top camera's 4:3 frame is wider than a square arena: ground fills its sides, not black."""
    image = _frame("top", scenario=scenario)
    black = (image.max(axis=2) < 25).mean()
    assert black < 0.01, f"{black:.1%} of the frame is black"


def test_obstacles_take_the_shared_palette():
    import mujoco

    from swarmnav.sim import palette
    from swarmnav.video.render import paint_obstacles

    model = mujoco.MjModel.from_xml_string(compile_scene(load_scenario("gwo-scenario-2")).xml)
    paint_obstacles(model)
    names = [model.geom(g).name for g in range(model.ngeom)]
    obstacles = [g for g, name in enumerate(names) if name.startswith("obstacle_")]
    assert obstacles
    allowed = np.array([palette.rgba(palette.OBSTACLE), palette.rgba(palette.MOVING_OBSTACLE)])
    for g in obstacles:
        assert np.isclose(model.geom_rgba[g], allowed, atol=1e-6).all(axis=1).any(), names[g]


def test_caption_writes_the_title_and_a_time_that_changes():
    caption = FrameCaption(run_title("gwo-scenario-2", "gwo", "replan", 0, 0), WIDTH, HEIGHT)
    grey = np.full((HEIGHT, WIDTH, 3), 180, dtype=np.uint8)
    early, late = caption.draw(grey.copy(), 1.0), caption.draw(grey.copy(), 12.5)
    bar = slice(0, caption.bar_px)
    assert (early[bar] > 230).any() and early[bar].mean() < 180  # white text on a darkened bar
    assert np.array_equal(early[caption.bar_px:], grey[caption.bar_px:])  # nothing drawn below the bar
    differs = np.flatnonzero((early[bar] != late[bar]).any(axis=(0, 2)))
    assert differs.size and differs.min() > WIDTH // 2  # only the clock, on the right, changed
    assert "gwo-scenario-2" in caption.title and "seed 0" in caption.title


def test_caption_shortens_a_long_title_to_fit():
    caption = FrameCaption("x" * 500, WIDTH, HEIGHT)
    assert caption.title.endswith("…") and len(caption.title) < 500
    assert run_title("s", "p", "n", 1, 2).endswith("seed 1, world seed 2")
