"""The empirical nominal atmosphere (atmosphere.model: nrlmsis): NRLMSIS 2.1 through pymsis at
one place and time with the scenario's own solar and geomagnetic indices, tabulated for the
Drake plant."""
import math

import numpy as np
import pytest

from drake_entry.errors import ScenarioError
from drake_entry.models.atmosphere import US76Atmosphere
from drake_entry.models.environment import AtmosphereSpec, atmosphere_from_spec

SPEC = AtmosphereSpec(model="nrlmsis", nrlmsis_utc="2025-06-21T12:00:00", nrlmsis_latitude_deg=45.0,
                      nrlmsis_longitude_deg=10.0, f107_sfu=120.0, f107a_sfu=130.0, ap=9.0)


def test_the_table_is_pymsis_at_its_nodes_and_names_its_inputs():
    import pymsis

    air = atmosphere_from_spec(SPEC)
    alts = np.array([0.0, 30.0, 61.0, 95.0, 150.0])
    out = pymsis.calculate(np.datetime64("2025-06-21T12:00:00"), 10.0, 45.0, alts, f107s=120.0, f107as=130.0,
                           aps=[[9.0] * 7], version=2.1)
    rho = out[..., pymsis.Variable.MASS_DENSITY].ravel()
    T = out[..., pymsis.Variable.TEMPERATURE].ravel()
    for h, r, t in zip(alts * 1e3, rho, T):
        assert air.density(h) == pytest.approx(r, rel=1e-6) and air.temperature(h) == pytest.approx(t, rel=1e-6)
    assert "NRLMSIS 2.1" in air.source and "45 deg N" in air.source and "F10.7 120" in air.source
    assert "Ap 9" in air.source and air.h_max == pytest.approx(200e3)


def test_at_mid_latitude_it_is_near_the_standard_atmosphere():
    """US76 is a mid-latitude annual mean: at 45 deg N in June NRLMSIS's density stays within 35 % of
    it and its temperature within 15 % from the ground to 90 km (the summer mesopause is 12 % colder
    at 85 km); an independent check of units and columns, not of either model."""
    air, us76 = atmosphere_from_spec(SPEC), US76Atmosphere()
    for h in np.arange(0.0, 90e3 + 1, 5e3):
        assert air.density(h) / us76.density(h) == pytest.approx(1.0, abs=0.35), h
        assert air.temperature(h) / us76.temperature(h) == pytest.approx(1.0, abs=0.15), h


@pytest.mark.parametrize("field, value, match", [
    ("nrlmsis_utc", "", "nrlmsis_utc = '': give the UTC date and time"),
    ("nrlmsis_utc", "midsummer", "nrlmsis_utc = 'midsummer'"),
    ("nrlmsis_latitude_deg", 95.0, r"nrlmsis_latitude_deg = 95.0 is out of range; allowed: \[-90, 90\]"),
    ("f107_sfu", -1.0, r"f107_sfu = -1.0 is out of range"),
    ("ap", math.nan, "ap = nan is out of range"),
])
def test_bad_nrlmsis_input_is_one_line_naming_the_field(field, value, match):
    import dataclasses as dc

    with pytest.raises(ScenarioError, match=f"atmosphere.{match}"):
        atmosphere_from_spec(dc.replace(SPEC, **{field: value}))


def test_a_scenario_flies_its_nrlmsis_atmosphere_natively():
    import dataclasses as dc

    from drake_entry.diagrams.closed_loop import ClosedLoopSetup, build_closed_loop
    from drake_entry.scenario import load_scenario

    scenario = load_scenario("horus2b")
    scenario.atmosphere = dc.replace(SPEC, nrlmsis_latitude_deg=-22.3, nrlmsis_longitude_deg=-106.7)
    scenario.validate()
    built = build_closed_loop(ClosedLoopSetup.from_scenario(scenario))
    assert built.plant == "native"
