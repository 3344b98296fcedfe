"""The FMUs in a host that is not a Python process: tests/build/fmi_host.c, compiled with cc.

The C master loads an extracted FMU with dlopen and drives it with nothing set in
its environment; its results must equal fmpy's bit for bit, and it checks the calls
FMI 2.0 requires of a co-simulation FMU, memory over many instances, several FMUs in
one process, and a clean exit.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave

HERE = Path(__file__).resolve().parent
REQUIRED_SYMBOLS = """fmi2GetTypesPlatform fmi2GetVersion fmi2SetDebugLogging fmi2Instantiate fmi2FreeInstance
fmi2SetupExperiment fmi2EnterInitializationMode fmi2ExitInitializationMode fmi2Terminate fmi2Reset fmi2GetReal
fmi2GetInteger fmi2GetBoolean fmi2GetString fmi2SetReal fmi2SetInteger fmi2SetBoolean fmi2SetString
fmi2GetFMUstate fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize fmi2SerializeFMUstate
fmi2DeSerializeFMUstate fmi2GetDirectionalDerivative fmi2SetRealInputDerivatives fmi2GetRealOutputDerivatives
fmi2DoStep fmi2CancelStep fmi2GetStatus fmi2GetRealStatus fmi2GetIntegerStatus fmi2GetBooleanStatus
fmi2GetStringStatus""".split()
KIND = {"Real": "r", "Integer": "i", "Boolean": "b"}
NAMES = ("BlockA", "BlockB", "BlockC", "Excitation", "BlockChain")


def clean_env(**extra) -> dict:
    """The environment of a plain C program: nothing that points at Python."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("PYTHON") and k not in ("VIBROBLOCK_PYTHON", "LD_PRELOAD", "LD_LIBRARY_PATH",
                                                       "VIRTUAL_ENV")}
    env.update(extra)
    return env


@pytest.fixture(scope="session")
def host(tmp_path_factory) -> Path:
    exe = tmp_path_factory.mktemp("host") / "fmi_host"
    subprocess.run(["cc", "-O1", "-Wall", "-Wextra", "-Werror", "-o", str(exe), str(HERE / "fmi_host.c"),
                    "-ldl", "-lm"], check=True)
    return exe


@pytest.fixture(scope="session")
def fmus(fmu_dir, tmp_path_factory):
    """name -> (extracted folder, model description)."""
    root = tmp_path_factory.mktemp("extracted")
    found = {}
    for name in NAMES:
        with zipfile.ZipFile(fmu_dir / f"{name}.fmu") as archive:
            archive.extractall(root / name)
        found[name] = (root / name, read_model_description(str(root / name)))
    return found


def run_host(host, *args, env=None, timeout=300):
    return subprocess.run([str(host), *map(str, args)], capture_output=True, text=True, timeout=timeout,
                          env=clean_env() if env is None else env)


def test_the_master_has_no_python_in_it(host):
    needed = subprocess.run(["readelf", "-d", str(host)], capture_output=True, text=True, check=True).stdout
    assert "NEEDED" in needed and "python" not in needed.lower()


@pytest.mark.parametrize("name", NAMES)
def test_binary_exports_what_the_model_description_promises(fmus, name):
    folder, md = fmus[name]
    identifier = md.coSimulation.modelIdentifier
    binary = folder / "binaries" / "linux64" / f"{identifier}.so"
    exported = subprocess.run(["nm", "-D", "--defined-only", str(binary)], capture_output=True, text=True,
                              check=True).stdout.split()
    assert set(REQUIRED_SYMBOLS) <= set(exported)
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate


# ---------------------------------------------------------------- bit for bit with fmpy
def columns(md):
    return [v for v in md.modelVariables if v.causality == "output"]


def as_values(md, settings):
    by_name = {v.name: v for v in md.modelVariables}
    args = []
    for name, value in settings.items():
        variable = by_name[name]
        args += [f"-{KIND[variable.type]}", variable.valueReference, repr(float(value))]
    return args


def host_run(host, fmus, name, settings, start, stop, step, drive=None, env=None):
    folder, md = fmus[name]
    args = ["run", folder, md.coSimulation.modelIdentifier, md.guid, repr(start), repr(stop), repr(step)]
    args += as_values(md, settings)
    for v in columns(md):
        args += ["-o", KIND[v.type], v.valueReference]
    if drive is not None:
        by_name = {v.name: v.valueReference for v in md.modelVariables}
        args += ["-d", by_name["plate_z"], by_name["plate_v"], by_name["plate_a"], repr(drive[0]), repr(drive[1])]
    done = run_host(host, *args, env=env)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    rows = [line.split() for line in done.stdout.splitlines()]
    table = np.array([[float.fromhex(x) if x.startswith(("0x", "-0x")) else float(x) for x in row] for row in rows])
    return table


def fmpy_driven(folder, md, settings, start, stop, step, amplitude, omega):
    """The same loop as the C master's, through fmpy's FMI 2.0 layer."""
    import math

    by_name = {v.name: v for v in md.modelVariables}
    slave = FMU2Slave(guid=md.guid, unzipDirectory=str(folder), modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="driven")
    slave.instantiate()
    for name, value in settings.items():
        v = by_name[name]
        setter = {"Real": slave.setReal, "Integer": slave.setInteger, "Boolean": slave.setBoolean}[v.type]
        setter([v.valueReference], [float(value) if v.type == "Real" else int(value)])
    slave.setupExperiment(startTime=start, stopTime=stop)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    inputs = [by_name[n].valueReference for n in ("plate_z", "plate_v", "plate_a")]

    def row(t):
        values = [t]
        for v in columns(md):
            getter = {"Real": slave.getReal, "Integer": slave.getInteger, "Boolean": slave.getBoolean}[v.type]
            values.append(float(getter([v.valueReference])[0]))
        return values

    rows, t, n = [row(start)], start, 0
    while not (t > stop or math.isclose(t, stop)):
        nxt = start + (n + 1) * step
        if nxt > stop and not math.isclose(nxt, stop):
            nxt = stop
        slave.setReal(inputs, [amplitude * math.sin(omega * t), amplitude * omega * math.cos(omega * t),
                               -amplitude * omega * omega * math.sin(omega * t)])
        slave.doStep(t, nxt - t)
        t, n = nxt, n + 1
        rows.append(row(t))
    slave.terminate()
    slave.freeInstance()
    return np.array(rows)


def as_table(result, md):
    """simulate_fmu's result in the master's column order (time, then outputs in model order)."""
    return np.column_stack([result["time"]] + [result[v.name].astype(float) for v in columns(md)])


def assert_same_bits(ours, reference):
    assert ours.shape == reference.shape
    assert ours.tobytes() == reference.tobytes(), np.argwhere(ours.view(np.int64) != reference.view(np.int64))[:5]


CASES = {
    "default": ({}, None),
    "vibrated": ({"A": 0.5, "omega": 0.8, "integrator": 1}, None),
    "driven": ({"initial_state": 0}, (0.2, 1.3)),
    # Every axis' last law, chosen through the Integer parameters.
    "other_laws": ({"A": 0.5, "omega": 0.8, "integrator": 1, "contact_law": 3, "friction_law": 2, "mu_k": 0.3,
                    "v_w": 0.5, "coulomb_normal": 2, "plate_motion": 1, "drive_angle": 0.7}, None),
    # Rate-and-state friction: its state theta lives in the FMU between the host's steps.
    "rate_state": ({"A": 0.5, "omega": 0.8, "integrator": 1, "friction_law": 4, "rs_D_c": 0.1, "rs_V_0": 1e-3,
                    "rs_theta_0": 100.0}, None),
}


@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("name", ["BlockA", "BlockB", "BlockC"])
def test_blocks_give_fmpys_bits(host, fmus, name, case):
    folder, md = fmus[name]
    settings, drive = CASES[case]
    experiment = md.defaultExperiment
    start, stop, step = float(experiment.startTime), float(experiment.stopTime), float(experiment.stepSize)
    if case != "default":
        stop = 20.0
    ours = host_run(host, fmus, name, settings, start, stop, step, drive)
    if drive is None:
        result = simulate_fmu(str(folder), start_time=start, stop_time=stop, output_interval=step,
                              start_values=settings, output=[v.name for v in columns(md)])
        reference = as_table(result, md)
    else:
        reference = fmpy_driven(folder, md, settings, start, stop, step, *drive)
    assert len(ours) == int(round((stop - start) / step)) + 1
    assert_same_bits(ours, reference)
    if case != "default":  # the case exercises the block: it moves
        assert np.ptp(ours[:, 2]) > 1e-3  # z


@pytest.mark.parametrize("name", ["BlockA", "Excitation"])
def test_do_steps_through_pythonfmu_give_the_same_bits(host, fmus, name):
    """The front end calls the slave's do_step directly; left to pythonfmu
    (VIBROBLOCK_PYTHONFMU_DOSTEP=1, for comparison) the run is the same."""
    folder, md = fmus[name]
    settings, drive = ({"A": 0.5, "omega": 0.8}, (0.2, 1.3)) if name == "BlockA" else ({}, None)
    e = md.defaultExperiment
    start, step = float(e.startTime), float(e.stepSize)
    runs = [host_run(host, fmus, name, settings, start, start + 200 * step, step, drive, env)
            for env in (None, clean_env(VIBROBLOCK_PYTHONFMU_DOSTEP="1"))]
    assert_same_bits(runs[0], runs[1])


def test_the_chain_gives_fmpys_bits(host, fmus):
    """A chain driven through its plate inputs, heterogeneous, coupled: every output."""
    folder, md = fmus["BlockChain"]
    settings = {"mu_s_spread": 0.3, "seed": 2}
    ours = host_run(host, fmus, "BlockChain", settings, 0.0, 6000.0, 2.0, drive=(0.05, 0.2))
    reference = fmpy_driven(folder, md, settings, 0.0, 6000.0, 2.0, 0.05, 0.2)
    assert_same_bits(ours, reference)
    names = [v.name for v in columns(md)]
    assert ours[-1, 1 + names.index("coulomb_resets")] > 0 and np.ptp(ours[:, 1 + names.index("x[1]")]) > 10.0


@pytest.mark.parametrize("settings", [{}, {"mode": 1, "omega_start": 0.2, "omega_end": 2.0, "sweep_time": 50.0}])
def test_excitation_gives_fmpys_bits(host, fmus, settings):
    folder, md = fmus["Excitation"]
    e = md.defaultExperiment
    start, stop, step = float(e.startTime), float(e.stopTime), float(e.stepSize)
    ours = host_run(host, fmus, "Excitation", settings, start, stop, step)
    result = simulate_fmu(str(folder), start_time=start, stop_time=stop, output_interval=step,
                          start_values=settings, output=[v.name for v in columns(md)])
    assert_same_bits(ours, as_table(result, md))
    assert np.ptp(ours[:, 1]) > 0.5


# ---------------------------------------------------------------- switches by name
# Every law axis, a reading and the integrator given by the names the FMU's model
# description lists (-p NAME VALUE), Reals by name too; a drive that makes the block slip
# within the run, so that the friction law shows.
BY_NAME = {"BlockA": {"integrator": "rk4", "contact_law": "hertz_hunt_crossley", "friction_law": "rate_state_aging",
                      "coulomb_normal": "load_only", "flight": "free", "plate_motion": "oblique", "drive_angle": 0.7,
                      "k_d": 0.1, "V_d": 0.5, "A": 0.5, "omega": 0.8, "rs_D_c": 0.1, "rs_V_0": 1e-3,
                      "rs_theta_0": 100.0},
           "BlockB": {"integrator": "symplectic_euler", "formulation": "tangent_frame", "friction_law": "rate_state_slip",
                      "contact_law": "linear_no_pull", "k_d": 0.1, "V_d": 0.5, "A": 0.5, "omega": 0.8,
                      "rs_D_c": 0.1, "rs_V_0": 1e-3, "rs_theta_0": 100.0},
           "BlockC": {"integrator": "adaptive", "friction_law": "rate_state_aging", "coulomb_normal": "applied_load",
                      "contact_law": "linear_along_normal", "k_d": 0.1, "V_d": 0.5, "A": 0.5, "omega": 0.8,
                      "rs_D_c": 1.0, "rs_V_0": 1e-3, "rs_theta_0": 1000.0}}


def by_name_args(settings):
    return [arg for name, value in settings.items() for arg in ("-p", name, str(value))]


@pytest.mark.parametrize("name", sorted(BY_NAME))
def test_switches_set_by_name_give_the_bits_of_their_values_and_fmpys(host, fmus, name):
    from harness.cosim.fmu import FmuInterface

    folder, md = fmus[name]
    settings = BY_NAME[name]
    as_numbers = FmuInterface(folder).typed(settings)  # the harness's reading of the same names
    assert as_numbers["friction_law"] in (3, 4) and all(isinstance(v, (int, float)) for v in as_numbers.values())
    start, stop, step = 0.0, 20.0, float(md.defaultExperiment.stepSize)
    outputs = [arg for v in columns(md) for arg in ("-o", KIND[v.type], v.valueReference)]
    head = ["run", folder, md.coSimulation.modelIdentifier, md.guid, repr(start), repr(stop), repr(step)]
    done = run_host(host, *head, *by_name_args(settings), *outputs)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    named = np.array([[float.fromhex(x) if x.startswith(("0x", "-0x")) else float(x) for x in line.split()]
                      for line in done.stdout.splitlines()])
    assert_same_bits(named, host_run(host, fmus, name, as_numbers, start, stop, step))
    result = simulate_fmu(str(folder), start_time=start, stop_time=stop, output_interval=step,
                          start_values=as_numbers, output=[v.name for v in columns(md)])
    assert_same_bits(named, as_table(result, md))
    # The laws chosen by name were run: another friction law moves the block differently.
    other = host_run(host, fmus, name, {**as_numbers, "friction_law": 0}, start, stop, step)
    assert other.tobytes() != named.tobytes()


@pytest.mark.parametrize("name", NAMES)
def test_the_master_reads_each_switchs_names_as_the_harness_does(host, fmus, name):
    from harness.cosim.fmu import FmuInterface

    folder, md = fmus[name]
    interface = FmuInterface(folder)
    switches = [v.name for v in md.modelVariables if v.type == "Integer" and v.causality == "parameter"]
    assert switches
    for switch in switches:
        done = run_host(host, "choices", folder, switch)
        assert done.returncode == 0, done.stderr
        listed = {}
        for line in done.stdout.splitlines():
            code, label = line.split()
            listed[label] = int(code)  # a name listed twice takes its last value, as in the harness
        assert listed == interface.choices(switch), switch
        if switch == "mode":  # each signal by name, the default's too
            assert listed["harmonic"] == 0 and listed["playback"] == 4


@pytest.mark.parametrize("option, message", [
    (("friction_law", "rate_state_agin"),
     "friction_law = 'rate_state_agin' is not one of its choices (0 = cundall_strack, 1 = cundall_strack_at_bound, "
     "2 = cundall_strack_kinetic, 3 = rate_state_aging, 4 = rate_state_slip; the FMU's modelDescription.xml)"),
    (("integrator", "rk5"), "integrator = 'rk5' is not one of its choices (0 = symplectic_euler, 1 = rk4, "
                            "2 = event_driven, 3 = implicit_contact, 4 = adaptive;"),
    (("integrator", "2.5"), "integrator = '2.5' is not one of its choices"),
    (("frictionlaw", "3"), "BlockA has no variable frictionlaw"),
    (("k_n", "stiff"), "k_n is a Real and cannot take 'stiff': give a number"),
    (("energy_balance", "yes"), "energy_balance is a Boolean and cannot take 'yes': give true or false"),
])
def test_a_name_the_fmu_does_not_list_ends_the_run_with_one_line(host, fmus, option, message):
    folder, md = fmus["BlockA"]
    z = next(v.valueReference for v in md.modelVariables if v.name == "z")
    done = run_host(host, "run", folder, "BlockA", md.guid, "0", "1", "0.5", "-p", "A", "0.5", "-p", *option,
                    "-o", "r", z)
    assert done.returncode == 1  # an exit of its own, not a signal
    assert done.stdout == ""  # nothing was run
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("fmi_host: BlockA") and message in lines[0], done.stderr


# ---------------------------------------------------------------- what FMI 2.0 requires
@pytest.mark.parametrize("name, output, parameter", [
    ("BlockA", "z", "k_t"), ("BlockB", "x", "A_x"), ("BlockC", "z", "P_l"), ("Excitation", "plate_z", "omega"),
    ("BlockChain", "x[1]", "k_c")])
def test_the_calls_fmi_requires(host, fmus, name, output, parameter):
    folder, md = fmus[name]
    by_name = {v.name: v for v in md.modelVariables}
    done = run_host(host, "check", folder, md.coSimulation.modelIdentifier, md.guid,
                    by_name[output].valueReference, by_name[parameter].valueReference,
                    repr(float(by_name[parameter].start)))
    assert done.returncode == 0 and f"checked {name}" in done.stdout, done.stdout + done.stderr[-3000:]
    # Each bad call was answered with a message in the log, not a crash.
    assert "doStep before a successful initialization" in done.stderr
    assert "nan" in done.stderr and "communication step size -1.0" in done.stderr
    assert "value reference 999999 is not a Real variable" in done.stderr
    assert "cannot be set" in done.stderr


# ---------------------------------------------------------------- lifecycle
def test_memory_stays_flat_over_200_instances(host, fmus):
    folder, md = fmus["BlockA"]
    z = next(v.valueReference for v in md.modelVariables if v.name == "z")
    done = run_host(host, "cycles", folder, "BlockA", md.guid, 200, z)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    rss = {int(i): int(kib) for _, i, kib in (line.split() for line in done.stdout.splitlines()
                                               if line.startswith("rss"))}
    # After the first instances (imports, caches), 180 more may not add more than 4 MiB.
    assert rss[200] - rss[20] < 4096, rss


def test_all_fmus_two_instances_each_in_one_process_and_a_clean_exit(host, fmus):
    specs = []
    for folder, md in fmus.values():
        plate = [next(v.valueReference for v in md.modelVariables if v.name == n)
                 for n in ("plate_z", "plate_v", "plate_a")]
        assert plate == [plate[0], plate[0] + 1, plate[0] + 2]  # fmi_host.c takes them as consecutive
        specs.append(f"{md.coSimulation.modelIdentifier}:{folder}:{md.guid}:{plate[0]}")
    done = run_host(host, "multi", *specs)
    assert done.returncode == 0 and "multi done" in done.stdout, done.stdout[-2000:] + done.stderr[-2000:]


# ---------------------------------------------------------------- finding Python
def instantiate_only(host, fmus, env, folder=None):
    f, md = fmus["BlockA"]
    return run_host(host, "run", folder or f, "BlockA", md.guid, "0", "1", "0.5", env=env)


def test_a_missing_environment_is_reported_with_how_to_fix_it(host, fmus, tmp_path):
    done = instantiate_only(host, fmus, clean_env(VIBROBLOCK_PYTHON=str(tmp_path / "nowhere")))
    assert done.returncode == 1 and "instantiate returned NULL" in done.stdout
    assert f"{tmp_path / 'nowhere'}, which does not exist" in done.stderr
    assert "VIBROBLOCK_PYTHON" in done.stderr and "vibroblock-python.txt" in done.stderr


def test_an_environment_without_numba_is_reported(host, fmus, tmp_path):
    bare = tmp_path / "bare"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(bare)], check=True)
    done = instantiate_only(host, fmus, clean_env(VIBROBLOCK_PYTHON=str(bare)))
    assert done.returncode == 1 and "instantiate returned NULL" in done.stdout
    assert "cannot find numpy" in done.stderr and str(bare) in done.stderr


def test_a_file_in_the_fmus_top_folder_points_at_the_environment(host, fmus, tmp_path):
    folder = tmp_path / "BlockA"
    shutil.copytree(fmus["BlockA"][0], folder)
    (folder / "resources" / "python-environment.txt").unlink()
    done = instantiate_only(host, fmus, clean_env(HOME=str(tmp_path)), folder)
    assert done.returncode == 1 and "No Python environment is configured" in done.stderr

    (folder / "vibroblock-python.txt").write_text(f"# the project's environment\npython = {sys.prefix}\n")
    done = instantiate_only(host, fmus, clean_env(HOME=str(tmp_path)), folder)
    assert done.returncode == 0, done.stdout + done.stderr[-2000:]
