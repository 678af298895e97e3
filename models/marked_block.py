"""A generated block of a text file: the text between a begin marker and the end marker after it, markers
included.  The docs pages' generated tables (claims, navigation, BARN, CrowdNav, odometry, the sensed map) are
such blocks: ``make readme-table`` and the benches' ``--write`` replace them, and the drift tests compare
them with what the committed results give."""

from __future__ import annotations

from dataclasses import dataclass

from swarmnav.models.errors import ConfigError


@dataclass(frozen=True)
class MarkedBlock:
    """The block from ``begin`` to the first ``end`` after it; ``name`` says which in errors."""

    begin: str
    end: str
    name: str

    def _span(self, text: str) -> tuple[int, int] | None:
        start = text.find(self.begin)
        stop = text.find(self.end, start) if start >= 0 else -1
        return (start, stop + len(self.end)) if start >= 0 and stop >= 0 else None

    def current(self, text: str) -> str | None:
        """The block as it stands in ``text`` (None: no markers)."""
        span = self._span(text)
        return None if span is None else text[span[0]:span[1]]

    def replace(self, text: str, new_block: str, source: str) -> str:
        """``text`` with its block replaced by ``new_block``; ConfigError naming ``source`` without markers."""
        span = self._span(text)
        if span is None:
            raise ConfigError("--readme", f"has no {self.name}", source)
        return text[:span[0]] + new_block + text[span[1]:]
