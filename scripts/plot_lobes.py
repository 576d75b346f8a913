#!/usr/bin/env python3
"""Plane-of-incidence lobes of a smithwalk run, per bounce order, with the models of models.csv.

The same figure as `smithwalk plot` draws (lobes_g<k>_<R|T>), for users who script their own:
for every surface and material of the run and each hemisphere with light, one row per bounce
order and one column per incident angle, the cosine-weighted lobe f |cos theta_o| (a bin's
energy over its solid angle, 1/sr) in the plane of incidence against the signed outgoing angle
(positive on the mirror side, phi = 180 deg; negative on the light's side, phi = 0). The
random walk is drawn as black points with one-standard-error bars; when models.csv sits next
to lobes.csv (after `smithwalk compare`), every model as a line in its fixed colour and dash,
the same as in `smithwalk plot` (docs/figures.md). models.csv has the rows of lobes.csv in the
same order, and per model a column `<model>` (its energy) with a column `<model>_stderr`; a
model's cells are empty where it gives no lobe (docs/compare.md).

    python3 scripts/plot_lobes.py out/quickstart/lobes.csv --out lobes.png [--orders 1 2 3 0]

With several surfaces, materials or hemispheres, one file each: lobes_g0_R.png, lobes_g1_T.png...
(the --out name with _g<k>_<R|T> before the extension), numbered as `smithwalk plot` numbers
its lobes_g<k>_<R|T>, so files of the same name show the same cases. The --out directory is
created if need be. An --out ending in .svg or .pdf writes vector files.
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

# A bin's edges: what plane_of_incidence needs besides the energy.
BIN_EDGES = ["cos_lo", "cos_hi", "phi_lo_deg", "phi_hi_deg"]
SURFACE = ["ndf", "alpha_x", "alpha_y", "height", "smith", "normals", "material", "phi_i_deg", "side"]
# The fixed style of every model, as in src/exports/plot/style.rs: (colour, dash).
MODEL_STYLE = {
    "single": ("#117733", "-"),
    "hammon-fit": ("#882255", "-"),
    "heitz-nee": ("#0072b2", (0, (3.5, 2))),
    "exact-position-free": ("#d55e00", (0, (7, 2))),
    "wang-correlated": ("#cc79a7", "-"),
    "wang-uncorrelated": ("#332288", (0, (1, 1.5))),
    "cui2023-released": ("#3300ff", (0, (3.5, 2))),
    "kulla-conty": ("#009e73", (0, (3.5, 2))),
    "turquin": ("#999933", (0, (1, 1.5))),
    "fdez-aguera": ("#ee6677", (0, (1, 1.5))),
    "materialx": ("#56b4e9", (0, (3.5, 2))),
    "lee2018": ("#7766ff", (0, (1, 1.5))),
    "external": ("#8c510a", (0, (7, 2))),
}


def plane_of_incidence(df):
    """Bins that contain phi = 0 or phi = 180 deg, with a signed outgoing angle in degrees and
    the lobe f |cos theta_o| (energy over the bin's solid angle in |cos theta| and phi)."""
    forward = (df.phi_lo_deg <= 180.0) & (df.phi_hi_deg > 180.0)
    backward = df.phi_lo_deg == 0.0
    rows = df[forward | backward].copy()
    mid = (rows.cos_lo.abs() + rows.cos_hi.abs()) / 2.0
    theta = mid.clip(upper=1.0).map(lambda c: math.degrees(math.acos(c)))
    rows["theta_o"] = theta.where(forward[forward | backward], -theta)
    solid = (rows.cos_hi - rows.cos_lo).abs() * (rows.phi_hi_deg - rows.phi_lo_deg).map(math.radians)
    rows["lobe"] = rows.energy / solid
    if "energy_stderr" in rows:
        rows["lobe_se"] = rows.energy_stderr / solid
    return rows.sort_values("theta_o")


def order_label(order, folded):
    if order == 0:
        return "all orders"
    return f"orders {order}+" if order == folded else f"order {order}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("lobes", help="lobes.csv of a smithwalk run (models.csv next to it is drawn too)")
    parser.add_argument("--out", default="lobes.png", help="file to write")
    parser.add_argument("--orders", type=int, nargs="+", help="orders to draw (0 = all; default: every order)")
    parser.add_argument("--channel", default="r", help="channel of RGB runs")
    parser.add_argument("--models", help="models.csv (default: next to lobes.csv, if there)")
    args = parser.parse_args()

    df = pd.read_csv(args.lobes)
    models_path = args.models or os.path.join(os.path.dirname(os.path.abspath(args.lobes)), "models.csv")
    model_names = []
    if os.path.exists(models_path):
        models = pd.read_csv(models_path)
        if len(models) != len(df):
            sys.exit(f"{models_path} has {len(models)} rows, {args.lobes} {len(df)}: not the models of this run")
        # Row for row beside lobes.csv: each model's energy becomes a column of df.
        model_names = [name for name in models.columns if f"{name}_stderr" in models.columns]
        df = pd.concat([df, models[model_names].add_prefix("model:")], axis=1)
    if "channel" in df.columns:
        df = df[df.channel == args.channel]
    summary_path = os.path.join(os.path.dirname(os.path.abspath(args.lobes)), "summary.csv")
    folded = None
    if os.path.exists(summary_path):
        summary = pd.read_csv(summary_path)
        if "folded" in summary and summary.folded.any():
            folded = int(summary[summary.folded].order.max())
    orders = args.orders or sorted(df.order.unique(), key=lambda o: (o == 0, o))
    stem, ext = os.path.splitext(args.out)
    # Numbered as `smithwalk plot` numbers lobes_g<k>_<R|T>: k counts the surfaces and
    # materials (cases that differ only in theta_i) in order of their first case, and both
    # hemispheres of one surface share its k.
    groups = [
        (g, key, hemisphere, part)
        for g, (key, surface) in enumerate(df.groupby(SURFACE, sort=False))
        for hemisphere, part in surface.groupby("hemisphere", sort=True)
    ]
    out_dir = os.path.dirname(args.out)
    if out_dir:
        os.makedirs(out_dir, exist_ok=True)
    for g, key, hemisphere, surface in groups:
        label = dict(zip(SURFACE, key))
        thetas = sorted(surface.theta_i_deg.unique())
        fig, axes = plt.subplots(
            len(orders), len(thetas), figsize=(2.6 * len(thetas), 1.9 * len(orders) + 0.8), squeeze=False
        )
        drawn = set()
        for t, theta in enumerate(thetas):
            case = surface[surface.theta_i_deg == theta]
            for r, order in enumerate(orders):
                ax = axes[r][t]
                these = case[case.order == order]
                lobe = plane_of_incidence(these)
                for name in sorted(model_names):
                    given = these[these[f"model:{name}"].notna()]
                    if given.empty:
                        continue
                    colour, dash = MODEL_STYLE.get(name, ("#777777", "-"))
                    m = plane_of_incidence(given[BIN_EDGES].assign(energy=given[f"model:{name}"]))
                    ax.plot(m.theta_o, m.lobe, color=colour, linestyle=dash, lw=1.3, label=name)
                    drawn.add(name)
                if not lobe.empty:
                    ax.errorbar(
                        lobe.theta_o, lobe.lobe, yerr=lobe.lobe_se, fmt="o", ms=2, color="black",
                        elinewidth=0.7, capsize=0, label="random walk (±1 SE)",
                    )
                ax.set_title(f"{order_label(order, folded)}, θ_i = {theta:.1f}°", fontsize=8)
                ax.set_xlim(-90, 90)
                ax.set_xticks([-90, -60, -30, 0, 30, 60, 90])
                ax.set_ylim(bottom=0)
                ax.tick_params(labelsize=7)
                ax.grid(color="#e4e4e4", lw=0.6)
        fig.supylabel("f·|cos θ_o| (1/sr)", fontsize=9)
        fig.supxlabel("θ_o (deg), + mirror side, − light's side (plane of incidence)", fontsize=9)
        side = "transmission (T)" if hemisphere == "T" else "reflection (R)"
        alpha = label["alpha_x"] if label["alpha_x"] == label["alpha_y"] else f"({label['alpha_x']}, {label['alpha_y']})"
        fig.suptitle(f"{label['ndf'].upper()}, α = {alpha}, {label['material']}: {side}", fontsize=10)
        handles, names = axes[0][0].get_legend_handles_labels()
        order_of = ["random walk (±1 SE)"] + sorted(drawn)
        pairs = sorted(zip(handles, names), key=lambda hn: order_of.index(hn[1]) if hn[1] in order_of else 99)
        fig.legend(
            [h for h, _ in pairs], [n for _, n in pairs], loc="upper center", ncol=len(pairs),
            bbox_to_anchor=(0.5, 0.965), fontsize=8, frameon=False,
        )
        fig.tight_layout(rect=(0, 0, 1, 0.93))
        out = args.out if len(groups) == 1 else f"{stem}_g{g}_{hemisphere}{ext}"
        fig.savefig(out, dpi=150)
        plt.close(fig)
        print(f"wrote {out}" + (f" with {', '.join(sorted(drawn))}" if drawn else ""), file=sys.stderr)


if __name__ == "__main__":
    main()
