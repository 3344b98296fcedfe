"""Install the FMI status shim into a pythonfmu-built FMU.

The Python slaves report bad input by logging a message with
``Fmi2Status.error`` (or warning/discard) and returning normally, keeping
their last good state.  pythonfmu's binary reports such calls as ``fmi2OK``
and forwards log messages only while the host has debug logging on.  The shim
(``fmi_status_shim.c``, next to this file) sits in front of that binary and
turns the worst status logged during a call into the call's return status.

Layout of a wrapped FMU (linux64 only)::

    binaries/linux64/<modelIdentifier>.so            the shim
    binaries/linux64/<modelIdentifier>_pythonfmu.so  pythonfmu's binary

The shim finds the second file from its own location, so both must stay in the
same folder under these names.  Status contract of every call on an instance:
the worse of pythonfmu's return status and the worst status logged during the
call, where a logged ``fmi2Warning``/``fmi2Discard``/``fmi2Error`` is returned
as such and a logged ``fmi2Fatal`` as ``fmi2Error``; ``fmi2Fatal`` returned by
pythonfmu (an exception escaped the slave) passes through.  Warning, error
and fatal messages always reach the host's logger; ``fmi2OK`` and
``fmi2Discard`` messages only while the host has debug logging on (FMI 2.0,
section 2.1.3).  Message text is passed on verbatim, never printf-formatted.

Other platforms' binaries (``binaries/win64``) are left as they are: there the
slave's logged errors still come back as ``fmi2OK``.

Usage::

    from status_shim import wrap_fmu
    wrap_fmu("BlockA.fmu")             # rewrites the FMU in place

    python build/status_shim.py BlockA.fmu [BlockB.fmu ...]

Wrapping an already wrapped FMU only refreshes the shim.
"""
from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import stat
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path
from typing import Union

HERE = Path(__file__).resolve().parent
SHIM_SOURCE = HERE / "fmi_status_shim.c"
# The shim finds and starts the Python runtime before it loads pythonfmu's binary.
RUNTIME_SOURCES = (HERE / "python_runtime.c", HERE / "python_runtime.h")
WORK_DIR = HERE / "work"

PLATFORM = "linux64"
INNER_SUFFIX = "_pythonfmu.so"  # must match INNER_SUFFIX in fmi_status_shim.c
CFLAGS = ("-O2", "-shared", "-fPIC", "-fvisibility=hidden", "-Wall", "-Wextra")
LIBS = ("-ldl", "-lpthread", "-lm")

PathLike = Union[str, os.PathLike]


def inner_library_name(model_identifier: str) -> str:
    """File name of pythonfmu's binary inside a wrapped FMU's binaries/linux64."""
    return model_identifier + INNER_SUFFIX


def build_shim() -> Path:
    """Compile the shim unless a build of the current source exists; return its path.

    The build is named after a hash of sources and flags, so editing a source
    gives a fresh build.  The compiler is ``$CC`` or ``gcc``.
    """
    compiler = os.environ.get("CC", "gcc")
    key = hashlib.sha256(SHIM_SOURCE.read_bytes())
    for source in RUNTIME_SOURCES:
        key.update(source.read_bytes())
    key.update(" ".join((compiler, *CFLAGS, *LIBS)).encode())
    target = WORK_DIR / f"fmi_status_shim-{key.hexdigest()[:16]}.so"
    if target.is_file():
        return target

    WORK_DIR.mkdir(parents=True, exist_ok=True)
    # Compile to a private name and rename: concurrent builders never see a half-written file.
    fd, tmp_name = tempfile.mkstemp(dir=WORK_DIR, prefix=".fmi_status_shim-", suffix=".so")
    os.close(fd)
    try:
        result = subprocess.run(
            [compiler, *CFLAGS, "-I", str(HERE), "-o", tmp_name, str(SHIM_SOURCE), str(RUNTIME_SOURCES[0]), *LIBS],
            capture_output=True,
            text=True,
        )
        if result.returncode != 0:
            raise RuntimeError(f"compiling {SHIM_SOURCE.name} failed:\n{result.stderr}")
        os.replace(tmp_name, target)
    finally:
        if os.path.exists(tmp_name):
            os.unlink(tmp_name)

    for stale in WORK_DIR.glob("fmi_status_shim-*.so"):
        if stale != target:
            stale.unlink(missing_ok=True)
    return target


def model_identifier(fmu: zipfile.ZipFile) -> str:
    """The Co-Simulation modelIdentifier from an FMU's modelDescription.xml."""
    root = ET.fromstring(fmu.read("modelDescription.xml"))
    cosim = root.find("CoSimulation")
    if cosim is None or not cosim.get("modelIdentifier"):
        raise ValueError("modelDescription.xml declares no Co-Simulation modelIdentifier")
    return cosim.get("modelIdentifier")


def _renamed(info: zipfile.ZipInfo, name: str) -> zipfile.ZipInfo:
    """A member header like ``info`` (date, permissions, compression) under another name."""
    renamed = zipfile.ZipInfo(name, date_time=info.date_time)
    renamed.external_attr = info.external_attr
    renamed.compress_type = info.compress_type
    return renamed


def wrap_fmu(fmu_path: PathLike) -> None:
    """Install the status shim into the FMU at ``fmu_path`` (rewritten in place).

    ``binaries/linux64/<modelIdentifier>.so`` (pythonfmu's binary) moves to
    ``binaries/linux64/<modelIdentifier>_pythonfmu.so`` and the shim takes its
    name.  Everything else in the archive is copied unchanged, win64 binaries
    included.  If the FMU is already wrapped, only the shim is replaced.
    """
    fmu_path = Path(fmu_path)
    shim = build_shim()

    with zipfile.ZipFile(fmu_path) as source:
        identifier = model_identifier(source)
        outer_name = f"binaries/{PLATFORM}/{identifier}.so"
        inner_name = f"binaries/{PLATFORM}/{inner_library_name(identifier)}"
        names = set(source.namelist())
        if outer_name not in names:
            raise ValueError(f"{fmu_path} has no {outer_name}")
        already_wrapped = inner_name in names

        fd, tmp_name = tempfile.mkstemp(dir=fmu_path.parent, prefix=f".{fmu_path.name}.", suffix=".tmp")
        os.close(fd)
        try:
            with zipfile.ZipFile(tmp_name, "w") as target:
                for info in source.infolist():
                    if info.filename != outer_name:
                        target.writestr(info, source.read(info))
                        continue
                    if not already_wrapped:
                        target.writestr(_renamed(info, inner_name), source.read(info))
                    # The shim is stored like the binary it stands in for.
                    target.writestr(_renamed(info, outer_name), shim.read_bytes())
        except BaseException:
            os.unlink(tmp_name)
            raise

    # Swap in the new archive in one step, keeping the file's permissions.
    os.chmod(tmp_name, stat.S_IMODE(fmu_path.stat().st_mode))
    os.replace(tmp_name, fmu_path)


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if not args or any(a in ("-h", "--help") for a in args):
        print("usage: status_shim.py FMU [FMU ...]  (installs the status shim in place)")
        return 0 if args else 2
    for path in args:
        wrap_fmu(path)
        print(f"{path}: status shim installed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
