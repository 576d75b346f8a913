"""A first smithwalk session in Python: a small sweep, the Wang et al. 2022 models beside it, the
per-order lobes in the plane of incidence.

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

# A GGX conductor (F = 1) at two roughnesses and two incident angles; orders 1, 2 and 3+.
CONFIG = {
    "paths": 1_000_000,
    "seed": 1,
    "surface": {"ndf": "ggx", "alpha": [0.3, 0.8]},
    "material": {"kind": "conductor", "fresnel": "none"},
    "incident": {"theta_deg": [30, 70]},
    "detector": {"cos_theta_bins": 32, "phi_bins": 64, "max_order": 3},
}
MODELS = ["wang-correlated", "wang-uncorrelated"]


def plane_of_incidence(values, phi_bins, stderr=False):
    """A lobe (cos_bin, phi_bin) in the plane of incidence: the two phi bins either side of the
    mirror azimuth (180 deg) and of the incident one (0 deg), averaged; returns (back, mirror).
    With `stderr`, `values` are standard errors, combined as those of independent bins."""
    half = phi_bins // 2
    pairs = ([0, phi_bins - 1], [half - 1, half])
    if stderr:
        return tuple(np.sqrt((values[:, p] ** 2).sum(axis=1)) / 2 for p in pairs)
    return tuple(values[:, p].mean(axis=1) for p in pairs)


def signed_angles(cos_edges):
    """Outgoing polar angle of each cos bin's centre, in degrees: back side negative."""
    theta = np.degrees(np.arccos(0.5 * (cos_edges[:-1] + cos_edges[1:])))
    return -theta, theta


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--paths", type=int, default=CONFIG["paths"], help="photons per case")
    parser.add_argument("--out", type=Path, default=Path("out/example"), help="output directory")
    args = parser.parse_args()

    result = smithwalk.run(CONFIG, paths=args.paths)
    comparison = result.compare(MODELS)
    result.save(args.out / "run")

    # Albedo per order: the walk against both models (all cases, reflection).
    table = comparison.table
    columns = ["case", "model", "order", "albedo_measured", "albedo_measured_stderr", "albedo_model"]
    print(table[table["hemisphere"] == "R"][columns].to_string(index=False))

    orders = range(1, len(result.orders))  # slot 0 is all orders together
    phi_bins = len(result.phi_edges_deg) - 1
    back_x, mirror_x = signed_angles(result.cos_edges)
    fig, axes = plt.subplots(
        len(orders), len(result.cases), figsize=(3.2 * len(result.cases), 2.4 * len(orders)),
        squeeze=False, sharex=True,
    )
    for j, case in enumerate(result.cases):
        for i, k in enumerate(orders):
            ax = axes[i, j]
            walk = plane_of_incidence(result.bsdf[j, k, 0], phi_bins)
            err = plane_of_incidence(result.bsdf_stderr[j, k, 0], phi_bins, stderr=True)
            models = {m: plane_of_incidence(comparison[m]["bsdf"][j, k, 0], phi_bins) for m in MODELS}
            for side, x in enumerate((back_x, mirror_x)):
                label = side == 1  # one legend entry per curve
                ax.errorbar(x, walk[side], yerr=err[side], fmt=".", color="black", ms=3,
                            label="walk" if label else None)
                for m, color in zip(MODELS, ("tab:blue", "tab:orange")):
                    ax.plot(x, models[m][side], color=color, lw=1, label=m if label else None)
            if i == 0:
                ax.set_title(f"alpha {case['alpha_x']}, theta_i {case['theta_i_deg']:g} deg", fontsize=9)
            if j == 0:
                ax.set_ylabel(f"order {result.orders[k]}\nf (1/sr)")
            if i == len(orders) - 1:
                ax.set_xlabel("theta_o (deg), mirror side > 0")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "lobes.png", dpi=90)
    print(f"wrote {args.out / 'run'} and {args.out / 'lobes.png'}")


if __name__ == "__main__":
    main()
