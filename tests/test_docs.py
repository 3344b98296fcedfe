"""Every file the code, the README and the docs cite exists in the repository.

Cited paths: anything starting with ``docs/``, ``fmu_src/``, ``harness/``, ``examples/``,
``build/`` or ``tests/`` (a file or a folder), and bare Markdown names (``claims.md``).
Paths the code writes (``build/fmus/``, ``out/``), templates (``model_<name>.py``) and
patterns (``*.fmu``) are not files to look for.
"""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PREFIXES = ("docs", "fmu_src", "harness", "examples", "build", "tests")
CITED = re.compile(r"(?<![\w./-])(?:" + "|".join(PREFIXES) + r")/[\w./-]*[\w/]")
BARE_MD = re.compile(r"(?<![\w./<-])[\w-]+\.md\b")
# Folders the build and the runs write into: cited as places, not as files of the repository.
WRITTEN = ("build/fmus", "build/work")
# Markdown files the code writes (name -> the module that writes it), cited by bare name.
GENERATED_MD = {"report.md": "harness/paper/report.py", "work_precision.md": "harness/benchmarks/work_precision.py",
                "communication_step.md": "examples/excitation_composition.py", "triggering.md": "examples/triggering.py"}
TEXT_SUFFIXES = {".py", ".md", ".c", ".h", ".toml", ".txt"}


def tracked_files() -> list[Path]:
    try:
        out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
        names = out.split()
    except (OSError, subprocess.CalledProcessError):
        names = [p.relative_to(ROOT).as_posix() for p in ROOT.rglob("*") if p.is_file() and ".venv" not in p.parts]
    return [ROOT / name for name in names if (ROOT / name).exists()]


def citing_files() -> list[Path]:
    return [p for p in tracked_files() if p.suffix in TEXT_SUFFIXES or p.name == "Makefile"]


def cited_paths(text: str) -> set[str]:
    found = set()
    for match in CITED.finditer(text):
        path, after = match.group().rstrip("."), text[match.end():match.end() + 1]
        if after in ("<", "*", "{") or path.startswith(WRITTEN):
            continue
        found.add(path)
    return found


def exists(path: str, source: Path) -> bool:
    """In the repository, or (a test helper citing its own tree) beside the citing file."""
    return (ROOT / path).exists() or (source.parent / path).exists()


def test_every_cited_path_exists():
    missing = []
    for source in citing_files():
        text = source.read_text(errors="replace")
        for path in sorted(cited_paths(text)):
            if not exists(path, source):
                missing.append(f"{source.relative_to(ROOT)}: {path}")
    assert not missing, "cited but not in the repository:\n" + "\n".join(missing)


def test_every_bare_markdown_name_is_in_the_repository():
    names = {p.name for p in tracked_files() if p.suffix == ".md"}
    missing = []
    for source in citing_files():
        for name in sorted(set(BARE_MD.findall(source.read_text(errors="replace")))):
            if name not in names and name not in GENERATED_MD:
                missing.append(f"{source.relative_to(ROOT)}: {name}")
    assert not missing, "Markdown files cited but not in the repository:\n" + "\n".join(missing)


@pytest.mark.parametrize("name, writer", sorted(GENERATED_MD.items()))
def test_the_generated_markdown_names_are_written_by_the_code(name, writer):
    assert f'"{name}"' in (ROOT / writer).read_text()


def test_the_scan_sees_citations():
    assert cited_paths("see docs/physics.md, Sec. 8 and `fmu_src/vibroblock/README.md`.") == {
        "docs/physics.md", "fmu_src/vibroblock/README.md"}
    assert cited_paths("the FMUs in build/fmus/BlockA.fmu and fmu_src/models/model_<name>.py") == set()
    assert BARE_MD.findall("see claims.md and docs/physics.md") == ["claims.md"]


def test_benchmarks_publish_one_section_with_date_commit_and_machine(tmp_path):
    from harness.benchmarks import publish

    path = tmp_path / "benchmarks.md"
    publish("first", "figures 1", path=path)
    publish("second", "figures 2", path=path)
    publish("first", "figures 3", "python -m harness.benchmarks.first", path=path)
    text = path.read_text()
    assert "figures 1" not in text and "figures 2" in text and "figures 3" in text
    assert text.index("figures 3") < text.index("figures 2")  # rewritten in place
    assert re.search(r"Measured \d{4}-\d\d-\d\d at commit `[^`]+` on \d+ CPUs, ", text)
    assert "Command: `python -m harness.benchmarks.first`" in text
