# Shared fixtures: the command line the module is compared with, and the sample effects.
# ctest (python/CMakeLists.txt) sets PYTHONPATH, TICKFX_CLI and TICKFX_SAMPLES.
import os
import subprocess
from fractions import Fraction
from pathlib import Path

import pytest


def _required_path(variable):
    value = os.environ.get(variable)
    if not value:
        raise RuntimeError(f"{variable} is not set: run these tests through ctest (python.pytest)")
    path = Path(value)
    if not path.exists():
        raise RuntimeError(f"{variable}={value} does not exist")
    return path


@pytest.fixture(scope="session")
def cli():
    return _required_path("TICKFX_CLI")


@pytest.fixture(scope="session")
def samples():
    return _required_path("TICKFX_SAMPLES")


def _cli_environment():
    # The sanitizer build preloads the ASan runtime into the interpreter for the module; the CLI
    # carries its own (clang links it statically) and refuses to start beside a second one.
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    return env


def run_cli(cli, *args, expect=0):
    """Runs `tickfx ARGS...`; returns (stdout, stderr) after checking the exit code."""
    done = subprocess.run(
        [str(cli), *map(str, args)], capture_output=True, text=True, env=_cli_environment()
    )
    assert done.returncode == expect, (
        f"tickfx {' '.join(map(str, args))} exited {done.returncode}\n{done.stdout}{done.stderr}"
    )
    return done.stdout, done.stderr


def cli_hash(cli, effect, *extra):
    """The CLI's (state hash, ticks) after running `effect` for its [output] length, no caches."""
    out, _ = run_cli(cli, "run", effect, "--hash", "--quiet", "--format", "none", *extra)
    fields = dict(line.split(": ", 1) for line in out.splitlines() if ": " in line)
    return fields["state-hash"], int(fields["ticks"])


def run_frames(system, frames=None):
    """Advances `system` frame by frame at its output fps; returns the frames' durations."""
    frame = 1 / system.output_fps
    assert isinstance(frame, Fraction)
    for _ in range(system.output_frames if frames is None else frames):
        result = system.advance(frame)
        assert result.dropped == 0
    return frame
