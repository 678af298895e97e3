"""One writer per study folder: an exclusive OS lock on ``DIR/.lock``, held while a study runs.

``fcntl.flock`` locks belong to the open file, so the kernel releases the lock
when the process ends in any way (Ctrl-C, SIGKILL, a crash): a folder is never
left locked by a dead study.  The holder writes its PID into the file, so a
second study into the same folder is refused at once naming it.
"""

from __future__ import annotations

import fcntl
import os
from pathlib import Path as FilePath

from swarmnav.models.contained_files import open_in_folder
from swarmnav.models.errors import ConfigError

LOCK_NAME = ".lock"


class FolderLock:
    """``with FolderLock(out_dir):`` holds the folder's lock, or raises ``ConfigError`` naming the holder."""

    def __init__(self, out_dir: FilePath):
        self.path = FilePath(out_dir) / LOCK_NAME
        self.fd: int | None = None

    def __enter__(self) -> "FolderLock":
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = open_in_folder(self.path, os.O_RDWR | os.O_CREAT, "--out")  # a planted link is refused
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "unknown"
            os.close(fd)
            raise ConfigError("--out", f"another swarmnav study is writing to this folder (PID {holder}); "
                                       "wait for it to end or choose another folder", str(self.path.parent)) from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self.fd = fd
        return self

    def __exit__(self, *exc) -> None:
        if self.fd is not None:
            os.close(self.fd)  # releases the lock; the file stays (removing it would race a waiting locker)
            self.fd = None
