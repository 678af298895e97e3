"""The per-step messages encoded from templates are the foxglove SDK's own bytes."""

import math

import numpy as np
import pytest
from foxglove.messages import FrameTransform, LaserScan, Pose, PoseInFrame, Quaternion, Vector3

from swarmnav.log.encoding import StepEncoder, timestamp_field, varint
from swarmnav.log.messages import stamp

SPECIAL = (0.0, -0.0, 1.0, -1.0, math.nan, math.inf, -math.inf, 5e-324, 1.7976931348623157e308, 0.1)


def values(rng, n):
    """n doubles: mostly random, some from SPECIAL (zeros, signed zero, NaN, infinities, extremes)."""
    out = rng.normal(0.0, 3.0, n)
    pick = rng.random(n) < 0.3
    out[pick] = rng.choice(SPECIAL, int(pick.sum()))
    return [float(v) for v in out]


def times_ns(rng):
    return [0, 1, 999_999_999, 1_000_000_000, 20_000_000, 65_360_000_000, 2**40 + 7,
            *(int(t) for t in rng.integers(0, 10**12, 20))]


@pytest.mark.parametrize("frames", [("world", "base_link"), ("w", ""), ("", "x" * 200)])
def test_transform_and_pose_are_the_sdk_encoding(frames):
    rng = np.random.default_rng(7)
    world, base = frames
    encoder = StepEncoder(world, base, ((0.0, 0.0, 0.1), (0.0, 0.0, 0.0, 1.0)), 0.0, 1.0)
    for t_ns in times_ns(rng):
        for _ in range(20):
            px, py, pz, qx, qy, qz, qw = values(rng, 7)
            tf, pose = encoder.transform(timestamp_field(t_ns), (px, py, pz), (qx, qy, qz, qw))
            translation, rotation = Vector3(x=px, y=py, z=pz), Quaternion(x=qx, y=qy, z=qz, w=qw)
            assert tf == FrameTransform(timestamp=stamp(t_ns), parent_frame_id=world, child_frame_id=base,
                                        translation=translation, rotation=rotation).encode()
            assert pose == PoseInFrame(timestamp=stamp(t_ns), frame_id=world,
                                       pose=Pose(position=translation, orientation=rotation)).encode()


def test_scan_is_the_sdk_encoding():
    rng = np.random.default_rng(8)
    for t_ns in times_ns(rng):
        for _ in range(20):
            position, orientation = values(rng, 3), values(rng, 4)
            start, end = values(rng, 2)
            encoder = StepEncoder("world", "base_link", (tuple(position), tuple(orientation)), start, end)
            ranges = values(rng, int(rng.choice([0, 1, 12, 17, 40])))
            expected = LaserScan(timestamp=stamp(t_ns), frame_id="base_link",
                                 pose=Pose(position=Vector3(x=position[0], y=position[1], z=position[2]),
                                           orientation=Quaternion(x=orientation[0], y=orientation[1],
                                                                  z=orientation[2], w=orientation[3])),
                                 start_angle=start, end_angle=end, ranges=ranges).encode()
            assert encoder.scan(timestamp_field(t_ns), ranges) == expected


def test_varint_against_the_definition():
    for value in (0, 1, 127, 128, 300, 2**31 - 1, 2**63 - 1, -1, -(2**63)):
        encoded, decoded, shift = varint(value), 0, 0
        for i, byte in enumerate(encoded):
            decoded |= (byte & 0x7F) << shift
            shift += 7
            assert (byte & 0x80 != 0) == (i < len(encoded) - 1)   # continuation bit on all but the last
        assert decoded == value % 2**64


def test_obstacle_scene_update_is_the_sdk_encoding():
    """Static entities encoded once plus moving cylinders and boxes at random positions (zeros, NaN
    and infinities among them) give the bytes of the SceneUpdate the SDK builds from obstacle_entity."""
    from foxglove.messages import SceneUpdate

    from swarmnav.log.encoding import SceneEncoder
    from swarmnav.log.messages import obstacle_entity, obstacle_template
    from swarmnav.sim.recording import ObstacleInfo

    rng = np.random.default_rng(9)
    static = [ObstacleInfo("obstacle_00", "cylinder", (0.3, 0.5), (1.0, 2.0, 0.5), False),
              ObstacleInfo("map_box_001", "box", (0.5, 0.25, 0.4), (3.0, 0.0, 0.4), False)]
    moving = [ObstacleInfo("obstacle_01", "cylinder", (0.2, 0.6), (0.0, 0.0, 0.6), True),
              ObstacleInfo("crate", "box", (0.1, 0.2, 0.3), (5.0, 5.0, 0.3), True),
              ObstacleInfo("o" * 150, "cylinder", (0.25, 0.0), (1.0, 1.0, 0.0), True)]
    for n_static, n_moving in ((2, 3), (0, 1), (2, 0), (0, 0)):
        encoder = SceneEncoder([obstacle_entity(o, o.position_m[0], o.position_m[1], 0).encode()
                                for o in static[:n_static]], "world",
                               [(o.entity_id, obstacle_template(o)) for o in moving[:n_moving]])
        for t_ns in times_ns(rng):
            xy = [values(rng, 2) for _ in range(n_moving)]
            entities = [obstacle_entity(o, o.position_m[0], o.position_m[1], 0) for o in static[:n_static]]
            entities += [obstacle_entity(o, x, y, t_ns) for o, (x, y) in zip(moving, xy)]
            assert encoder.update(timestamp_field(t_ns), xy) == SceneUpdate(entities=entities).encode()
