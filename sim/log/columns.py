"""A table of numbers grown one row at a time: what a streamed log is read into.

Reading a long log row by row into Python lists of floats (or of small arrays)
costs about ten times the numbers' own size; :class:`Rows` keeps them in one
NumPy array whose capacity doubles, so a log of any length costs what its
numbers take (at most twice, while growing).
"""

from __future__ import annotations

import numpy as np

INITIAL_ROWS = 256


class Rows:
    """An (N, width) array appended to row by row (amortised doubling).

    Args:
        width: numbers per row; None: taken from the first row appended.
        dtype: the array's type.
    """

    def __init__(self, width: int | None = None, dtype: type = float):
        self.width = width
        self.dtype = dtype
        self.size = 0
        self._data = np.empty((INITIAL_ROWS, width), dtype) if width is not None else None

    def append(self, row) -> None:
        if self._data is None:
            self.width = len(row)
            self._data = np.empty((INITIAL_ROWS, self.width), self.dtype)
        if self.size == len(self._data):
            grown = np.empty((2 * len(self._data), self.width), self.dtype)
            grown[:self.size] = self._data
            self._data = grown
        self._data[self.size] = row
        self.size += 1

    def __len__(self) -> int:
        return self.size

    def array(self) -> np.ndarray:
        """The (N, width) rows so far, as one array of exactly N rows (a copy)."""
        if self._data is None:
            return np.zeros((0, self.width or 0), self.dtype)
        return self._data[:self.size].copy()
