"""The gravity of ``fit --gravity-axis`` as a library call: its refusals name the library's
parameters (``gravity``, ``gravity_axis``); the command line shows its options in their place
(``tests/core/test_gravity_tref.py`` checks the command line's texts)."""

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


def test_a_channel_without_an_axis_letter_names_gravity_axis_and_known_input() -> None:
    """``channel_gravity`` of an accelerometer channel named ``acc`` (no x, y or z at its
    end) with an up axis: the refusal names both parameters, the command line's options."""
    import numpy as np

    from thermocal.gravity import channel_gravity

    with pytest.raises(ParameterError) as err:
        channel_gravity(None, 0, "run.csv", "acc", "mg", np.full(10, 1000.0), "+z", 9.81)
    assert str(err.value) == (
        "gravity_axis +z: channel 'acc' names no axis (x, y or z as its last letter); "
        "fit it with known_input instead"
    )
    assert error_text(err.value)[0] == (
        "--gravity-axis +z: channel 'acc' names no axis (x, y or z as its last letter); "
        "fit it with --known-input instead"
    )


def test_an_up_axis_reading_off_gravity_names_gravity_axis() -> None:
    """az reads 0 mg where +z up means +1000.0 mg (g = 9.80665 m/s²): refused."""
    import numpy as np

    from thermocal.gravity import channel_gravity

    with pytest.raises(ParameterError) as err:
        channel_gravity(None, 0, "run.csv", "az", "mg", np.zeros(10), "+z", 9.80665)
    text, users = error_text(err.value)
    assert users and text.startswith("run.csv: --gravity-axis +z: az should read about +1000.0")
    assert str(err.value).startswith("run.csv: gravity_axis +z: az should read about +1000.0")
