"""The benchmarks: scripts that print figures measured side by side in one run.

Each benchmark's command-line run also writes what it printed into its own section of
``docs/benchmarks.md`` (:func:`publish`, through :func:`recorded`), under a header giving
the date, the commit (``git describe --always --dirty``), the machine (CPU count and
model) and the command line, so that every figure in the docs says when and where it was
measured.  Smoke runs (``--quick``) and redraws (``--replot``) measure nothing new and
publish nothing; ``VIBROBLOCK_PUBLISH=0`` turns publishing off, and
``VIBROBLOCK_BENCHMARKS_MD`` writes to another file.
"""
from __future__ import annotations

import contextlib
import datetime
import io
import os
import platform
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCUMENT = ROOT / "docs" / "benchmarks.md"
NOT_PUBLISHED = ("--quick", "--replot")
TITLE = "# Benchmarks: measured figures"
PREAMBLE = """\
Every section below is written by the benchmark it is named after (`python -m
harness.benchmarks.<name>`), with the date, the commit and the machine of its latest run.
A section whose header says "as last stated in the README" holds figures measured before
the benchmarks wrote this file, labelled with the commit that last changed them there.
"""


def _start(section: str) -> str:
    return f"<!-- section {section} -->"


def _end(section: str) -> str:
    return f"<!-- end {section} -->"


def commit() -> str:
    """``git describe --always --dirty`` of the repository, or "unknown" outside a checkout."""
    try:
        out = subprocess.run(["git", "describe", "--always", "--dirty"], cwd=ROOT, capture_output=True,
                             text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() if out.returncode == 0 and out.stdout.strip() else "unknown"


def machine() -> str:
    """CPU count and model name, e.g. ``2 CPUs, Intel(R) Xeon(R) ...``."""
    model = cpu_info("model name") or platform.processor() or platform.machine()
    return f"{os.cpu_count() or '?'} CPUs, {model}"


def cpu_info(field: str) -> str | None:
    """The first core's ``field`` in /proc/cpuinfo (e.g. "model name", "cpu MHz"), or None."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith(field):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def header(command: str | None = None, when: datetime.date | None = None) -> str:
    when = when or datetime.date.today()
    text = f"Measured {when.isoformat()} at commit `{commit()}` on {machine()}."
    return text + (f" Command: `{command}`." if command else "")


def document_path() -> Path:
    return Path(os.environ.get("VIBROBLOCK_BENCHMARKS_MD", DOCUMENT))


def publish(section: str, text: str, command: str | None = None, path: Path | None = None) -> Path:
    """Rewrite the section ``section`` of docs/benchmarks.md with ``text`` under a header
    of date, commit and machine (appended if the section is new); the other sections stay
    as they are.  Returns the file written."""
    path = Path(path) if path is not None else document_path()
    body = f"{_start(section)}\n## {section}\n\n{header(command)}\n\n{text.strip()}\n{_end(section)}"
    old = path.read_text() if path.exists() else f"{TITLE}\n\n{PREAMBLE}"
    pattern = re.compile(re.escape(_start(section)) + r".*?" + re.escape(_end(section)), re.S)
    new = pattern.sub(lambda _: body, old, count=1) if pattern.search(old) else old.rstrip("\n") + f"\n\n{body}"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(new.rstrip("\n") + "\n")
    return path


class _Tee(io.TextIOBase):
    def __init__(self, stream):
        self.stream, self.buffer_ = stream, io.StringIO()

    def write(self, text):
        self.buffer_.write(text)
        return self.stream.write(text)

    def flush(self):
        self.stream.flush()


@contextlib.contextmanager
def recorded(section: str, argv: list[str] | None = None):
    """Run a benchmark's main path, printing as usual; if it finishes, publish what it
    printed as the section ``section`` (a code block, with the command line)."""
    argv = sys.argv[1:] if argv is None else argv
    skip = os.environ.get("VIBROBLOCK_PUBLISH", "1") == "0" or any(
        arg.split("=")[0] in NOT_PUBLISHED for arg in argv)
    tee = _Tee(sys.stdout)
    with contextlib.redirect_stdout(tee):
        yield
    if skip:
        return
    command = " ".join(["python -m", f"harness.benchmarks.{section}", *argv])
    path = publish(section, "```\n" + tee.buffer_.getvalue().rstrip() + "\n```", command)
    print(f"published to {path} (section {section})")
