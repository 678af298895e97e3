"""Refuse, before any worker starts, a local study run from a script's top level without a main guard.

The local engine's workers are spawned processes (``multiprocessing``'s ``spawn``), and a spawned process
imports the parent's main script again (as ``__mp_main__``) before it runs anything.  A script that calls
``swarmnav.run_study`` at its top level, outside ``if __name__ == "__main__":``, would start the study again in
every worker: a lock error per worker and rows that are all errors.  :func:`check_main_guard` finds the line of
the main script that led to the call (the call stack's frame of the script's top level), reads the script with
``ast`` and raises :class:`MainGuardMissing` unless that line sits under such a guard.  A main module that
``spawn`` does not import again (an interactive session, ``python -c``, ``python -m package``) passes.
"""

from __future__ import annotations

import ast
import sys
from types import FrameType


class MainGuardMissing(SystemExit):
    """The script calls a local study at its top level: a ``SystemExit`` with exit code 2 (no traceback),
    raised after its one line (``message``) went to stderr."""

    def __init__(self, script: str, line: int):
        self.script, self.line = script, line
        self.message = (f"swarmnav: error: {script}:{line} runs a study at the script's top level; its worker "
                        "processes import the script again and would run it too: put the call under "
                        "`if __name__ == \"__main__\":`")
        super().__init__(2)


def _rerun_script() -> tuple[str, dict] | None:
    """The file and globals of the main module if a spawned worker would import it again (the rules of
    ``multiprocessing.spawn.get_preparation_data``), else ``None``."""
    main = sys.modules.get("__main__")
    if main is None:
        return None
    name = getattr(getattr(main, "__spec__", None), "name", None)
    if name is not None and (name == "__main__" or name.endswith(".__main__")):
        return None
    path = getattr(main, "__file__", None)
    if not isinstance(path, str) or not path.endswith(".py"):
        return None
    return path, main.__dict__


def _top_level_frame(main_globals: dict) -> FrameType | None:
    frame = sys._getframe(1)
    while frame is not None:
        if frame.f_globals is main_globals and frame.f_code.co_name == "<module>":
            return frame
        frame = frame.f_back
    return None


def _guarded_lines(source: str) -> list[tuple[int, int]]:
    """Line ranges of the bodies of ``if __name__ == "__main__":`` at a module's top level."""
    ranges = []
    for node in ast.parse(source).body:
        if isinstance(node, ast.If) and _is_main_test(node.test):
            ranges.append((node.body[0].lineno, max(n.end_lineno or n.lineno for n in node.body)))
    return ranges


def _is_main_test(test: ast.expr) -> bool:
    if not (isinstance(test, ast.Compare) and len(test.ops) == 1 and isinstance(test.ops[0], ast.Eq)):
        return False
    sides = [test.left, test.comparators[0]]
    return (any(isinstance(s, ast.Name) and s.id == "__name__" for s in sides)
            and any(isinstance(s, ast.Constant) and s.value == "__main__" for s in sides))


def check_main_guard() -> None:
    """Raise :class:`MainGuardMissing` if the main script reached this call from its unguarded top level."""
    script = _rerun_script()
    if script is None:
        return
    path, main_globals = script
    frame = _top_level_frame(main_globals)
    if frame is None:  # called from a thread or a callback, not from the script's top level
        return
    line = frame.f_lineno
    try:
        with open(path, encoding="utf-8") as handle:
            ranges = _guarded_lines(handle.read())
    except (OSError, SyntaxError, UnicodeDecodeError, ValueError):
        return  # the script cannot be read back: nothing to say about it
    if not any(first <= line <= last for first, last in ranges):
        refusal = MainGuardMissing(path, line)
        print(refusal.message, file=sys.stderr)
        raise refusal
