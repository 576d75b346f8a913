"""The bindings against the command line: the same config and seed give byte-identical tables,
and the arrays hold exactly the numbers of the CSV files (parsed here with the csv module and
float(), independently of the package's own reader)."""

import csv
import json

import numpy as np
import pytest

import smithwalk
from conftest import MONO, RGB

# run.json fields that measure the run rather than describe it.
# What differs between two runs of the same config: timing, and the run's identity (a fresh
# run_id per run, and run.json's digest of itself, which covers it).
PER_RUN = ("wall_seconds", "paths_per_second", "threads", "run_id", "self_sha256")


def run_both(cli, write_config, tmp_path, text, seed):
    config = write_config(text)
    cli("run", config, "--seed", seed, "--out", tmp_path / "cli", "--threads", 2)
    result = smithwalk.run(config, seed=seed, threads=1)
    result.save(tmp_path / "py")
    return result


@pytest.mark.parametrize("text", [MONO, RGB], ids=["mono", "rgb"])
def test_save_writes_the_command_lines_files_byte_for_byte(cli, write_config, tmp_path, text):
    run_both(cli, write_config, tmp_path, text, seed=11)
    for name in ("lobes.csv", "summary.csv"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    py, ref = (json.loads((tmp_path / d / "run.json").read_text()) for d in ("py", "cli"))
    for field in PER_RUN:
        py.pop(field), ref.pop(field)
    assert py == ref
    assert sorted(p.name for p in (tmp_path / "py").iterdir()) == ["lobes.csv", "run.json", "summary.csv"]


def csv_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize("text", [MONO, RGB], ids=["mono", "rgb"])
def test_arrays_equal_the_csv(cli, write_config, tmp_path, text):
    result = run_both(cli, write_config, tmp_path, text, seed=5)
    rows = csv_rows(tmp_path / "cli" / "lobes.csv")
    seen = np.zeros(result.energy.shape, dtype=bool)
    cos_bins, phi_bins = len(result.cos_edges) - 1, len(result.phi_edges_deg) - 1
    for row in rows:
        ic = int(abs(float(row["cos_lo"]) + float(row["cos_hi"])) / 2 * cos_bins)
        ip = round(float(row["phi_lo_deg"]) / 360 * phi_bins)
        index = (int(row["case"]), int(row["order"]), "RT".index(row["hemisphere"]), ic, ip)
        if result.channels:
            index += ("rgb".index(row["channel"]),)
        assert not seen[index], f"two rows for bin {index}"
        seen[index] = True
        for name in ("energy", "energy_stderr", "bsdf", "bsdf_stderr"):
            assert getattr(result, name)[index] == float(row[name]), (name, index)
        assert result.count[index] == int(row["count"])
        assert float(row["cos_lo"]) in (result.cos_edges[ic], -result.cos_edges[ic + 1])
        assert float(row["phi_lo_deg"]) == result.phi_edges_deg[ip]
    # Bins without a row (T of materials that do not transmit) are exactly zero.
    for name in ("energy", "energy_stderr", "count", "bsdf", "bsdf_stderr"):
        assert not getattr(result, name)[~seen].any(), name
    assert seen.sum() == len(rows)


def test_the_bins_add_up_to_the_albedos_of_the_summary(cli, write_config, tmp_path):
    """Two independent tallies: each bin's energy and the per-order albedo, summed in fixed point
    separately; their floating-point sums agree to rounding."""
    result = run_both(cli, write_config, tmp_path, MONO, seed=5)
    rows = csv_rows(tmp_path / "cli" / "summary.csv")
    checked = 0
    for row in rows:
        if row["hemisphere"] not in ("R", "T"):
            continue
        bins = result.energy[int(row["case"]), int(row["order"]), "RT".index(row["hemisphere"])]
        assert bins.sum() == pytest.approx(float(row["albedo"]), rel=1e-12, abs=1e-15)
        checked += 1
    assert checked == 4 * 4 + 4 * 4 * 2  # 4 order slots; conductors R only, dielectrics R and T


def test_load_reads_back_the_arrays_of_the_run(tmp_path):
    result = smithwalk.run(MONO, seed=2)
    result.save(tmp_path / "run")
    loaded = smithwalk.load(tmp_path / "run")
    for name in ("energy", "energy_stderr", "count", "bsdf", "bsdf_stderr"):
        a, b = getattr(result, name), getattr(loaded, name)
        assert a.dtype == b.dtype and a.shape == b.shape, name
        assert np.array_equal(a, b), name
    assert loaded.orders == result.orders and np.array_equal(loaded.folded, result.folded)
    assert loaded.cases == result.cases and loaded.config == result.config
    assert loaded.summary.equals(result.summary)
    # A loaded run saves the same files again.
    loaded.save(tmp_path / "again")
    for name in ("lobes.csv", "summary.csv", "run.json"):
        assert (tmp_path / "again" / name).read_bytes() == (tmp_path / "run" / name).read_bytes()


def test_thread_count_and_progress_bar_do_not_change_the_arrays():
    one = smithwalk.run(RGB, threads=1)
    three = smithwalk.run(RGB, threads=3, progress=True)
    assert np.array_equal(one.energy, three.energy) and np.array_equal(one.count, three.count)
