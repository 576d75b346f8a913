#!/usr/bin/env python3
"""Plane-of-incidence lobes from a smithwalk lobes.csv, per bounce order.

For every surface and material of the run, draws one panel per incident angle: the
cosine-weighted lobe f |cos theta_o| (the bin's energy over its solid angle) in the plane of
incidence, against the signed outgoing angle (positive on the mirror side, phi = 180 deg;
negative on the light's side, phi = 0), with one-standard-error bars, for each bounce order
and all orders together. Reflection above, transmission (if any) below.

    python3 scripts/plot_lobes.py out/quickstart/lobes.csv --out lobes.png [--orders 1 2 3 0]
"""
import argparse
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

SURFACE = ["ndf", "alpha_x", "alpha_y", "height", "smith", "normals", "material", "side"]


def plane_of_incidence(df):
    """Bins that contain phi = 0 or phi = 180 deg, with a signed outgoing angle in degrees."""
    forward = (df.phi_lo_deg <= 180.0) & (df.phi_hi_deg > 180.0)
    backward = df.phi_lo_deg == 0.0
    rows = df[forward | backward].copy()
    mid = (rows.cos_lo.abs() + rows.cos_hi.abs()) / 2.0
    theta = mid.clip(upper=1.0).map(lambda c: math.degrees(math.acos(c)))
    rows["theta_o"] = theta.where(forward[forward | backward], -theta)
    solid = (rows.cos_hi - rows.cos_lo).abs() * (rows.phi_hi_deg - rows.phi_lo_deg).map(math.radians)
    rows["lobe"] = rows.energy / solid
    rows["lobe_se"] = rows.energy_stderr / solid
    return rows.sort_values("theta_o")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("lobes", help="lobes.csv of a smithwalk run")
    parser.add_argument("--out", default="lobes.png", help="PNG file to write")
    parser.add_argument("--orders", type=int, nargs="+", default=[1, 2, 3, 0], help="orders to draw (0 = all)")
    parser.add_argument("--channel", default="r", help="channel of RGB runs")
    args = parser.parse_args()

    df = pd.read_csv(args.lobes)
    if "channel" in df.columns:
        df = df[df.channel == args.channel]
    # One row of panels per surface, material and hemisphere that has light.
    panels = [
        (dict(zip(SURFACE, key)), hemisphere, part)
        for key, surface in df.groupby(SURFACE, sort=False)
        for hemisphere, part in surface.groupby("hemisphere", sort=True)
    ]
    thetas = sorted(df.theta_i_deg.unique())
    rows = len(panels)
    fig, axes = plt.subplots(rows, len(thetas), figsize=(3.2 * len(thetas), 2.6 * rows), squeeze=False)
    for row, (label, hemisphere, surface) in enumerate(panels):
        for t, theta in enumerate(thetas):
            ax = axes[row][t]
            case = surface[surface.theta_i_deg == theta]
            for order in args.orders:
                lobe = plane_of_incidence(case[case.order == order])
                if lobe.empty:
                    continue
                name = "all" if order == 0 else f"order {order}"
                ax.errorbar(lobe.theta_o, lobe.lobe, yerr=lobe.lobe_se, label=name, lw=1, capsize=1.5)
            ax.set_title(
                f"{label['ndf']} a=({label['alpha_x']},{label['alpha_y']}) {label['material']}\n"
                f"theta_i={theta:.1f} {hemisphere}",
                fontsize=7,
            )
            ax.set_xlim(-90, 90)
            ax.tick_params(labelsize=6)
            if t == 0:
                ax.set_ylabel("f |cos theta_o|", fontsize=7)
            if row == rows - 1:
                ax.set_xlabel("theta_o (deg, + mirror side)", fontsize=7)
    axes[0][0].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
