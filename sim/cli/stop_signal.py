"""SIGTERM for the command line: the handler, and which signal stopped this process.

The handler raises ``SystemExit(128 + signum)``, which unwinds through the runner (closing the log it was
writing) and the study driver (keeping the rows written so far).  A native library can turn the pending
exception into one of its own on the way (Ray's ``wait`` raises ``SystemExit(1)`` when a signal interrupts
it), so the signal is also recorded here, where the command that reports the stop reads it.
"""

from __future__ import annotations

from typing import Any

received: int | None = None  # the signal number that stopped this process, if one did


def exit_on_signal(signum: int, frame: Any) -> None:
    global received
    received = signum
    raise SystemExit(128 + signum)
