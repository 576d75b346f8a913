"""The Python API: config forms, shapes and dtypes, labels, errors with the command line's
messages, comparisons, the GIL, Ctrl-C, life without pandas, docstrings."""

import errno
import inspect
import os
import pydoc
import re
import signal
import subprocess
import sys
import threading
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

import smithwalk
from conftest import MONO, RGB, REPO

FIELDS = ("energy", "energy_stderr", "count", "bsdf", "bsdf_stderr")


@pytest.fixture(scope="module")
def mono():
    return smithwalk.run(MONO)


def test_shapes_dtypes_and_labels(mono):
    # 8 cases (2 alphas x 2 materials x 2 angles), slots all, 1, 2, 3+, R and T, 6 x 10 bins.
    for name in FIELDS:
        a = getattr(mono, name)
        assert a.shape == (8, 4, 2, 6, 10), name
        assert a.dtype == (np.uint64 if name == "count" else np.float64), name
        assert a.flags.c_contiguous and a.flags.writeable, name
    assert mono.orders == ("all", "1", "2", "3+")
    assert mono.folded.tolist() == [False, False, False, True]
    assert mono.hemispheres == ("R", "T") and mono.channels is None
    assert np.array_equal(mono.cos_edges, np.arange(7) / 6)
    assert np.array_equal(mono.phi_edges_deg, np.arange(11) * 36.0)
    # Projected solid angle of a bin: 2 pi / phi_bins * (hi^2 - lo^2) / 2; over the hemisphere, pi.
    assert mono.projected_solid_angle.sum() * 10 == pytest.approx(np.pi, rel=1e-14)
    assert np.array_equal(mono.bsdf, mono.energy / mono.projected_solid_angle[:, None])
    assert len(mono.cases) == 8
    assert [c["theta_i_deg"] for c in mono.cases[:2]] == [20.0, 70.0]
    assert mono.cases[0]["alpha_x"] == 0.3 and mono.cases[4]["alpha_y"] == 0.2
    assert {"reflected", "transmitted", "absorbed"} <= mono.cases[0]["energy"].keys()
    assert mono.info["paths"] == 40_000 and mono.info["seed"] == 7
    # Conductors do not transmit.
    assert not mono.energy[:2, :, 1].any() and mono.energy[2:4, :, 1].any()


def test_columns_are_the_ones_the_files_have(tmp_path):
    # The schema comes from the extension (the crate's io::schema), not from a Python list: the
    # header of every table a saved run and its comparison write is the schema's, in order.
    result = smithwalk.run(MONO, paths=2000)
    result.compare(["single"])
    result.save(tmp_path / "run")
    tables = smithwalk.columns()
    assert set(tables) == {"lobes.csv", "summary.csv", "models.csv", "compare.csv"}
    for file, columns in tables.items():
        header = (tmp_path / "run" / file).read_text().split("\n", 1)[0].split(",")
        names = [name for name, unit, meaning in columns if name != "channel"]
        names = [n.replace("<model>", "single") for n in names]
        assert header == names, file
    assert all(meaning for _, _, meaning in smithwalk.columns("lobes.csv"))
    with pytest.raises(ValueError, match="file = 'lobe.csv' is not allowed"):
        smithwalk.columns("lobe.csv")


def test_rgb_runs_have_a_channel_axis():
    r = smithwalk.run(RGB)
    assert r.channels == ("r", "g", "b")
    assert r.energy.shape[2:] == (2, 4, 8, 3) and r.count.shape == r.energy.shape
    assert r.orders[:2] == ("all", "1") and not r.folded.any()
    # A diffuse facet of albedo (0.9, 0.5, 0.1): the channels reflect in that order.
    albedo = r.energy[0, 0, 0].sum(axis=(0, 1))
    assert albedo[0] > albedo[1] > albedo[2] > 0


def test_the_config_can_be_a_path_text_or_dict(tmp_path, mono):
    path = tmp_path / "mono.toml"
    path.write_text(MONO)
    as_dict = tomllib.loads(MONO)
    # numpy values in a dict are accepted.
    as_dict["incident"]["theta_deg"] = np.array([20.0, 70.0])
    as_dict["paths"] = np.int64(as_dict["paths"])
    for config in (path, str(path), as_dict):
        other = smithwalk.run(config)
        assert np.array_equal(other.energy, mono.energy), type(config)
    assert smithwalk.run(as_dict, paths=20_000, seed=8).info["seed"] == 8


def test_summary_is_a_dataframe(mono):
    pd = pytest.importorskip("pandas")
    s = mono.summary
    assert isinstance(s, pd.DataFrame)
    assert s["albedo"].dtype == np.float64 and s["folded"].dtype == bool
    assert set(s["hemisphere"]) == {"R", "T", "absorbed", "lost"}
    conductor = s[(s["case"] == 0) & (s["hemisphere"] == "R") & (s["order"] == 0)]
    assert conductor["albedo"].iloc[0] == pytest.approx(mono.energy[0, 0, 0].sum(), rel=1e-12)


def test_without_pandas_tables_are_dicts_of_arrays(mono, monkeypatch):
    frame = mono.summary
    monkeypatch.setitem(sys.modules, "pandas", None)
    plain = smithwalk.run(MONO).summary
    assert isinstance(plain, dict) and list(plain) == list(frame.columns)
    for name, column in plain.items():
        assert column.tolist() == frame[name].tolist(), name
    assert plain["case"].dtype == np.int64 and plain["folded"].dtype == bool


def cli_message(cli, config_path):
    done = cli("run", config_path, "--out", config_path.parent / "out", check=False)
    assert done.returncode != 0 and done.stderr.startswith("error: ") and done.stderr.endswith("\n")
    assert not (config_path.parent / "out" / "lobes.csv").exists()
    # `error: {message}` and the newline of eprintln.
    return done.stderr[len("error: ") : -1]


@pytest.mark.parametrize(
    "change",
    [
        ("alpha = [0.3, [0.8, 0.2]]", "alpha = [0.3, 0.0]"),
        ("theta_deg = [20, 70]", "theta_deg = [20, 90]"),
        ("eta = 1.5", "eta = 1.0"),
        ("max_order = 3", "max_order = 0"),
        ("phi_bins = 10", "phi_bins = 10\nspin = 3"),
        ("paths = 40_000", "paths = 1"),
        ('fresnel = "schlick"', 'fresnel = "schlik"'),
    ],
)
def test_invalid_configs_raise_value_error_with_the_cli_message(cli, write_config, change):
    path = write_config(MONO.replace(*change))
    expected = cli_message(cli, path)
    with pytest.raises(ValueError) as error:
        smithwalk.run(path)
    assert str(error.value) == expected
    # The same error from TOML text and from a dict, past the config's name.
    with pytest.raises(ValueError) as error:
        smithwalk.run(path.read_text())
    assert str(error.value).replace("<text>", str(path)) == expected
    try:
        as_dict = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError:
        return
    with pytest.raises(ValueError) as error:
        smithwalk.run(as_dict)
    # A dict has no lines: the same message without them.
    without_lines = re.sub(r" \(line \d+(, column \d+)?\)| from the table at line \d+", "", expected)
    assert str(error.value).replace("<dict>", str(path)) == without_lines


@pytest.mark.parametrize(
    "change, message",
    [
        (
            {"material": {"kind": "dielectric", "eta": float("nan")}},
            "`material.eta` = NaN is not allowed: a relative index n_inside / n_outside > 0 and != 1",
        ),
        ({"incident": {"theta_deg": float("inf")}}, "`incident.theta_deg` = inf is not allowed: an angle in"),
        ({"surface": {"alpha": "rough"}}, '`surface.alpha` = "rough" is not allowed: '),
        ({"surface": {"alpha": 0.5, "ndf": None}}, "`surface.ndf` = None is not allowed: "),
        ({"paths": 1e6}, "`paths` = 1000000.0 is not allowed: "),
        ({"paths": np.float64(1e6)}, "e.g. 1000000 or 1_000_000"),
    ],
)
def test_dict_errors_name_the_field_and_value(change, message):
    config = {
        "paths": 1000,
        "surface": {"alpha": 0.5},
        "material": {"kind": "conductor"},
        "incident": {"theta_deg": 30},
        **change,
    }
    with pytest.raises(ValueError) as error:
        smithwalk.run(config)
    text = str(error.value)
    assert text.startswith("config <dict> is not valid: ") and message in text, text
    assert "line" not in text and "u64" not in text, text


def test_missing_tables_and_keys_say_what_is_expected():
    config = {
        "paths": 1000,
        "surface": {"alpha": 0.5},
        "material": {"kind": "conductor", "fresnel": "schlick"},
    }
    with pytest.raises(ValueError) as error:
        smithwalk.run(config)
    assert str(error.value) == (
        "config <dict> is not valid: `[incident]` is missing: "
        "a table with `theta_deg` or `theta_rad`, the incident polar angles"
    )
    with pytest.raises(ValueError) as error:
        smithwalk.run({**config, "incident": {"theta_deg": 30}})
    assert str(error.value) == (
        "config <dict> is not valid: `material.f0` is missing: "
        'fresnel = "schlick" needs a reflectance in [0, 1], or one per channel [r, g, b]'
    )


def test_bad_arguments(tmp_path):
    with pytest.raises(ValueError, match=r"`paths` = 1 is not allowed"):
        smithwalk.run(MONO, paths=1)
    with pytest.raises(ValueError, match=r"`threads` = 0 is not allowed"):
        smithwalk.run(MONO, threads=0)
    with pytest.raises(ValueError, match=r"`seed` = -1 is not allowed"):
        smithwalk.run(MONO, seed=-1)
    # The smallest allowed value, not 0, for counts that must be at least 2 or 1.
    with pytest.raises(ValueError, match=r"`paths` = -5 is not allowed: an integer >= 2"):
        smithwalk.run(MONO, paths=-5)
    with pytest.raises(ValueError, match=r"`threads` = -1 is not allowed: an integer >= 1"):
        smithwalk.run(MONO, threads=-1)
    with pytest.raises(TypeError, match="must be an integer"):
        smithwalk.run(MONO, paths=1e5)
    with pytest.raises(TypeError, match="TOML string, a path or a dict"):
        smithwalk.run(42)
    with pytest.raises(OSError, match="cannot read config") as error:
        smithwalk.run(tmp_path / "quickstart.tom")
    assert str(error.value).count(os.strerror(errno.ENOENT)) == 1, error.value
    with pytest.raises(ValueError, match=r"`surface.alpha` = None is not allowed"):
        smithwalk.run({"paths": 1000, "surface": {"alpha": None}})
    with pytest.raises(ValueError, match="run.json"):
        smithwalk.load(tmp_path)


def test_compare_matches_the_command_line(cli, tmp_path):
    result = smithwalk.run(MONO, paths=20_000)
    comparison = result.compare(["single", "wang-correlated"], paths=20_000, threads=2)
    assert comparison is result.comparison and comparison.models == ("single", "wang-correlated")
    assert set(comparison.lobes) == {"single", "wang-correlated"}
    for model, lobes in comparison.lobes.items():
        assert set(lobes) == {"energy", "energy_stderr", "bsdf"}
        for a in lobes.values():
            assert a.shape == result.energy.shape and a.dtype == np.float64, model
    # Exact single scattering has order 1 only, for every case.
    single = comparison["single"]["energy"]
    assert single[:, 1].any() and not single[:, 2:].any()
    # models.csv carries energies only; the BSDF is the energy over the projected solid angle.
    assert np.array_equal(comparison["single"]["bsdf"], single / result.projected_solid_angle[:, None])
    table = comparison.table
    assert set(table["model"]) == {"single", "wang-correlated"}
    assert "wang-correlated" in comparison.report
    # The same files as `smithwalk compare` on the saved run.
    result.save(tmp_path / "py")
    (tmp_path / "cli").mkdir()
    for name in ("lobes.csv", "summary.csv", "run.json"):
        (tmp_path / "cli" / name).write_bytes((tmp_path / "py" / name).read_bytes())
    cli("compare", tmp_path / "cli", "--models", "single,wang-correlated", "--paths", 20_000)
    for name in ("models.csv", "compare.csv"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # models.csv: lobes.csv's rows, then a value and a standard error per model, in order.
    header = (tmp_path / "py" / "models.csv").read_text().split("\n", 1)[0].split(",")
    assert header[-4:] == ["single", "single_stderr", "wang-correlated", "wang-correlated_stderr"]
    lines = [(tmp_path / "py" / name).read_text().count("\n") for name in ("models.csv", "lobes.csv")]
    assert lines[0] == lines[1]
    # And a loaded run carries its comparison.
    loaded = smithwalk.load(tmp_path / "py")
    assert loaded.comparison.models == ("single", "wang-correlated")
    for model in comparison.models:
        assert np.array_equal(loaded.comparison[model]["energy"], comparison[model]["energy"])
    again = loaded.compare("single")
    assert np.array_equal(again["single"]["bsdf"], comparison["single"]["bsdf"])
    with pytest.raises(ValueError, match='"wang" is not a model; allowed: single'):
        result.compare(["wang"])


def test_load_refuses_a_comparison_that_is_not_sealed_with_the_run(tmp_path):
    # Issue 36 item 5: compare.json seals models.csv and compare.csv with the run's tables.
    result = smithwalk.run(MONO, paths=5_000)
    result.compare(["single"], paths=5_000, threads=2)
    run = tmp_path / "run"
    result.save(run)
    assert smithwalk.load(run).comparison is not None
    models = run / "models.csv"
    header, rows = models.read_text().split("\n", 1)
    models.write_text(header.replace("single", "hammon-fit") + "\n" + rows)
    with pytest.raises(ValueError, match="is not the models.csv that .* records"):
        smithwalk.load(run)
    (run / "compare.json").unlink()
    with pytest.raises(ValueError, match="without compare.json"):
        smithwalk.load(run)


def test_a_compare_table_in_the_config_runs_the_comparison():
    result = smithwalk.run(RGB + '\n[compare]\nmodels = ["single"]\n', paths=5_000)
    assert result.comparison.models == ("single",)
    assert result.comparison["single"]["energy"].shape == result.energy.shape


def test_the_walk_releases_the_gil():
    """Another Python thread keeps running while a run is walking."""
    ticks = 0
    done = threading.Event()

    def walk():
        smithwalk.run(MONO, paths=600_000, threads=1)
        done.set()

    thread = threading.Thread(target=walk)
    thread.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    thread.join()
    # 8 cases of 600 000 photons take over a second; with the GIL held the loop would stall.
    assert ticks > 100


def test_ctrl_c_stops_a_run(tmp_path):
    """SIGINT in the middle of a long run raises KeyboardInterrupt within a round of chunks."""
    script = (
        "import signal, sys, smithwalk\n"
        # A job started in the background of a script inherits SIGINT ignored, and Python then
        # installs no handler: restore Python's, which is what a user at a terminal has.
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "print('walking', flush=True)\n"
        f"smithwalk.run({MONO!r}, paths=10**9, threads=1)\n"
        "print('finished', flush=True)\n"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    assert child.stdout.readline().strip() == "walking"
    time.sleep(1.5)
    child.send_signal(signal.SIGINT)
    sent = time.monotonic()
    out, err = child.communicate(timeout=60)
    assert child.returncode != 0
    assert "KeyboardInterrupt" in err and "finished" not in out
    # Raised from inside the walk, not before it started.
    assert "_native.run(" in err, err
    # One round is 32 chunks of 16 384 photons: well under a few seconds on one core.
    assert time.monotonic() - sent < 10


def test_help_shows_numpy_style_docstrings():
    text = pydoc.render_doc(smithwalk, renderer=pydoc.plaintext)
    needles = (
        "run(config, *, paths=None, seed=None, threads=None, progress=False)",
        "load(path)",
        "class RunResult",
        "compare(self, models=None, *, paths=None, threads=None)",
        "class Comparison",
        "Parameters",
        "Returns",
    )
    for needle in needles:
        assert needle in text, needle
    for item in (smithwalk.run, smithwalk.load, smithwalk.RunResult.compare, smithwalk.RunResult.save):
        assert "Parameters\n----------" in inspect.cleandoc(item.__doc__), item.__name__
    assert smithwalk.MODELS[0] == "single" and len(smithwalk.MODELS) == 12


def test_the_example_runs_and_plots(tmp_path):
    pytest.importorskip("matplotlib")
    script = REPO / "scripts" / "example.py"
    done = subprocess.run(
        [sys.executable, str(script), "--paths", "20000", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    png = tmp_path / "lobes.png"
    import matplotlib.image

    image = matplotlib.image.imread(png)
    assert image.shape[0] > 300 and image.shape[1] > 300
    assert image[..., :3].std() > 0.05  # drawn, not blank
    assert (tmp_path / "run" / "compare.csv").exists()
    assert "wang-correlated" in done.stdout


def test_plot_lobes_draws_the_models_of_models_csv(tmp_path):
    pytest.importorskip("matplotlib")
    result = smithwalk.run(MONO, paths=5_000)
    result.compare(["single", "heitz-nee"], paths=5_000, threads=2)
    result.save(tmp_path / "run")
    script = REPO / "scripts" / "plot_lobes.py"
    lobes = tmp_path / "run" / "lobes.csv"
    done = subprocess.run(
        [sys.executable, str(script), str(lobes), "--out", str(tmp_path / "l.png")],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    for name in ("l_g0_R.png", "l_g1_T.png"):
        assert f"{name} with heitz-nee, single" in done.stderr, done.stderr
        assert (tmp_path / name).exists()
    # A models.csv that is not beside this lobes.csv row for row is refused.
    short = tmp_path / "short.csv"
    short.write_text("\n".join((tmp_path / "run" / "models.csv").read_text().split("\n")[:100]) + "\n")
    refused = subprocess.run(
        [sys.executable, str(script), str(lobes), "--models", str(short), "--out", str(tmp_path / "x.png")],
        capture_output=True,
        text=True,
    )
    assert refused.returncode != 0 and "not the models of this run" in refused.stderr
