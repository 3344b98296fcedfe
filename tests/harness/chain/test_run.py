"""``harness.chain.run.simulate_chain`` drives either chain FMU: BlockChain.fmu (FMI 2.0, N
fixed at build) and BlockChain3.fmu (FMI 3.0, N set at run time) give the same run."""
import numpy as np
import pytest

from harness.chain.run import simulate_chain


def harmonic_table(stop: float, step: float, acceleration: float, omega: float) -> np.ndarray:
    t = np.arange(0.0, stop + 1e-9, step)
    table = np.zeros(t.size, dtype=[("time", float), ("plate_z", float), ("plate_v", float), ("plate_a", float)])
    amplitude = acceleration / omega ** 2
    table["time"] = t
    table["plate_z"], table["plate_v"] = amplitude * np.sin(omega * t), amplitude * omega * np.cos(omega * t)
    table["plate_a"] = -acceleration * np.sin(omega * t)
    return table


@pytest.mark.parametrize("plate", [False, True], ids=["own drive", "plate input"])
def test_both_chain_fmus_give_the_same_catalogue_and_aggregates(fmu_dir, tmp_path, plate):
    stop, step = 12_000.0, 4.0
    values = {"mu_s_spread": 0.3, "seed": 1}
    if plate:
        kwargs = {"plate": harmonic_table(stop, step, 0.3, 0.2)}
    else:
        kwargs = {}
        values.update(A=0.5, omega=0.25)
    runs = {}
    for name, extra in (("BlockChain", {}), ("BlockChain3", {"N": 16})):
        runs[name] = simulate_chain(fmu_dir / f"{name}.fmu", stop_time=stop, step_size=step,
                                    catalog=tmp_path / f"{name}.csv", start_values={**values, **extra}, **kwargs)
    (result2, events2), (result3, events3) = runs["BlockChain"], runs["BlockChain3"]
    assert len(events2) >= 2 and events2.equals(events3)
    for name in ("moment_rate", "event_count", "coulomb_resets", "slipping_fraction"):
        assert np.array_equal(result2[name], result3[name]), name
    assert result2["coulomb_resets"][-1] > 0
