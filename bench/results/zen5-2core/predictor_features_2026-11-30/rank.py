"""Does any evidence a corrected query has rank its first-frequency error? (shapedb, issue of the
predicted error.) Reads SET_evaluation.csv (the corrected and nearest rows of `shapedb bench`) and
SET_candidates.txt (each query's three candidates corrected each: volume, the chosen one's index, then per
candidate its first frequency in the entry's units, target distance, stray share and mass scale) for the
four sets; prints each feature's Spearman rho with |error| per set, the best feature sets of one to three
refitted with three sets and measured on the fourth, and the candidates' disagreement's rho.
Pure Python: python3 rank.py"""
import csv, itertools, math

SETS = ['plate', 'sphere', 'bob', 'real']


def ranks(v):
    order = sorted(range(len(v)), key=lambda i: v[i])
    r = [0.0] * len(v)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and v[order[j + 1]] == v[order[i]]:
            j += 1
        for k in range(i, j + 1):
            r[order[k]] = (i + j) / 2
        i = j + 1
    return r


def spearman(a, b):
    ra, rb = ranks(a), ranks(b)
    n = len(a)
    ma, mb = sum(ra) / n, sum(rb) / n
    num = sum((x - ma) * (y - mb) for x, y in zip(ra, rb))
    den = math.sqrt(sum((x - ma) ** 2 for x in ra) * sum((y - mb) ** 2 for y in rb))
    return num / den if den else float('nan')


def ln(x, floor):
    return math.log(max(x, 0.0) + floor)


FEATURES = {  # name: f(corrected row, nearest row)
    'ln mass scale|': lambda c, n: abs(math.log(float(c['mass_scale']))),
    'stray share': lambda c, n: float(c['stray_share']),
    'ln target distance': lambda c, n: ln(float(c['morph_target_distance']), 1e-3),
    'ln mean deviation': lambda c, n: ln(float(c['mean_deviation']), 1e-3),
    '|ln f_corrected/f_nearest|': lambda c, n: abs(math.log(float(c['f1_hz']) / float(n['f1_hz']))),
    'ln worst quality': lambda c, n: ln(float(c['worst_quality']), 1e-3),
    'ln entry worst quality': lambda c, n: ln(float(c['entry_worst_quality']), 1e-3),
    'ln quality kept': lambda c, n: math.log(float(c['worst_quality']) / float(c['entry_worst_quality'])),
    'ln max boundary move': lambda c, n: ln(float(c['max_boundary_move']), 1e-3),
    'ln mean boundary move': lambda c, n: ln(float(c['mean_boundary_move']), 1e-3),
    '1 - projected': lambda c, n: 1.0 - float(c['projected']),
    'prestretch': lambda c, n: float(c['prestretch']),
    'ln point mass peak': lambda c, n: ln(float(c['point_mass_peak']), 1.0),
    'lumped mode share': lambda c, n: float(c['lumped_mode_share']),
}


def load(s):
    by = {}
    for r in csv.DictReader(open(f'{s}_evaluation.csv')):
        by.setdefault(r['shape'], {})[r['method']] = r
    rows = []
    for shape, m in sorted(by.items()):
        c, n = m.get('centroid-voxel-corrected'), m.get('centroid-voxel-nearest')
        if c and n and c['status'] == 'ok' and c['f1_error']:
            rows.append((shape, c, n))
    return rows


def solve(a, b):  # least squares by the normal equations, a small ridge
    k = len(a[0])
    m = [[sum(r[i] * r[j] for r in a) + (1e-6 if i == j else 0.0) for j in range(k)] for i in range(k)]
    v = [sum(r[i] * y for r, y in zip(a, b)) for i in range(k)]
    for i in range(k):
        p = max(range(i, k), key=lambda r: abs(m[r][i]))
        m[i], m[p], v[i], v[p] = m[p], m[i], v[p], v[i]
        for r in range(i + 1, k):
            f = m[r][i] / m[i][i]
            m[r] = [x - f * y for x, y in zip(m[r], m[i])]
            v[r] -= f * v[i]
    w = [0.0] * k
    for i in reversed(range(k)):
        w[i] = (v[i] - sum(m[i][j] * w[j] for j in range(i + 1, k))) / m[i][i]
    return w


data = {s: load(s) for s in SETS}
X = {s: [{f: fn(c, n) for f, fn in FEATURES.items()} for _, c, n in data[s]] for s in SETS}
Y = {s: [abs(float(c['f1_error'])) for _, c, _ in data[s]] for s in SETS}

print('Spearman rho of each feature with |error|, per set (in sample):')
for f in FEATURES:
    print(f'  {f:30s}' + ''.join(f' {s} {spearman([x[f] for x in X[s]], Y[s]):+.2f}' for s in SETS))


def held_out(feats):
    out = []
    for held in SETS:
        a, b = [], []
        for s in SETS:
            if s != held:
                a += [[1.0] + [x[f] for f in feats] for x in X[s]]
                b += [math.log(y + 0.005) for y in Y[s]]
        w = solve(a, b)
        p = [sum(wi * xi for wi, xi in zip(w, [1.0] + [x[f] for f in feats])) for x in X[held]]
        out.append(spearman(p, Y[held]))
    return out


results = []
for k in (1, 2, 3):
    for feats in itertools.combinations(FEATURES, k):
        r = held_out(list(feats))
        results.append((min(r), feats, r))
results.sort(key=lambda t: -t[0])
print('\nBest sets of one to three features by their worst held-out rho (fitted on three sets):')
for worst, feats, r in results[:8]:
    print(f'  {worst:.2f}  {" + ".join(feats)}:', ' '.join(f'{s} {v:.2f}' for s, v in zip(SETS, r)))

print('\nThe shipped weights (-4.16857 + 2.87024 |ln mass scale| + 9.12106 stray share), in sample:')
for s in SETS:
    p = [-4.16857 + 2.87024 * x['ln mass scale|'] + 9.12106 * x['stray share'] for x in X[s]]
    print(f'  {s} {spearman(p, Y[s]):.2f}')

print('\nThe candidates\' disagreement: max |ln f_other / f_chosen| over the other candidates:')
for s in SETS:
    cand = []
    for line in open(f'{s}_candidates.txt'):
        t = line.split()
        cand.append((float(t[1]), int(t[3]), [tuple(map(float, t[4 + 4 * i:8 + 4 * i])) for i in range((len(t) - 4) // 4)]))
    d, e = [], []
    for _, c, _ in data[s]:
        v = float(c['volume_m3'])
        m = [x for x in cand if abs(x[0] - v) <= 1e-6 * v]
        if not m:
            continue
        _, best, cs = m[0]
        others = [x for i, x in enumerate(cs) if i != best and not math.isnan(x[0])]
        d.append(max((abs(math.log(x[0] / cs[best][0])) for x in others), default=0.0))
        e.append(abs(float(c['f1_error'])))
    print(f'  {s} rho {spearman(d, e):+.2f} over {len(e)}')
