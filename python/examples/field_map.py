"""A map of |B| around a fibre magnetised by an external field, plotted with matplotlib.

    python python/examples/field_map.py [--out field_map.png]

The fibre (radius 300 um, length 12 mm, iron-like M_s = 985 kA/m) lies along x in a uniform
field of 1 T along x; its magnetisation follows from the field (Stoner-Wohlfarth). The map is
the plane y = 0 around the fibre's end, evaluated at 400 x 400 points in one call.
"""

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import magsep  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="field_map.png", help="output image (PNG, SVG, PDF)")
    parser.add_argument("--n", type=int, default=400, help="points per side")
    args = parser.parse_args()

    fibre = magsep.Cylinder(radius=300e-6, half_length=6e-3, axis=(1, 0, 0), saturation_magnetisation=985e3)
    external = [1.0, 0.0, 0.0]  # B_ext [T]
    x = np.linspace(4e-3, 8e-3, args.n)  # [m], around the end at x = 6 mm
    z = np.linspace(-1.5e-3, 1.5e-3, args.n)
    X, Z = np.meshgrid(x, z)
    points = np.column_stack([X.ravel(), np.zeros(X.size), Z.ravel()])
    B = magsep.field([fibre], points, external=external)  # (N, 3) [T]
    magnitude = np.linalg.norm(B, axis=1).reshape(X.shape)
    inside = (np.abs(Z) <= 300e-6) & (X <= 6e-3)
    magnitude[inside] = np.nan

    fig, ax = plt.subplots(figsize=(7, 4.5))
    im = ax.pcolormesh(X * 1e3, Z * 1e3, magnitude, shading="auto", cmap="viridis")
    fig.colorbar(im, ax=ax, label="|B| [T]")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("z [mm]")
    ax.set_title("|B| at the end of a magnetised fibre (y = 0, B_ext = 1 T along x)")
    ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"{args.out}: |B| from {np.nanmin(magnitude):.3f} to {np.nanmax(magnitude):.3f} T at {points.shape[0]} points")


if __name__ == "__main__":
    main()
