"""Shared fixtures: small databases written by the built `panoptes` command (PANOPTES_BINARY)."""
import os
import subprocess

import pytest


def panoptes_binary():
    path = os.environ.get("PANOPTES_BINARY")
    if not path:
        pytest.skip("PANOPTES_BINARY not set (ctest sets it)")
    return path


@pytest.fixture(scope="session")
def synth_db(tmp_path_factory):
    """4 cameras x 3 tasks x 5 frames of 64x48, every frame stamped."""
    out = tmp_path_factory.mktemp("db") / "synth"
    subprocess.run([panoptes_binary(), "synth-db", str(out), "--cameras", "4", "--tasks", "3", "--frames", "5",
                    "--size", "64x48", "--gop", "1"], check=True, stdout=subprocess.DEVNULL)
    return out


HEAT_TOML = """
[output]
dir = "{dir}"
overwrite = true
title = "python heat"
[image]
width = 48
height = 40
[rig]
spec = "fibonacci:6"
[schedule]
every_steps = 2
[[task]]
name = "temperature"
type = "volume"
field = "T"
preset = "hot"
relative = false
window = [0.0, 1.0]
"""
