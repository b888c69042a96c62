"""The table of README.md's `bench` section from the four runs here: python3 table.py"""
import csv
import math
import statistics

SETS = [('plate', '48 plate fragments'), ('sphere', '50 sphere fragments'), ('bob', '50 fragments of bob_small'),
        ('real', 'the 12 real meshes')]
METHODS = [('centroid-voxel', 'nearest tier'), ('centroid-voxel-nearest', 'nearest entry alone'),
           ('centroid-voxel-corrected', 'corrected'), ('box', 'box'), ('ellipsoid', 'ellipsoid')]


def p90(values):
    """The benchmark's own: the nearest rank, ceil(0.9 n)."""
    v = sorted(values)
    return v[max(math.ceil(0.9 * len(v)), 1) - 1]


print('| shapes | ' + ' | '.join(m[1] for m in METHODS) +
      ' | corrected beats both | speedup, nearest tier | speedup, corrected | corrected query | direct |')
print('|---|' + '---:|' * (len(METHODS) + 5))
for key, label in SETS:
    rows = list(csv.DictReader(open(f'{key}_evaluation.csv')))
    by = {}
    for r in rows:
        by.setdefault(r['method'], {})[r['shape']] = r
    shapes = sorted(s for s, r in by['centroid-voxel-corrected'].items() if r['f1_error'])
    cells = []
    for method, _ in METHODS:
        e = [abs(float(by[method][s]['f1_error'])) for s in shapes]
        cells.append('%.1f %% (%.1f)' % (100 * statistics.median(e), 100 * p90(e)))
    beats = sum(abs(float(by['centroid-voxel-corrected'][s]['f1_error'])) <
                min(abs(float(by['box'][s]['f1_error'])), abs(float(by['ellipsoid'][s]['f1_error']))) for s in shapes)
    speed = [statistics.median(float(by[m][s]['speedup']) for s in shapes)
             for m in ('centroid-voxel', 'centroid-voxel-corrected')]
    query = statistics.median(float(by['centroid-voxel-corrected'][s]['query_us']) for s in shapes) / 1e3
    direct = statistics.median(float(by['centroid-voxel-corrected'][s]['truth_s']) for s in shapes)
    print('| %s | %s | %d of %d | %s× | %.0f× | %.0f ms | %.2f s |' % (
        label, ' | '.join(cells), beats, len(shapes), format(round(speed[0]), ','), speed[1], query, direct))
