#!/usr/bin/env python3
"""The scoreboard: every model of `smithwalk compare` judged per order against the walk on one
grid, written as a Markdown page with figures (docs/scoreboard.md).

    python3 scripts/scoreboard.py configs/scoreboard.toml [--out out/scoreboard]
        [--doc docs/scoreboard.md] [--figures docs/figures] [--paths N] [--threads N]

Needs the `smithwalk` binary (`--bin`, else $SMITHWALK_BIN, else `smithwalk` on PATH, else
target/release/smithwalk) and pandas and matplotlib (scripts/requirements.txt).

For each [[run]] of the scoreboard config it writes a run config (the run's tables plus the
shared `paths`, `seed` and `[detector]`), runs `smithwalk run` and `smithwalk compare --models
...` into OUT/<name>, and then scores every lobe that compare tested (a case, an order slot, a
hemisphere, a channel), leaving out lobes whose measured albedo is below `albedo_floor`:

* albedo error: albedo_model - albedo_measured, as compare.csv gives them;
* lobe error, corrected for the Monte Carlo noise of both sides: with w the walk's energy in a
  bin and m the model's, s_w and s_m their standard errors,
      e = sqrt(max(0, sum (m - w)^2 - sum (s_m^2 + s_w^2)) / sum w^2),
  the relative L2 distance whose expectation under noise alone has been taken out (E[(m - w)^2]
  = bias^2 + s_m^2 + s_w^2 for independent estimates). An exact model gives e near 0 at any
  photon count; what remains of e for an approximation is its bias, whatever the photons.
* for the exact oracles, compare's p-values: the smallest one over the grid against the Sidak
  level that keeps the family-wise level at 0.01, and the number of lobes rejected.
* cost: compare's CPU seconds per lobe for each model, and for the Monte Carlo models the
  relative variance per photon of their albedo estimate, beside the walk's own.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
EXACT = ["single", "heitz-nee", "exact-position-free", "cui2023-released"]
MONTE_CARLO = ["heitz-nee", "exact-position-free", "wang-correlated", "wang-uncorrelated", "cui2023-released"]
LEVEL = 0.01
SLOTS = ["1", "2", "3", "4+", "all"]
LOBE_KEYS = ["case", "order", "hemisphere"]


def binary(given: str | None) -> str:
    """The smithwalk command-line binary to run."""
    for candidate in [given, os.environ.get("SMITHWALK_BIN"), shutil.which("smithwalk")]:
        if candidate:
            return candidate
    built = REPO / "target" / "release" / "smithwalk"
    if built.exists():
        return str(built)
    sys.exit("error: no smithwalk binary: give --bin, set SMITHWALK_BIN or `cargo install --path .`")


def toml_value(value) -> str:
    """A scalar or a (nested) list as TOML writes it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise ValueError(f"cannot write {value!r} as a TOML value")


def toml_text(config: dict) -> str:
    """A run config as TOML: top-level keys, then a [table] per dict and [[table]] per list of
    dicts (one level deep, as run configs are)."""
    lines, tables = [], []
    for key, value in config.items():
        if isinstance(value, dict) or (isinstance(value, list) and value and isinstance(value[0], dict)):
            tables.append((key, value))
        else:
            lines.append(f"{key} = {toml_value(value)}")
    for key, value in tables:
        for table, header in ([(value, f"[{key}]")] if isinstance(value, dict) else [(t, f"[[{key}]]") for t in value]):
            lines.append(header)
            lines += [f"{k} = {toml_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def run_configs(board: dict, paths: int | None) -> list[tuple[str, dict]]:
    """(name, run config) of each [[run]] of the scoreboard config."""
    runs = []
    for run in board["run"]:
        run = dict(run)
        name = run.pop("name")
        config = {"paths": paths or board["paths"], "seed": board["seed"], **run}
        if "detector" in board:
            config["detector"] = board["detector"]
        runs.append((name, config))
    return runs


def walk_and_compare(bin_: str, name: str, config: dict, models: list[str], out: Path, threads) -> dict:
    """Run one [[run]] and compare it with every model; the CPU seconds compare reports per model."""
    directory = out / name
    config_path = out / f"{name}.toml"
    config_path.write_text(toml_text(config))
    extra = ["--threads", str(threads)] if threads else []
    subprocess.run([bin_, "run", str(config_path), "--out", str(directory), *extra], check=True,
                   stdout=subprocess.DEVNULL)
    done = subprocess.run([bin_, "compare", str(directory), "--models", ",".join(models), *extra],
                          check=True, capture_output=True, text=True)
    cpu = {}
    # `compare: MODEL done: L lobes in W s (C CPU s)`; the chain models share one walk, whose
    # line names them all: its CPU time is shared among them in proportion to their lobes.
    for line in done.stderr.splitlines():
        one = re.match(r"compare: (\S+) done: (\d+) lobes in [\d.]+ s \(([\d.]+) CPU s\)", line)
        joint = re.match(r"compare: (.+) walked on one chain of directions in [\d.]+ s \(([\d.]+) CPU s\)", line)
        if one:
            cpu.setdefault(one[1], [0.0, 0])
            cpu[one[1]][0] += float(one[3])
            cpu[one[1]][1] += int(one[2])
        elif joint:
            cpu["chain"] = [float(joint[2]), [m.strip() for m in joint[1].split(",")]]
    return cpu


def cpu_per_lobe(cpu: dict) -> dict:
    """CPU seconds per lobe of each model, the joint chain walk shared by lobe count."""
    seconds = {m: v[0] for m, v in cpu.items() if m != "chain"}
    lobes = {m: v[1] for m, v in cpu.items() if m != "chain"}
    if "chain" in cpu:
        total, members = cpu["chain"]
        shared = sum(lobes.get(m, 0) for m in members)
        for m in members:
            if shared:
                seconds[m] = seconds.get(m, 0.0) + total * lobes.get(m, 0) / shared
    return {m: seconds[m] / lobes[m] for m in seconds if lobes.get(m)}


def lobe_errors(lobes: pd.DataFrame, models: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    """Per lobe and model, the noise-corrected relative L2 error e (module docstring)."""
    keys = LOBE_KEYS + (["channel"] if "channel" in lobes else [])
    frames = []
    w, s_w = lobes["energy"].to_numpy(), lobes["energy_stderr"].to_numpy()
    for name in names:
        m = models[name].to_numpy(dtype=float)
        s_m = models[f"{name}_stderr"].fillna(0.0).to_numpy(dtype=float)
        part = lobes[keys].copy()
        part["model"] = name
        part["d2"] = (m - w) ** 2
        part["n2"] = s_m**2 + s_w**2
        part["n4"] = part["n2"] ** 2
        part["w2"] = w**2
        part = part[~np.isnan(m)]
        frames.append(part.groupby(keys + ["model"], as_index=False)[["d2", "n2", "n4", "w2"]].sum())
    sums = pd.concat(frames)
    excess = (sums["d2"] - sums["n2"]).clip(lower=0.0)
    w2 = sums["w2"].where(sums["w2"] > 0)
    sums["lobe_error"] = np.sqrt(excess / w2)
    # Under noise alone each (m - w)^2 is s^2 chi^2_1, of variance 2 s^4: the standard
    # deviation of the sum, on the scale of e, is what an unbiased model scores by chance.
    sums["lobe_noise"] = np.sqrt(np.sqrt(2.0 * sums["n4"]) / w2)
    return sums.drop(columns=["d2", "n2", "n4", "w2"])


def score_run(directory: Path, paths: int) -> pd.DataFrame:
    """Every lobe compare tested in one run directory, with its errors and its slot label."""
    lobes = pd.read_csv(directory / "lobes.csv")
    models = pd.read_csv(directory / "models.csv")
    if len(lobes) != len(models):
        sys.exit(f"error: {directory}: models.csv has {len(models)} rows, lobes.csv {len(lobes)}")
    compare = pd.read_csv(directory / "compare.csv")
    names = [m for m in compare["model"].unique()]
    keys = LOBE_KEYS + (["channel"] if "channel" in compare else [])
    scored = compare.merge(lobe_errors(lobes, models, names), on=keys + ["model"], how="left")
    scored["slot"] = [
        "all" if order == 0 else f"{order}+" if folded else str(order)
        for order, folded in zip(scored["order"], scored["folded"])
    ]
    scored["albedo_error"] = scored["albedo_model"] - scored["albedo_measured"]
    scored["albedo_noise"] = np.hypot(scored["albedo_measured_stderr"], scored["albedo_model_stderr"].fillna(0.0))
    # Relative variance per photon of an albedo estimate: n stderr^2 / albedo^2.
    scored["walk_var"] = paths * (scored["albedo_measured_stderr"] / scored["albedo_measured"]) ** 2
    model_albedo = scored["albedo_model"].where(scored["albedo_model"] > 0)
    scored["model_var"] = paths * (scored["albedo_model_stderr"] / model_albedo) ** 2
    scored["run"] = directory.name
    return scored


def describe(row) -> str:
    """A case in words: NDF, roughness, material, side, incidence."""
    alpha = f"{row.alpha_x:g}" if row.alpha_x == row.alpha_y else f"{row.alpha_x:g}x{row.alpha_y:g}"
    channel = f" ({row.channel})" if "channel" in row.index and isinstance(row.channel, str) else ""
    return f"{row.ndf} {alpha}, {row.material}{channel}, {row.side} {row.theta_i_deg:g}°"


def worst(group: pd.DataFrame, column: str, noise: str) -> str:
    """The largest |column| of a group, its noise level and the case it occurs in."""
    values = group[column].abs()
    if values.isna().all():
        return "—"
    row = group.loc[values.idxmax()]
    sign = "+" if column == "albedo_error" else ""
    return f"{row[column]:{sign}.4f} ± {row[noise]:.4f} ({describe(row)})"


def table(scored: pd.DataFrame, models: list[str]) -> list[str]:
    """Markdown rows: per model, slot and hemisphere, the median and worst errors."""
    lines = [
        "| model | order | hemi | lobes | median abs. albedo error | worst albedo error (case) | median lobe error ± noise | worst lobe error (case) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for model in models:
        for slot in SLOTS:
            for hemi in ["R", "T"]:
                g = scored[(scored["model"] == model) & (scored["slot"] == slot) & (scored["hemisphere"] == hemi)]
                if g.empty:
                    continue
                lines.append(
                    f"| `{model}` | {slot} | {hemi} | {len(g)} | {g['albedo_error'].abs().median():.4f} | "
                    f"{worst(g, 'albedo_error', 'albedo_noise')} | "
                    f"{g['lobe_error'].median():.4f} ± {g['lobe_noise'].median():.4f} | {worst(g, 'lobe_error', 'lobe_noise')} |"
                )
    return lines


def verdicts(scored_all: pd.DataFrame) -> list[str]:
    """Markdown rows: each exact oracle's p-values over the whole grid (no albedo floor)."""
    lines = ["| exact model | lobes | Sidak level per lobe | smallest p (case) | rejected |", "|---|---|---|---|---|"]
    for model in EXACT:
        g = scored_all[scored_all["model"] == model]
        if g.empty:
            continue
        level = 1.0 - (1.0 - LEVEL) ** (1.0 / len(g))
        row = g.loc[g["p_value"].idxmin()]
        lines.append(
            f"| `{model}` | {len(g)} | {level:.2e} | {row.p_value:.2e} ({describe(row)}, order {row.slot} "
            f"{row.hemisphere}) | {(g['p_value'] < level).sum()} |"
        )
    return lines


def costs(scored: pd.DataFrame, per_lobe: dict, models: list[str]) -> list[str]:
    """Markdown rows: CPU per lobe, and the relative variance per photon of Monte Carlo models."""
    lines = [
        "| model | CPU ms per lobe | median relative variance per photon of its albedo (the walk's, same lobes) |",
        "|---|---|---|",
    ]
    for model in models:
        if model not in per_lobe:
            continue
        g = scored[scored["model"] == model]
        variance = "— (deterministic quadrature)"
        if model in MONTE_CARLO and not g.empty:
            variance = f"{g['model_var'].median():.3g} ({g['walk_var'].median():.3g})"
        lines.append(f"| `{model}` | {1e3 * per_lobe[model]:.2f} | {variance} |")
    return lines


def figure(scored: pd.DataFrame, models: list[str], axis: str, label: str, path: Path) -> None:
    """Median errors against one case parameter, one line per model, a panel per slot."""
    slots = [s for s in SLOTS if (scored["slot"] == s).any()]
    fig, axes = plt.subplots(2, len(slots), figsize=(3.2 * len(slots), 6.0), squeeze=False, sharex=True)
    colours = plt.get_cmap("tab10")
    for j, slot in enumerate(slots):
        panels = [("albedo_error", "abs. albedo error", "albedo_noise"), ("lobe_error", "lobe error", "lobe_noise")]
        for i, (column, what, noise) in enumerate(panels):
            ax = axes[i][j]
            # What noise alone gives: the albedos' standard error, the lobe error's noise level.
            floor = scored[scored["slot"] == slot].groupby(axis)[noise].median()
            ax.plot(floor.index, floor.clip(lower=1e-5), color="0.6", ls="--", lw=1.2, label="noise level")
            for k, model in enumerate(models):
                g = scored[(scored["model"] == model) & (scored["slot"] == slot)]
                if g.empty:
                    continue
                curve = g.assign(v=g[column].abs()).groupby(axis)["v"].median()
                # Ten colours, then the same colours dashed with other markers: no two models alike.
                style = dict(color=colours(k % 10), ls="-" if k < 10 else "--", marker="os^DvP<>Xh"[k // 10 % 10])
                ax.plot(curve.index, curve.clip(lower=1e-5), ms=3, label=model, **style)
            ax.set_yscale("log")
            ax.set_ylim(1e-5, 2.0)
            if i == 0:
                ax.set_title("all orders" if slot == "all" else f"order {slot}")
            if i == 1:
                ax.set_xlabel(label)
            if j == 0:
                ax.set_ylabel(f"median {what}")
            ax.grid(alpha=0.3)
    handles, labels = [], []
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 5), frameon=False)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    tmp = path.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    tmp.replace(path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("--out", type=Path, default=Path("out/scoreboard"))
    parser.add_argument("--doc", type=Path, default=REPO / "docs" / "scoreboard.md")
    parser.add_argument("--figures", type=Path, default=REPO / "docs" / "figures")
    parser.add_argument("--paths", type=int, help="photons per case (overrides the config's)")
    parser.add_argument("--threads", type=int)
    parser.add_argument("--bin")
    args = parser.parse_args()

    board = tomllib.loads(args.config.read_text())
    bin_ = binary(args.bin)
    models = board["models"]
    floor = board.get("albedo_floor", 1e-3)
    args.out.mkdir(parents=True, exist_ok=True)
    args.figures.mkdir(parents=True, exist_ok=True)

    start, cpu_start = time.time(), os.times()
    scored, per_lobe, cases, paths = [], {}, 0, None
    for name, config in run_configs(board, args.paths):
        print(f"scoreboard: {name}", file=sys.stderr)
        cpu = walk_and_compare(bin_, name, config, models, args.out, args.threads)
        for model, value in cpu_per_lobe(cpu).items():
            per_lobe.setdefault(model, []).append(value)
        paths = config["paths"]
        scored.append(score_run(args.out / name, paths))
        cases += len(json.loads((args.out / name / "run.json").read_text())["cases"])
    wall = time.time() - start
    cpu_end = os.times()
    cpu_seconds = (cpu_end.children_user - cpu_start.children_user) + (cpu_end.children_system - cpu_start.children_system)
    scored_all = pd.concat(scored, ignore_index=True)
    above = scored_all[scored_all["albedo_measured"] >= floor]
    present = [m for m in models if (scored_all["model"] == m).any()]
    per_lobe = {m: float(np.mean(v)) for m, v in per_lobe.items()}

    stem = args.doc.stem
    figure_alpha = args.figures / f"{stem}-alpha.png"
    figure_theta = args.figures / f"{stem}-theta.png"
    figure(above, present, "alpha_x", "alpha", figure_alpha)
    figure(above, present, "theta_i_deg", "theta_i (deg)", figure_theta)
    relative = os.path.relpath(args.figures, args.doc.parent)
    commit = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    absent = [m for m in models if m not in present]

    text = [
        "# The scoreboard: every model against the exact walk, per order",
        "",
        "<!-- Written by scripts/scoreboard.py; edit the script or configs/scoreboard.toml, not this page. -->",
        "",
        f"`python3 scripts/scoreboard.py {args.config}` ran {cases} cases ({', '.join(n for n, _ in run_configs(board, args.paths))}: "
        f"GGX and Beckmann, the roughnesses, materials and angles of `{args.config}`) with {paths:,} photons per case "
        f"for the walk and for each Monte Carlo model, in {wall / 60:.1f} min of wall time and {cpu_seconds / 60:.1f} min "
        f"of CPU time (smithwalk {commit}). A lobe is one case, order slot (1, 2, 3, 4 and above, or all orders "
        "together for the models that do not separate orders), hemisphere (R the side the light came from) and "
        f"channel; lobes whose measured albedo is below {floor:g} are not scored. Which model applies to which "
        "case is `smithwalk compare`'s rule (docs/compare.md)"
        + (f"; {', '.join(f'`{m}`' for m in absent)} applied to no case here." if absent else ".")
        + (" `lee2018` is another microsurface, specular V-grooves (docs/theory.md §14), not an approximation of "
           "the walk's: its errors measure how far that family is from the Smith walk at each order."
           if "lee2018" in present else ""),
        "",
        "**Albedo error**: the model's albedo minus the walk's. **Lobe error**: the relative L2 distance of the "
        "model's lobe from the walk's over the detector's bins, with the part that the Monte Carlo noise of both "
        "sides contributes taken out, `sqrt(max(0, Σ(m-w)² - Σ(s_m²+s_w²)) / Σw²)`: an exact model scores near 0 "
        "at any photon count, an approximation its bias. Both are median and worst over the grid, with the case of "
        "the worst. Beside each, what noise alone gives: for an albedo error the standard error of the "
        "difference (the walk's, and the model's for a Monte Carlo model), for a lobe error its noise level, the standard "
        "deviation of that statistic for a model without bias, `sqrt(sqrt(2 Σ(s_m²+s_w²)²) / Σw²)` (the median "
        "of it beside the median). An exact model's errors are of this size and shrink with it as photons "
        "grow; an approximation's stay.",
        "",
        "## Exact models: consistent with the walk",
        "",
        f"Their p-values over every lobe they were tested on (no albedo floor), judged at the Šidák level that keeps "
        f"the family-wise level at {LEVEL}: a rejection would be a fault in the walk or in the model.",
        "",
        *verdicts(scored_all),
        "",
        "## Errors per model, order and hemisphere",
        "",
        *table(above, present),
        "",
        f"![median errors against roughness]({relative}/{figure_alpha.name})",
        "",
        f"![median errors against incidence]({relative}/{figure_theta.name})",
        "",
        "Median over the other parameters of the grid, with the median noise level dashed in grey; errors "
        "below 1e-5 are drawn at 1e-5.",
        "",
        "## Cost",
        "",
        "CPU time per lobe as `smithwalk compare` reports it (the three chain models share one walk, divided "
        "among them by lobes), averaged over the runs; for the Monte Carlo models, the median relative "
        "variance per photon of their albedo estimate, `n s² / a²`, beside the walk's own on the same lobes "
        "(smaller is better: the variance of one photon's contribution).",
        "",
        *costs(above, per_lobe, present),
        "",
    ]
    tmp = args.doc.with_suffix(".md.tmp")
    tmp.write_text("\n".join(text))
    tmp.replace(args.doc)
    print(f"wrote {args.doc}, {figure_alpha}, {figure_theta}", file=sys.stderr)


if __name__ == "__main__":
    main()
