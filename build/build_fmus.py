"""Build the vibroblock FMUs: ``python build/build_fmus.py [--dest build/fmus] [NAME ...]``.

One FMU per registered model variant (``vibroblock.models``: ``Block<Name>.fmu``, its
facade script generated here) and one per FMU script in ``fmu_src`` (``Excitation``,
``BlockChain``: its number of blocks is fixed here, ``--chain-blocks N``; ``BlockChain3``,
the chain as FMI 3.0 co-simulation by pythonfmu3, N a structural parameter defaulting to it),
FMI 2.0 co-simulation, with the physics core ``fmu_src/vibroblock`` bundled as pythonfmu
project files.  ``--list`` prints the names; ``--sources`` builds from another source
tree (e.g. a copy with one more variant).  After pythonfmu has written the archive, finishing steps make it a
complete, reproducible FMI 2.0 FMU:

* the native status shim is installed in front of pythonfmu's library, so that a
  call the model rejects returns fmi2Error instead of fmi2OK (see build/status_shim.py);
* the model description gets the ``InitialUnknowns`` section that FMI 2.0 requires
  for outputs with ``initial="calculated"`` (pythonfmu does not write it);
* ``resources/python-environment.txt`` records the Python environment of the build
  (the interpreter and its shared library), where the native front end looks for a
  Python when the host is not a Python process (see build/python_runtime.c);
* the Block FMUs carry the physics core's kernels compiled at build time
  (``resources/vibroblock_kernels``, see build/kernels.py), so that a first doStep
  does not wait for numba;
* ``documentation/index.html`` and ``model.png`` document the FMU (FMI 2.0, section
  2.3; see build/documentation.py);
* the archive is written deterministically (see ``finish_archive``).
"""
from __future__ import annotations

import argparse
import hashlib
import shutil
import sys
import sysconfig
import tempfile
import uuid
import zipfile
from pathlib import Path
from xml.etree import ElementTree

ROOT = Path(__file__).resolve().parent.parent
SOURCES = ROOT / "fmu_src"
CORE = SOURCES / "vibroblock"
# The ground-motion record package (relative imports only), bundled in the Excitation FMU.
RECORDS = ROOT / "harness" / "ground" / "records"
DEFAULT_DEST = ROOT / "build" / "fmus"
FIXED_TIMESTAMP = (1980, 1, 1, 0, 0, 0)  # the earliest a zip archive can record
BLOCK_SCRIPT = '''"""FMU: {description} (vibroblock, a spring-block on a vibrating plate)."""
from pythonfmu import Fmi2Slave

from vibroblock.slave import block_fmu


@block_fmu("{model}")
class Block{model}(Fmi2Slave):
    """{description}. Forces and geometry: vibroblock/models/model_{module}.py."""
'''

sys.path.insert(0, str(Path(__file__).resolve().parent))


def use_sources(sources: Path = SOURCES) -> None:
    """Import the core from ``sources`` (the build's process imports nothing else of it)."""
    global SOURCES, CORE
    SOURCES, CORE = Path(sources).resolve(), Path(sources).resolve() / "vibroblock"
    sys.path.insert(0, str(SOURCES))


def variant_scripts() -> dict[str, str]:
    """FMU name -> facade script of every registered variant."""
    from vibroblock.models import VARIANTS
    return {v.fmu_name: BLOCK_SCRIPT.format(model=v.name, module=v.name.lower(), description=v.description)
            for v in VARIANTS.values()}


def fmu_names() -> list[str]:
    scripts = sorted(p.stem for p in SOURCES.glob("*.py"))
    return list(variant_scripts()) + scripts


# A short run at the default parameters, for masters that start from the model
# description (FMI 2.0, section 2.2.5); a master's own settings take precedence.
DEFAULT_EXPERIMENT = {"startTime": "0", "stopTime": "100", "stepSize": "0.5"}


def complete_model_description(xml_text: bytes) -> bytes:
    """Add ModelStructure/InitialUnknowns listing every calculated output, and a DefaultExperiment.
    (An FMI 3.0 description gets the DefaultExperiment only: pythonfmu3 writes its structure.)"""
    root = ElementTree.fromstring(xml_text)
    if root.find("DefaultExperiment") is None:
        experiment = ElementTree.Element("DefaultExperiment", DEFAULT_EXPERIMENT)
        root.insert(list(root).index(root.find("ModelVariables")), experiment)
    if root.get("fmiVersion") == "3.0":
        ElementTree.indent(root)
        return ElementTree.tostring(root, encoding="UTF-8", xml_declaration=True)
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


PYTHON_ENVIRONMENT = "resources/python-environment.txt"
KERNELS_FOLDER = "resources/vibroblock_kernels/"  # build/kernels.py


def python_environment_record() -> bytes:
    """The build's Python environment, as the native front end reads it."""
    library = Path(sysconfig.get_config_var("LIBDIR") or "") / (sysconfig.get_config_var("INSTSONAME") or "")
    lines = ["# The Python environment this FMU was built with; the FMU's native front end starts it",
             "# when the host is not a Python process.  VIBROBLOCK_PYTHON or vibroblock-python.txt",
             "# in the FMU's top folder take precedence (see documentation/index.html).",
             f"python = {sys.executable}"]
    if library.is_file():
        lines.append(f"library = {library}")
    return ("\n".join(lines) + "\n").encode()


def finish_archive(fmu: Path, extra: dict[str, bytes] | None = None) -> None:
    """Complete the model description and make the archive reproducible.

    The same sources give the same bytes: members in name order with a fixed time
    stamp, no generation time, and a GUID derived from the archive's content (a master
    can tell two builds apart by it, and a result store can reuse points across
    rebuilds of unchanged sources).  ``extra`` adds (or replaces) members.
    """
    with zipfile.ZipFile(fmu) as src:
        members = {item.filename: (item, src.read(item)) for item in src.infolist() if not item.is_dir()}
    for name, data in (extra or {}).items():
        item = zipfile.ZipInfo(name)
        item.external_attr = 0o644 << 16
        members[name] = (item, data)
    content = hashlib.sha256()
    for name in sorted(members):
        # Not in the GUID: where it was built, and kernels compiled for the build's CPU.
        if name not in ("modelDescription.xml", PYTHON_ENVIRONMENT) and not name.startswith(KERNELS_FOLDER):
            content.update(name.encode())
            content.update(members[name][1])
    root = ElementTree.fromstring(complete_model_description(members["modelDescription.xml"][1]))
    token = "guid" if root.get("fmiVersion") == "2.0" else "instantiationToken"
    root.set(token, "{%s}" % uuid.uuid5(uuid.NAMESPACE_URL, f"vibroblock:{content.hexdigest()}"))
    root.attrib.pop("generationDateAndTime", None)
    item, _ = members["modelDescription.xml"]
    members["modelDescription.xml"] = (item, ElementTree.tostring(root, encoding="UTF-8", xml_declaration=True))

    with tempfile.NamedTemporaryFile(dir=fmu.parent, suffix=".fmu", delete=False) as tmp:
        tmp_path = Path(tmp.name)
    with zipfile.ZipFile(tmp_path, "w", zipfile.ZIP_DEFLATED) as dst:
        for name in sorted(members):
            item, data = members[name]
            fixed = zipfile.ZipInfo(name, date_time=FIXED_TIMESTAMP)
            fixed.external_attr = item.external_attr
            fixed.compress_type = zipfile.ZIP_DEFLATED
            dst.writestr(fixed, data)
    tmp_path.chmod(0o644)
    tmp_path.replace(fmu)


CHAIN_FMUS = ("BlockChain", "BlockChain3")
# pythonfmu3's loader finds the slave class by this text (as pythonfmu's by "(Fmi2Slave):").
FMI3_MARK = "(Fmi3Slave):"
# What pythonfmu3 0.3.4 would write wrongly: it gives every co-simulation flag the value
# of its last common one (fmi3slave.py, Fmi3SlaveBase.to_xml).
FMI3_OPTIONS = {"canGetAndSetFMUState": True, "canSerializeFMUState": True,
                "canHandleVariableCommunicationStepSize": True}


def chain_script(n_blocks: int, name: str = "BlockChain") -> str:
    """A chain FMU script with its number of blocks (the default N of BlockChain3) set to ``n_blocks``."""
    if n_blocks < 1:
        raise SystemExit(f"--chain-blocks {n_blocks}: a chain has at least one block")
    text = (SOURCES / f"{name}.py").read_text()
    default = "\nN_BLOCKS = "
    start = text.index(default) + len(default)
    return text[:start] + str(int(n_blocks)) + text[text.index("\n", start):]


def build(name: str, dest: Path, ship_kernels: bool = True, chain_blocks: int | None = None) -> Path:
    from pythonfmu.builder import FmuBuilder

    generated = variant_scripts()
    if chain_blocks is not None:
        generated.update({chain: chain_script(chain_blocks, chain) for chain in CHAIN_FMUS})
    with tempfile.TemporaryDirectory() as scratch:
        script = SOURCES / f"{name}.py"
        if name in generated:
            script = Path(scratch) / f"{name}.py"
            script.write_text(generated[name])
        elif not script.is_file():
            raise SystemExit(f"no FMU named {name!r}; the FMUs are {fmu_names()}")
        project_files = [CORE]
        if name == "Excitation":  # it processes seismic records itself: harness.ground.records, bundled
            records = Path(scratch) / "vibroblock_records"
            shutil.copytree(RECORDS, records, ignore=shutil.ignore_patterns("__pycache__"))
            project_files.append(records)
        fmi3 = FMI3_MARK in script.read_text()
        if fmi3:
            fmu = Path(build_fmi3(script, dest, project_files, Path(scratch)))
        else:
            fmu = Path(FmuBuilder.build_FMU(script, dest=dest, project_files=project_files,
                                            canGetAndSetFMUstate=True, canSerializeFMUstate=True))
    import documentation
    extra = documentation.archive_members(name)
    if not fmi3:  # the status shim and its Python environment record are FMI 2.0 code
        from status_shim import wrap_fmu
        wrap_fmu(fmu)
        extra[PYTHON_ENVIRONMENT] = python_environment_record()
    if name.startswith("Block") and ship_kernels:  # the variants' and the chains' ("Chain")
        import kernels
        extra.update(kernels.archive_members(CORE, "Chain" if name in CHAIN_FMUS else name[len("Block"):]))
    finish_archive(fmu, extra)
    return fmu


def build_fmi3(script: Path, dest: Path, project_files: list, scratch: Path) -> Path:
    """An FMI 3.0 FMU by pythonfmu3.  Its facades are FMI 2.0 facades behind an adapter
    (vibroblock/fmi3.py), so the FMU bundles pythonfmu's Python modules too (pythonfmu3
    bundles its own)."""
    import pythonfmu
    from pythonfmu3 import FmuBuilder as Fmi3Builder

    bundled = scratch / "pythonfmu"
    shutil.copytree(Path(pythonfmu.__file__).parent, bundled,
                    ignore=shutil.ignore_patterns("__pycache__", "resources", "pythonfmu-export", "tests"))
    return Fmi3Builder.build_FMU(script, dest=dest, project_files=[*project_files, bundled], **FMI3_OPTIONS)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="FMUs to build (default: all)")
    parser.add_argument("--dest", type=Path, default=DEFAULT_DEST, help="output folder")
    parser.add_argument("--sources", type=Path, default=SOURCES, help="source tree (fmu_src)")
    parser.add_argument("--list", action="store_true", help="print the FMU names and stop")
    parser.add_argument("--chain-blocks", type=int, default=None,
                        help="the number of blocks of BlockChain.fmu (default: N_BLOCKS of fmu_src/BlockChain.py)")
    parser.add_argument("--without-kernels", action="store_true",
                        help="do not ship compiled kernels (the first doStep compiles them)")
    args = parser.parse_args(argv)
    use_sources(args.sources)
    if args.list:
        print(" ".join(fmu_names()))
        return 0
    args.dest.mkdir(parents=True, exist_ok=True)
    for name in args.names or fmu_names():
        print(f"built {build(name, args.dest, ship_kernels=not args.without_kernels, chain_blocks=args.chain_blocks)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
