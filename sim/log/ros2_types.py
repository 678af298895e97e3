"""The ROS 2 message definitions a ``--log-format ros2`` log carries, as ``ros2msg`` schema text.

The fields of the standard interfaces as ROS 2 Humble defines them (``common_interfaces``,
``rcl_interfaces``, ``geometry2``; the same in Iron and Jazzy for these types), written out
here (constants left out: they are not part of the wire format).  A schema's text is the
type's own fields followed by every type it uses, each after a line of ``=`` and
``MSG: pkg/Type``: the ``ros2msg`` encoding of MCAP's ``ros2`` profile, which
``ros2 bag``, Foxglove and ``mcap-ros2-support`` read.  ``tests/test_log_ros2.py`` checks
each definition against the Humble type store of ``rosbags``, an independent library.
"""

from __future__ import annotations

import functools
import re

FIELDS: dict[str, str] = {
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec",
    "builtin_interfaces/Duration": "int32 sec\nuint32 nanosec",
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "std_msgs/ColorRGBA": "float32 r\nfloat32 g\nfloat32 b\nfloat32 a",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Quaternion": "float64 x\nfloat64 y\nfloat64 z\nfloat64 w",
    "geometry_msgs/Pose": "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation",
    "geometry_msgs/PoseStamped": "std_msgs/Header header\ngeometry_msgs/Pose pose",
    "geometry_msgs/PoseWithCovariance": "geometry_msgs/Pose pose\nfloat64[36] covariance",
    "geometry_msgs/Twist": "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular",
    "geometry_msgs/TwistWithCovariance": "geometry_msgs/Twist twist\nfloat64[36] covariance",
    "geometry_msgs/Transform": "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation",
    "geometry_msgs/TransformStamped": "std_msgs/Header header\nstring child_frame_id\n"
                                      "geometry_msgs/Transform transform",
    "tf2_msgs/TFMessage": "geometry_msgs/TransformStamped[] transforms",
    "nav_msgs/Odometry": "std_msgs/Header header\nstring child_frame_id\n"
                         "geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist",
    "nav_msgs/Path": "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses",
    "nav_msgs/MapMetaData": "builtin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\n"
                            "uint32 height\ngeometry_msgs/Pose origin",
    "nav_msgs/OccupancyGrid": "std_msgs/Header header\nnav_msgs/MapMetaData info\nint8[] data",
    "sensor_msgs/LaserScan": "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\n"
                             "float32 angle_increment\nfloat32 time_increment\nfloat32 scan_time\n"
                             "float32 range_min\nfloat32 range_max\nfloat32[] ranges\nfloat32[] intensities",
    "sensor_msgs/JointState": "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
                              "float64[] effort",
    "sensor_msgs/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data",
    "visualization_msgs/UVCoordinate": "float32 u\nfloat32 v",
    "visualization_msgs/MeshFile": "string filename\nuint8[] data",
    "visualization_msgs/Marker": "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n"
                                 "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
                                 "builtin_interfaces/Duration lifetime\nbool frame_locked\n"
                                 "geometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\n"
                                 "string texture_resource\nsensor_msgs/CompressedImage texture\n"
                                 "visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\n"
                                 "string mesh_resource\nvisualization_msgs/MeshFile mesh_file\n"
                                 "bool mesh_use_embedded_materials",
    "visualization_msgs/MarkerArray": "visualization_msgs/Marker[] markers",
    "rosgraph_msgs/Clock": "builtin_interfaces/Time clock",
    "rcl_interfaces/Log": "builtin_interfaces/Time stamp\nuint8 level\nstring name\nstring msg\nstring file\n"
                          "string function\nuint32 line",
}

# Marker.type / Marker.action and Log.level values (the constants of the definitions).
MARKER_ARROW, MARKER_CUBE, MARKER_CYLINDER, MARKER_LINE_STRIP = 0, 1, 3, 4
MARKER_ADD, MARKER_DELETEALL = 0, 3
LOG_INFO, LOG_WARN, LOG_ERROR = 20, 30, 40

_SEPARATOR = "=" * 80
_FIELD_TYPE = re.compile(r"^([a-z_0-9]+/[A-Za-z0-9_]+)")


def schema_name(short: str) -> str:
    """``pkg/Type`` to the schema name of MCAP's ros2 profile, ``pkg/msg/Type``."""
    package, name = short.split("/")
    return f"{package}/msg/{name}"


def _dependencies(short: str, seen: list[str]) -> list[str]:
    for line in FIELDS[short].splitlines():
        match = _FIELD_TYPE.match(line)
        if match and match.group(1) not in seen:
            seen.append(match.group(1))
            _dependencies(match.group(1), seen)
    return seen


@functools.lru_cache(maxsize=None)
def msgdef(short: str) -> str:
    """The ``ros2msg`` schema text of ``pkg/Type``: its fields, then each type it uses (depth first)."""
    parts = [FIELDS[short]]
    for dependency in _dependencies(short, []):
        parts.append(f"{_SEPARATOR}\nMSG: {dependency}\n{FIELDS[dependency]}")
    return "\n".join(parts)
