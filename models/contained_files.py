"""Files from elsewhere stay contained: the one way swarmnav reads an input file and writes into an output folder.

Reading (:func:`read_input_text`, :func:`read_input_bytes`): the path must name a regular file (a FIFO, a
device, a socket or a directory is one :class:`ConfigError`; a FIFO is opened non-blocking, so it never
waits for a writer) no larger than :data:`~swarmnav.models.scenario_limits.MAX_INPUT_FILE_BYTES`, checked on
the open file before anything is read.  The structured formats are parsed here too (:func:`loads_toml`,
:func:`loads_json`), with the same bound on nesting (:data:`~swarmnav.models.scenario_limits.MAX_NESTING_DEPTH`)
and every parser limit (Python's recursion, its 4,300-digit integers) turned into a one-line error.

Writing (:func:`folder`, :func:`open_in_folder`, :func:`check_no_link`): an output folder and every file
written into it are refused when a symbolic link stands where they go (a link planted in a study folder
would otherwise redirect or truncate its target): files are opened with ``O_NOFOLLOW`` and folders checked
with ``lstat``.  The user's own ``--out`` may be a link (they chose it); what lies inside it may not.

A name read from a file is never a path: :func:`name_problem` says why a name cannot be one file-name part.
"""

from __future__ import annotations

import errno
import json
import os
import re
import stat
import tomllib
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario_limits import MAX_INPUT_FILE_BYTES, MAX_NAME_CHARS, MAX_NESTING_DEPTH


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "is a directory, not a file"
    if stat.S_ISFIFO(mode):
        return "is a FIFO (named pipe), not a regular file"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "is a device, not a regular file"
    if stat.S_ISSOCK(mode):
        return "is a socket, not a regular file"
    return "is not a regular file"


def read_input_bytes(path: str | os.PathLike, field: str, max_bytes: int = MAX_INPUT_FILE_BYTES) -> bytes:
    """The bytes of a regular input file of at most ``max_bytes`` (the file named as the error's source).

    Raises:
        ConfigError: missing, unreadable, not a regular file, or larger than ``max_bytes``.
    """
    source = str(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise ConfigError(field, "file does not exist", source) from None
    except IsADirectoryError:
        raise ConfigError(field, _kind(stat.S_IFDIR), source) from None
    except OSError as exc:
        raise ConfigError(field, f"cannot be read ({exc.strerror or exc})", source) from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise ConfigError(field, _kind(info.st_mode), source)
        if info.st_size > max_bytes:
            raise ConfigError(field, f"{info.st_size:,} bytes, more than the maximum {max_bytes:,} "
                                     "(MAX_INPUT_FILE_BYTES)", source)
        os.set_blocking(fd, True)
        chunks, total = [], 0
        while True:  # a file that grows while read is still cut at the maximum
            chunk = os.read(fd, min(1 << 20, max_bytes + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > max_bytes:
                raise ConfigError(field, f"more than the maximum {max_bytes:,} bytes (MAX_INPUT_FILE_BYTES)", source)
        return b"".join(chunks)
    except OSError as exc:
        raise ConfigError(field, f"cannot be read ({exc.strerror or exc})", source) from None
    finally:
        os.close(fd)


def read_input_text(path: str | os.PathLike, field: str, max_bytes: int = MAX_INPUT_FILE_BYTES) -> str:
    """:func:`read_input_bytes` decoded as UTF-8 (a binary file is one error naming the first bad byte)."""
    data = read_input_bytes(path, field, max_bytes)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(field, f"is not UTF-8 text (byte {exc.start})", str(path)) from None


def is_input_path(path: str | os.PathLike) -> bool:
    """Whether something (of any kind, even a dangling link) is at ``path``: a name that exists is read as that
    path, and :func:`read_input_bytes` says what is wrong with it, rather than "no bundled ... named"."""
    return os.path.lexists(path)


def check_depth(value: Any, field: str, source: str | None, limit: int = MAX_NESTING_DEPTH) -> Any:
    """``value`` unless arrays or tables nest deeper than ``limit`` (checked without recursion)."""
    stack = [(value, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            children = item.values()
        elif isinstance(item, (list, tuple)):
            children = item
        else:
            continue
        if depth > limit:
            raise ConfigError(field, f"arrays or tables nested more than {limit} deep (MAX_NESTING_DEPTH)", source)
        stack.extend((child, depth + 1) for child in children)
    return value


_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.S)
_TOML_STRINGS_AND_COMMENTS = re.compile(r'"""(?:[^\\]|\\.)*?"""|\'\'\'.*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*',
                                        re.S)
_NOT_BRACKETS = re.compile(r"[^\[\]{}]+")


def bracket_depth(text: str, toml: bool = False) -> int:
    """How deep ``[`` and ``{`` nest in a JSON (or TOML) text, strings and comments left out, counted without
    recursion and in C-speed passes: checked before a parser recurses into it (after a RecursionError a
    CPython 3.11 process can misbehave, so the parsers never meet one)."""
    if text.count("[") + text.count("{") <= MAX_NESTING_DEPTH:
        return 0  # too few brackets to nest beyond the limit
    import numpy as np
    bare = (_TOML_STRINGS_AND_COMMENTS if toml else _JSON_STRING).sub("", text)
    brackets = _NOT_BRACKETS.sub("", bare).encode("ascii")
    if not brackets:
        return 0
    codes = np.frombuffer(brackets, dtype=np.uint8)
    steps = np.where((codes == ord("[")) | (codes == ord("{")), 1, -1)
    return int(np.cumsum(steps).max())


def _check_brackets(text: str, source: str | None, field: str, toml: bool) -> None:
    # a TOML table header ([table], [[array]]) opens at most two brackets: the limit leaves room for them
    if bracket_depth(text, toml) > MAX_NESTING_DEPTH + (2 if toml else 0):
        raise ConfigError(field, f"arrays or tables nested more than {MAX_NESTING_DEPTH} deep (MAX_NESTING_DEPTH)",
                          source)


def _parser_limit(exc: BaseException) -> str | None:
    """What a parser's own limit says, for the limits it meets before ours (None: not one of them)."""
    if isinstance(exc, RecursionError):
        return f"arrays or tables nested more than {MAX_NESTING_DEPTH} deep (MAX_NESTING_DEPTH)"
    if isinstance(exc, ValueError) and "integer string conversion" in str(exc):
        return "an integer of more than 4,300 digits"
    return None


def loads_toml(text: str, source: str | None, field: str = "toml") -> dict[str, Any]:
    """A TOML document (malformed, too deep or a too-long integer: one ConfigError naming ``field``)."""
    _check_brackets(text, source, field, toml=True)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(field, f"malformed TOML ({exc})", source) from None
    except (RecursionError, ValueError) as exc:
        problem = _parser_limit(exc)
        if problem is None:
            raise
        raise ConfigError(field, problem, source) from None
    return check_depth(data, field, source)


def loads_json(text: str | bytes, source: str | None, field: str = "json") -> Any:
    """A JSON document (malformed, too deep or a too-long integer: one ConfigError naming ``field``)."""
    _check_brackets(text.decode("utf-8", "replace") if isinstance(text, bytes) else text, source, field, toml=False)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ConfigError(f"line {exc.lineno}" if field == "json" else field, f"malformed JSON ({exc.msg})",
                          source) from None
    except (RecursionError, ValueError) as exc:
        problem = _parser_limit(exc)
        if problem is None:
            raise
        raise ConfigError(field, problem, source) from None
    return check_depth(data, field, source)


def name_problem(name: str) -> str | None:
    """Why a name read from a file cannot be one file-name part (it would become a path), or None.

    Printable, no path separator, not ``.`` or ``..``, at most :data:`MAX_NAME_CHARS` characters.
    """
    if not name.strip():
        return "must not be empty"
    if len(name) > MAX_NAME_CHARS:
        return f"must be at most {MAX_NAME_CHARS} characters, got {len(name)}"
    bad = next((ch for ch in name if not ch.isprintable()), None)
    if bad is not None:
        return f"must be printable, has {bad!r}"
    if "/" in name or "\\" in name:
        return f"must not contain a path separator ('/' or '\\'), got {name!r}"
    if name.strip() in (".", ".."):
        return f"must not be {name.strip()!r}"
    return None


# --- writing into an output folder -----------------------------------------------------------------------


def check_no_link(path: str | os.PathLike, field: str) -> None:
    """Refuse a symbolic link standing where swarmnav is about to write (one ConfigError naming it)."""
    if os.path.islink(path):
        raise ConfigError(field, f"is a symbolic link (to {os.readlink(path)!r}); swarmnav does not write "
                                 "through a link inside an output folder: remove it", str(path))


def folder(path: str | os.PathLike, field: str) -> FilePath:
    """Make (or keep) a folder inside an output folder, refusing a symbolic link where it goes."""
    path = FilePath(path)
    check_no_link(path, field)
    path.mkdir(parents=True, exist_ok=True)
    check_no_link(path, field)  # planted in between
    return path


def open_in_folder(path: str | os.PathLike, flags: int, field: str, mode: int = 0o644) -> int:
    """``os.open`` of a file inside an output folder with ``O_NOFOLLOW``: a link planted there is refused."""
    try:
        return os.open(path, flags | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0), mode)
    except OSError as exc:
        if exc.errno == errno.ELOOP or os.path.islink(path):
            check_no_link(path, field)
        raise


def replace_file(path: str | os.PathLike, text: str, field: str) -> None:
    """Write ``text`` to ``path`` inside an output folder, atomically (a dot-named temporary renamed over it),
    refusing a link planted at either name."""
    path = FilePath(path)
    check_no_link(path, field)
    temporary = path.with_name(f".{path.name}.tmp")
    fd = open_in_folder(temporary, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, field)
    with os.fdopen(fd, "w", encoding="utf-8") as out:
        out.write(text)
    os.replace(temporary, path)


def check_output_target(path: str | os.PathLike, field: str, folder_ok: bool = True) -> None:
    """Refuse an output path where something other than a regular file (or, with ``folder_ok``, a folder)
    stands: writing there would feed a device or block on a FIFO, and replacing it atomically would put a
    file where a device was."""
    try:
        mode = os.lstat(path).st_mode
    except OSError:
        return  # nothing there (or not reachable): the write itself says what is wrong
    if stat.S_ISREG(mode) or stat.S_ISLNK(mode) or (folder_ok and stat.S_ISDIR(mode)):
        return
    raise ConfigError(field, f"{_kind(mode)}: swarmnav writes only regular files and folders", str(path))
