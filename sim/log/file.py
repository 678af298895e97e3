"""The file a run log is written to: opened by us, so every failure names its path.

foxglove's writer accepts a file-like object.  Handing it :class:`LogFile`
instead of a path means that opening the file (permissions, a directory, an
existing file) raises Python's own ``OSError`` with the file name, and that a
failed write (a full disk, a file-size limit) is kept as that ``OSError`` rather
than only as the writer's generic "I/O error from writing".  Writes go straight
to the operating system (no Python buffer), so what the writer has written
survives a SIGKILL.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

from swarmnav.models.contained_files import open_in_folder


class LogFile:
    """An unbuffered binary file that remembers the first write error.

    Args:
        path: the file to create; its parent directories are made.
        overwrite: replace an existing file (a directory is never replaced).

    Raises:
        OSError: with ``filename`` set: the path is a directory, exists (without
            ``overwrite``), or cannot be created.
    """

    def __init__(self, path: str | Path, *, overwrite: bool = False):
        self.path = Path(path)
        self.error: OSError | None = None
        if self.path.is_dir():
            raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(self.path))
        if not overwrite and (self.path.exists() or self.path.is_symlink()):
            raise FileExistsError(errno.EEXIST, "file exists (use --overwrite)", str(self.path))
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise type(error)(error.errno, error.strerror, str(self.path.parent)) from None
        # never through a symbolic link (a link planted in a study's logs/ would redirect the write)
        flags = os.O_WRONLY | os.O_CREAT | (os.O_TRUNC if overwrite else os.O_EXCL)
        self._file = os.fdopen(open_in_folder(self.path, flags, "log"), "wb", buffering=0)

    def write(self, data: bytes) -> int:
        """Write all of ``data`` (a full disk keeps what fitted and raises)."""
        view = memoryview(data)
        try:
            while view:
                written = self._file.write(view)
                view = view[written:]
        except OSError as error:
            if self.error is None:
                self.error = type(error)(error.errno, error.strerror, str(self.path))
            raise
        return len(data)

    def seek(self, offset: int, whence: int = os.SEEK_SET) -> int:
        return self._file.seek(offset, whence)

    def tell(self) -> int:
        return self._file.tell()

    def flush(self) -> None:
        """Nothing is buffered here: every write already reached the operating system."""

    def close(self) -> None:
        self._file.close()
