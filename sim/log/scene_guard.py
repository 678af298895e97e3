"""A log's attached ``scene.xml`` is data from elsewhere: checked, then compiled with nothing beyond itself.

``replay --verify`` and ``replay --video`` rebuild the scene from the MJCF a log carries.  A log may come
from anyone, and MuJoCo's compiler would follow an ``<include file=...>`` or an asset's ``file`` to any local
path, reserve whatever ``<size memory=...>`` asks for, and allocate textures and offscreen buffers of any
declared size.  :func:`compile_log_scene` first reads the XML itself (the standard library's parser, which
resolves no external entity) and refuses, in one :class:`LogError` naming the log:

* anything that names a file or folder (``include``, ``model``, any ``file``/``*dir`` attribute), a plugin or
  extension, or a ``<size>`` section (swarmnav's scenes declare none: MuJoCo sizes them itself);
* a texture or an offscreen buffer larger than :data:`MAX_SCENE_PIXELS_SIDE` a side;
* a scene larger than :data:`MAX_SCENE_ELEMENTS` elements or :data:`MAX_INPUT_FILE_BYTES` bytes;

and then compiles it from the string, a compiler error being the same one line.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

from swarmnav.models.scenario_limits import (MAX_INPUT_FILE_BYTES, MAX_MOVING_OBSTACLES, MAX_NESTING_DEPTH,
                                             MAX_STATIC_OBSTACLES)
from swarmnav.log.records import LogError

MAX_SCENE_PIXELS_SIDE = 8_192  # a texture's or an offscreen buffer's side (video frames are at most 4,096)
MAX_SCENE_ELEMENTS = 4 * (MAX_STATIC_OBSTACLES + MAX_MOVING_OBSTACLES) + 1_000  # bodies, geoms, sensors...
REFUSED_ELEMENTS = {"include", "model", "plugin", "extension", "instance", "size"}
PIXEL_ATTRIBUTES = {"width", "height", "offwidth", "offheight", "shadowsize"}


def check_log_scene(xml: str, source: str) -> None:
    """Refuse a scene that would reach beyond itself (see the module docstring)."""
    def refuse(problem: str) -> None:
        raise LogError(source, f"its scene.xml {problem}; a log's scene is compiled only from itself")

    if len(xml) > MAX_INPUT_FILE_BYTES:
        refuse(f"has {len(xml):,} characters, more than {MAX_INPUT_FILE_BYTES:,}")
    try:
        root = ElementTree.fromstring(xml)
    except ElementTree.ParseError as exc:
        refuse(f"is not XML ({exc})")
    except RecursionError:
        refuse(f"nests elements more than {MAX_NESTING_DEPTH} deep")
    count = 0
    stack = [(root, 1)]
    while stack:
        element, depth = stack.pop()
        count += 1
        if count > MAX_SCENE_ELEMENTS:
            refuse(f"has more than {MAX_SCENE_ELEMENTS:,} elements")
        if depth > 4 * MAX_NESTING_DEPTH:
            refuse(f"nests elements more than {4 * MAX_NESTING_DEPTH} deep")
        tag = str(element.tag)
        if tag in REFUSED_ELEMENTS:
            refuse(f"has a <{tag}> element")
        for name, value in element.attrib.items():
            if name == "file" or name.startswith("file") or name.endswith("dir"):
                refuse(f"names a file or folder (<{tag} {name}={value[:60]!r}>)")
            if name in PIXEL_ATTRIBUTES and tag in ("texture", "global", "quality"):
                try:
                    side = float(value)
                except ValueError:
                    refuse(f"has <{tag} {name}={value[:40]!r}>, not a number")
                if not 0 <= side <= MAX_SCENE_PIXELS_SIDE:
                    refuse(f"asks for <{tag} {name}={value[:40]!r}> (at most {MAX_SCENE_PIXELS_SIDE:,})")
        stack.extend((child, depth + 1) for child in element)
    if root.tag != "mujoco":
        refuse(f"is not MJCF (its root is <{root.tag}>)")


def compile_log_scene(xml: str | None, source: str):
    """The ``mujoco.MjModel`` of a log's scene, checked first (:func:`check_log_scene`).

    Raises:
        LogError: no scene, a refused one, or one MuJoCo cannot compile (its first line).
    """
    import mujoco

    if not xml:
        raise LogError(source, "the log has no MJCF attachment (scene.xml)")
    check_log_scene(xml, source)
    try:
        return mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        message = " ".join(str(exc).split())[:200]
        raise LogError(source, f"its scene.xml does not compile ({message})") from None
