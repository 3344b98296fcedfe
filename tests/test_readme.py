"""The README's interface table is the one the code generates."""
from pathlib import Path

from vibroblock.interface import markdown_table

README = Path(__file__).resolve().parent.parent / "README.md"


def test_readme_interface_table_matches_the_fmus():
    assert markdown_table() in README.read_text()


def test_readme_gives_the_two_commands():
    text = README.read_text()
    assert "make run" in text and "make test" in text
