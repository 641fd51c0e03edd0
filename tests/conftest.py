import numpy as np
import pytest

from drake_entry.models.atmosphere import US76Atmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import load_vehicle


@pytest.fixture(scope="session")
def horus():
    return load_vehicle("horus2b")


@pytest.fixture(scope="session")
def us76():
    return US76Atmosphere()


@pytest.fixture
def entry_state():
    """A HORUS-like hypersonic state [h, lon, lat, V, gamma, psi]."""
    return np.array([70e3, np.radians(-100.0), np.radians(-20.0), 6500.0, np.radians(-0.5), np.radians(70.0)])


@pytest.fixture(scope="session")
def earth():
    return Earth.spherical()
