"""The core reads like the physics: short functions with short argument lists, a thin runner."""
import ast
from pathlib import Path

import pytest

CORE = Path(__file__).resolve().parents[2] / "fmu_src" / "vibroblock"
MAX_LINES, MAX_ARGUMENTS, MAX_BLOCK_LINES = 100, 12, 250


def functions():
    for path in sorted(CORE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield f"{path.relative_to(CORE)}:{node.name}", node


@pytest.mark.parametrize("limit", ["lines", "arguments"])
def test_no_function_is_long_or_takes_many_arguments(limit):
    too_big = []
    for name, node in functions():
        lines = node.end_lineno - node.lineno + 1
        arguments = len(node.args.posonlyargs) + len(node.args.args) + len(node.args.kwonlyargs)
        if (limit == "lines" and lines > MAX_LINES) or (limit == "arguments" and arguments > MAX_ARGUMENTS):
            too_big.append(f"{name} ({lines} lines, {arguments} arguments)")
    assert not too_big, too_big


def test_the_runner_stays_thin():
    assert len((CORE / "block.py").read_text().splitlines()) <= MAX_BLOCK_LINES
