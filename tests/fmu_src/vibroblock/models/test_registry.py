"""The variant registry: a variant is one module, and everything else follows from it.

The last test adds a throw-away variant (a flat plate tilted by an angle) to a copy of
the sources as one module, and shows that the build makes its FMU and that the FMU
runs in fmpy with the physics the module states (rest on an incline, and sliding
where tan(tilt) > mu_s), with no other file changed."""
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from vibroblock.interface import markdown_table
from vibroblock.models import VARIANTS, defaults, parameters_for

ROOT = Path(__file__).resolve().parents[4]

TILTED = '''"""Model T: flat plate tilted by the angle tilt, block confined by gravity."""
import math

from numba import njit

from ..layout import P_G, P_M, slot
from ..parameters import FINITE, Parameter

PARAMETERS = ("g", Parameter("tilt", 0.2, "rad", "inclination of the plate", FINITE))
P_TILT = slot("tilt")


@njit(inline="always")
def profile(x, prm):
    slope = math.tan(prm[P_TILT])
    return slope * x, slope


@njit(inline="always")
def load(cos_a, sin_a, prm):
    return 0.0, -prm[P_M] * prm[P_G]
'''

RUN_FMU = '''
import json, sys
from fmpy import simulate_fmu
results = {}
for tilt in (0.2, 0.7):  # tan 0.2 = 0.2 < mu_s = 0.5 holds, tan 0.7 = 0.84 slides
    r = simulate_fmu(sys.argv[1], stop_time=400.0, output_interval=4.0,
                     start_values={"tilt": tilt, "k_d": 0.0, "V_d": 0.0, "gamma_t": 0.05, "dt": 1e-3,
                                   "integrator": 0},  # (symplectic_euler: ~10 s to compile, adaptive ~200 s)
                     output=["x", "penetration", "normal_force"])
    results[tilt] = {"x": float(r["x"][-1]), "penetration": float(r["penetration"][-1]),
                     "normal_force": float(r["normal_force"][-1])}
print(json.dumps(results))
'''


def test_the_paper_variants_are_registered_with_their_parameters():
    assert sorted(VARIANTS) == ["A", "B", "C"]
    names = {m: [p.name for p in parameters_for(m)] for m in VARIANTS}
    assert "g" in names["A"] and "g" in names["B"] and "g" not in names["C"]
    assert "P_l" in names["C"] and "A_x" not in names["A"]
    # The variant's own parameters follow the drive, in the FMU's order.
    assert names["C"].index("omega") + 1 == names["C"].index("A_x")
    assert defaults("B")["k_d"] == 5e-6 and defaults("A")["k_d"] == 5e-4


def test_the_interface_table_lists_every_variant_parameter_once():
    table = markdown_table()
    for variant in VARIANTS.values():
        for p in variant.parameters:
            assert table.count(f"| `{p.name}` |") == 1


@pytest.mark.slow
def test_a_new_variant_is_one_module_and_its_fmu_builds_and_runs(tmp_path):
    sources = tmp_path / "fmu_src"
    shutil.copytree(ROOT / "fmu_src", sources, ignore=shutil.ignore_patterns("__pycache__"))
    (sources / "vibroblock" / "models" / "model_t.py").write_text(TILTED)
    build = [sys.executable, str(ROOT / "build" / "build_fmus.py"), "--sources", str(sources),
             "--dest", str(tmp_path / "fmus")]
    listed = subprocess.run(build + ["--list"], capture_output=True, text=True, check=True).stdout.split()
    assert listed == ["BlockA", "BlockB", "BlockC", "BlockT", "BlockChain", "BlockChain3", "Excitation"]
    # Without shipped kernels: the new variant's kernels compile on first use in the run below
    # (the paper's own scheme: the cheapest to compile on a fresh machine).
    subprocess.run(build + ["--without-kernels", "BlockT"], capture_output=True, text=True, check=True)
    fmu = tmp_path / "fmus" / "BlockT.fmu"
    # A fresh process: this one holds the repository's core, which lacks model T.
    out = subprocess.run([sys.executable, "-c", RUN_FMU, str(fmu)], capture_output=True, text=True,
                         cwd=tmp_path, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    results = {float(k): v for k, v in json.loads(out.stdout.strip().splitlines()[-1]).items()}
    held, sliding = results[0.2], results[0.7]
    # On the incline at rest: N = m g cos(tilt), penetration N / k_n along the normal.
    assert held["normal_force"] == pytest.approx(math.cos(0.2), rel=1e-3)
    assert held["penetration"] == pytest.approx(math.cos(0.2), rel=1e-3)
    # Held by the friction spring, loaded by the travel along the slope: k_t F = m g sin(tilt).
    assert held["x"] == pytest.approx(-math.sin(0.2) / 0.28 * math.cos(0.2), rel=1e-2)
    # Steeper than arctan(mu_s): the block slides down the slope (x decreases).
    assert sliding["x"] < -10.0
