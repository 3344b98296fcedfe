"""The README and the interface table say what the FMUs are.

The full interface table (docs/interface.md) is the one the code generates, and it lists
exactly the variables of each Block FMU's model description, with the right kind; the
README's short table names every variable once; the README stays a front door.
"""
import re
from pathlib import Path

import pytest

from vibroblock.interface import markdown_table

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
INTERFACE = ROOT / "docs" / "interface.md"
README_MAX_LINES = 250


def interface_rows() -> dict[str, tuple[str, str]]:
    """name -> (kind, models) of every row of the generated table."""
    rows = {}
    for line in markdown_table().splitlines()[2:]:
        cells = [cell.strip() for cell in line.strip("|").split("|")]
        rows[cells[0].strip("`")] = (cells[1], cells[2])
    return rows


def model_description(model: str) -> dict[str, str]:
    """name -> causality of the Block FMU's model description, built from its facade
    (the XML the build writes into the FMU) without building the FMU."""
    from pythonfmu import Fmi2Slave

    from vibroblock.slave import block_fmu

    @block_fmu(model)
    class Block(Fmi2Slave):
        """The FMU script's class."""

    xml = Block(instance_name="readme").to_xml()
    return {v.get("name"): v.get("causality") for v in xml.iter("ScalarVariable")}


def test_interface_table_is_the_generated_one():
    assert markdown_table() in INTERFACE.read_text()


@pytest.mark.parametrize("model", "ABC")
def test_interface_table_lists_the_model_description(model):
    described = model_description(model)
    rows = {name: kind for name, (kind, models) in interface_rows().items() if model in models}
    assert sorted(rows) == sorted(described)
    for name, causality in described.items():
        assert rows[name].split()[0].rstrip(",") == causality, name


def test_readme_names_every_variable_once_in_its_interface_table():
    text = README.read_text()
    section = text[text.index("## Interface"):text.index("\n## ", text.index("## Interface") + 1)]
    table = "\n".join(line for line in section.splitlines() if line.startswith("|"))
    named = re.findall(r"`(\w+)`", table)
    assert sorted(named) == sorted(interface_rows())
    assert "docs/interface.md" in section


def test_readme_gives_the_two_commands():
    text = README.read_text()
    assert "make run" in text and "make test" in text


def test_readme_is_a_front_door():
    assert len(README.read_text().splitlines()) <= README_MAX_LINES


def test_core_readme_integrator_table_matches_the_registry():
    from vibroblock.interface import integrator_table

    core_readme = ROOT / "fmu_src" / "vibroblock" / "README.md"
    assert integrator_table() in core_readme.read_text()


def test_core_readme_lists_every_module_of_the_core():
    core = ROOT / "fmu_src" / "vibroblock"
    text = (core / "README.md").read_text()
    for path in sorted(core.rglob("*.py")):
        relative = path.relative_to(core).as_posix()
        assert f"`{relative}`" in text, relative
