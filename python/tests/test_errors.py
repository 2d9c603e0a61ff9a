# Effect errors come back as EffectError with exactly the lines `tickfx check` prints.
import pickle
import re

import pytest
import tickfx
from conftest import run_cli

BAD_EFFECT = """\
format_version = 1

[simulation]
step_rate = "fast"
integratr = "rk4"

[[emitters]]
shape = "point"
rate = 100.0
lifetime = 1.0

[output]
fps = 24
seconds = 1.0
"""

DIAGNOSTIC = re.compile(r"^.+:\d+:\d+: error: [a-z_.0-9]+: .+$")


def cli_check_lines(cli, path, *args, expect):
    _, err = run_cli(cli, "check", path, *args, expect=expect)
    return [line for line in err.splitlines() if ": error: " in line or ": warning: " in line]


@pytest.fixture
def bad_effect(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(BAD_EFFECT)
    return path


def test_bad_effect_raises_the_cli_diagnostics(cli, bad_effect):
    expected = cli_check_lines(cli, bad_effect, expect=2)
    assert len(expected) == 2
    assert all(DIAGNOSTIC.match(line) for line in expected)
    assert expected[0].startswith(f"{bad_effect}:4:13: error: simulation.step_rate: ")
    assert expected[1].startswith(f"{bad_effect}:5:1: error: simulation.integratr: ")
    assert "integrator" in expected[1]  # did you mean

    with pytest.raises(tickfx.EffectError) as raised:
        tickfx.load_effect(bad_effect)
    assert raised.value.diagnostics == expected
    assert str(raised.value) == "\n".join(expected)
    assert isinstance(raised.value, ValueError)

    with pytest.raises(tickfx.EffectError) as checked:
        tickfx.check(str(bad_effect))
    assert checked.value.diagnostics == expected

    copy = pickle.loads(pickle.dumps(raised.value))
    assert copy.diagnostics == expected and str(copy) == str(raised.value)


def test_bad_override_names_the_override(cli, samples):
    effect = samples / "fountain.toml"
    expected = cli_check_lines(
        cli, effect, "--set", "simulation.step_rate=0", "--set", "emitters.0.sped=3", expect=2
    )
    assert len(expected) == 2
    with pytest.raises(tickfx.EffectError) as raised:
        tickfx.load_effect(effect, {"simulation.step_rate": 0, "emitters.0.sped": 3})
    assert raised.value.diagnostics == expected
    assert expected[0].startswith("--set simulation.step_rate: error: ")


def test_missing_file(tmp_path):
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(tickfx.EffectError, match=re.escape(str(missing))):
        tickfx.load_effect(missing)


def test_check_returns_the_cli_warnings(cli, samples):
    effect = samples / "wind_aliasing.toml"
    expected = cli_check_lines(cli, effect, expect=0)
    assert len(expected) == 1 and ": warning: forces.0.frequency: " in expected[0]
    assert tickfx.check(effect) == expected
    assert tickfx.check(samples / "wind_aliasing_fixed.toml") == []
    # A wind sampled fast enough no longer warns.
    assert tickfx.check(effect, {"simulation.step_rate": 240}) == []


def test_override_values_are_checked(samples):
    with pytest.raises(TypeError):
        tickfx.load_effect(samples / "fountain.toml", {"simulation.seed": object()})
    with pytest.raises(TypeError):
        tickfx.load_effect(samples / "fountain.toml", [("simulation.seed", 1)])
    with pytest.raises(TypeError):
        tickfx.load_effect(samples / "fountain.toml", {1: 2})
