"""examples/choosing_an_integrator.py runs every integrator through BlockC.fmu and shows the trade."""
import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "choosing_an_integrator.py"


def test_adaptive_is_accurate_where_the_fixed_step_schemes_are_first_order(fmu_path):
    spec = importlib.util.spec_from_file_location("example_choosing_an_integrator", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = {(r["integrator"], r["setting"]): r
            for r in module.run_experiment(fmu=fmu_path("C"), scenarios=("C stick-slip",))["C stick-slip"]}
    fixed_step = [r for (integrator, _), r in rows.items() if integrator != "adaptive"]
    # The fixed-step schemes place each Coulomb reset on their grid: whatever their order and
    # step, the switches keep their error far above the adaptive runs'.
    assert len(fixed_step) == 4 and min(r["error"] for r in fixed_step) > 1e-3
    assert rows["adaptive", "rtol 1e-6"]["error"] < 1e-3
    tight = rows["adaptive", "rtol 1e-10"]
    assert tight["error"] < 1e-8
    # The cost outputs count the resets the run went through and the steps it took.
    assert tight["located_events"] > 50 and tight["accepted_steps"] > tight["located_events"]
