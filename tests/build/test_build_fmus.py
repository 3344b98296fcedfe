"""build/build_fmus.py: complete, valid and reproducible FMUs."""
import zipfile
from xml.etree import ElementTree

import build_fmus
from fmpy.validation import validate_fmu


def test_the_same_sources_build_the_same_bytes(tmp_path):
    first = build_fmus.build("BlockA", tmp_path / "one").read_bytes()
    second = build_fmus.build("BlockA", tmp_path / "two").read_bytes()
    assert first == second


def test_calculated_outputs_are_listed_as_initial_unknowns(fmu_path):
    with zipfile.ZipFile(fmu_path("A")) as fmu:
        root = ElementTree.fromstring(fmu.read("modelDescription.xml"))
    variables = list(root.find("ModelVariables"))
    outputs = {str(i) for i, v in enumerate(variables, 1) if v.get("causality") == "output"}
    unknowns = {u.get("index") for u in root.find("ModelStructure/InitialUnknowns")}
    assert outputs and unknowns == outputs
    assert validate_fmu(fmu_path("A")) == []
