"""A path someone else planned, read from a file and driven instead of a plan (``swarmnav run --waypoints``).

Three formats, told apart by their content (not their name):

* CSV with a header naming ``x`` and ``y`` columns (other columns are ignored), one waypoint a row;
* a JSON list of ``[x, y]`` pairs;
* a JSON object with a ``waypoints`` list (what ``swarmnav plan --json`` prints).

Every problem is one :class:`ConfigError` naming the file, the row (or JSON index) and what is wrong.  The
path is data: nothing in the file is run.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path as FilePath
from typing import Any, Sequence

import warnings

import numpy as np

from swarmnav.models.contained_files import loads_json, read_input_text
from swarmnav.models.errors import ConfigError
from swarmnav.planners.problem import Path, scenario_problem

FIELD = "--waypoints"
MAX_WAYPOINTS = 1_000_000  # a path longer than this is not a path a controller follows; it is refused by size


def _finite_pair(value: Any, where: str, source: str) -> tuple[float, float]:
    if (not isinstance(value, (list, tuple)) or len(value) != 2
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise ConfigError(where, f"expected an [x, y] pair of numbers, got {value!r}"[:200], source)
    x, y = float(value[0]), float(value[1])
    if not (math.isfinite(x) and math.isfinite(y)):
        raise ConfigError(where, f"must be finite, got [{x}, {y}]", source)
    return x, y


def _fast_pairs(rows: Any) -> np.ndarray | None:
    """A list of finite ``[x, y]`` number pairs as an ``(N, 2)`` array in NumPy's bulk calls, or None for
    anything else (then the row-by-row reader names the first bad row)."""
    if not rows or len(rows) > MAX_WAYPOINTS:
        return None
    try:
        array = np.array(rows)
    except (ValueError, TypeError, OverflowError):  # ragged, or an integer beyond 64 bits
        return None
    if array.ndim != 2 or array.shape[1] != 2 or array.dtype.kind not in "fi":
        return None
    array = array.astype(float, copy=False)
    if not np.all(np.isfinite(array)) or any(type(v) is bool for pair in rows for v in pair):  # noqa: E721
        return None
    return array


def _from_json(data: Any, source: str) -> list[tuple[float, float]] | np.ndarray:
    key = ""
    if isinstance(data, dict):
        if "waypoints" not in data:
            raise ConfigError(FIELD, "a JSON object needs a 'waypoints' list (as `swarmnav plan --json` prints)",
                              source)
        data, key = data["waypoints"], "waypoints"
    if not isinstance(data, list):
        raise ConfigError(FIELD, "expected a JSON list of [x, y] pairs", source)
    if len(data) > MAX_WAYPOINTS:
        raise ConfigError(FIELD, f"{len(data)} waypoints (at most {MAX_WAYPOINTS:,})", source)
    fast = _fast_pairs(data)
    if fast is not None:
        return fast
    return [_finite_pair(v, f"{key}[{i}]", source) for i, v in enumerate(data)]


def _fast_csv(text: str) -> np.ndarray | None:
    """The common CSV, a header of x and y and numbers below it, read by NumPy's C reader; None for anything
    else (a bad row, a quoted cell, more than MAX_WAYPOINTS rows): the row-by-row reader then names the problem."""
    header, _, body = text.partition("\n")
    columns = [c.strip().lower() for c in header.split(",")]
    if "x" not in columns or "y" not in columns or '"' in text:
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "input contained no data": the row-by-row reader says it
            array = np.loadtxt(io.StringIO(body), delimiter=",", usecols=(columns.index("x"), columns.index("y")),
                               ndmin=2, dtype=float, max_rows=MAX_WAYPOINTS + 1, comments=None)
    except (ValueError, IndexError):
        return None
    if len(array) > MAX_WAYPOINTS or not np.all(np.isfinite(array)):
        return None
    return array


def _from_csv(text: str, source: str) -> list[tuple[float, float]] | np.ndarray:
    fast = _fast_csv(text)
    if fast is not None:
        return fast
    rows = csv.reader(io.StringIO(text))
    out: list[tuple[float, float]] = []
    number, ix, iy = 0, 0, 0
    try:  # csv.Error: a cell over the csv module's field limit, a NUL byte
        for number, row in enumerate(rows, start=1):
            if number == 1:
                columns = [c.strip().lower() for c in row]
                if "x" not in columns or "y" not in columns:
                    raise ConfigError("row 1", "a CSV file needs a header naming its x and y columns", source)
                ix, iy = columns.index("x"), columns.index("y")
            elif row and any(cell.strip() for cell in row):
                if len(out) >= MAX_WAYPOINTS:
                    raise ConfigError(f"row {number}", f"more than {MAX_WAYPOINTS:,} waypoints", source)
                out.append(_csv_pair(row, ix, iy, f"row {number}", source))
    except csv.Error as exc:
        raise ConfigError(f"row {number + 1}", f"not a CSV row ({exc})", source) from None
    if number == 0:
        raise ConfigError("row 1", "a CSV file needs a header naming its x and y columns", source)
    return out


def _csv_pair(row: list[str], ix: int, iy: int, where: str, source: str) -> tuple[float, float]:
    try:
        x, y = float(row[ix]), float(row[iy])
    except (IndexError, ValueError):
        raise ConfigError(where, f"expected numbers in columns x and y, got {row!r}"[:200], source) from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise ConfigError(where, f"must be finite, got {x}, {y}", source)
    return x, y


def read_waypoints(file: str | FilePath) -> np.ndarray:
    """The ``(N, 2)`` waypoints in metres of a CSV or JSON file (see the module's docstring).

    Raises:
        ConfigError: unreadable file, unknown format, a bad row, or fewer than two waypoints.
    """
    source = str(file)
    text = read_input_text(file, FIELD)  # a regular file of at most MAX_INPUT_FILE_BYTES, never a FIFO or device
    stripped = text.lstrip()
    if stripped.startswith(("[", "{")):
        points = _from_json(loads_json(text, source), source)
    else:
        points = _from_csv(text, source)
    return as_waypoints(points, source)


def as_waypoints(points: Sequence[Sequence[float]] | np.ndarray, source: str = FIELD) -> np.ndarray:
    """Waypoints given in code or read from a file, checked: at least two finite ``[x, y]`` pairs."""
    array = np.asarray(points, dtype=float)
    if array.ndim != 2 or array.shape[1] != 2:
        raise ConfigError(FIELD, f"expected (N, 2) waypoints, got shape {array.shape}", source)
    if len(array) < 2:
        raise ConfigError(FIELD, f"a path needs at least two waypoints, got {len(array)}", source)
    if not np.all(np.isfinite(array)):
        raise ConfigError(FIELD, "every waypoint must be finite", source)
    return np.ascontiguousarray(array)


def given_path(scenario, waypoints: np.ndarray, source: str) -> tuple[Any, Path]:
    """The scenario's problem and the given waypoints as a :class:`Path` (no planning time, no search),
    ``stats.extra`` saying where the path came from."""
    problem = scenario_problem(scenario)
    path = Path.from_waypoints(waypoints, 0.0, extra={"given": source})
    return problem, path
