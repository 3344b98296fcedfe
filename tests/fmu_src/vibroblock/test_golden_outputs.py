"""Outputs stay bit-identical to the stored set (``golden_outputs.py`` says why and how)."""
import json

import pytest

from golden_outputs import DATA, cases, run_case

STORED = json.loads(DATA.read_text())


@pytest.mark.parametrize("key, model, settings", list(cases()), ids=[key for key, _, _ in cases()])
def test_outputs_are_bit_identical_to_the_stored_set(key, model, settings):
    assert run_case(model, settings) == STORED[key]
