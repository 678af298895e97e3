"""Text on video frames: a title bar (scenario, planner, navigator, seed) and the simulation time.

Drawn on the frame's array after MuJoCo rendered it, with Pillow's built-in
scalable font (``ImageFont.load_default(size)``, Pillow >= 10.1), so it works
wherever the frames come from (EGL offscreen on a CPU included) and needs no
font file.  The title's coverage is rendered once per video and only the clock's
box per frame, then blended into the bar's strip with NumPy.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw, ImageFont

BAR_DARKEN = 0.3        # the strip under the text keeps this fraction of its brightness
TEXT_RGB = (255, 255, 255)
FONT_FRACTION = 1 / 28  # font size as a fraction of the frame height


class FrameCaption:
    """Writes ``title`` at the top left and the time at the top right of each frame.

    Args:
        title: the fixed text (shortened with an ellipsis to fit beside the time).
        width, height: the frame size in pixels.
    """

    def __init__(self, title: str, width: int, height: int):
        self.width, self.height = width, height
        size = max(9, round(height * FONT_FRACTION))
        self._font = ImageFont.load_default(size)
        self._pad = max(2, size // 3)
        self.bar_px = min(height, size + 2 * self._pad)
        time_room = self._text_width("t = 0000.00 s") + 3 * self._pad
        self.title = self._fit(title, max(0, width - time_room - self._pad))
        self._title_mask: np.ndarray | None = None

    def _text_width(self, text: str) -> float:
        return self._font.getlength(text)

    def _fit(self, text: str, room_px: float) -> str:
        if self._text_width(text) <= room_px:
            return text
        while text and self._text_width(text + "…") > room_px:
            text = text[:-1]
        return text + "…" if text else ""

    def _mask(self, text: str, width_px: int) -> np.ndarray:
        """(bar_px, width_px) text coverage in 0..1 (antialiased), the text at the bar's padding."""
        image = Image.new("L", (max(1, width_px), self.bar_px))
        ImageDraw.Draw(image).text((self._pad, self._pad), text, font=self._font, fill=255)
        return np.asarray(image, dtype=np.float32)[:, :, None] / 255.0

    def draw(self, frame: np.ndarray, time_s: float) -> np.ndarray:
        """``frame`` (H, W, 3) uint8 with the bar drawn in place; returned for chaining.

        The title's coverage is rendered once; only the clock's small box is rendered per frame.
        """
        if self._title_mask is None:
            self._title_mask = self._mask(self.title, self.width)
        clock = f"t = {time_s:.2f} s"
        clock_px = int(self._text_width(clock)) + 2 * self._pad + 1
        left = max(0, self.width - clock_px)
        coverage = self._title_mask.copy()
        coverage[:, left:] = np.maximum(coverage[:, left:], self._mask(clock, self.width - left))
        strip = frame[: self.bar_px].astype(np.float32) * BAR_DARKEN
        text = np.array(TEXT_RGB, dtype=np.float32)
        frame[: self.bar_px] = (strip * (1.0 - coverage) + text * coverage).astype(np.uint8)
        return frame


def run_title(scenario: str, planner: str, navigator: str, seed: int, world_seed: int) -> str:
    """The title of a run's video."""
    seeds = f"seed {seed}" if seed == world_seed else f"seed {seed}, world seed {world_seed}"
    return f"{scenario} | {planner} + {navigator} | {seeds}"
