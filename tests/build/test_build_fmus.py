"""build/build_fmus.py: complete, valid and reproducible FMUs."""
import zipfile
from xml.etree import ElementTree

import build_fmus
from fmpy.validation import validate_fmu


def test_the_same_sources_build_the_same_bytes(tmp_path):
    first = build_fmus.build("BlockA", tmp_path / "one").read_bytes()
    second = build_fmus.build("BlockA", tmp_path / "two").read_bytes()
    assert first == second


def test_the_fmi3_chain_builds_the_same_bytes_and_takes_its_default_n_from_chain_blocks(tmp_path):
    first = build_fmus.build("BlockChain3", tmp_path / "one", ship_kernels=False).read_bytes()
    second = build_fmus.build("BlockChain3", tmp_path / "two", ship_kernels=False).read_bytes()
    assert first == second
    other = build_fmus.build("BlockChain3", tmp_path / "three", ship_kernels=False, chain_blocks=5)
    with zipfile.ZipFile(other) as fmu:
        root = ElementTree.fromstring(fmu.read("modelDescription.xml"))
    assert root.get("fmiVersion") == "3.0" and root.get("generationDateAndTime") is None
    size = root.find("ModelVariables/UInt64[@name='N']")
    assert size.get("causality") == "structuralParameter" and size.get("start") == "5"
    assert all(root.find("CoSimulation").get(flag) == "true" for flag in build_fmus.FMI3_OPTIONS)


def test_calculated_outputs_are_listed_as_initial_unknowns(fmu_path):
    with zipfile.ZipFile(fmu_path("A")) as fmu:
        root = ElementTree.fromstring(fmu.read("modelDescription.xml"))
    variables = list(root.find("ModelVariables"))
    outputs = {str(i) for i, v in enumerate(variables, 1) if v.get("causality") == "output"}
    unknowns = {u.get("index") for u in root.find("ModelStructure/InitialUnknowns")}
    assert outputs and unknowns == outputs
    assert validate_fmu(fmu_path("A")) == []


def test_each_fmu_documents_itself(fmu_dir):
    """documentation/index.html (FMI 2.0, 2.3) lists every parameter with unit and default,
    the integrators, and how to point the FMU at a Python environment; model.png is an icon."""
    import sys

    sys.path.insert(0, str(build_fmus.SOURCES))
    from vibroblock.integrators import INTEGRATORS
    from vibroblock.models import defaults, parameters_for

    for name in build_fmus.fmu_names():
        with zipfile.ZipFile(fmu_dir / f"{name}.fmu") as fmu:
            page = fmu.read("documentation/index.html").decode()
            icon = fmu.read("model.png")
        assert icon.startswith(b"\x89PNG") and icon[16:24] == (128).to_bytes(4, "big") * 2
        if name == "BlockChain3":  # FMI 3.0: pythonfmu3's library, not the FMI 2.0 front end
            assert "structural parameter" in page and "fmi3Error" in page and "VIBROBLOCK_PYTHON" not in page
        else:
            assert "VIBROBLOCK_PYTHON" in page and "vibroblock-python.txt" in page
        if name in build_fmus.variant_scripts():
            model = name[-1]
            for spec in parameters_for(model):
                assert f"<td><code>{spec.name}</code></td><td>{spec.unit}</td><td>{defaults(model)[spec.name]:g}</td>" \
                    in page, spec.name
            assert all(f"<code>{integrator}</code>" in page for integrator in INTEGRATORS)
            assert "Equations" in page and "mu_s N" in page
        if name in ("BlockChain", "BlockChain3"):
            assert all(f"<code>{n}</code>" in page for n in ("k_p", "k_c", "v_start", "v_stop", "event_count"))
