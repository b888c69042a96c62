#!/usr/bin/env python3
"""How the nearest tier's blend was chosen, and the alternatives tried: reads this folder's files.

rerank_SET.csv: per shape, its first eight centroid-voxel matches (rerank_experiment.cpp): each one's
adapted first frequency, fidelity terms and distance. SET.csv: `shapedb bench` output, whose
centroid-voxel-nearest rows hold the truth's first frequency. stretch_SET.csv: the nearest entry
stretched to the query's second moments, modes computed exactly (stretch_experiment.cpp).
"""
import collections
import csv
import math
import statistics as st

SETS = ["plate", "sphere", "bob", "real"]


def truths(name):
    return {r["shape"]: float(r["f1_truth_hz"]) for r in csv.DictReader(open(f"{name}.csv"))
            if r["method"] == "centroid-voxel-nearest" and r["status"] == "ok"}


def candidates(name, t):
    rows = collections.defaultdict(list)
    for r in csv.DictReader(open(f"rerank_{name}.csv")):
        if r["shape"] in t:
            rows[r["shape"]].append(r)
    return rows


def summary(errors):
    e = sorted(errors)
    return f"{100 * st.median(e):5.1f} % (p90 {100 * e[int(0.9 * (len(e) - 1))]:4.0f})"


def blend(c, k, power, reach):
    d0 = float(c[0]["distance"])
    kept = [r for r in c[:k] if float(r["distance"]) <= reach * d0]
    w = [float(r["distance"]) ** -power for r in kept]
    return math.exp(sum(wi * math.log(float(r["f1"])) for wi, r in zip(w, kept)) / sum(w))


for name in SETS:
    t = truths(name)
    rows = candidates(name, t)
    err = lambda f, s: abs(f / t[s] - 1)
    print(f"== {name}: {len(rows)} shapes")
    for k in [1, 2, 3, 4, 5, 6, 8]:
        line = [f"k={k}"]
        for power in [0, 1, 2]:
            line.append(f"1/d^{power}: " + summary([err(blend(c, k, power, 1e9), s) for s, c in rows.items()]))
        print("   ".join(line))
    for reach in [1.25, 1.5, 2.0]:
        print(f"k=3 1/d reach {reach}: " + summary([err(blend(c, 3, 1, reach), s) for s, c in rows.items()]))
    for key in ["mean_dev", "max_dev", "max_moment", "predicted"]:
        for k in [3, 5, 8]:
            picks = [err(float(min(c[:k], key=lambda r: float(r[key]))["f1"]), s) for s, c in rows.items()]
            print(f"choose the least {key} of {k}: " + summary(picks))
    print("best of 8, had it been known: " + summary([min(err(float(r["f1"]), s) for r in c) for s, c in rows.items()]))
    try:
        stretched = {r["shape"]: r for r in csv.DictReader(open(f"stretch_{name}.csv"))}
        e = [err(float(stretched[s]["f1_stretched"]), s) for s in rows if s in stretched]
        print("nearest entry stretched, exact modes: " + summary(e))
    except FileNotFoundError:
        pass
