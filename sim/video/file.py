"""Frames to an H.264 MP4 through the ffmpeg binary that imageio-ffmpeg bundles.

We run ffmpeg ourselves (rather than through ``imageio_ffmpeg.write_frames``) so
that its messages never reach the user's terminal unasked and a failure is one
``OSError`` naming the video file: the file is created here first (a refused path
fails before ffmpeg starts), ffmpeg's stderr goes to a temporary file, and its
exit status is checked when the video is closed.

A writer stops when its consumer fails: ffmpeg runs with ``-xerror`` (it exits at
its first error rather than reading and dropping every further frame), and each
frame first checks that ffmpeg is still running, so a dead or failed encoder ends
the run at the next frame with that one ``OSError`` (the run's log is then finished
by the runner as for any error).
"""

from __future__ import annotations

import errno
import os
import subprocess
import tempfile
from pathlib import Path

import imageio_ffmpeg
import numpy as np

# Fast H.264 at a quality that keeps thin lines readable; yuv420p plays everywhere.
ENCODER_OPTIONS = ("-an", "-vcodec", "libx264", "-pix_fmt", "yuv420p", "-preset", "veryfast", "-crf", "23")


class VideoWriter:
    """Writes (height, width, 3) uint8 RGB frames to ``path`` as an MP4.

    Raises:
        OSError: (with the file name) the path is a directory or cannot be created,
            or ffmpeg could not write the video (its own last message says why).
    """

    def __init__(self, path: str | Path, width: int, height: int, fps: float):
        self.path = Path(path)
        self.frames = 0
        if self.path.is_dir():
            raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(self.path))
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.path.open("wb").close()  # a path the file system refuses fails here, named
        except OSError as error:
            raise type(error)(error.errno, error.strerror, str(self.path)) from None
        self._messages = tempfile.TemporaryFile()
        command = [imageio_ffmpeg.get_ffmpeg_exe(), "-y", "-v", "error", "-xerror", "-f", "rawvideo", "-vcodec", "rawvideo",
                   "-s", f"{width}x{height}", "-pix_fmt", "rgb24", "-r", f"{fps:.12g}", "-i", "-",
                   *ENCODER_OPTIONS, str(self.path)]
        self._process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                         stderr=self._messages)

    def add(self, frame: np.ndarray) -> None:
        if self._process is None or self._process.poll() is not None:  # ffmpeg stopped: never feed it
            self._fail()
        try:
            self._process.stdin.write(np.ascontiguousarray(frame, dtype=np.uint8).data)
        except (BrokenPipeError, ValueError):
            self._fail()
        self.frames += 1

    def close(self) -> None:
        if self._process is None:
            return
        try:
            self._process.stdin.close()
        except BrokenPipeError:
            pass
        status = self._process.wait()
        if status != 0:
            self._fail()
        self._process = None
        self._messages.close()

    def _fail(self) -> None:
        process, self._process = self._process, None
        if process is None and self._messages.closed:
            raise OSError(errno.EIO, "ffmpeg could not write the video (it stopped earlier)", str(self.path))
        if process is not None:
            try:
                process.stdin.close()
            except BrokenPipeError:
                pass
            process.wait()
        self._messages.seek(0)
        lines = [line.strip() for line in self._messages.read().decode(errors="replace").splitlines() if line.strip()]
        self._messages.close()
        reason = lines[-1] if lines else "ffmpeg stopped without a message"
        raise OSError(errno.EIO, f"ffmpeg could not write the video ({reason})", str(self.path))
