#!/usr/bin/env python3
"""Breaks a mesh into fragments, gives every fragment physical data from a shapedb database in one burst,
and plots each fragment's first vibration frequency against its size.

    python3 fracture_frequencies.py DATABASE MESH [--pieces 50] [--seed 1] [--material steel] [--plot out.png]

For geometrically similar solids of one material the first frequency goes as 1/size: the plot draws that
line through the fragments' median, so the spread about it is what the fragments' shapes do. Prints one
line per fragment: name, size (m, the cube root of its volume), first frequency (Hz), the entry matched.
"""

import argparse
import sys

import numpy as np

import shapedb


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("database", help="a database file (shapedb build)")
    parser.add_argument("mesh", help="a closed surface mesh (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)")
    parser.add_argument("--pieces", type=int, default=50, help="Voronoi seeds of the fracture (default 50)")
    parser.add_argument("--seed", type=int, default=1, help="the fracture's random seed (default 1)")
    parser.add_argument("--material", default="steel", help=f"one of {', '.join(shapedb.materials())}")
    parser.add_argument("--plot", default="fracture_frequencies.png", help="where to write the plot (PNG)")
    args = parser.parse_args()

    try:
        vertices, faces = shapedb.load_mesh(args.mesh)
        broken = shapedb.fracture(vertices, faces, pieces=args.pieces, seed=args.seed)
        db = shapedb.Database(args.database)
    except shapedb.Error as e:
        sys.exit(f"fracture_frequencies: {e}")
    print(f"{len(broken['fragments'])} fragments keep {100 * broken['kept_fraction']:.1f} % of the volume")

    # The whole burst at once, over all cores; matching only needs the first frequency, not the fidelity.
    results = db.query_many(broken["fragments"], material=args.material, fidelity=False)
    sizes, firsts = [], []
    for index, ((v, f), result) in enumerate(zip(broken["fragments"], results)):
        name = f"fragment-{index:03d}"
        if isinstance(result, shapedb.Error):
            print(f"{name}  failed: {result}")
            continue
        size = shapedb.mass_properties(v, f)["volume"] ** (1 / 3)
        first = result.physics["frequencies"][0]
        sizes.append(size)
        firsts.append(first)
        print(f"{name}  {size:.4f}  {first:.1f}  {result.match.name}")
    if not sizes:
        sys.exit("fracture_frequencies: no fragment was answered")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sizes, firsts = 1000.0 * np.array(sizes), np.array(firsts)  # sizes in mm
    constant = np.median(firsts * sizes)
    line = np.geomspace(sizes.min(), sizes.max(), 50)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(sizes, firsts / 1000.0, "o", alpha=0.7, label="fragments (database answer)")
    ax.plot(line, constant / line / 1000.0, "--", color="grey", label="f ∝ 1 / size")
    ax.set_xlabel("fragment size, volume^(1/3) (mm)")
    ax.set_ylabel(f"first frequency in {args.material} (kHz)")
    ax.set_title(f"{len(sizes)} fragments of {args.mesh.rsplit('/', 1)[-1]}")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.plot, dpi=120)
    print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
