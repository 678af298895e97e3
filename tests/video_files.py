"""Test helpers: decode the MP4 files the renderer wrote (imageio-ffmpeg's bundled ffmpeg)."""

from __future__ import annotations

from pathlib import Path

import imageio_ffmpeg
import numpy as np


def video_info(path: str | Path) -> tuple[int, float]:
    """(frame count, seconds) of a video file, counted by decoding it."""
    return imageio_ffmpeg.count_frames_and_secs(str(path))


def read_video_frames(path: str | Path, every: int = 1) -> list[np.ndarray]:
    """Decode an MP4 into (H, W, 3) uint8 frames (every ``every``-th one)."""
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    width, height = meta["size"]
    frames = []
    for index, raw in enumerate(reader):
        if index % every == 0:
            frames.append(np.frombuffer(raw, dtype=np.uint8).reshape(height, width, 3))
    return frames


