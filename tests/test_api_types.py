"""The API is typed for a user's ``mypy --strict`` on this editable install: ``swarmnav`` is found (the static
path of the Makefile's ``typing-path``, py.typed included), its names are explicit re-exports, and its
parameters are precise enough that a wrong argument is flagged."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "api" / "plan_and_run.py"

pytest.importorskip("mypy", reason="mypy is in the test extra (pip install 'swarmnav[test]')")


def test_an_api_script_passes_mypy_strict_and_a_wrong_argument_is_flagged(tmp_path):
    wrong = tmp_path / "wrong.py"
    wrong.write_text("import swarmnav\n\nswarmnav.run(123)\nswarmnav.plan('gwo-scenario-1', seed='0')\n")
    # one mypy process for both scripts (the cache in tmp: a cold run); imported modules are followed silently,
    # so only the scripts' own errors are reported
    done = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--follow-imports=silent", "--cache-dir",
                           str(tmp_path / "cache"), "--no-error-summary", str(EXAMPLE), str(wrong)],
                          capture_output=True, text=True, cwd=tmp_path, timeout=300)
    errors = [line for line in done.stdout.splitlines() if ": error:" in line]
    assert all(line.startswith("wrong.py:") for line in errors), done.stdout  # the example is clean
    assert len(errors) == 2, done.stdout
    assert re.search(r':3: error: Argument 1 to "run" has incompatible type "int"; expected '
                     r'"str \| PathLike\[str\] \| Scenario"', errors[0])
    assert ':4: error: Argument "seed" to "plan" has incompatible type "str"' in errors[1]
