"""The DOP853 tableau the adaptive integrator ships is scipy's, to the bit."""
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate._ivp import dop853_coefficients as scipy_tableau

from vibroblock.integrators.adaptive import dop853


@pytest.mark.parametrize("name", ["A", "B", "C", "E5", "E3"])
def test_the_stored_tableau_is_scipys(name):
    with np.load(dop853.TABLEAU) as stored:
        np.testing.assert_array_equal(stored[name], getattr(scipy_tableau, name), strict=True)


def test_the_first_step_of_an_fmu_does_not_import_scipy_integrate():
    """Importing the core (what an FMU's instantiate does) leaves scipy.integrate out: it
    costs a third of a second, a third of the first doStep's budget."""
    probe = "import sys, vibroblock.integrators; print('scipy.integrate' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "False"
