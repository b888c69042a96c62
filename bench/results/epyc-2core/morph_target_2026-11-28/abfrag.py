import json, subprocess, sys, statistics, glob
files = sorted(glob.glob(sys.argv[2] + '/*.obj'))
bins = {'before': './shapedb.old', 'after': './shapedb.new3'}
res = {b: [] for b in bins}
freq = {}
for rep in range(int(sys.argv[1])):
    for b, exe in (bins.items() if rep % 2 == 0 else reversed(list(bins.items()))):
        out = subprocess.run(['taskset', '-c', '0', exe, 'query', 'default12.db'] + files + ['--correct', '--json', '--no-fidelity'], capture_output=True, text=True).stdout
        qs = json.loads(out)['queries']
        res[b].append(statistics.median(q['timing_us']['correct'] / 1000 for q in qs))
        freq[b] = [q['physics']['frequencies_hz'][6:9] for q in qs]
same = all(abs(x - y) <= 1e-9 * abs(x) for a, c in zip(freq['before'], freq['after']) for x, y in zip(a, c))
print('median correct per fragment, ms:', {b: [round(x, 1) for x in res[b]] for b in bins}, 'same answers:', same)
