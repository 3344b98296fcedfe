"""On-disk cache of the compiled kernels, addressed by the core's content.

numba files its cache under a folder derived from the source file's directory.  An
FMU is usually extracted to a fresh temporary folder, which would make every new
extraction recompile the kernels (seconds per instance).  This locator files the
kernels of this package under a digest of the package's sources instead: any copy of
the same core shares one cache, and any change of any core file (kernels inline
functions from several files) invalidates it.

numba also stamps each cache index with its source file's modification time and size,
which a new extraction changes; the locator stamps it with the file's content instead.

An FMU can ship kernels compiled when it was built (``resources/vibroblock_kernels``,
next to this package): they are copied into the cache where it has none for a
function yet.  numba then checks them as its own (numba and Python version, CPU) and
recompiles what does not match.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import warnings
from pathlib import Path

# An FMU is often extracted to a fresh folder, so unless the host chose a cache folder,
# use a stable per-user one.  numba reads the setting when it is first imported, just
# below; every module with compiled kernels imports this one first.
os.environ.setdefault("NUMBA_CACHE_DIR", os.path.join(
    os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "vibroblock", "numba"))

from numba.core import caching, config, errors  # noqa: E402

# numba's pedantic SSA check flags a variable assigned in several branches of a function
# inlined at its IR level (vibroblock.dispatch) as "not in scope"; the code is correct (the
# golden outputs are bit-identical) and the warning says nothing to a user.
warnings.filterwarnings("ignore", category=errors.NumbaIRAssumptionWarning)

PACKAGE_DIR = Path(__file__).resolve().parent
SHIPPED_KERNELS = PACKAGE_DIR.parent / "vibroblock_kernels"


def core_digest(package_dir: Path = PACKAGE_DIR) -> str:
    """Digest of the physics core's sources, to tell two copies apart."""
    digest = hashlib.sha256()
    for path in sorted(Path(package_dir).rglob("*.py")):
        digest.update(path.relative_to(package_dir).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


# Taken at import: an FMU's extraction folder may be deleted while the process lives on.
CORE_DIGEST = core_digest(PACKAGE_DIR)


class CoreCacheLocator(caching.UserProvidedCacheLocator):
    """numba cache locator for this package's kernels (see module doc)."""

    @classmethod
    def from_function(cls, py_func, py_file):
        if not config.CACHE_DIR or not Path(py_file).resolve().is_relative_to(PACKAGE_DIR):
            return None
        return super().from_function(py_func, py_file)

    @classmethod
    def get_suitable_cache_subpath(cls, py_file):
        relative = Path(py_file).resolve().parent.relative_to(PACKAGE_DIR).as_posix()
        folder = hashlib.sha1(f"{CORE_DIGEST}/{relative}".encode()).hexdigest()
        return f"vibroblock_{folder}"

    def get_source_stamp(self):
        return "sha256:" + hashlib.sha256(Path(self._py_file).read_bytes()).hexdigest()


def seed_cache(shipped: Path = SHIPPED_KERNELS) -> None:
    """Copy shipped kernels into numba's cache folder for functions it has no index for."""
    if not config.CACHE_DIR or not shipped.is_dir():
        return
    try:
        for index in sorted(shipped.glob("vibroblock_*/*.nbi")):
            target = Path(config.CACHE_DIR) / index.parent.name
            if (target / index.name).exists():
                continue
            target.mkdir(parents=True, exist_ok=True)
            data = sorted(index.parent.glob(index.name[:-len(".nbi")] + ".*.nbc"))
            for source in [*data, index]:  # the index last: it names the data files
                partial = target / f".{source.name}.{os.getpid()}"
                shutil.copyfile(source, partial)
                os.replace(partial, target / source.name)
    except OSError:
        pass  # an unwritable cache: numba compiles as it would without shipped kernels


def install() -> None:
    """Put the locator first in numba's list (idempotent)."""
    if not config.CACHE_DIR:  # numba was imported (by the host) before the package chose a folder
        config.CACHE_DIR = os.environ.get("NUMBA_CACHE_DIR", "")
    locators = caching.CacheImpl._locator_classes
    if not any(cls.__name__ == CoreCacheLocator.__name__ and cls.__module__ == __name__ for cls in locators):
        locators.insert(0, CoreCacheLocator)
        seed_cache()


install()
