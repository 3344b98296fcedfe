"""Process exit after plain pythonfmu FMUs ran through fmpy (harness/cosim/exit_guard.py).

Without the guard, pythonfmu 0.7.0's library releases its interpreter guard twice at
exit and writes into freed heap memory; that aborts the process only now and then
("free(): corrupted unsorted chunks"), so the write itself is what is checked, under
valgrind, which sees it every time.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from pythonfmu.builder import FmuBuilder

REPO = Path(__file__).resolve().parents[3]

SLAVE = '''
from pythonfmu import Fmi2Causality, Fmi2Slave, Real


class VbTestCounter(Fmi2Slave):
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.n = 0.0
        self.register_variable(Real("n", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self.n += 1.0
        return True
'''

# Several instances of the FMU, each from its own extraction (a new copy of the library,
# as fmpy's simulate_fmu loads it), then exit.  argv[2] == "guard": as in the harness.
HOST = textwrap.dedent('''
    import sys
    if sys.argv[2] == "guard":
        import harness.cosim  # noqa: F401  (installs the exit guard)
    from fmpy import simulate_fmu
    for _ in range(3):
        result = simulate_fmu(sys.argv[1], stop_time=0.05, output_interval=0.01)
        assert result["n"][-1] == 5.0
    from harness.cosim import exit_guard
    print("guards", exit_guard.release_pythonfmu_guards() if sys.argv[2] == "count" else "-", flush=True)
''')


@pytest.fixture(scope="module")
def plain_fmu(tmp_path_factory):
    folder = tmp_path_factory.mktemp("plain")
    script = folder / "vb_test_counter.py"
    script.write_text(textwrap.dedent(SLAVE))
    return str(FmuBuilder.build_FMU(script, dest=folder))


def host(fmu, mode, *prefix, **env):
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")])),
                       **env)
    return subprocess.run([*prefix, sys.executable, "-c", HOST, fmu, mode], capture_output=True, text=True,
                          env=environment, timeout=600)


def test_the_guard_finds_the_library_that_stays_loaded(plain_fmu):
    # fmpy unloads each copy when its instance is freed, except the first: pythonfmu's
    # library has STB_GNU_UNIQUE symbols, so the loader keeps it until exit.
    done = host(plain_fmu, "count")
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["guards", "1"]


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="needs valgrind")
def test_no_write_to_freed_memory_at_exit(plain_fmu, tmp_path):
    log = tmp_path / "valgrind.log"
    done = host(plain_fmu, "guard", "valgrind", f"--log-file={log}", "--error-limit=no", PYTHONMALLOC="malloc")
    assert done.returncode == 0, done.stderr
    text = log.read_text()
    assert "ERROR SUMMARY" in text
    # The function appears in the log only in the stack of an error it made.
    at = text.find("finalizePythonInterpreter")
    assert at < 0, text[max(0, at - 1500):at + 2500]
