"""Build the vibroblock FMUs: ``python build/build_fmus.py [--dest build/fmus] [NAME ...]``.

Each ``fmu_src/<Name>.py`` facade script becomes ``<dest>/<Name>.fmu`` (FMI 2.0
co-simulation) with the physics core ``fmu_src/vibroblock`` bundled as pythonfmu
project files.  After pythonfmu has written the archive, two finishing steps make it
a complete FMI 2.0 FMU:

* the model description gets the ``InitialUnknowns`` section that FMI 2.0 requires
  for outputs with ``initial="calculated"`` (pythonfmu does not write it);
* the native status shim is installed in front of pythonfmu's library, so that a
  call the model rejects returns fmi2Error instead of fmi2OK (see build/status_shim.py).
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree

ROOT = Path(__file__).resolve().parent.parent
SOURCES = ROOT / "fmu_src"
CORE = SOURCES / "vibroblock"
DEFAULT_DEST = ROOT / "build" / "fmus"
FMU_NAMES = ("BlockA", "BlockB", "BlockC", "Excitation")

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(SOURCES))


def complete_model_description(xml_text: bytes) -> bytes:
    """Add ModelStructure/InitialUnknowns listing every calculated output."""
    root = ElementTree.fromstring(xml_text)
    variables = root.find("ModelVariables")
    structure = root.find("ModelStructure")
    calculated = [str(index) for index, var in enumerate(variables, start=1)
                  if var.get("causality") == "output" and var.get("initial", "calculated") == "calculated"]
    for old in structure.findall("InitialUnknowns"):
        structure.remove(old)
    if calculated:
        unknowns = ElementTree.SubElement(structure, "InitialUnknowns")
        for index in calculated:
            ElementTree.SubElement(unknowns, "Unknown", {"index": index})
    ElementTree.indent(root)
    return ElementTree.tostring(root, encoding="UTF-8", xml_declaration=True)


def rewrite_member(fmu: Path, member: str, transform) -> None:
    """Replace one member of a zip archive (zipfile cannot update in place)."""
    with tempfile.NamedTemporaryFile(dir=fmu.parent, suffix=".fmu", delete=False) as tmp:
        tmp_path = Path(tmp.name)
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(tmp_path, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            data = src.read(item)
            dst.writestr(item, transform(data) if item.filename == member else data)
    tmp_path.chmod(0o644)
    tmp_path.replace(fmu)


def build(name: str, dest: Path) -> Path:
    from pythonfmu.builder import FmuBuilder

    script = SOURCES / f"{name}.py"
    fmu = FmuBuilder.build_FMU(script, dest=dest, project_files=[CORE],
                               canGetAndSetFMUstate=True, canSerializeFMUstate=True)
    fmu = Path(fmu)
    rewrite_member(fmu, "modelDescription.xml", complete_model_description)
    from status_shim import wrap_fmu
    wrap_fmu(fmu)
    return fmu


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", default=list(FMU_NAMES), help="FMUs to build (default: all)")
    parser.add_argument("--dest", type=Path, default=DEFAULT_DEST, help="output folder")
    args = parser.parse_args(argv)
    args.dest.mkdir(parents=True, exist_ok=True)
    for name in args.names:
        print(f"built {build(name, args.dest)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
