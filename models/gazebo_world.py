"""Gazebo world import: an SDF world's static cylinders and boxes as a scenario file (``scenarios import``).

World files come from elsewhere, so they are read as untrusted data:

* at most :data:`MAX_FILE_BYTES` are read from disk and, for a gzip file (told by its magic bytes, not its
  name), at most :data:`MAX_XML_BYTES` are decompressed (a gzip bomb stops there);
* the XML is parsed with ``defusedxml`` with DTDs forbidden, so an entity bomb (billion laughs), an external
  entity or a DTD fetch is refused before any expansion;
* at most :data:`MAX_OBSTACLES` obstacles are imported.

Every problem is a :class:`~swarmnav.models.errors.ConfigError` naming the file, the element (``model[3]
'wall'.pose``) and what is wrong: the command line prints it as one line and exits 2.

What is imported: every ``<model>`` that is a direct child of ``<world>`` and is static (``<static>1``),
each ``<link>``'s ``<collision>`` whose ``<geometry>`` is a ``<cylinder>`` (radius, length) or a ``<box>``
(size), placed by composing the model's, the link's and the collision's ``<pose>`` (x y z roll pitch yaw;
only the yaw turns the plan).  The ``<state>`` section, which repeats the poses, is not read.  What is not
imported is counted in :attr:`GazeboWorld.skipped` (a non-static model, a ``<plane>``, a mesh or sphere, an
``<include>``): the caller says so.  A cylinder must stand upright (roll and pitch multiples of pi); a box
must also be turned by a multiple of 90 degrees in total (swarmnav's boxes are axis-aligned), else the file
is refused, naming the model.
"""

from __future__ import annotations

import gzip
import io
import math
import zlib
from dataclasses import dataclass, field
from pathlib import Path as FilePath

from swarmnav.models.errors import ConfigError

MAX_FILE_BYTES = 32 * 1024 * 1024   # read from disk (compressed or not)
MAX_XML_BYTES = 32 * 1024 * 1024    # of XML after gzip decompression
MAX_OBSTACLES = 100_000             # cylinders and boxes together
ANGLE_TOLERANCE_RAD = 1e-6          # an angle counts as a multiple of pi (or pi/2) within this
GZIP_MAGIC = b"\x1f\x8b"


@dataclass(frozen=True)
class Cylinder:
    """An upright cylinder in the world's frame: centre (metres), radius and height (its SDF ``length``)."""

    model: str
    x_m: float
    y_m: float
    radius_m: float
    height_m: float


@dataclass(frozen=True)
class Block:
    """An axis-aligned box in the world's frame (its footprint) and its height."""

    model: str
    x_min_m: float
    y_min_m: float
    x_max_m: float
    y_max_m: float
    height_m: float


@dataclass(frozen=True)
class GazeboWorld:
    """A world file's static obstacles, in the file's order, and what was left out (reason -> count)."""

    source: str
    cylinders: tuple[Cylinder, ...]
    blocks: tuple[Block, ...]
    skipped: dict[str, int] = field(default_factory=dict)


def read_world(path: str | FilePath) -> GazeboWorld:
    """Read a ``.world`` or ``.world.gz`` (or ``.sdf``) file.

    Raises:
        ConfigError: missing, too large, a broken gzip stream, not XML, a forbidden DTD or entity, not an SDF
            world, or a geometry swarmnav cannot place (naming the file and the element).
    """
    source = str(path)
    return parse_world(read_world_bytes(path), source)


def read_world_bytes(path: str | FilePath) -> bytes:
    """The file's XML bytes, decompressed when it is gzip, within the stated bounds."""
    source = str(path)
    try:
        with open(path, "rb") as stream:
            raw = stream.read(MAX_FILE_BYTES + 1)
    except FileNotFoundError:
        raise ConfigError("world", "file does not exist", source) from None
    except IsADirectoryError:
        raise ConfigError("world", "is a directory, not a world file", source) from None
    except OSError as exc:
        raise ConfigError("world", f"cannot be read ({exc.strerror or exc})", source) from None
    if len(raw) > MAX_FILE_BYTES:
        raise ConfigError("world", f"is larger than {MAX_FILE_BYTES:,} bytes", source)
    if not raw.startswith(GZIP_MAGIC):
        return raw
    try:
        with gzip.GzipFile(fileobj=io.BytesIO(raw)) as unzipped:
            data = unzipped.read(MAX_XML_BYTES + 1)
    except (EOFError, OSError, zlib.error) as exc:
        raise ConfigError("world", f"is a broken gzip file ({exc})", source) from None
    if len(data) > MAX_XML_BYTES:
        raise ConfigError("world", f"decompresses to more than {MAX_XML_BYTES:,} bytes", source)
    return data


def parse_world(data: bytes, source: str = "<world>") -> GazeboWorld:
    """The static cylinders and boxes of SDF world XML (see the module docstring)."""
    import defusedxml.ElementTree as SafeTree
    from defusedxml import DefusedXmlException
    from xml.etree.ElementTree import ParseError
    try:
        root = SafeTree.fromstring(data, forbid_dtd=True, forbid_entities=True, forbid_external=True)
    except DefusedXmlException as exc:
        raise ConfigError("world", f"refused: {type(exc).__name__} (a DTD or entity in a world file)",
                          source) from None
    except ParseError as exc:
        raise ConfigError("world", f"is not well-formed XML ({exc})", source) from None
    world = root.find("world") if root.tag == "sdf" else None
    if world is None:
        raise ConfigError("world", f"expected <sdf><world>, found <{root.tag}>", source)
    cylinders: list[Cylinder] = []
    blocks: list[Block] = []
    skipped: dict[str, int] = {}

    def skip(reason: str) -> None:
        skipped[reason] = skipped.get(reason, 0) + 1

    for _ in world.findall("include"):
        skip("include (a model by URI, not read)")
    for index, model in enumerate(world.findall("model")):
        name = model.get("name", "")
        where = f"model[{index}] {name!r}"
        if (model.findtext("static") or "0").strip() not in ("1", "true"):
            skip("non-static model")
            continue
        model_pose = _pose(model, where, source)
        for link in model.findall("link"):
            link_pose = _compose(model_pose, _pose(link, f"{where}.link", source))
            for collision in link.findall("collision"):
                cwhere = f"{where}.collision {collision.get('name', '')!r}"
                pose = _compose(link_pose, _pose(collision, cwhere, source))
                geometry = collision.find("geometry")
                shape = geometry[0] if geometry is not None and len(geometry) else None
                if shape is None:
                    skip("collision without geometry")
                elif shape.tag == "cylinder":
                    _upright(pose, cwhere, source)
                    cylinders.append(Cylinder(name, pose[0], pose[1],
                                              _positive(shape, "radius", cwhere, source),
                                              _positive(shape, "length", cwhere, source)))
                elif shape.tag == "box":
                    blocks.append(_block(name, pose, shape, cwhere, source))
                else:
                    skip(f"{shape.tag} geometry")
                if len(cylinders) + len(blocks) > MAX_OBSTACLES:
                    raise ConfigError("world", f"has more than {MAX_OBSTACLES:,} obstacles", source)
    return GazeboWorld(source, tuple(cylinders), tuple(blocks), skipped)


Pose = tuple[float, float, float, float, float, float]  # x y z roll pitch yaw (metres, radians)
ZERO_POSE: Pose = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def _pose(element, where: str, source: str) -> Pose:
    """An element's own ``<pose>`` (zero without one); one relative to another frame is refused."""
    node = element.find("pose")
    if node is None:
        return ZERO_POSE
    frame = node.get("relative_to") or node.get("frame") or ""
    if frame:
        raise ConfigError(f"{where}.pose", f"is relative to frame {frame!r} (only the parent's frame is read)",
                          source)
    values = _numbers(node.text, f"{where}.pose", source)
    if len(values) != 6:
        raise ConfigError(f"{where}.pose", f"expected 6 numbers (x y z roll pitch yaw), got {len(values)}", source)
    return tuple(values)  # type: ignore[return-value]


def _numbers(text: str | None, where: str, source: str) -> list[float]:
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        raise ConfigError(where, f"expected numbers, got {(text or '').strip()[:40]!r}", source) from None
    if not all(math.isfinite(v) for v in values):
        raise ConfigError(where, f"expected finite numbers, got {(text or '').strip()[:40]!r}", source)
    return values


def _compose(parent: Pose, child: Pose) -> Pose:
    """``child`` given in ``parent``'s frame, in the parent's parent's frame (both upright: yaw turns x, y)."""
    px, py, pz, proll, ppitch, pyaw = parent
    cx, cy, cz, croll, cpitch, cyaw = child
    if not (_multiple(proll, 2 * math.pi) and _multiple(ppitch, 2 * math.pi)):
        # a tilted (or flipped) parent would move its children out of the plan: the caller refuses them
        return (math.nan,) * 6  # type: ignore[return-value]
    c, s = math.cos(pyaw), math.sin(pyaw)
    return (px + c * cx - s * cy, py + s * cx + c * cy, pz + cz, proll + croll, ppitch + cpitch, pyaw + cyaw)


def _multiple(angle: float, step: float) -> bool:
    k = round(angle / step)
    return abs(angle - k * step) <= ANGLE_TOLERANCE_RAD


def _upright(pose: Pose, where: str, source: str) -> None:
    if not all(math.isfinite(v) for v in pose) or not (_multiple(pose[3], math.pi) and _multiple(pose[4], math.pi)):
        raise ConfigError(where, "is tilted (roll or pitch not a multiple of 180 degrees): only upright "
                                 "obstacles stand on the plan", source)


def _positive(shape, key: str, where: str, source: str) -> float:
    values = _numbers(shape.findtext(key), f"{where}.{shape.tag}.{key}", source)
    if len(values) != 1 or values[0] <= 0.0:
        raise ConfigError(f"{where}.{shape.tag}.{key}", f"expected one positive number, got {values}", source)
    return values[0]


def _block(model: str, pose: Pose, shape, where: str, source: str) -> Block:
    """A box's axis-aligned footprint: its total yaw must be a multiple of 90 degrees."""
    _upright(pose, where, source)
    size = _numbers(shape.findtext("size"), f"{where}.box.size", source)
    if len(size) != 3 or min(size) <= 0.0:
        raise ConfigError(f"{where}.box.size", f"expected 3 positive numbers, got {size}", source)
    yaw = pose[5]
    if not _multiple(yaw, math.pi / 2):
        raise ConfigError(where, f"box turned by {math.degrees(yaw):g} degrees (only boxes turned by a multiple "
                                 "of 90 degrees are modelled: swarmnav's boxes are axis-aligned)", source)
    half_x, half_y = size[0] / 2, size[1] / 2
    if round(yaw / (math.pi / 2)) % 2:
        half_x, half_y = half_y, half_x
    return Block(model, pose[0] - half_x, pose[1] - half_y, pose[0] + half_x, pose[1] + half_y, size[2])


__all__ = ["Block", "Cylinder", "GazeboWorld", "MAX_FILE_BYTES", "MAX_OBSTACLES", "MAX_XML_BYTES", "parse_world",
           "read_world", "read_world_bytes"]
