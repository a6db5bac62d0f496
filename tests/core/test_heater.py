"""The heater's hold (thermocal.heater) on heated IMUs simulated as boards record them (cold
boot, the heater's ramp, its controller's overshoot, a ±0.3 °C hold, the heater turned off,
a log that starts at the set-point): the simulator's truth (tests/helpers/fc_logs.py), not
the code under test, gives the numbers."""

from __future__ import annotations

import numpy as np
import pytest

from fc_logs import heated_truth
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.heater import (
    HeaterOptions,
    HeaterPolicy,
    find_heater_hold,
    heater_setpoint,
    judge_heater,
    thin_hold,
)


@pytest.mark.parametrize("seed", [0, 7])
@pytest.mark.parametrize("setpoint", [55.0, None])
def test_hold_found_within_a_second_of_the_truth(seed: int, setpoint: float | None) -> None:
    tr = heated_truth(seed)
    hold = find_heater_hold(tr["time_s"], tr["temp"], setpoint_c=setpoint)
    assert hold is not None
    assert abs(hold.reached_s - tr["reached_s"]) < 1.0
    assert abs(hold.setpoint_c - 55.0) < 0.05
    assert hold.setpoint_source == ("given" if setpoint else "inferred")
    # the peak: the noiseless overshoot plus at most the ±0.2 °C ripple and 4σ of noise
    assert abs(hold.overshoot_c - tr["overshoot_c"]) < 0.2 + 0.12
    assert abs(hold.overshoot_at_s - tr["overshoot_at_s"]) < 45.0 / 4  # a quarter ripple
    # held to the end of the log; the band held within the asked ±0.5 °C and its 1 s gaps
    assert hold.heater_off_s is None
    assert hold.hold_end_s == pytest.approx(tr["time_s"][-1])
    lo, hi = hold.held_c
    assert -0.65 < lo < -0.2 and 0.2 < hi < 0.65
    # settled once the overshoot (1.6 °C·e^(−u/25 s)) is inside the band with the ripple:
    # 1.6·e^(−u/25) + 0.2 + 0.1 ≤ 0.5 → u ≥ 25·ln(8) = 52 s at the latest
    assert 0.0 < hold.settling_s < 25.0 * np.log(1.6 / 0.2)
    assert hold.range_cut
    assert hold.sweep_c[0] == pytest.approx(15.0, abs=0.15)


def test_heater_turned_off_mid_log() -> None:
    tr = heated_truth(3, heater_off_s=1500.0)
    hold = find_heater_hold(tr["time_s"], tr["temp"], setpoint_c=55.0)
    assert hold is not None and hold.heater_off_s is not None
    # cooling 40 °C/300 s = 0.13 °C/s leaves the band (0.5 °C + 0.1 noise) within 5 s
    assert 0.0 <= hold.heater_off_s - 1500.0 < 5.0
    assert hold.range_cut  # cooling afterwards: still nothing above the set-point


def test_a_log_at_the_setpoint_is_refused_naming_the_heater_parameter() -> None:
    tr = heated_truth(1, at_setpoint=True)
    with pytest.raises(ThermocalInputError, match=r"no sweep.*SENS_EN_THERMAL=0"):
        judge_heater(tr["time_s"], tr["temp"], where="log", setpoint_c=55.0, firmware="px4")
    with pytest.raises(ThermocalInputError, match=r"BRD_HEAT_TARG=-1"):
        judge_heater(tr["time_s"], tr["temp"], where="log", setpoint_c=55.0, firmware="ardupilot")
    # no set-point known: a plateau without a sweep is no heater's (the adequacy judges it)
    assert judge_heater(tr["time_s"], tr["temp"], where="log", firmware="px4").hold is None


def test_plateaus_of_other_tests_are_no_heater() -> None:
    # a MEMS gyro's self-heating warm-up: 8 °C in a first-order rise (τ = 120 s), then flat
    t = np.arange(0.0, 1800.0, 0.5)
    warmup = 25.0 + 8.0 * (1.0 - np.exp(-t / 120.0))
    assert find_heater_hold(t, warmup) is None
    # a turntable's or a multi-position session at one temperature
    assert find_heater_hold(t, np.full(t.size, 25.0)) is None


def test_refuse_names_the_policy_and_ignore_looks_for_nothing() -> None:
    tr = heated_truth(2)
    with pytest.raises(ThermocalInputError) as err:
        judge_heater(tr["time_s"], tr["temp"], where="log", policy=HeaterPolicy.REFUSE)
    assert "give heater cut" in str(err.value) and "its set-point raised" in str(err.value)
    ignored = judge_heater(tr["time_s"], tr["temp"], where="log", policy=HeaterPolicy.IGNORE)
    assert ignored.hold is None and ignored.keep is None


def test_a_setpoint_never_reached_is_said() -> None:
    t = np.arange(0.0, 1800.0, 0.1)
    temp = 20.0 + 30.0 * (0.5 - 0.5 * np.cos(np.pi * t / t[-1]))  # a sweep, no plateau
    judged = judge_heater(t, temp, where="log", setpoint_c=65.0, setpoint_source="BRD_HEAT_TARG")
    assert judged.hold is None
    assert len(judged.warnings) == 1
    assert "65.0 °C (BRD_HEAT_TARG) is never held" in judged.warnings[0]
    assert "peaks at 50.0 °C" in judged.warnings[0]


def test_a_chamber_step_program_is_no_heater() -> None:
    # three 20-minute holds at 0, 25 and 50 °C joined by 1 °C/min ramps: a chamber's program
    t = np.arange(0.0, 3 * 1200.0 + 2 * 1500.0, 1.0)
    temp = np.interp(t, [0, 1200, 2700, 3900, 5400, 6600], [0, 0, 25, 25, 50, 50])
    temp = temp + np.random.default_rng(0).normal(0.0, 0.05, t.size)
    assert find_heater_hold(t, temp) is None
    # told its set-point, the top hold is found (what the user asked)
    assert find_heater_hold(t, temp, setpoint_c=50.0) is not None


def test_thinned_hold_has_the_density_of_the_sweep() -> None:
    tr = heated_truth(4)
    hold = find_heater_hold(tr["time_s"], tr["temp"], setpoint_c=55.0)
    assert hold is not None
    keep = thin_hold(tr["time_s"], tr["temp"], hold)
    inside = (tr["time_s"] >= hold.hold_start_s) & (tr["time_s"] <= hold.hold_end_s)
    out_t = tr["temp"][~inside]
    density = out_t.size / (out_t.max() - out_t.min())  # samples per °C outside the hold
    width = np.diff(np.percentile(tr["temp"][inside], [5, 95]))[0]  # its central 90 %
    assert np.all(keep[~inside])
    assert int(keep[inside].sum()) == pytest.approx(density * width, abs=2)
    assert int(keep[inside].sum()) < inside.sum() / 20


def test_the_thinned_fit_is_judged_on_the_sweep() -> None:
    # the bias is no exact cubic (a quartic term) and keeps settling during the hold (the
    # board warms after its thermometer: 2 units with τ = 600 s from the set-point on); a
    # cubic's least squares dominated by the hold's samples at 55 °C bends away from the
    # sweep. numpy's polyfit is the fit
    tr = heated_truth(5, hold_s=3000.0)
    T, t = tr["temp"], tr["time_s"]
    x = (T - 35.0) / 20.0
    rng = np.random.default_rng(1)
    settling = 2.0 * (1.0 - np.exp(-np.clip(t - tr["reached_s"], 0.0, None) / 600.0))
    bias = 10.0 * x + 4.0 * x**2 + 3.0 * x**4 + settling + rng.normal(0.0, 0.3, T.size)
    hold = find_heater_hold(t, T, setpoint_c=55.0)
    assert hold is not None
    inside = (t >= hold.hold_start_s) & (t <= hold.hold_end_s)
    sweep = ~inside

    def rms_on_sweep(mask: np.ndarray) -> float:
        p = np.polyfit(x[mask], bias[mask], 3)
        return float(np.sqrt(np.mean((np.polyval(p, x[sweep]) - bias[sweep]) ** 2)))

    without_hold = rms_on_sweep(sweep)
    thinned = rms_on_sweep(thin_hold(t, T, hold))
    everything = rms_on_sweep(np.ones(T.size, dtype=bool))
    assert thinned <= 1.1 * without_hold
    assert everything > 1.1 * without_hold  # the hold unthinned would have spoilt the sweep


def test_heater_setpoint_from_the_firmware_parameters() -> None:
    assert heater_setpoint({"SENS_EN_THERMAL": 1, "SENS_IMU_TEMP": 60.0}, "px4") == (
        60.0,
        "SENS_IMU_TEMP",
    )
    assert heater_setpoint({"SENS_EN_THERMAL": 0, "SENS_IMU_TEMP": 60.0}, "px4") == (
        None,
        "SENS_EN_THERMAL=0",
    )
    assert heater_setpoint({"SENS_EN_THERMAL": -1, "SENS_IMU_TEMP": 55.0}, "px4")[0] is None
    assert heater_setpoint({"BRD_IMU_TARGTEMP": 45.0}, "ardupilot") == (45.0, "BRD_IMU_TARGTEMP")
    assert heater_setpoint({"BRD_HEAT_TARG": -1.0}, "ardupilot") == (None, "BRD_HEAT_TARG=-1")
    assert heater_setpoint({}, "ardupilot") == (None, None)


def test_bad_options_name_their_parameter() -> None:
    with pytest.raises(ParameterError, match="heater must be cut, refuse or ignore"):
        HeaterOptions("off")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="band_c must be positive"):
        find_heater_hold(np.arange(3.0), np.zeros(3), band_c=0.0)
    with pytest.raises(ParameterError, match="heater_min_hold must be positive"):
        HeaterOptions(min_hold_s=-1.0)


def test_lost_readings_are_left_out_not_fatal() -> None:
    """A log whose thermometer drops readings (NaN every 1000th sample, as a DataFlash log
    with lost IMU temperatures): the hold is the one found without them; it raised
    ``arange: cannot compute length`` (an internal error, exit 1, through the commands)."""
    import numpy as np

    from thermocal.heater import find_heater_hold

    t = np.arange(0.0, 600.0, 0.1)
    temp = np.minimum(20.0 + 0.2 * t, 55.0)
    clean = find_heater_hold(t, temp)
    lost = temp.copy()
    lost[::1000] = np.nan
    found = find_heater_hold(t, lost)
    assert clean is not None and found is not None
    assert abs(found.reached_s - clean.reached_s) < 0.2
    assert abs(found.hold_s - clean.hold_s) < 0.2


def test_a_damaged_temperature_range_infers_no_setpoint() -> None:
    """A damaged log whose temperature field reads 1e9 °C in one row: the plateau search
    asked for 17e9 windows (MemoryError: 128 GiB, an internal error through ardupilot-tempcal);
    no set-point is inferred from a range no thermometer spans."""
    import numpy as np

    from thermocal.heater import find_heater_hold

    t = np.arange(0.0, 600.0, 0.1)
    temp = np.minimum(20.0 + 0.2 * t, 55.0)
    temp[100] = 1e9
    assert find_heater_hold(t, temp) is None


def test_a_long_record_is_searched_on_a_bounded_subsample() -> None:
    """Above HOLD_MAX_SAMPLES the hold is looked for on every k-th sample (the search held
    26 B per sample: +150 MB for a 1e7-row fit): a 3e6-sample ramp at 1 kHz to 55 °C and a
    hold still has its set-point reached within k sample intervals of the truth."""
    import numpy as np

    from thermocal.heater import HOLD_MAX_SAMPLES, find_heater_hold

    t = np.arange(3_000_000) * 1e-3  # 50 min at 1 kHz
    temp = np.minimum(20.0 + 0.05 * t, 55.0)  # 55 °C reached at 700 s
    hold = find_heater_hold(t, temp, setpoint_c=55.0)
    assert hold is not None and t.size > HOLD_MAX_SAMPLES
    k = -(-t.size // HOLD_MAX_SAMPLES)
    assert abs(hold.reached_s - 700.0) <= k * 1e-3 + 1e-9
    assert abs(hold.hold_end_s - t[-1]) <= k * 1e-3


def _chamber_with_heater(boost_c: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A chamber sweep −20 → 70 °C over 3 h (1 Hz) recorded with a heater holding 45 °C:
    the IMU at the ambient plus 5 °C of self-heating, plus up to ``boost_c`` from the
    heater, never above the set-point while the ambient is below it; powered on cold, the
    heater warming it at 0.5 °C/s at most."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 3 * 3600.0, 1.0)
    ambient = -20.0 + 90.0 * t / t[-1]
    own = ambient + 5.0
    target = np.maximum(own, np.minimum(45.0, own + boost_c))
    temp = np.minimum(target, own[0] + 0.5 * t)  # the warm-up from power-on
    return t, temp + 0.05 * rng.standard_normal(t.size)


def test_a_sweep_recorded_with_the_heater_on_misses_its_cold_end() -> None:
    t, temp = _chamber_with_heater(boost_c=80.0)
    j = judge_heater(t, temp, where="log", setpoint_c=45.0, firmware="px4")
    assert j.hold is not None and j.hold.cold_cut and not j.hold.range_cut
    # the ambient reaches 40 °C (45 − 5 of self-heating) at 2 h: held until then
    assert j.hold.hold_end_s == pytest.approx(7200.0, abs=120.0)
    (said,) = j.warnings
    assert "cold end of the range is missing" in said and "SENS_EN_THERMAL=0" in said
    with pytest.raises(ThermocalInputError, match="cold end"):
        judge_heater(t, temp, where="log", setpoint_c=45.0, policy=HeaterPolicy.REFUSE)


def test_a_weak_heater_tracking_the_chamber_below_its_setpoint_keeps_its_cold_end() -> None:
    # 25 °C of boost: the IMU below 45 °C until the ambient reaches 15 °C (70 min)
    t, temp = _chamber_with_heater(boost_c=25.0)
    j = judge_heater(t, temp, where="log", setpoint_c=45.0, firmware="px4")
    assert j.hold is not None and not j.hold.cold_cut and not j.hold.range_cut
    assert j.warnings == ()


def test_a_heater_hold_at_the_top_is_no_cold_cut() -> None:
    tr = heated_truth(0)
    hold = find_heater_hold(tr["time_s"], tr["temp"], setpoint_c=55.0)
    assert hold is not None and hold.range_cut and not hold.cold_cut


@pytest.mark.parametrize("step", [0.5, 0.0625, 0.1])
def test_the_plateau_search_bins_every_sample_as_numpy_histogram(step: float) -> None:
    """The time per temperature window (the search for an inferred set-point) is summed
    without a sort, a block at a time: each sample in the window ``np.histogram`` gives it
    against the same edges — samples exactly on an edge, one unit in the last place either
    side of one, on the last (closed) edge, outside the edges, a record of several blocks
    and a partial one — and the same time per window to rounding."""
    from thermocal.heater import WINDOW_BLOCK, _window_time

    rng = np.random.default_rng(11)
    n = 2 * WINDOW_BLOCK + 123
    temp = np.round(rng.uniform(-10.0, 60.0, n) / step) * step  # a thermometer's lattice
    temp[::7] += rng.uniform(-step, step, temp[::7].size)  # and readings between
    lo, hi = float(temp.min()), float(temp.max())
    edges = np.arange(lo, hi + 2 * step, step)  # as the search makes them
    temp[:50] = edges[rng.integers(0, edges.size, 50)]  # exactly on edges, the last included
    temp[50], temp[51] = edges[-1], lo - 1.0  # the closed last edge; a sample outside
    near = edges[rng.integers(1, edges.size - 1, 400)]  # one unit in the last place off
    temp[52:452] = np.nextafter(near, np.where(np.arange(400) % 2, np.inf, -np.inf))
    weights = rng.uniform(0.05, 0.15, n)
    counted = _window_time(temp, np.ones(n), edges)
    np.testing.assert_array_equal(counted, np.histogram(temp, bins=edges)[0])
    spent = _window_time(temp, weights, edges)
    want = np.histogram(temp, bins=edges, weights=weights)[0]
    np.testing.assert_allclose(spent, want, rtol=1e-12, atol=1e-12 * weights.sum())
