"""The renderer of the ascent envs: images of the right shape that follow the frame, robust to empty and nan data."""

import dataclasses
import warnings

import matplotlib
import numpy as np
import pytest

from lvgym.envs.render import HumanViewer, Renderer, RenderFrame, example_frame, render_rgb
from lvgym.errors import ConfigError


@pytest.fixture(scope="module")
def renderer():
    r = Renderer()
    yield r
    r.close()


def _empty(frame: RenderFrame) -> RenderFrame:
    z = np.zeros(0)
    return dataclasses.replace(frame, stations=z, deflection=z, slosh_stations=z, slosh_lengths=z,
                               slosh_angles_deg=z, slosh_masses=z, rates_t=z, rates_degps=np.zeros((0, 2)))


def _changed(a: np.ndarray, b: np.ndarray) -> int:
    """Number of pixels that differ."""
    return int(np.any(a != b, axis=2).sum())


@pytest.mark.parametrize("size", [(480, 640), (333, 517), (640, 360)])
def test_shape_dtype_and_not_blank(size):
    img = render_rgb(example_frame(), size=size)
    assert img.shape == (*size, 3) and img.dtype == np.uint8
    colours = np.unique(img.reshape(-1, 3), axis=0)
    assert len(colours) > 20


def test_image_follows_deflection_slosh_and_gimbal(renderer):
    f = example_frame()
    base = renderer.render_rgb(f)
    assert _changed(base, renderer.render_rgb(f)) == 0  # reused figure: same frame, same picture
    variants = {
        "deflection": dataclasses.replace(f, deflection=-f.deflection),
        "slosh": dataclasses.replace(f, slosh_angles_deg=f.slosh_angles_deg + 25.0),
        "gimbal": dataclasses.replace(f, gimbal_deg=-4.0),
    }
    for name, g in variants.items():
        assert _changed(base, renderer.render_rgb(g)) > 20, name
    # a zero deflection looks different from the exaggerated one
    flat = dataclasses.replace(f, deflection=np.zeros_like(f.deflection))
    assert _changed(base, renderer.render_rgb(flat)) > 20


def test_exaggeration_is_written_and_changes_the_picture():
    f = example_frame()
    a = Renderer(exaggeration=50.0)
    b = Renderer(exaggeration=5.0)
    ia, ib = a.render_rgb(f), b.render_rgb(f)
    assert a._bend.get_text().startswith("bending x50")
    assert b._bend.get_text().startswith("bending x5")
    assert _changed(ia, ib) > 20


def test_no_modes_no_pendulums_no_rates(renderer):
    img = renderer.render_rgb(_empty(example_frame()))
    assert img.shape == (480, 640, 3)
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 10


def test_inactive_pendulum_and_ragged_arrays(renderer):
    f = dataclasses.replace(example_frame(), slosh_masses=np.array([0.0, 22.0]),
                            slosh_angles_deg=np.array([5.0]), rates_degps=np.zeros(7))
    assert renderer.render_rgb(f).shape == (480, 640, 3)


def test_non_finite_values_do_not_raise(renderer):
    f = example_frame()
    nan = float("nan")
    bad = dataclasses.replace(
        f, t=nan, length=nan, diameter=-1.0, pitch_deg=nan, deflection=f.deflection * nan,
        slosh_angles_deg=np.array([nan, 3.0]), slosh_masses=np.array([np.inf, nan]),
        slosh_stations=np.array([-3.0, nan]), gimbal_deg=np.inf, gimbal_station=nan, wind_mps=(nan, 1.0),
        rates_degps=np.where(np.arange(f.rates_t.size)[:, None] % 3 == 0, nan, f.rates_degps))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        img = renderer.render_rgb(bad)
    assert img.shape == (480, 640, 3)
    # partly nan deflection: the finite samples are drawn
    part = f.deflection.copy()
    part[::2] = nan
    assert renderer.render_rgb(dataclasses.replace(f, deflection=part)).shape == (480, 640, 3)


def test_huge_deflection_is_clipped(renderer):
    f = example_frame()
    renderer.render_rgb(dataclasses.replace(f, deflection=f.deflection * 1e3))
    assert "clipped" in renderer._bend.get_text()
    renderer.render_rgb(f)
    assert "clipped" not in renderer._bend.get_text()


def test_bad_options():
    with pytest.raises(ConfigError):
        Renderer(size=(10, 640))
    with pytest.raises(ConfigError):
        Renderer(exaggeration=-1.0)


def test_two_renderers_do_not_share_state():
    f = example_frame()
    a, b = Renderer(), Renderer(size=(300, 400))
    ia = a.render_rgb(f)
    b.render_rgb(dataclasses.replace(f, gimbal_deg=-5.0, pitch_deg=40.0))
    assert _changed(ia, a.render_rgb(f)) == 0
    a.close()
    b.close()


def test_human_viewer_under_agg():
    import matplotlib.pyplot as plt
    old = matplotlib.get_backend()
    plt.switch_backend("agg")
    try:
        _human_viewer_checks(plt)
    finally:
        plt.switch_backend(old)


def _human_viewer_checks(plt):
    before = plt.get_fignums()
    v = HumanViewer()
    assert not v.interactive()
    with pytest.warns(UserWarning, match="cannot show a window.*rgb_array"):
        v.show(example_frame())                    # a headless machine shows nothing: said once
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v.show(_empty(example_frame()))
    v.close()
    v.close()
    assert plt.get_fignums() == before


def test_frames_show_model_termination_and_the_task_axes():
    import gymnasium as gym
    from lvgym.envs.frames import make_frame
    rigid = gym.make("lvgym/SmileAscent-v0", model="rigid", render_mode="rgb_array")
    rigid.reset(seed=0)
    rigid.step(np.zeros(2, np.float32))
    f = make_frame(rigid.unwrapped)
    assert f.model == "rigid" and not f.bending and f.rate_axes == ("pitch", "yaw") and f.termination == ""
    r = Renderer()
    r.draw(f)
    assert "bending" not in r._bend.get_text() and "[rigid]" in r._head.get_text()
    roll = gym.make("lvgym/StratosIII-v0", model="nonrigid", render_mode="rgb_array", mission_time_s=0.1)
    roll.reset(seed=0)
    for _ in range(5):
        *_, trunc, _ = roll.step(np.array([1]))
    f = make_frame(roll.unwrapped)
    assert f.bending and f.rate_axes == ("roll", "pitch", "yaw") and f.rates_degps.shape[1] == 3
    assert trunc and f.termination == "mission time reached"
    r.draw(f)
    assert r._lines["roll"].get_visible() and "ENDED: mission time reached" in r._head.get_text()
    assert roll.render().shape[2] == 3
