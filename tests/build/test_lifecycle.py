"""Instantiate -> simulate -> terminate -> free, over and over, and leaving the process:
in fmpy and in libcosim (the C master's share is in test_c_host.py).  Each host runs in
a child process, so that a crash at exit shows as its exit status."""
from __future__ import annotations

import subprocess
import sys
import textwrap

FMPY_CYCLES = textwrap.dedent("""
    import sys
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    def rss_kib():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4
    fmu = sys.argv[1]
    md = read_model_description(fmu)
    folder = extract(fmu)
    z = next(v.valueReference for v in md.modelVariables if v.name == "z")
    for i in range(1, 201):
        slave = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                          instanceName=f"cycle{i}")
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        slave.doStep(0.0, 0.25)
        assert slave.getReal([z])[0] == -1.0
        slave.terminate()
        slave.freeInstance()
        if i in (20, 200):
            print("rss", i, rss_kib(), flush=True)
""")

LIBCOSIM_SYSTEM = textwrap.dedent("""
    import sys
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimSlave import CosimLocalSlave

    def rss_kib():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4
    log_output_level(CosimLogLevel.ERROR)
    CYCLES = int(sys.argv[2])
    for cycle in range(1, CYCLES + 1):
        execution = CosimExecution.from_step_size(step_size=int(0.5e9))
        for name in ("BlockA", "BlockB", "BlockC", "Excitation"):
            for k in range(2):
                execution.add_local_slave(CosimLocalSlave(fmu_path=f"{sys.argv[1]}/{name}.fmu",
                                                          instance_name=f"{name}_{k}"))
        assert execution.simulate_until(target_time=int(5e9))
        del execution
        print("rss", cycle, rss_kib(), flush=True)
    print("done", flush=True)
""")


def rss(stdout):
    return {int(i): int(kib) for _, i, kib in (line.split() for line in stdout.splitlines() if line.startswith("rss"))}


def test_fmpy_200_instances_flat_memory_and_a_clean_exit(fmu_path, tmp_path):
    done = subprocess.run([sys.executable, "-c", FMPY_CYCLES, fmu_path("A")], capture_output=True, text=True,
                          timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    used = rss(done.stdout)
    assert used[200] - used[20] < 8192, used  # KiB over 180 instances


LIBCOSIM_EXECUTIONS = 25  # of 8 instances each: 200 instantiate/free cycles


def test_libcosim_200_instances_of_all_fmus_flat_memory_and_a_clean_exit(fmu_dir, tmp_path):
    done = subprocess.run([sys.executable, "-c", LIBCOSIM_SYSTEM, str(fmu_dir), str(LIBCOSIM_EXECUTIONS)],
                          capture_output=True, text=True, timeout=900, cwd=tmp_path,
                          env={**__import__("os").environ, "TMPDIR": str(tmp_path)})
    assert done.returncode == 0 and "done" in done.stdout, done.stdout[-2000:] + done.stderr[-3000:]
    used = rss(done.stdout)
    # The first executions warm the process (libcosim's and the kernels' first loads);
    # after that, 160 more instances in 20 executions must not grow it.
    assert used[LIBCOSIM_EXECUTIONS] - used[5] < 8192, used  # KiB
