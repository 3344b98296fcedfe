"""A clean process exit after pythonfmu FMUs ran in this process (through fmpy).

pythonfmu 0.7.0's library keeps its interpreter guard in a static ``shared_ptr``
that two exit paths release: its C++ static destructor (one of the process's exit
handlers) and its unload hook (``__attribute__((destructor))``, run by the dynamic
loader after the exit handlers).  The destructor leaves the pointer dangling, so the
unload hook decrements a counter in a 128-byte block that is already free.  Whether
that shows depends on what the block holds by then: mostly nothing happens, but when
it heads a free list the process aborts on its last free ("free(): corrupted unsorted
chunks", exit status 134), after all its work is done.

A library that is unloaded before exit (fmpy unloads an FMU's library when its
instance is freed) runs the unload hook first, which is safe.  But the first copy of
pythonfmu's library a process loads stays loaded until exit: it defines
``STB_GNU_UNIQUE`` symbols, which the dynamic loader never unloads.  So every
process that ran a plain pythonfmu FMU (one built by ``pythonfmu build``, without
this project's native front end) is exposed.  The project's FMUs release the guard
themselves (build/fmi_status_shim.c); for any other pythonfmu FMU,
:func:`release_pythonfmu_guards` does the same from the outside: it calls the
library's own ``finalizePythonInterpreter`` (which only resets the pointer) for every
loaded library that exports it, after which both releases at exit find nothing to
release.  :func:`install` runs it from Python's exit handlers, which finish before
the process's C++ static destructors start.

The interpreter guard of a Python host does not own the interpreter (it was running
before the FMU was loaded), so releasing it early changes nothing else: instances
still alive keep working.
"""
from __future__ import annotations

import atexit
import ctypes
import sys
import threading

_SYMBOL = b"finalizePythonInterpreter"
_RTLD_LAZY, _RTLD_NOLOAD = 0x0001, 0x0004  # glibc's values
_installed = False
_lock = threading.Lock()


class _DlPhdrInfo(ctypes.Structure):
    _fields_ = [("dlpi_addr", ctypes.c_void_p), ("dlpi_name", ctypes.c_char_p),
                ("dlpi_phdr", ctypes.c_void_p), ("dlpi_phnum", ctypes.c_uint16)]


_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(_DlPhdrInfo), ctypes.c_size_t, ctypes.c_void_p)


def _loader():
    libc = ctypes.CDLL(None)
    libc.dl_iterate_phdr.argtypes = [_CALLBACK, ctypes.c_void_p]
    libc.dl_iterate_phdr.restype = ctypes.c_int
    libc.dlopen.argtypes = [ctypes.c_char_p, ctypes.c_int]
    libc.dlopen.restype = ctypes.c_void_p
    libc.dlsym.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
    libc.dlsym.restype = ctypes.c_void_p
    libc.dlclose.argtypes = [ctypes.c_void_p]
    libc.dlclose.restype = ctypes.c_int
    return libc


def loaded_libraries() -> list[bytes]:
    """The names (as the loader knows them) of the shared libraries in this process."""
    libc = _loader()
    names: list[bytes] = []

    def collect(info, size, data):
        name = info.contents.dlpi_name
        if name:
            names.append(name)
        return 0

    libc.dl_iterate_phdr(_CALLBACK(collect), None)
    return names


def release_pythonfmu_guards() -> int:
    """Release the interpreter guard of every loaded pythonfmu library; returns how many
    libraries had one.  Safe to call more than once, and a no-op where there is
    none (or on a system without glibc's loader functions)."""
    if not sys.platform.startswith("linux"):
        return 0
    try:
        libc = _loader()
        names = loaded_libraries()
    except (AttributeError, OSError):
        return 0
    released = 0
    for name in names:
        # RTLD_NOLOAD: only a library that is loaded already (by this exact name) is found.
        handle = libc.dlopen(name, _RTLD_LAZY | _RTLD_NOLOAD)
        if not handle:
            continue
        try:
            # fmi2Instantiate too: only an FMU's library (pythonfmu's, or the inner
            # library behind this project's front end) is touched.
            release = libc.dlsym(handle, _SYMBOL)
            if release and libc.dlsym(handle, b"fmi2Instantiate"):
                ctypes.CFUNCTYPE(None)(release)()
                released += 1
        finally:
            libc.dlclose(handle)
    return released


def install() -> None:
    """Release the guards when this Python process exits (before its static destructors)."""
    global _installed
    with _lock:
        if not _installed:
            atexit.register(release_pythonfmu_guards)
            _installed = True
