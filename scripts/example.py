"""A first smithwalk session in Python: a small sweep, the Wang et al. 2022 models beside it, the
per-order lobes f·|cos θ_o| in the plane of incidence, drawn as `smithwalk plot` draws them (same
bins, quantity, labels and model colours).

    pip install ./crates/python matplotlib pandas
    python scripts/example.py                  # 10^6 photons per case
    python scripts/example.py --paths 20000    # a quick look

Writes OUT/run/ (the run directory, as `smithwalk run` and `smithwalk compare` write it) and
OUT/lobes.png, and prints the per-order albedos of the walk and of both models.
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt
import numpy as np

import smithwalk

# A GGX conductor (F = 1) at two roughnesses and two incident angles; orders 1, 2, 3+ and all.
CONFIG = {
    "paths": 1_000_000,
    "seed": 1,
    "surface": {"ndf": "ggx", "alpha": [0.3, 0.8]},
    "material": {"kind": "conductor", "fresnel": "none"},
    "incident": {"theta_deg": [30, 70]},
    "detector": {"cos_theta_bins": 32, "phi_bins": 64, "max_order": 3},
}
MODELS = ["wang-correlated", "wang-uncorrelated"]


# The fixed style of these models in every smithwalk figure (src/exports/plot/style.rs,
# scripts/plot_lobes.py): (colour, dash).
MODEL_STYLE = {"wang-correlated": ("#cc79a7", "-"), "wang-uncorrelated": ("#332288", (0, (1, 1.5)))}


def plane_of_incidence(energy, cos_edges, phi_edges_deg):
    """A lobe's energies (cos_bin, phi_bin) in the plane of incidence as `smithwalk plot` draws
    it: f |cos theta_o|, a bin's energy over its solid angle, in the bins that contain phi = 0
    (the light's side) and phi = 180 deg (the mirror side); returns (light's side, mirror side)."""
    half = (len(phi_edges_deg) - 1) // 2
    solid = np.diff(cos_edges)[:, None] * np.radians(np.diff(phi_edges_deg))[None, :]
    lobe = energy / solid
    return lobe[:, 0], lobe[:, half]


def signed_angles(cos_edges):
    """Outgoing polar angle of each cos bin's centre, in degrees: the light's side negative."""
    theta = np.degrees(np.arccos(0.5 * (cos_edges[:-1] + cos_edges[1:])))
    return -theta, theta


def across_the_plane(sides, x_sides):
    """Both sides of the plane of incidence as one curve from the light's horizon to the
    mirror side's, so that a line runs through theta_o = 0 instead of stopping short of it."""
    x = np.concatenate(x_sides)
    order = np.argsort(x)
    return x[order], np.concatenate(sides)[order]


def order_label(label):
    """How `smithwalk plot` names an order slot ("all", "1", "3+" in `result.orders`)."""
    if label == "all":
        return "all orders"
    return f"orders {label}" if label.endswith("+") else f"order {label}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--paths", type=int, default=CONFIG["paths"], help="photons per case")
    parser.add_argument("--out", type=Path, default=Path("out/example"), help="output directory")
    args = parser.parse_args()

    result = smithwalk.run(CONFIG, paths=args.paths)
    comparison = result.compare(MODELS)
    result.save(args.out / "run")

    # Albedo per order: the walk against both models (all cases, reflection); order as in
    # `result.orders` ("all", "1", "2", "3+").
    table = comparison.table
    columns = ["case", "model", "order", "albedo_measured", "albedo_measured_stderr", "albedo_model"]
    reflected = table[table["hemisphere"] == "R"][columns].copy()
    reflected["order"] = [result.orders[o] for o in reflected["order"]]
    print(reflected.to_string(index=False))

    rows = [*range(1, len(result.orders)), 0]  # orders 1, 2, ..., then all orders (slot 0)
    back_x, mirror_x = signed_angles(result.cos_edges)
    fig, axes = plt.subplots(
        len(rows), len(result.cases), figsize=(3.2 * len(result.cases), 2.4 * len(rows)),
        squeeze=False, sharex=True,
    )
    for j, case in enumerate(result.cases):
        for i, k in enumerate(rows):
            ax = axes[i, j]
            walk = plane_of_incidence(result.energy[j, k, 0], result.cos_edges, result.phi_edges_deg)
            err = plane_of_incidence(result.energy_stderr[j, k, 0], result.cos_edges, result.phi_edges_deg)
            models = {
                m: plane_of_incidence(comparison[m]["energy"][j, k, 0], result.cos_edges, result.phi_edges_deg)
                for m in MODELS
            }
            x, y = across_the_plane(walk, (back_x, mirror_x))
            _, yerr = across_the_plane(err, (back_x, mirror_x))
            ax.errorbar(x, y, yerr=yerr, fmt=".", color="black", ms=3, label="random walk (±1 SE)")
            for m in MODELS:
                colour, dash = MODEL_STYLE[m]
                ax.plot(*across_the_plane(models[m], (back_x, mirror_x)), color=colour, ls=dash, lw=1, label=m)
            if i == 0:
                ax.set_title(f"alpha {case['alpha_x']}, theta_i {case['theta_i_deg']:g} deg", fontsize=9)
            if j == 0:
                ax.set_ylabel(f"{order_label(result.orders[k])}\nf·|cos θ_o| (1/sr)")
            if i == len(rows) - 1:
                ax.set_xlabel("θ_o (deg), + mirror side, − light's side")
    # One legend above the panels, where it hides no data.
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=len(labels), fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "lobes.png", dpi=90)
    print(f"wrote {args.out / 'run'} and {args.out / 'lobes.png'}")


if __name__ == "__main__":
    main()
