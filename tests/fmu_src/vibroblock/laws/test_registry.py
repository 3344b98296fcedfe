"""The law registry: every law is one module, chosen by an Integer parameter by value or
name, and no integrator writes a law's formula itself."""
import re
from pathlib import Path

import numpy as np
import pytest

from vibroblock import Block, ModelError
from vibroblock.laws import AXES, LAWS, choices, encode
from vibroblock.readings import VARIANT_MASK, choices as all_choices

CORE = Path(__file__).resolve().parents[4] / "fmu_src" / "vibroblock"


def test_every_axis_has_its_default_and_distinct_bits():
    used = VARIANT_MASK | (1 << 3) | (1 << 5)  # the variant and the readings formulation, flight
    for name, axis in AXES.items():
        assert 0 in LAWS[name], name
        bits = ((1 << axis.width) - 1) << axis.shift
        assert not used & bits, f"{name} overlaps other bits of kind"
        used |= bits
        assert max(LAWS[name]) < max(1, 1 << axis.width)


def test_choices_follow_the_registry_and_encode_into_kind():
    table = choices()
    assert set(table) == {AXES[a].parameter for a in AXES if len(LAWS[a]) > 1}
    for name, axis in AXES.items():
        if axis.parameter not in table:
            continue
        _, values = table[axis.parameter]
        assert {value: text.split(":")[0] for value, text in values.items()} == \
            {law.id: law.name for law in LAWS[name].values()}
        for law in LAWS[name].values():
            assert (encode({axis.parameter: law.id}) >> axis.shift) & ((1 << axis.width) - 1) == law.id


@pytest.mark.parametrize("name", sorted(all_choices()))
def test_a_choice_is_taken_by_value_or_by_name_and_refused_otherwise(name):
    models, values = all_choices()[name]
    model = "B" if models in ("*", "BC") else models[0]
    for value, text in values.items():
        by_value = Block(model, "rk4", **{name: value})
        by_name = Block(model, "rk4", **{name: text.split(":")[0]})
        assert by_value.settings.kind == by_name.settings.kind
        assert by_value.readings[name] == value
    with pytest.raises(ModelError, match=f"{name} = 99 is not admissible"):
        Block(model, "rk4", **{name: 99})


# The linear contact law's formula, k_n delta - gamma_n u_n, however it is spelt.
CONTACT_FORMULA = re.compile(r"(P_KN\]|\bk_n\b)\s*\*[^\n]*[-+]\s*(prm\[P_GN\]|\bg(am)?_n\b)\s*\*")
RESET_RULE = re.compile(r">=\s*(prm\[P_MUS\]|\bmu_s\b)\s*\*")


@pytest.mark.parametrize("pattern, owner", [(CONTACT_FORMULA, "contact_linear.py"),
                                            (RESET_RULE, "friction_cundall_strack.py")])
def test_a_law_formula_is_written_once_in_its_module(pattern, owner):
    found = []
    for path in sorted(CORE.rglob("*.py")):
        for number, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split("#")[0]
            if pattern.search(code) and not code.strip().startswith(('"', "'")):
                found.append(f"{path.relative_to(CORE)}:{number}")
    assert [f.split(":")[0] for f in found] == [f"laws/{owner}"], found


def test_the_linear_laws_agree_off_a_curved_plate():
    """On a flat plate the conservative contact and the force along the normal are one law:
    the same bits (model A)."""
    outputs = []
    for contact in ("linear", "linear_along_normal"):
        block = Block("A", "rk4", 0, True, A=2.5, omega=0.9, dt=4e-3, contact_law=contact)
        block.start()
        block.advance_to(40.0)
        outputs.append(block.outputs())
    assert outputs[0] == outputs[1]
    assert np.isfinite(outputs[0]["energy_residual"])


def test_an_integrator_a_law_refuses_is_refused_with_the_law_s_reason(monkeypatch):
    """A law module's REFUSED_BY names the integrators whose closed forms assume another law."""
    from vibroblock.laws import LAWS
    law = LAWS["contact"][1]
    monkeypatch.setitem(law.refused_by, "implicit_contact", "its closed forms assume the conservative law")
    with pytest.raises(ModelError, match="implicit_contact integrator cannot run contact_law = 1 "
                                         r"\(linear_along_normal\): its closed forms assume"):
        Block("B", "implicit_contact", dt=1e-2, contact_law=1).start()
    Block("B", "rk4", contact_law=1).start()  # the others run it
