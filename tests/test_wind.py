"""Wind models: 1-cosine gust, profiles, Dryden turbulence statistics, jet stream, sums."""

import doctest
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.signal import welch

from lvgym.environment import turbulence, wind
from lvgym.environment.registry import make, names
from lvgym.errors import ConfigError

FT = 0.3048


def rng(seed=0):
    return np.random.default_rng(seed)


def test_all_models_registered():
    assert set(names("wind")) >= {"none", "profile", "gust", "dryden", "jet_stream", "sum"}


def test_none_is_zero():
    model = make("wind", "none")
    model.reset(rng())
    np.testing.assert_array_equal(model.velocity_ned([0.0, 1e4], [0.0, 5.0]), np.zeros((2, 3)))


# ---------------------------------------------------------------- 1-cosine gust (MIL-HDBK-1797)
def test_one_minus_cosine_shape_at_hand_points():
    # V = (Vm / 2)(1 - cos(pi x / dm)) for 0 <= x <= dm, 0 before, Vm after (MIL-F-8785C)
    gust = make("wind", {"model": "gust", "amplitude": 10.0, "length": 100.0,
                         "direction_deg": 90.0, "onset": 1000.0})
    x = np.array([-10.0, 0.0, 25.0, 50.0, 75.0, 100.0, 150.0, 1e4])
    v = gust.velocity_ned(1000.0 + x)
    expected = [0.0, 0.0, 5.0 * (1.0 - math.sqrt(0.5)), 5.0, 5.0 * (1.0 + math.sqrt(0.5)), 10.0,
                10.0, 10.0]
    # an east (90 deg) gust blows towards the west: negative east component, nothing else
    np.testing.assert_allclose(-v[:, 1], expected, atol=1e-12)
    np.testing.assert_allclose(v[:, [0, 2]], 0.0, atol=1e-12)
    bump = make("wind", {"model": "gust", "amplitude": 10.0, "length": 100.0,
                         "direction_deg": 0.0, "onset": 1000.0, "shape": "bump"})
    np.testing.assert_allclose(-bump.velocity_ned(1000.0 + np.array([50.0, 100.0, 150.0, 200.0,
                                                                      300.0]))[:, 0],
                               [5.0, 10.0, 5.0, 0.0, 0.0], atol=1e-12)


def test_gust_onset_by_time():
    gust = make("wind", {"model": "gust", "amplitude": 4.0, "length": 100.0, "direction_deg": 180.0,
                         "onset": 10.0, "onset_by": "time", "speed": 200.0})
    # x = 200 m/s (t - 10 s): half amplitude at x = 50 m, t = 10.25 s; blows from the south
    v = gust.velocity_ned(5000.0, np.array([9.0, 10.25, 10.5, 30.0]))
    np.testing.assert_allclose(v[:, 0], [0.0, 2.0, 4.0, 4.0], atol=1e-12)
    with pytest.raises(ConfigError, match=r"wind\.speed = <missing>: required"):
        make("wind", {"model": "gust", "onset_by": "time"})
    with pytest.raises(ConfigError, match=r"wind\.shape = 'square': one of"):
        make("wind", {"model": "gust", "shape": "square"})


# ---------------------------------------------------------------- profile
def test_profile_interpolation_and_from_convention():
    prof = make("wind", {"model": "profile", "altitude_m": [0.0, 1000.0, 3000.0],
                         "speed": [0.0, 10.0, 20.0], "direction_deg": [0.0, 270.0, 270.0]})
    v = prof.velocity_ned(np.array([-50.0, 1000.0, 2000.0, 9000.0]))
    # a 270 deg (west) wind blows towards the east; components interpolated linearly; held outside
    np.testing.assert_allclose(v, [[0, 0, 0], [0, 10, 0], [0, 15, 0], [0, 20, 0]], atol=1e-12)
    # halfway between 0 m/s from the north and 10 m/s from the west: half the west vector
    np.testing.assert_allclose(prof.velocity_ned(500.0), [0.0, 5.0, 0.0], atol=1e-12)
    north = make("wind", {"model": "profile", "altitude_m": [0.0], "speed": [7.0],
                          "direction_deg": [0.0]})
    np.testing.assert_allclose(north.velocity_ned(123.0), [-7.0, 0.0, 0.0], atol=1e-12)
    to = make("wind", {"model": "profile", "altitude_m": [0.0], "speed": [7.0],
                       "direction_deg": [0.0], "convention": "to"})
    np.testing.assert_allclose(to.velocity_ned(123.0), [7.0, 0.0, 0.0], atol=1e-12)


def test_profile_from_csv_and_yaml(tmp_path):
    csv_file = tmp_path / "w.csv"
    csv_file.write_text("# sounding\naltitude_m,speed,direction_deg\n0,2,90\n1000,12,90\n")
    yaml_file = tmp_path / "w.yaml"
    yaml_file.write_text("altitude_m: [0, 1000]\nspeed: [2, 12]\ndirection_deg: [270, 270]\n"
                         "convention: to\n")
    a = make("wind", {"model": "profile", "file": str(csv_file)}).velocity_ned(500.0)
    b = make("wind", {"model": "profile", "file": str(yaml_file)}).velocity_ned(500.0)
    np.testing.assert_allclose(a, [0.0, -7.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(b, a, atol=1e-12)
    bad = tmp_path / "bad.yaml"
    bad.write_text("altitude_m: [0]\nspeed: [1]\ndirection: [0]\n")
    with pytest.raises(ConfigError, match=r"bad\.yaml: wind\.direction = \[0\]: unknown key"):
        make("wind", {"model": "profile", "file": str(bad)})


def test_profile_config_errors():
    with pytest.raises(ConfigError, match=r"wind\.altitude_m = .*strictly increasing"):
        make("wind", {"model": "profile", "altitude_m": [0, 0], "speed": [1, 1],
                      "direction_deg": [0, 0]})
    with pytest.raises(ConfigError, match=r"wind\.speed = .*as many values"):
        make("wind", {"model": "profile", "altitude_m": [0, 1], "speed": [1],
                      "direction_deg": [0, 0]})
    with pytest.raises(ConfigError, match=r"wind\.convention = 'towards': one of"):
        make("wind", {"model": "profile", "altitude_m": [0], "speed": [1], "direction_deg": [0],
                      "convention": "towards"})


# ---------------------------------------------------------------- Dryden scales and intensities
def test_dryden_low_altitude_scales_match_the_formula():
    # MIL-F-8785C: L_u = L_v = h / (0.177 + 0.000823 h)^1.2, L_w = h (h in ft),
    # sigma_w = 0.1 W20, sigma_u / sigma_w = 1 / (0.177 + 0.000823 h)^0.4. At h = 500 ft by hand:
    # 0.177 + 0.4115 = 0.5885; 0.5885^1.2 = 0.52930 -> L_u = 944.66 ft; 0.5885^-0.4 = 1.23624.
    # (The wrong 0.00823 / exponent 0.2 variant gives 373.5 ft.)
    lengths, sigmas = turbulence.dryden_scales(500.0 * FT, 15.0, 1e-3)
    assert lengths[0] / FT == pytest.approx(944.66, abs=0.01)
    assert lengths[1] == lengths[0]
    assert lengths[2] / FT == pytest.approx(500.0)
    assert sigmas[2] == pytest.approx(1.5)
    assert sigmas[0] / sigmas[2] == pytest.approx(1.23624, abs=1e-5)
    assert sigmas[1] == sigmas[0]
    # clipped at 10 ft like JSBSim
    np.testing.assert_allclose(turbulence.dryden_scales(0.0, 15.0, 1e-3)[0],
                               turbulence.dryden_scales(10 * FT, 15.0, 1e-3)[0])


def test_dryden_medium_high_altitude_table():
    # above 2000 ft: L = 1750 ft; sigma from MIL-F-8785C Fig. 7 (JSBSim FGWinds table). At 5000 ft,
    # moderate (1e-3): 10.6 + (5000 - 3750) / 3750 (10.1 - 10.6) = 10.4333 ft/s
    lengths, sigmas = turbulence.dryden_scales(5000 * FT, 15.0, 1e-3)
    np.testing.assert_allclose(lengths / FT, 1750.0)
    np.testing.assert_allclose(sigmas / FT, 10.43333, atol=1e-5)
    # severe (1e-5) at 80,000 ft and above: 5.1 ft/s; light (1e-2) at 45,000 ft: none
    assert turbulence.dryden_scales(90000 * FT, 15.0, 1e-5)[1][0] / FT == pytest.approx(5.1)
    assert turbulence.dryden_scales(45000 * FT, 15.0, 1e-2)[1][2] == 0.0
    # 1500 ft: halfway between the 1000 ft low-altitude values (L = 1000 ft, sigma = 0.1 W20 for
    # all three) and the 2000 ft table values (L = 1750 ft, 9.725 ft/s)
    lengths, sigmas = turbulence.dryden_scales(1500 * FT, 15.0, 1e-3)
    np.testing.assert_allclose(lengths / FT, 1375.0)
    np.testing.assert_allclose(sigmas, 0.5 * 1.5 + 0.5 * 9.725 * FT)


def test_dryden_spectra_integrate_to_the_variance():
    for comp in "uvw":
        total, _ = quad(lambda om: turbulence.dryden_psd(om, 2.0, 300.0, comp), 0.0, np.inf)
        assert total == pytest.approx(4.0, rel=1e-8)


def test_dryden_intensity_presets_and_errors():
    model = make("wind", {"model": "dryden", "intensity": "severe", "alt_max_m": 2000.0})
    assert model.w20 == pytest.approx(45 * 1852 / 3600) and model.probability == 1e-5
    with pytest.raises(ConfigError, match=r"wind\.probability = 0\.5: one of"):
        make("wind", {"model": "dryden", "probability": 0.5})
    with pytest.raises(ConfigError, match=r"wind\.airspeed = <missing>: required"):
        make("wind", {"model": "dryden", "coordinate": "time"})
    with pytest.raises(RuntimeError, match="reset"):
        model.velocity_ned(10.0)
    with pytest.raises(TypeError):
        model.reset(42)


# ---------------------------------------------------------------- Dryden realisations
@pytest.fixture(scope="module")
def long_time_field():
    # time field at 3000 m (L = 533.4 m, moderate sigma 9.444 ft/s) and 100 m/s: T_c = 5.334 s,
    # 20,000 correlation times, 10 nodes per correlation time
    model = make("wind", {"model": "dryden", "coordinate": "time", "airspeed": 100.0,
                          "altitude_m": 3000.0, "duration": 20000 * 533.4 / 100.0,
                          "resolution": 0.1, "wind_from_deg": 0.0})
    model.reset(rng(7))
    return model


def test_dryden_time_field_variance(long_time_field):
    m = long_time_field
    sigma = 9.44400 * FT                   # 10.1 + (9842.5 - 7500) / 7500 (8.0 - 10.1) ft/s
    np.testing.assert_allclose(m.sigma, sigma, rtol=1e-4)
    # wind from the north: u (along the mean wind) is -north, v is -east (to its right), w is down
    uvw = np.stack([-m.ned[:, 0], -m.ned[:, 1], m.ned[:, 2]], -1)
    var = np.mean(uvw ** 2, axis=0) / sigma ** 2
    # the sample variance over T = 20,000 T_c has a relative standard deviation sqrt(2 T_c / T) =
    # 1.0 % for u (correlation exp(-tau)) and sqrt(1.25 T_c / T) = 0.79 % for v, w; allow 4 of them
    assert abs(var[0] - 1.0) < 0.04
    assert np.all(np.abs(var[1:] - 1.0) < 0.032)
    assert np.all(np.abs(uvw.mean(axis=0)) / sigma < 0.05)


def test_dryden_time_field_correlation_and_spectrum(long_time_field):
    m = long_time_field
    unit = m.unit
    lag = 10                                   # one scale length (resolution 0.1)
    rho = [np.mean(unit[:-lag, c] * unit[lag:, c]) / np.mean(unit[:, c] ** 2) for c in range(3)]
    # Dryden correlations at xi = L: u exp(-1) = 0.3679, v and w exp(-1) / 2 = 0.1839. Bartlett's
    # formula for u (10 nodes of 0.1 L, 200,001 nodes) gives a standard error of 0.0055; allow 0.02
    assert rho[0] == pytest.approx(math.exp(-1.0), abs=0.02)
    assert rho[1] == pytest.approx(0.5 * math.exp(-1.0), abs=0.02)
    assert rho[2] == pytest.approx(0.5 * math.exp(-1.0), abs=0.02)
    # Welch PSD against the Dryden spectrum in time, S(f) = 2 pi Phi(2 pi f / V) / V, on octave bands
    # of L Omega from 0.25 to 4. Segments of 204.8 T_c (2048 nodes), ~190 half-overlapping: about
    # 350 degrees of freedom, 7.6 % scatter per bin; the bands hold 8 to 65 bins (3.8 % to 1.3 %),
    # so 12 % is about three standard deviations of the lowest band
    dt = m.grid[1] - m.grid[0]
    length, speed = m.scale_length[0, 0], 100.0
    f, psd = welch(unit * m.sigma[0], fs=1.0 / dt, nperseg=2048, axis=0)
    omega = 2 * math.pi * f / speed
    edges = np.geomspace(0.25, 4.0, 5) / length
    for c, comp in enumerate("uvw"):
        model = 2 * math.pi * turbulence.dryden_psd(omega, m.sigma[0, c], length, comp) / speed
        for lo, hi in zip(edges[:-1], edges[1:]):
            band = (omega >= lo) & (omega < hi)
            assert band.sum() >= 8
            assert psd[band, c].mean() / model[band].mean() == pytest.approx(1.0, abs=0.12)


def test_dryden_altitude_field_follows_local_scales():
    model = make("wind", {"model": "dryden", "intensity": "severe", "alt_min_m": 100.0,
                          "alt_max_m": 30e3, "wind_from_deg": 90.0})
    h = model.grid - 100.0
    lengths, sigmas = turbulence.dryden_scales(h, model.w20, 1e-5)
    np.testing.assert_allclose(model.scale_length, lengths)
    np.testing.assert_allclose(model.sigma, sigmas)
    assert h[0] == 0.0 and h[-1] == pytest.approx(29900.0)
    assert model._dtau.max() <= 0.02 * (1 + 1e-9)
    second = []
    for seed in range(12):
        model.reset(rng(seed))
        second.append(model.unit)
        # zero outside the column
        np.testing.assert_array_equal(model.velocity_ned([50.0, 30001.0]), 0.0)
    # normalised by the local sigma the field has unit variance. One 30 km column spans 57 (u, v)
    # and 61 (w) scale lengths; the mean square of one column scatters by 0.18 (u) and 0.14 (v, w)
    # over 200 seeds, so by 0.05 and 0.04 over these 12; allow 3 of them
    mean_square = np.mean(np.concatenate(second) ** 2, axis=0)
    assert abs(mean_square[0] - 1.0) < 0.15 and np.all(np.abs(mean_square[1:] - 1.0) < 0.12)
    # u is along the mean wind: from the east it blows towards the west
    model.reset(rng(1))
    v = model.velocity_ned(model.grid[2000])
    np.testing.assert_allclose(v, [model.sigma[2000, 1] * model.unit[2000, 1],
                                   -model.sigma[2000, 0] * model.unit[2000, 0],
                                   model.sigma[2000, 2] * model.unit[2000, 2]], atol=1e-12)


def test_dryden_is_seeded():
    model = make("wind", {"model": "dryden", "alt_max_m": 5000.0})
    model.reset(rng(3))
    first = model.params.copy()
    z = np.linspace(0.0, 5000.0, 101)
    v1 = model.velocity_ned(z, 1.0)
    model.reset(rng(3))
    np.testing.assert_array_equal(model.params, first)
    np.testing.assert_array_equal(model.velocity_ned(z, 7.0), v1)     # frozen: no time dependence
    model.reset(rng(4))
    assert np.abs(model.velocity_ned(z) - v1).max() > 0.1


# ---------------------------------------------------------------- jet stream and sums
def test_jet_stream_draws_within_ranges():
    jet = make("wind", {"model": "jet_stream", "peak_speed": [40.0, 50.0],
                        "direction_deg": [250.0, 290.0]})
    for seed in range(5):
        jet.reset(rng(seed))
        d = jet.drawn
        for key, (lo, hi) in jet.ranges.items():
            assert lo <= d[key] <= hi
        h_jet = d["peak_altitude_m"]
        v = jet.velocity_ned(h_jet)
        node = np.argmin(np.abs(jet.altitude_m - h_jet))
        assert np.linalg.norm(jet.velocity_ned(jet.altitude_m[node])) == pytest.approx(
            jet.profile.speed[node])
        assert np.linalg.norm(v) == pytest.approx(d["peak_speed"], rel=2e-3)
        azimuth_to = math.degrees(math.atan2(v[1], v[0]))
        assert (azimuth_to - d["direction_deg"] - 180.0 + 540.0) % 360.0 - 180.0 == \
            pytest.approx(0.0, abs=0.5)
        assert np.linalg.norm(jet.velocity_ned(0.0)) < 0.2 * d["peak_speed"]
        assert np.linalg.norm(jet.velocity_ned(40e3)) < 0.05 * d["peak_speed"]
    jet.reset(rng(9))
    a = jet.params.copy()
    jet.reset(rng(9))
    np.testing.assert_array_equal(jet.params, a)
    with pytest.raises(ConfigError, match=r"wind\.peak_speed = \[50, 40\]: a pair"):
        make("wind", {"model": "jet_stream", "peak_speed": [50, 40]})


def test_sum_adds_its_parts_and_resets_each():
    gust = {"model": "gust", "amplitude": 5.0, "length": 50.0, "onset": 500.0}
    prof = {"model": "profile", "altitude_m": [0.0, 2000.0], "speed": [0.0, 8.0],
            "direction_deg": [180.0, 180.0]}
    total = make("wind", {"model": "sum", "models": [gust, {"model": "sum", "models": [prof]},
                                                     {"model": "dryden", "alt_max_m": 3000.0}]})
    assert len(total.children) == 3                     # nested sum flattened
    total.reset(rng(11))
    z = np.linspace(0.0, 2500.0, 51)
    parts = sum(c.velocity_ned(z, 0.0) for c in total.children)
    np.testing.assert_allclose(total.velocity_ned(z, 0.0), parts, atol=1e-12)
    first = total.params.copy()
    total.reset(rng(11))
    np.testing.assert_array_equal(total.params, first)
    with pytest.raises(ConfigError, match=r"wind\.models\[0\]\.model = 'breeze'"):
        make("wind", {"model": "sum", "models": ["breeze"]})


@pytest.mark.parametrize("spec", [
    "none",
    {"model": "gust", "onset": 20.0, "onset_by": "time", "speed": 100.0},
    {"model": "profile", "altitude_m": [0, 5e3, 2e4], "speed": [3, 30, 5],
     "direction_deg": [10, 250, 300]},
    {"model": "dryden", "alt_max_m": 20e3},
    {"model": "dryden", "coordinate": "time", "airspeed": 300.0, "altitude_m": 1e4,
     "duration": 60.0},
    "jet_stream",
    {"model": "sum", "models": ["jet_stream", "dryden"]},
])
def test_batch_equals_single(spec):
    model = make("wind", spec)
    model.reset(rng(5))
    alt = np.linspace(-100.0, 25e3, 37)
    t = np.linspace(0.0, 70.0, 37)
    batch = model.velocity_ned(alt, t)
    assert batch.shape == (37, 3)
    out = np.empty(3)
    for i in range(alt.size):
        np.testing.assert_array_equal(model.velocity_ned(alt[i], t[i]), batch[i])
        wind.wind_ned(model.params, alt[i], t[i], out)         # the compiled caller's path
        np.testing.assert_array_equal(out, batch[i])
    assert model.velocity_ned(alt.reshape(37, 1), t[:3]).shape == (37, 3, 3)


def test_docstring_example():
    result = doctest.testmod(wind)
    assert result.attempted > 0 and result.failed == 0


def test_docs_example_runs():
    text = (Path(__file__).resolve().parents[1] / "docs" / "atmosphere-and-wind.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "docs/atmosphere-and-wind.md", "exec"), namespace)
    assert namespace["w_n"].shape == (2, 3) and namespace["rho"][0] == pytest.approx(1.225, rel=1e-5)


def test_nested_model_errors_name_the_full_key_path():
    from lvgym.errors import ConfigError as _ConfigError

    with pytest.raises(_ConfigError, match=r"^wind\.models\[0\]\.amplitude = -1: "):
        make("wind", {"model": "sum", "models": [{"model": "gust", "amplitude": -1}]})


def test_sum_is_reproduced_from_a_saved_generator_state():
    wind = make("wind", {"model": "sum", "models": [{"model": "jet_stream"}, {"model": "dryden"}]})
    rng = np.random.default_rng(5)
    saved = rng.bit_generator.state
    wind.reset(rng)
    first = wind.velocity_ned(np.array([1000.0, 5000.0]), 0.0)
    again = np.random.default_rng()
    again.bit_generator.state = saved
    wind.reset(again)
    np.testing.assert_array_equal(wind.velocity_ned(np.array([1000.0, 5000.0]), 0.0), first)


def test_random_gust_draws_within_its_ranges_and_is_the_gust_it_drew():
    from lvgym.environment import make
    from lvgym.environment.wind import GustWind
    w = make("wind", {"model": "random_gust", "onset_m": [8000.0, 11500.0]})
    seen = []
    for seed in range(20):
        w.reset(np.random.default_rng(seed))
        d = w.drawn
        assert 5.0 <= d["amplitude"] <= 15.0 and 30.0 <= d["length"] <= 300.0
        assert 8000.0 <= d["onset"] <= 11500.0 and 0.0 <= d["direction_deg"] <= 360.0
        np.testing.assert_array_equal(w.params, GustWind(shape="bump", **d).params)
        # the bump peaks at the amplitude one ramp length above the onset and is gone two lengths above
        peak = w.velocity_ned(d["onset"] + d["length"])
        assert np.linalg.norm(peak) == pytest.approx(d["amplitude"], rel=1e-9)
        assert np.linalg.norm(w.velocity_ned(d["onset"] + 2.0 * d["length"] + 1.0)) == pytest.approx(0.0, abs=1e-9)
        seen.append(d["amplitude"])
    assert len(set(seen)) == 20                                  # a new gust at every reset
    w.reset(np.random.default_rng(3))
    a = w.params.copy()
    w.reset(np.random.default_rng(3))
    np.testing.assert_array_equal(a, w.params)                  # seeded
