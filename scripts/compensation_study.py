#!/usr/bin/env python3
"""Figures and the summary table of the energy-compensation study (docs/compensation.md).

    smithwalk run configs/compensation.toml --out out/compensation
    python3 scripts/compensation_study.py out/compensation [--figures docs/figures]

Reads the run's compare.csv (written by the run's [compare] section, or by
`smithwalk compare out/compensation --models single,kulla-conty,turquin,fdez-aguera,materialx`) and
lobes.csv, and writes
  compensation-albedo.png  albedo error (model - walk) of each model against incidence, one
                           line per roughness, with the walk's 2-standard-error bars;
  compensation-lobe.png    relative L1 error of each model's all-orders lobe against incidence,
                           with the walk's own noise floor (the L1 that noise alone gives);
and prints a Markdown table: per model and material, the worst albedo error and where, and the
median and worst lobe error. Models are judged on the all-orders slot (order 0).
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

MODELS = ["kulla-conty", "turquin", "fdez-aguera", "materialx"]
COLOURS = plt.get_cmap("viridis")


def panels(compare):
    """(label, material, channel) of each row of figures: the mono materials once, gold per channel."""
    rows = []
    for material in compare["material"].unique():
        sub = compare[compare["material"] == material]
        channels = sorted(sub["channel"].unique()) if "channel" in sub else [None]
        coloured = "channel" in sub and sub.groupby("channel")["albedo_measured"].mean().std() > 1e-6
        if coloured:
            for ch in ["r", "b"]:
                rows.append((f"{material} ({ch})", material, ch))
        else:
            rows.append((material, material, channels[0]))
    return rows


def select(df, material, channel, model=None):
    out = df[df["material"] == material]
    if channel is not None and "channel" in out:
        out = out[out["channel"] == channel]
    if model is not None:
        out = out[out["model"] == model]
    return out


def noise_floor(lobes):
    """Per case and channel: the relative L1 that the walk's noise alone gives an exact model,
    sqrt(2/pi) sum(stderr) / sum(energy), over the all-orders reflection bins."""
    all_orders = lobes[(lobes["order"] == 0) & (lobes["hemisphere"] == "R")]
    keys = ["case"] + (["channel"] if "channel" in lobes else [])
    g = all_orders.groupby(keys)
    floor = math.sqrt(2 / math.pi) * g["energy_stderr"].sum() / g["energy"].sum()
    return floor.rename("floor").reset_index()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run_dir")
    ap.add_argument("--figures", default="docs/figures")
    args = ap.parse_args()
    compare = pd.read_csv(os.path.join(args.run_dir, "compare.csv"))
    compare = compare[(compare["order"] == 0) & (compare["hemisphere"] == "R")]
    missing = [m for m in MODELS if m not in set(compare["model"])]
    if missing:
        sys.exit(f"compare.csv has no all-orders rows of {', '.join(missing)}: run compare with these models")
    lobes = pd.read_csv(os.path.join(args.run_dir, "lobes.csv"))
    floor = noise_floor(lobes)
    keys = ["case"] + (["channel"] if "channel" in compare else [])
    compare = compare.merge(floor, on=keys, how="left")
    os.makedirs(args.figures, exist_ok=True)
    rows = panels(compare)
    alphas = sorted(compare["alpha_x"].unique())
    colour = {a: COLOURS(i / max(1, len(alphas) - 1)) for i, a in enumerate(alphas)}

    def figure(quantity, ylabel, name, error, floor_band):
        fig, axes = plt.subplots(len(rows), len(MODELS), figsize=(4.2 * len(MODELS), 3.0 * len(rows)), squeeze=False,
                                 sharex=True)
        for r, (label, material, channel) in enumerate(rows):
            for c, model in enumerate(MODELS):
                ax = axes[r][c]
                sub = select(compare, material, channel, model)
                for a in alphas:
                    s = sub[sub["alpha_x"] == a].sort_values("theta_i_deg")
                    if s.empty:
                        continue
                    ax.errorbar(s["theta_i_deg"], quantity(s), yerr=error(s), color=colour[a], marker="o", ms=3,
                                lw=1.2, capsize=2, label=f"alpha {a:g}")
                    if floor_band:
                        ax.plot(s["theta_i_deg"], s["floor"], color=colour[a], lw=0.8, ls=":")
                if not floor_band:
                    ax.axhline(0.0, color="k", lw=0.6)
                ax.set_title(f"{model}: {label}", fontsize=9)
                ax.grid(alpha=0.3)
                if c == 0:
                    ax.set_ylabel(ylabel)
                if r == len(rows) - 1:
                    ax.set_xlabel("incidence theta_i (deg)")
                if floor_band:
                    ax.set_yscale("log")
        axes[0][0].legend(fontsize=7, ncol=2)
        fig.tight_layout()
        path = os.path.join(args.figures, name)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        print(f"wrote {path}", file=sys.stderr)

    figure(lambda s: s["albedo_model"] - s["albedo_measured"], "albedo error (model - walk)",
           "compensation-albedo.png", lambda s: 2.0 * s["albedo_measured_stderr"], False)
    figure(lambda s: s["rel_l1"], "lobe error, relative L1 (dotted: walk noise)", "compensation-lobe.png",
           lambda s: None, True)

    print("| model | material | worst albedo error (alpha, theta) | albedo error at alpha <= 0.2 | "
          "lobe rel. L1: median / worst (alpha, theta) |")
    print("|---|---|---|---|---|")
    for model in MODELS:
        for label, material, channel in rows:
            s = select(compare, material, channel, model)
            if s.empty:
                continue
            err = s["albedo_model"] - s["albedo_measured"]
            w = err.abs().idxmax()
            smooth = err[s["alpha_x"] <= 0.2].abs().max()
            l = s["rel_l1"].idxmax()
            print(f"| {model} | {label} | {err[w]:+.4f} ({s.loc[w, 'alpha_x']:g}, {s.loc[w, 'theta_i_deg']:g}) | "
                  f"{smooth:.4f} | {s['rel_l1'].median():.3f} / {s.loc[l, 'rel_l1']:.3f} "
                  f"({s.loc[l, 'alpha_x']:g}, {s.loc[l, 'theta_i_deg']:g}) |")
    worst_se = compare["albedo_measured_stderr"].max()
    print(f"\nlargest standard error of a walk albedo: {worst_se:.2e}; "
          f"median noise floor of the lobe L1: {compare['floor'].median():.4f}", file=sys.stderr)


if __name__ == "__main__":
    main()
