"""The hostile-input sweep (issue 36): every CLI option and every declared field, tried with the worst values.

Nothing here lists an option or a parameter by name: the CLI's options are found by walking the argparse
tree :func:`swarmnav.cli.main.build_parser` returns, the components' parameters from
:func:`swarmnav.models.parameters.parameter_table` over the registries, and the scenario, study and suite
fields by walking small valid documents.  An option or field added later is swept with no new case.

Every invocation runs in this process (``main(argv)``, stderr captured) under a small wall budget: an
invocation still working when its budget ends has passed validation and is stopped (:class:`Stopped`, a
``BaseException`` no handler of swarmnav catches), and so is one that starts a process or a Ray cluster
(that is work, not validation).  An outcome passes when the exit code is 0, 2, 3 or 5, stderr is at most
one line and not ``bug:``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import os
import signal
import sys
import sysconfig
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator

DEEP = "[" * 5000 + "]" * 5000
LONG = "x" * 200_000
NUMBERS = ["nan", "inf", "-inf", "0", "-1", "1e-300", "1e300", str(2**63), str(10**20), "9" * 5000, "1.5"]
WRONG = ["", "x", "true", DEEP, LONG, "[1, 2]", "{a = 1}"]
# Special files are made by the sweep in its own folder (SPECIAL_PATHS): never a real device as an output.
SPECIAL_PATHS: list[str] = []
PATHISH = ["", "../../escaped", "nonexistent/file.toml", LONG, DEEP]
OK_EXITS = {0, 2, 3, 5}
STDLIB = sysconfig.get_paths()["stdlib"]  # the standard library's own files, where a budget stop waits (Sweep.guarded)


class Stopped(BaseException):
    """The invocation's budget ended, or it started a process: it was past validation (a pass)."""


@dataclass
class Outcome:
    label: str
    argv: list[str]
    code: int | str
    err: str
    wall_s: float

    @property
    def failed(self) -> str | None:
        lines = self.err.strip().splitlines()
        if self.code == "stopped":
            return None
        if self.code not in OK_EXITS:
            return f"exit {self.code}"
        if len(lines) > 1:
            return f"{len(lines)} stderr lines"
        if "bug:" in self.err or "Traceback" in self.err:
            return "bug"
        return None

    def describe(self) -> str:
        shown = [a if len(a) <= 80 else f"{a[:30]}...<{len(a):,} chars>" for a in self.argv]
        return f"{self.label}: {self.failed} after {self.wall_s:.2f} s: swarmnav {' '.join(shown)}\n    " \
               f"{self.err.strip()[:300]}"


@dataclass
class Sweep:
    """Runs invocations with a budget each and keeps their outcomes."""

    budget_s: float = 0.5
    outcomes: list[Outcome] = field(default_factory=list)

    @contextlib.contextmanager
    def guarded(self, budget_s: float | None = None) -> Iterator[io.StringIO]:
        """stderr captured; after the budget a watchdog thread signals this one (SIGUSR1: swarmnav's own
        wall limits use SIGALRM, so the sweep keeps out of its way), whose handler raises :class:`Stopped`."""
        import threading
        err = io.StringIO()
        timers: list[threading.Timer] = []
        pid = os.getpid()

        def arm(seconds: float) -> None:
            timer = threading.Timer(seconds, lambda: os.kill(pid, signal.SIGUSR1))
            timer.daemon = True
            timers.append(timer)
            timer.start()

        deferred = [0]
        over = [False]  # the body has returned: a timer firing now has nothing left to stop

        def stop(_signal, frame):
            if over[0]:
                return
            # Never inside an import (a half-imported module would stay broken), and, for up to 2 s, never inside a
            # library's own Python code: an exception raised mid-draw left matplotlib's state broken for the next
            # invocation in this process ("Invalid affine transformation matrix" on a report that runs fine alone).
            # The standard library likewise: raised inside a weakref callback run by the garbage collector, the
            # exception is swallowed ("Exception ignored in WeakKeyDictionary...remove") and the stop is lost.
            inner = frame.f_code.co_filename if frame is not None else ""
            library = "site-packages" in inner or inner.startswith(STDLIB)
            if library and deferred[0] < 40:
                deferred[0] += 1
                arm(0.05)
                return
            while frame is not None:
                if "importlib" in frame.f_code.co_filename:
                    arm(0.05)
                    return
                frame = frame.f_back
            raise Stopped("budget")
        previous = signal.signal(signal.SIGUSR1, stop)
        arm(budget_s or self.budget_s)
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                try:
                    yield err
                except Stopped:  # landed as the body returned, before the flag below (a late timer): nothing to stop
                    pass
                over[0] = True
        finally:
            over[0] = True
            for timer in timers:
                timer.cancel()
            signal.signal(signal.SIGUSR1, previous)

    def cli(self, main: Callable[[list[str]], int], label: str, argv: list[str], budget_s: float | None = None
            ) -> Outcome:
        t0 = time.perf_counter()
        code: int | str
        with self.guarded(budget_s) as err:
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse: a bad value of an option's own type
                code = exc.code if isinstance(exc.code, int) else 2
            except Stopped:
                code = "stopped"
            except Exception as exc:  # noqa: BLE001 - nothing may escape main: record it as a failure
                code, _ = "escaped", err.write(f"escaped main: {type(exc).__name__}: {exc}")
        outcome = Outcome(label, argv, code, err.getvalue(), time.perf_counter() - t0)
        self.outcomes.append(outcome)
        return outcome

    def call(self, label: str, argv: list[str], work: Callable[[], Any], budget_s: float | None = None) -> Outcome:
        """A library call: ConfigError is exit 2, PlanningError exit 3, anything else a bug."""
        from swarmnav.models.errors import ConfigError
        from swarmnav.planners.errors import PlanningError
        t0 = time.perf_counter()
        with self.guarded(budget_s) as err:
            try:
                work()
                code: int | str = 0
            except ConfigError as exc:
                code = 2
                err.write(f"swarmnav: error: {exc}".replace("\n", " ") + "\n")
            except PlanningError:
                code = 3
            except Stopped:
                code = "stopped"
            except Exception as exc:  # noqa: BLE001
                code = 1
                err.write(f"swarmnav: bug: {type(exc).__name__}: {exc}"[:500] + "\n")
        outcome = Outcome(label, argv, code, err.getvalue(), time.perf_counter() - t0)
        self.outcomes.append(outcome)
        return outcome

    def slowest(self, count: int = 8) -> str:
        """The labels that took the most time in total (to keep the sweep fast)."""
        total: dict[str, float] = {}
        for o in self.outcomes:
            total[o.label] = total.get(o.label, 0.0) + o.wall_s
        return ", ".join(f"{k} {v:.1f} s" for k, v in sorted(total.items(), key=lambda kv: -kv[1])[:count])

    def failures(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.failed]


@contextlib.contextmanager
def no_new_processes():
    """Starting a process, a pool or a Ray cluster is work: the invocation is stopped there."""
    import multiprocessing.context
    import subprocess

    def refuse(*_, **__):
        raise Stopped("process")
    saved = [(subprocess.Popen, "__init__", subprocess.Popen.__init__),
             (multiprocessing.context.BaseContext, "Pool", multiprocessing.context.BaseContext.Pool),
             (multiprocessing.process.BaseProcess, "start", multiprocessing.process.BaseProcess.start)]
    try:
        import ray
        saved.append((ray, "init", ray.init))
    except ImportError:
        pass
    for owner, name, _ in saved:
        setattr(owner, name, refuse)
    try:
        yield
    finally:
        for owner, name, original in saved:
            setattr(owner, name, original)


# --- the CLI -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CliOption:
    words: tuple[str, ...]  # the subcommand path, e.g. ("bench", "sim")
    flag: str | None  # None: a positional
    dest: str
    kind: str  # "number", "choice", "text"
    choices: tuple[str, ...] = ()


def walk_parser(parser: argparse.ArgumentParser, words: tuple[str, ...] = ()
                ) -> Iterator[tuple[tuple[str, ...], argparse.ArgumentParser]]:
    yield words, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from walk_parser(sub, (*words, name))


def _kind(action: argparse.Action) -> str:
    if action.choices:
        return "choice"
    kind = action.type
    name = getattr(kind, "__name__", "") if kind is not None else ""
    if kind in (int, float) or name in ("integer", "number", "seed", "positive_int", "non_negative_int",
                                         "positive_float", "non_negative_float", "_rate"):
        return "number"
    if kind is not None:  # another checked type: its values are numbers or text; both are tried
        return "typed"
    return "text"


def cli_options(parser: argparse.ArgumentParser) -> list[CliOption]:
    """Every option that takes a value and every positional, of every subcommand (the leaves of the tree)."""
    out = []
    for words, sub in walk_parser(parser):
        if any(isinstance(a, argparse._SubParsersAction) for a in sub._actions):
            continue  # a group (bench, log): its leaves are swept
        for action in sub._actions:
            if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)) or action.nargs == 0:
                continue
            flag = max(action.option_strings, key=len) if action.option_strings else None
            out.append(CliOption(words, flag, action.dest, _kind(action), tuple(map(str, action.choices or ()))))
    return out


def values_for(option: CliOption) -> list[str]:
    if option.kind == "choice":
        return ["nosuch", "", LONG, *option.choices[:1]]
    if option.kind == "number":
        return NUMBERS + WRONG
    if option.flag is None or "out" in option.dest or option.dest in ("video", "waypoints", "junit", "readme"):
        return PATHISH + SPECIAL_PATHS + ["nan", "-1", "k=" + DEEP]
    return ["", "nan", "-1", DEEP, LONG, "k=" + DEEP, "k=nan", "a:b:c=" + DEEP, "../../x"]


def base_argv(words: tuple[str, ...], parser: argparse.ArgumentParser, files: dict[str, str],
              cheap: dict[tuple[str, ...], list[str]]) -> list[str]:
    """The subcommand with its required positionals and options filled from ``files`` by name (the cheapest
    inputs), plus the cheap settings known for it (smallest durations); an unknown one gets its required
    positionals only."""
    argv = list(words)
    for action in parser._actions:
        if not action.option_strings and not isinstance(action, argparse._SubParsersAction):
            argv.append(files.get(action.dest, files["default"]))
    for action in parser._actions:
        if action.option_strings and action.required:
            argv += [action.option_strings[-1], files.get(action.dest, "1")]
    return argv + cheap.get(words, [])


def without(argv: list[str], flag: str | None, parser: argparse.ArgumentParser) -> list[str]:
    """``argv`` without ``flag`` and its value (the option under test replaces it)."""
    if flag is None:
        return argv
    flags = next((a.option_strings for a in parser._actions if flag in a.option_strings), [flag])
    out, skip = [], False
    for arg in argv:
        if skip:
            skip = False
            continue
        if arg in flags:
            skip = True
            continue
        out.append(arg)
    return out


def cli_cases(parser: argparse.ArgumentParser, files: dict[str, str], cheap: dict[tuple[str, ...], list[str]]
              ) -> Iterator[tuple[str, list[str]]]:
    subparsers = dict(walk_parser(parser))
    for option in cli_options(parser):
        sub = subparsers[option.words]
        base = base_argv(option.words, sub, files, cheap)
        for value in values_for(option):
            label = f"{' '.join(option.words)} {option.flag or option.dest}"
            if option.flag is None:
                argv = list(base)
                index = list(option.words).__len__() + [a.dest for a in sub._actions if not a.option_strings
                                                       and not isinstance(a, argparse._SubParsersAction)
                                                       ].index(option.dest)
                argv[index] = value
            else:
                argv = without(base, option.flag, sub) + [f"{option.flag}={value}" if value.startswith("-")
                                                          else option.flag, *([] if value.startswith("-")
                                                                              else [value])]
            yield label, argv


# --- component parameters -------------------------------------------------------------------------------


DEEP_LIST = json.loads("[" * 900 + "]" * 900)  # deeper than MAX_NESTING_DEPTH, within Python's recursion
PARAMETER_VALUES: list[Any] = [math.nan, math.inf, -math.inf, 0, -1, 1e-300, 1e300, 2**63, 10**20, 0.0, 1.5,
                               "x", LONG, True, None, [1, 2], {"a": 1}, DEEP_LIST]


def component_parameters() -> Iterator[tuple[str, str, dict[str, Any]]]:
    """(kind, name, one row of its parameter table) of every registered planner and navigator."""
    from swarmnav.controllers.navigators import NAVIGATORS
    from swarmnav.models.parameters import parameter_table
    from swarmnav.planners.registry import PLANNERS
    for kind, registry in (("planner", PLANNERS), ("navigator", NAVIGATORS)):
        for name, cls in sorted(registry.items()):
            for row in parameter_table(cls):
                yield kind, name, row


# --- documents (scenario, study, suite) --------------------------------------------------------------------


def leaves(data: Any, path: tuple = ()) -> Iterator[tuple]:
    """The key path of every leaf of a document (a list of tables counts as tables; other lists as leaves)."""
    if isinstance(data, dict):
        if not data and path:
            yield path
        for key, value in data.items():
            yield from leaves(value, (*path, key))
    elif isinstance(data, list) and data and all(isinstance(v, dict) for v in data):
        for i, value in enumerate(data):
            yield from leaves(value, (*path, i))
    else:
        yield path


def replaced(data: Any, path: tuple, value: Any) -> Any:
    if not path:
        return value
    head, rest = path[0], path[1:]
    if isinstance(data, dict):
        return {**data, head: replaced(data[head], rest, value)}
    copy = list(data)
    copy[head] = replaced(copy[head], rest, value)
    return copy


def toml_text(data: dict[str, Any]) -> str:
    """A document as TOML (inline tables; every value TOML can hold, NaN and infinities included)."""
    def value(v: Any) -> str:
        if v is DEEP_LIST:
            return "[" * 900 + "]" * 900
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, int):
            return str(v)
        if isinstance(v, float):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{json.dumps(k)} = {value(x)}" for k, x in v.items()) + " }"
        raise TypeError(type(v))
    lines = []
    for key, v in data.items():
        if isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            continue
        if v is not None:
            lines.append(f"{json.dumps(key)} = {value(v)}")
    for key, v in data.items():
        if isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for table in v:
                lines.append(f"[[{json.dumps(key)}]]")
                lines += [f"{json.dumps(k)} = {value(x)}" for k, x in table.items() if x is not None]
    return "\n".join(lines) + "\n"


def document_values(current: Any) -> list[Any]:
    """The worst values for a leaf whose valid value is ``current`` (every type is tried on every leaf)."""
    values = list(PARAMETER_VALUES)
    if isinstance(current, str):
        values += ["", "../../x", "nosuch", *SPECIAL_PATHS]
    return [v for v in values if v is not None]


def current_rss_mb() -> float:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return 0.0


def peak_rss_mb() -> float:
    import resource
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


__all__ = ["Sweep", "Outcome", "Stopped", "cli_options", "cli_cases", "component_parameters", "leaves",
           "replaced", "toml_text", "document_values", "no_new_processes", "PARAMETER_VALUES", "DEEP", "LONG",
           "os", "sys", "Path", "peak_rss_mb", "current_rss_mb"]
