"""Shared fixtures: the command-line binary to check the bindings against, and small configs."""

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]

# Two materials (one transmits), two roughnesses, two angles, folded orders, a small grid:
# every axis of the arrays has more than one entry and the T hemisphere is partly empty.
MONO = """\
paths = 40_000
seed = 7

[surface]
alpha = [0.3, [0.8, 0.2]]

[[material]]
kind = "conductor"
fresnel = "schlick"
f0 = 0.9

[[material]]
kind = "dielectric"
eta = 1.5

[incident]
theta_deg = [20, 70]
phi_deg = 30

[detector]
cos_theta_bins = 6
phi_bins = 10
max_order = 3
"""

# Three channels, no order folding.
RGB = """\
paths = 30_000
seed = 3

[surface]
ndf = "beckmann"
alpha = 0.6

[material]
kind = "diffuse"
albedo = [0.9, 0.5, 0.1]

[incident]
theta_deg = 45

[detector]
cos_theta_bins = 4
phi_bins = 8
"""


@pytest.fixture(scope="session")
def binary():
    """The `smithwalk` binary's path (SMITHWALK_BIN, or the repository's target/release)."""
    path = os.environ.get("SMITHWALK_BIN") or str(
        Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target")) / "release" / "smithwalk"
    )
    if not Path(path).exists():
        pytest.fail(f"no smithwalk binary at {path}: run `cargo build --release` or set SMITHWALK_BIN")
    return path


@pytest.fixture(scope="session")
def cli(binary):
    """Runs the `smithwalk` binary."""

    def call(*args, check=True):
        done = subprocess.run([binary, *map(str, args)], capture_output=True, text=True)
        if check and done.returncode != 0:
            raise AssertionError(f"smithwalk {' '.join(map(str, args))} failed:\n{done.stderr}")
        return done

    return call


@pytest.fixture
def write_config(tmp_path):
    """Writes TOML text to a file in the test's directory and returns its path."""

    def write(text, name="config.toml"):
        path = tmp_path / name
        path.write_text(text)
        return path

    return write
