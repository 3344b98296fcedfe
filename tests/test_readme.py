"""The README's interface table is the one the code generates."""
from pathlib import Path

from vibroblock.interface import markdown_table

README = Path(__file__).resolve().parent.parent / "README.md"


def test_readme_interface_table_matches_the_fmus():
    assert markdown_table() in README.read_text()


def test_readme_gives_the_two_commands():
    text = README.read_text()
    assert "make run" in text and "make test" in text


def test_core_readme_integrator_table_matches_the_registry():
    from vibroblock.interface import integrator_table

    core_readme = README.parent / "fmu_src" / "vibroblock" / "README.md"
    assert integrator_table() in core_readme.read_text()


def test_core_readme_lists_every_module_of_the_core():
    core = README.parent / "fmu_src" / "vibroblock"
    text = (core / "README.md").read_text()
    for path in sorted(core.rglob("*.py")):
        relative = path.relative_to(core).as_posix()
        assert f"`{relative}`" in text, relative
