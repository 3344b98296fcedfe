"""What a user gets when a command line or an example is given something it cannot use:
one line on standard error, ``<program>: error: <what, the rule, the fix>``, and exit
status 2 -- never a traceback.

The messages themselves come from where the rule lives (the FMU's log for a value it
refuses, ``RecordError`` for a record, the settings' checks); this module only turns
them into that one line.  A programming error (anything else) still shows its traceback.
"""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Callable

EXIT_USER_ERROR = 2


def user_error_types() -> tuple[type, ...]:
    """The exceptions that mean "bad input", not a bug."""
    from harness.cosim.fmu import FmuError
    from harness.ground.records.errors import RecordError

    return (RecordError, FmuError, ValueError, KeyError, TypeError, OSError)


def one_line(exc: BaseException) -> str:
    """The exception's message on one line (a KeyError's without its quotes)."""
    message = str(exc.args[0]) if isinstance(exc, KeyError) and exc.args else str(exc)
    return "; ".join(line.strip() for line in message.splitlines() if line.strip()) or type(exc).__name__


def report(program: str, exc: BaseException) -> int:
    print(f"{program}: error: {one_line(exc)}", file=sys.stderr)
    return EXIT_USER_ERROR


def run_main(program: str, main: Callable[[], int | None]) -> int:
    """Run ``main``; a user error ends it with one line and exit status 2."""
    try:
        return int(main() or 0)
    except user_error_types() as exc:
        return report(program, exc)


def require_fmu(path, option: str = "--fmu") -> Path:
    """The FMU file at ``path``, or why there is none and how to get one."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"FMU {path} does not exist: build the FMUs with 'make fmus' in the vibroblock repository "
            f"(they go to build/fmus/), or give the path of a built FMU with {option} PATH")
    return path
