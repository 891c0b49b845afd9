"""Environment models chosen by name: errors name the key, the value and what is allowed."""

import pytest

from lvgym.environment import registry
from lvgym.errors import ConfigError


@registry.register("_testkind", "plain")
class _Plain:
    def __init__(self, scale: float = 1.0):
        self.scale = scale


def test_make_by_name_and_by_mapping():
    assert registry.make("_testkind", "plain").scale == 1.0
    assert registry.make("_testkind", {"model": "plain", "scale": 3.0}).scale == 3.0
    assert "plain" in registry.names("_testkind")


def test_unknown_name_and_option_are_named():
    with pytest.raises(ConfigError, match=r"_testkind\.model = 'nope': one of \['plain'\]"):
        registry.make("_testkind", "nope")
    with pytest.raises(ConfigError, match=r"wind\.sclae = 2: unknown option"):
        registry.make("_testkind", {"model": "plain", "sclae": 2}, key="wind")
    with pytest.raises(ConfigError, match=r"_testkind\.model = <missing>: required"):
        registry.make("_testkind", {"scale": 2})


def test_config_error_message():
    err = ConfigError("stages[0].tanks[1].fill_ratio", 1.3, "must be in [0, 1]", source="smile.yaml")
    assert str(err) == "smile.yaml: stages[0].tanks[1].fill_ratio = 1.3: must be in [0, 1]"
    assert isinstance(err, ValueError)
