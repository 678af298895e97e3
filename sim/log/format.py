"""The run log's format: channels, schemas, names, time stamps and the scan convention.

Shared by the writer (:mod:`swarmnav.log.writer`) and the readers (:mod:`swarmnav.log.records`,
:mod:`swarmnav.log.reader`), so both sides agree on one table.

Channels (Foxglove well-known protobuf schemas unless said otherwise):

======================  ===============================================================
``/tf``                 FrameTransform world -> base_link, every control step
``/robot/pose``         PoseInFrame in ``world``, every control step
``/planner/path``       PosesInFrame in ``world``; at the start and after any replan
``/obstacles``          SceneUpdate, one cylinder / cube entity per obstacle with a fixed
                        ``id``; sent once when nothing moves, otherwise every control
                        step with *all* entities (so a seek in Foxglove, which only
                        back-fills the latest message of a topic, still shows the static
                        ones)
``/range/scan``         LaserScan in ``base_link``; misses are NaN
``/wheels``             JSON ``swarmnav.WheelSpeeds``: commanded and measured rad/s
``/controller``         JSON ``swarmnav.ControllerState``: v, omega, active waypoint
                        (both JSON with a JSON Schema (``jsonschema``), which Foxglove
                        decodes and plots by field path, e.g. ``/wheels.measured_left_rad_s``)
``/events``             ``foxglove.Log``: one per event (goal_reached, collision_begin/end,
                        timeout, replan, ...); ``message`` is the kind, then a space and the
                        details as JSON when there are any (:func:`event_text`); collisions
                        and timeouts at level WARNING, the rest INFO.  Logs written before
                        this carried JSON ``swarmnav.Event``; readers accept both.
``/scene``              SceneUpdate, once at t = 0: the arena's outline (``arena``, in
                        ``world``) and the robot's footprint (``robot_footprint``, a disc of
                        the chassis radius with a heading arrow, in ``base_link`` and
                        ``frame_locked``, so it follows ``/tf``): Foxglove's 3D panel shows
                        the scene with no set-up.
``/navigator``          SceneUpdate: what the navigator acted on (its sensed obstacles,
                        their velocities and predicted sweeps); only in logs of navigators
                        that use the sensing, from the first step they sensed something,
                        then every step until they sense nothing (one update that only
                        deletes).  Not in :data:`CHANNELS`: readers leave it alone.
``/map``                Grid in ``world``: the occupancy grid the laser built, once a
                        simulated second; only with the map unknown (``knowledge.map``).
                        One int8 field ``occupancy``: percent, -1 never seen.  Optional.
``/odom``               PoseInFrame in ``world``: the pose the navigator saw, integrated
                        from the wheels' speeds, every control step; only with
                        ``knowledge.pose = "odometry"`` (``/robot/pose`` stays the truth).
                        Optional.
======================  ===============================================================

Profile ``ros2`` (``--log-format ros2``): CDR messages with ``ros2msg`` schemas of the standard
ROS 2 types (:mod:`swarmnav.log.ros2_types`), frames after REP 105 (``map`` -> ``odom`` ->
``base_link``; ``base_scan`` the rangefinders' plane) and units after REP 103:

======================  ===============================================================
``/tf_static``          tf2_msgs/TFMessage, once at t = 0: ``world`` -> ``map`` (identity,
                        for views set up on ``world``), ``base_link`` -> ``base_scan``
                        and, when the run has no odometry estimate, ``map`` -> ``odom``
                        (identity: odometry is the simulator's pose)
``/tf``                 tf2_msgs/TFMessage, every control step: ``odom`` -> ``base_link``
                        (and ``map`` -> ``odom`` when the run estimates odometry)
``/odom``               nav_msgs/Odometry in ``odom``, child ``base_link``; the twist is
                        the base's velocity over the last control period, in ``base_link``
``/scan``               sensor_msgs/LaserScan in ``base_scan``; +inf where a beam saw
                        nothing (REP 117); ranges from base_link's axis, as above
``/joint_states``       sensor_msgs/JointState: the wheels' measured rad/s (``velocity``)
``/wheels/command``     sensor_msgs/JointState: the wheels' commanded rad/s
``/cmd_vel``            geometry_msgs/Twist: the controller's v and omega
``/plan``               nav_msgs/Path in ``map``; at the start and after any replan
``/obstacles``          visualization_msgs/MarkerArray, one marker per obstacle (``ns`` its
                        entity id); sent as ``/obstacles`` above
``/scene``              visualization_msgs/MarkerArray at t = 0: arena outline, footprint
``/navigator``          visualization_msgs/MarkerArray: what the navigator acted on (as above)
``/map``                nav_msgs/OccupancyGrid in ``map``: the map the robot builds, when the
                        run's map is unknown (the same cells as the Grid above)
``/rosout``             rcl_interfaces/Log: one per event, ``msg`` as ``/events`` above
``/clock``              rosgraph_msgs/Clock: simulation time, every control step
======================  ===============================================================

The active waypoint of ``/controller`` has no standard message and is not in ``ros2`` logs.

Time: ``log_time`` = ``publish_time`` = every message's own timestamp = simulation
time in ns from 0.  No wall-clock time is written, so two runs with the same seed
give identical message bytes on every channel.
"""

from __future__ import annotations

import functools
import importlib.metadata
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from swarmnav.sim.defaults import LOG_FORMATS as _DEFAULT_FORMATS

WORLD_FRAME = "world"
BASE_FRAME = "base_link"
MJCF_ATTACHMENT = "scene.xml"
LOG_PROFILE = "swarmnav"
ROS2_PROFILE = "ros2"
LOG_FORMATS = _DEFAULT_FORMATS  # (LOG_PROFILE, ROS2_PROFILE): --log-format; the MCAP profile of each is its name
assert LOG_FORMATS == (LOG_PROFILE, ROS2_PROFILE)
MAP_FRAME, ODOM_FRAME, SCAN_FRAME = "map", "odom", "base_scan"

WHEELS_SCHEMA = {
    "title": "swarmnav.WheelSpeeds",
    "type": "object",
    "properties": {
        "command_left_rad_s": {"type": "number"},
        "command_right_rad_s": {"type": "number"},
        "measured_left_rad_s": {"type": "number"},
        "measured_right_rad_s": {"type": "number"},
    },
}
CONTROLLER_SCHEMA = {
    "title": "swarmnav.ControllerState",
    "type": "object",
    "properties": {
        "linear_m_s": {"type": "number"},
        "angular_rad_s": {"type": "number"},
        "waypoint_index": {"type": "integer"},
    },
}
# The schema of ``/events`` in logs written before events became ``foxglove.Log``; still read.
LEGACY_EVENT_SCHEMA = {
    "title": "swarmnav.Event",
    "type": "object",
    "properties": {
        "kind": {
            "type": "string",
            "description": "goal_reached | collision_begin | collision_end | timeout",
        },
        "details": {"type": "object"},
    },
}

# topic -> (message encoding, schema name): what a reader may expect on each channel.
CHANNELS: dict[str, tuple[str, str]] = {
    "/tf": ("protobuf", "foxglove.FrameTransform"),
    "/robot/pose": ("protobuf", "foxglove.PoseInFrame"),
    "/planner/path": ("protobuf", "foxglove.PosesInFrame"),
    "/obstacles": ("protobuf", "foxglove.SceneUpdate"),
    "/range/scan": ("protobuf", "foxglove.LaserScan"),
    "/wheels": ("json", WHEELS_SCHEMA["title"]),
    "/controller": ("json", CONTROLLER_SCHEMA["title"]),
    "/events": ("protobuf", "foxglove.Log"),
    "/scene": ("protobuf", "foxglove.SceneUpdate"),
}
# The ros2 profile's channels: topic -> (message encoding, schema name).
ROS2_CHANNELS: dict[str, tuple[str, str]] = {
    topic: ("cdr", f"{short.split('/')[0]}/msg/{short.split('/')[1]}") for topic, short in (
        ("/tf_static", "tf2_msgs/TFMessage"), ("/tf", "tf2_msgs/TFMessage"), ("/odom", "nav_msgs/Odometry"),
        ("/scan", "sensor_msgs/LaserScan"), ("/joint_states", "sensor_msgs/JointState"),
        ("/wheels/command", "sensor_msgs/JointState"), ("/cmd_vel", "geometry_msgs/Twist"),
        ("/plan", "nav_msgs/Path"), ("/obstacles", "visualization_msgs/MarkerArray"),
        ("/scene", "visualization_msgs/MarkerArray"), ("/navigator", "visualization_msgs/MarkerArray"),
        ("/map", "nav_msgs/OccupancyGrid"), ("/rosout", "rcl_interfaces/Log"), ("/clock", "rosgraph_msgs/Clock"))}
ROS2_EVENTS_TOPIC = "/rosout"
# Older logs may carry these instead: topic -> (message encoding, schema name).
LEGACY_CHANNELS: dict[str, tuple[str, str]] = {"/events": ("json", LEGACY_EVENT_SCHEMA["title"])}
EVENTS_TOPIC = "/events"
SCENE_TOPIC = "/scene"
ARENA_ENTITY = "arena"
FOOTPRINT_ENTITY = "robot_footprint"
TOPICS = tuple(CHANNELS)
NAVIGATOR_TOPIC = "/navigator"  # a foxglove.SceneUpdate; optional (see the table above)
MAP_TOPIC = "/map"  # a foxglove.Grid; optional (see the table above)
ODOM_TOPIC = "/odom"  # a foxglove.PoseInFrame; optional (see the table above)


def events_topic(profile: str) -> str:
    """The topic a log of ``profile`` carries its events on."""
    return ROS2_EVENTS_TOPIC if profile == ROS2_PROFILE else EVENTS_TOPIC


def time_ns(time_s: float) -> int:
    """Simulation seconds to the integer nanoseconds used as MCAP log time."""
    return int(round(time_s * 1e9))


def _json_value(value: Any) -> Any:
    """Turn numpy scalars / arrays (and anything else odd) into JSON-able values."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return str(value)


def dumps(value: Any) -> str:
    """Deterministic JSON text for metadata values and JSON messages."""
    return json.dumps(value, sort_keys=True, default=_json_value)


def event_text(kind: str, details: dict[str, Any]) -> str:
    """The ``message`` of an event's ``foxglove.Log``: the kind, then its details as JSON if any."""
    return f"{kind} {dumps(details)}" if details else kind


def event_from_text(text: str) -> tuple[str, dict[str, Any]]:
    """The inverse of :func:`event_text`: (kind, details).

    Raises:
        ValueError: the details are not a JSON object.
    """
    kind, _, rest = text.partition(" ")
    details = json.loads(rest) if rest else {}
    if not isinstance(details, dict):
        raise ValueError(f"event details are not a JSON object: {rest[:60]!r}")
    return kind, details


def metadata_text(value: Any) -> str:
    """A metadata value as Foxglove should show it: a string as itself, anything else as JSON.

    A string that would read back as JSON (``"true"``, ``"12"``, ``"null"``) is written as
    JSON text (quoted) instead, so :func:`metadata_value` always recovers the value written.
    """
    if isinstance(value, str):
        try:
            json.loads(value)
        except ValueError:
            return value
    return dumps(value)


def metadata_value(text: str) -> Any:
    """The value :func:`metadata_text` wrote: JSON where the text is JSON, else the text itself."""
    try:
        return json.loads(text)
    except (ValueError, RecursionError):  # not JSON (or nested beyond the parser): the text itself
        return text


def scan_from_ranges(range_m: np.ndarray, beam_offset_m: float) -> np.ndarray:
    """Sensor ranges (from each site, ``inf`` = nothing in range) to LaserScan ranges.

    A LaserScan has one origin, base_link's, and the rangefinders sit on the rim
    of the body pointing outward: a reading plus the rim offset is the range from
    that origin.  Nothing in range is NaN in the log.
    """
    ranges = np.asarray(range_m, dtype=float)
    return np.where(np.isinf(ranges), np.nan, ranges + beam_offset_m)


def scan_list_from_ranges(range_m: np.ndarray, beam_offset_m: float) -> list[float]:
    """:func:`scan_from_ranges` as a list of floats, without NumPy's per-call cost (a dozen
    beams every control step): the same additions, NaN for an infinite reading."""
    return [math.nan if r == math.inf or r == -math.inf else r + beam_offset_m
            for r in np.asarray(range_m, dtype=float).tolist()]


def ranges_from_scan(scan_m: np.ndarray, beam_offset_m: float) -> np.ndarray:
    """The inverse of :func:`scan_from_ranges`: back to distances from the sites, ``inf`` for NaN."""
    scan = np.asarray(scan_m, dtype=float)
    return np.where(np.isnan(scan), np.inf, scan - beam_offset_m)


@functools.lru_cache(maxsize=1)
def _foxglove_sdk_version() -> str:
    """Looked up once per process: reading package metadata costs about a millisecond."""
    try:
        return importlib.metadata.version("foxglove-sdk")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def writer_versions(run_versions: dict[str, str]) -> dict[str, str]:
    """The run's versions (swarmnav, MuJoCo, Python) plus the log writer's."""
    return {"foxglove_sdk": _foxglove_sdk_version(), **run_versions}


def default_log_path(scenario: str, planner: str, seed: int, stamp: str, directory: str | Path = "logs") -> Path:
    """``logs/<scenario>_<planner>_seed<N>_<stamp>.mcap`` (the caller supplies the stamp)."""
    return Path(directory) / f"{scenario}_{planner}_seed{seed}_{stamp}.mcap"
