"""Per shape, the corrected first frequency's error three ways, from three `shapedb bench` runs' CSVs:
   python3 compare.py SCALED.csv DENSITY.csv LUMPED.csv > OUT.csv  (summary on stderr)"""
import csv
import statistics
import sys


def corrected(path):
    rows = {}
    for r in csv.DictReader(open(path)):
        if r["method"] == "centroid-voxel-corrected" and r["status"] == "ok" and r["f1_error"]:
            rows[r["shape"]] = r
    return rows


runs = [corrected(p) for p in sys.argv[1:4]]
shapes = [s for s in runs[2] if all(s in run for run in runs)]
out = csv.writer(sys.stdout)
out.writerow(["shape", "f1_truth_hz", "error_scaled", "error_density", "error_lumped"])
for s in shapes:
    out.writerow([s, runs[2][s]["f1_truth_hz"]] + [runs[i][s]["f1_error"] for i in range(3)])
for i, name in enumerate(["scaled", "density", "lumped"]):
    errors = sorted(abs(float(run[s]["f1_error"])) for run in [runs[i]] for s in shapes)
    signed = statistics.median(float(runs[i][s]["f1_error"]) for s in shapes)
    p90 = errors[min(len(errors) - 1, int(0.9 * len(errors)))]
    print(f"{name:8s} {len(shapes)} shapes: median {100 * statistics.median(errors):.1f} %, "
          f"p90 {100 * p90:.1f} %, signed median {100 * signed:+.1f} %", file=sys.stderr)
