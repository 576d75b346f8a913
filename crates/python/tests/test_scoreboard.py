"""scripts/scoreboard.py (docs/scoreboard.md): its noise-corrected lobe error against a known
bias, and the whole pipeline on a tiny grid.

pandas or matplotlib missing: the module skips with a visible reason, but fails when CI is set."""

import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import REPO


def _missing(reason):
    if os.environ.get("CI"):
        pytest.fail(f"{reason} (CI is set: the scoreboard test must run)", pytrace=False)
    pytest.skip(reason, allow_module_level=True)


try:
    import matplotlib  # noqa: F401  (the script draws with it)
    import pandas as pd
except ImportError as error:
    _missing(f"{error}: pip install -r scripts/requirements.txt")

SCRIPT = REPO / "scripts" / "scoreboard.py"
sys.path.insert(0, str(SCRIPT.parent))
import scoreboard  # noqa: E402

# Conductor F = 1 and glass from both sides, GGX, two roughnesses, two angles, 4000 photons.
TINY = """\
paths = 4000
seed = 11
albedo_floor = 1e-3
models = ["single", "heitz-nee", "exact-position-free", "wang-uncorrelated", "kulla-conty", "turquin"]

[detector]
cos_theta_bins = 8
phi_bins = 16
max_order = 3

[[run]]
name = "outside"
[run.surface]
alpha = [0.3, 1.0]
[[run.material]]
name = "F=1"
kind = "conductor"
[[run.material]]
name = "glass"
kind = "dielectric"
eta = 1.5
[run.incident]
theta_deg = [0, 60]

[[run]]
name = "inside"
[run.surface]
alpha = 0.5
[run.material]
kind = "dielectric"
eta = 1.5
[run.incident]
theta_deg = 30
side = "inside"
"""


def synthetic(bias, bins=20_000, seed=5):
    """A walk's lobe (truth plus noise of known standard error) and a model of the truth scaled
    by 1 + bias with its own noise, as lobes.csv and models.csv rows of one lobe."""
    rng = np.random.default_rng(seed)
    truth = rng.uniform(0.5, 1.5, bins)
    s_w, s_m = 0.05 * truth, 0.03 * truth
    walk = truth + s_w * rng.standard_normal(bins)
    model = truth * (1.0 + bias) + s_m * rng.standard_normal(bins)
    keys = {"case": 0, "order": 1, "hemisphere": "R"}
    lobes = pd.DataFrame({**keys, "energy": walk, "energy_stderr": s_w})
    models = pd.DataFrame({"m": model, "m_stderr": s_m})
    return scoreboard.lobe_errors(lobes, models, ["m"]).iloc[0]


def test_the_lobe_error_recovers_a_known_bias_and_is_noise_for_none():
    # 20 000 bins with relative noise 5 % (walk) and 3 % (model): the raw relative L2 of an
    # unbiased model would be about sqrt(0.05^2 + 0.03^2) = 0.058; the corrected error must
    # give the bias instead, to the accuracy its noise level states.
    for bias in [0.02, 0.05, 0.2]:
        row = synthetic(bias)
        assert abs(row.lobe_error - bias) < 0.1 * bias + 3 * row.lobe_noise, (bias, row.lobe_error)
    unbiased = synthetic(0.0)
    assert unbiased.lobe_error < 3 * unbiased.lobe_noise, unbiased
    assert unbiased.lobe_noise < 0.02


def test_toml_text_round_trips_a_run_config():
    import tomllib

    board = tomllib.loads(TINY)
    for _, config in scoreboard.run_configs(board, None):
        assert tomllib.loads(scoreboard.toml_text(config)) == config


@pytest.fixture(scope="module")
def tiny(tmp_path_factory, binary):
    out = tmp_path_factory.mktemp("scoreboard")
    (out / "board.toml").write_text(TINY)
    command = [sys.executable, str(SCRIPT), str(out / "board.toml"), "--out", str(out / "runs")]
    command += ["--doc", str(out / "board.md"), "--figures", str(out / "figures"), "--bin", binary]
    done = subprocess.run(command, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return out


def test_the_tiny_scoreboard_writes_its_page_and_figures(tiny):
    page = (tiny / "board.md").read_text()
    for model in ["single", "heitz-nee", "exact-position-free", "wang-uncorrelated", "kulla-conty", "turquin"]:
        assert f"| `{model}` |" in page, model
    assert "nan" not in page.lower() and "inf " not in page.lower()
    for name in ["board-alpha.png", "board-theta.png"]:
        assert (tiny / "figures" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "(figures/board-alpha.png)" in page


def test_the_tiny_scoreboard_scores_what_theory_fixes(tiny):
    scored = pd.concat([scoreboard.score_run(tiny / "runs" / name, 4000) for name in ["outside", "inside"]])
    # Kulla-Conty with F = 1 integrates to exactly 1 over the outgoing directions for every
    # incident one (docs/compensation.md), and the walk with F = 1 loses nothing: the albedo
    # error is the quadrature's, far below 1e-3.
    kc = scored[(scored["model"] == "kulla-conty") & (scored["material"] == "F=1")]
    assert len(kc) == 4 and kc["albedo_error"].abs().max() < 1e-3, kc["albedo_error"]
    # Exact models have no bias: their median lobe error is within their median noise level.
    for model in ["single", "heitz-nee", "exact-position-free"]:
        g = scored[scored["model"] == model]
        assert len(g) > 0 and g["lobe_error"].median() <= g["lobe_noise"].median(), model
    # Light from inside reaches the scoreboard as its own side.
    assert set(scored["side"]) == {"outside", "inside"}
