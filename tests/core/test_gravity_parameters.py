"""The gravity of ``fit --gravity-axis`` as a library call: its refusals name the library's
parameters (``gravity``, ``gravity_axis``); the command line shows its options in their place
(``tests/test_gravity_tref.py`` checks the command line's texts)."""

from __future__ import annotations

import pickle

import pytest

from thermocal.errors import ParameterError
from thermocal.gravity import local_gravity_m_s2
from thermocal.pipeline.messages import error_text


def test_gravity_without_its_axis_names_both_parameters() -> None:
    with pytest.raises(ParameterError) as err:
        local_gravity_m_s2(None, 9.8, None)
    assert err.value.parameter == "gravity"
    assert str(err.value) == "gravity applies with gravity_axis only"
    # the command line's line: both parameters shown as their options
    assert error_text(err.value) == ("--gravity applies with --gravity-axis only", True)
    # the fleet's workers send it across processes
    back = pickle.loads(pickle.dumps(err.value))
    assert str(back) == str(err.value) and back.others == ("gravity_axis",)


@pytest.mark.parametrize("g", [98.1, 9.69, 9.91])
def test_gravity_off_the_earth_is_refused_by_its_name(g: float) -> None:
    """Local gravity on the earth's surface is 9.78-9.83 m/s² (WGS-84 normal gravity 9.7803
    at the equator to 9.8322 at the poles); 9.7-9.9 is accepted."""
    with pytest.raises(ParameterError) as err:
        local_gravity_m_s2("+z", g, None)
    assert str(err.value).startswith(f"gravity {g:g}: local gravity")


def test_gravity_accepted_and_latitude_gives_normal_gravity() -> None:
    """WGS-84 normal gravity (Somigliana with the WGS-84 constants) at 45°: 9.806199 m/s²,
    computed here from its published constants, not from thermocal."""
    assert local_gravity_m_s2("+z", 9.8, None) == 9.8
    assert local_gravity_m_s2(None, None, 45.0) is None
    ge, k, e2 = 9.7803253359, 0.00193185265241, 0.00669437999013
    s2 = 0.5  # sin²(45°)
    want = ge * (1 + k * s2) / (1 - e2 * s2) ** 0.5
    assert local_gravity_m_s2("+z", None, 45.0) == pytest.approx(want, abs=1e-6)
