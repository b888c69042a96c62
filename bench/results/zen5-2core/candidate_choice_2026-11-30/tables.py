"""The tables of README.md, from candidates.csv, truths.csv and lumped_spread.csv: python3 tables.py"""
import collections
import csv
import math
import statistics

truth = {(r['set'], r['shape']): float(r['f1_truth_hz']) for r in csv.DictReader(open('truths.csv'))}
candidates = collections.defaultdict(list)
for r in csv.DictReader(open('candidates.csv')):
    key = (r['set'], r['shape'])
    if key not in truth:
        continue
    c = {k: (v if k in ('set', 'shape', 'entry', 'family') else float(v)) for k, v in r.items()}
    c['error'] = (c['f1'] - truth[key]) / truth[key]
    candidates[key].append(c)
SETS = ['bob', 'sphere', 'plate', 'real']
STRAY = 0.1  # volume::kStrayShareWarning


def p90(values):
    """shapedb bench's: the nearest rank, ceil(0.9 n)."""
    v = sorted(values)
    return v[max(math.ceil(0.9 * len(v)), 1) - 1]


def summary(errors):
    e = [abs(x) for x in errors]
    return '%.2f %% | %.2f %% | %.1f %%' % (100 * statistics.median(e), 100 * p90(e), 100 * max(e))


def least(score):
    """betterMorph's shape: a candidate whose tets do not stray first, then the least score."""
    def pick(cs):
        return min([c for c in cs if c['stray'] <= STRAY] or cs, key=score)
    return pick


RULES = [
    ('the target distance (betterMorph)', least(lambda c: c['target_distance'])),
    ('the search\'s rank', lambda cs: min(cs, key=lambda c: c['rank'])),
    ('the mean boundary move', least(lambda c: c['mean_move'])),
    ('the largest boundary move', least(lambda c: c['max_move'])),
    ('distance × (1 + mean move)', least(lambda c: c['target_distance'] * (1 + c['mean_move']))),
    ('distance + mean move / 4', least(lambda c: c['target_distance'] + c['mean_move'] / 4)),
    ('distance / projected share', least(lambda c: c['target_distance'] / max(c['projected'], 0.05))),
    ('distance × (1 + void share)', least(lambda c: c['target_distance'] * (1 + c['void']))),
    ('the void share', least(lambda c: c['void'])),
    ('(the median of the three frequencies)', None),
    ('(the best of the three: an oracle)', lambda cs: min(cs, key=lambda c: abs(c['error']))),
]
print('## Choosing among the three candidates (no fallback)\n')
print('| rule | ' + ' | '.join('%s median | p90 | worst' % s for s in SETS) + ' |')
print('|---|' + '---:|' * (3 * len(SETS)))
for name, rule in RULES:
    cells = []
    for s in SETS:
        keys = [k for k in candidates if k[0] == s]
        if rule is None:
            errors = [sorted(c['error'] for c in candidates[k])[len(candidates[k]) // 2] for k in keys]
        else:
            errors = [rule(candidates[k])['error'] for k in keys]
        cells.append(summary(errors))
    print('| %s | %s |' % (name, ' | '.join(cells)))

print('\n## Every candidate of the fragments, by family\n')
print('| family | candidates | median error | median abs. error | lowest | highest |')
print('|---|---:|---:|---:|---:|---:|')
families = collections.defaultdict(list)
for key, cs in candidates.items():
    if key[0] != 'real':
        for c in cs:
            families[c['family']].append(c['error'])
for f, e in sorted(families.items()):
    print('| %s | %d | %+.1f %% | %.1f %% | %+.1f %% | %+.1f %% |' % (
        f, len(e), 100 * statistics.median(e), 100 * statistics.median([abs(x) for x in e]), 100 * min(e),
        100 * max(e)))

print('\n## The largest void shares\n')
print('| set | shape | candidate | void share | error | stray share | chosen |')
print('|---|---|---|---:|---:|---:|---|')
for c in sorted((c for cs in candidates.values() for c in cs), key=lambda c: -c['void'])[:16]:
    print('| %s | %s | %s | %.3f | %+.1f %% | %.3f | %s |' % (c['set'], c['shape'], c['entry'], c['void'],
                                                          100 * c['error'], c['stray'], 'yes' if c['chosen'] else ''))

print('\n## The missing mass lumped (as shipped) or spread over the tets\n')
print('| set | shapes | lumped: median, p90 | signed median | spread: median, p90 | signed median | spread closer |')
print('|---|---:|---:|---:|---:|---:|---:|')
rows = list(csv.DictReader(open('lumped_spread.csv')))
for s in SETS:
    r = [x for x in rows if x['set'] == s]
    lumped = [float(x['error_lumped']) for x in r]
    spread = [float(x['error_spread']) for x in r]

    def two(e):
        a = [abs(x) for x in e]
        return '%.2f %%, %.2f %%' % (100 * statistics.median(a), 100 * p90(a))
    closer = sum(abs(b) < abs(a) for a, b in zip(lumped, spread))
    print('| %s | %d | %s | %+.2f %% | %s | %+.2f %% | %d |' % (s, len(r), two(lumped), 100 * statistics.median(lumped),
                                                          two(spread), 100 * statistics.median(spread), closer))
