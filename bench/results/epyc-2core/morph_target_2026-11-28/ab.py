import json, subprocess, sys, statistics, os
meshes = sorted(os.listdir('real'))
bins = {'old': './shapedb.old', 'new': './shapedb.new2'}
res = {b: {m: [] for m in meshes} for b in bins}
freq = {b: {} for b in bins}
for rep in range(int(sys.argv[1])):
    for m in meshes:
        for b, exe in (bins.items() if rep % 2 == 0 else reversed(list(bins.items()))):
            out = subprocess.run([exe, 'query', 'default12.db', 'real/' + m, '--correct', '--json', '--no-fidelity'],
                                 capture_output=True, text=True).stdout
            q = json.loads(out)['queries'][0]
            res[b][m].append((q['timing_us']['correct'] / 1000, q['timing_us']['total'] / 1000))
            freq[b][m] = q['physics']['frequencies_hz'][6:8]
print('%-30s %10s %10s %8s %s' % ('mesh', 'old ms', 'new ms', 'ratio', 'same answer'))
ratios = []
for m in meshes:
    o = statistics.median(x[0] for x in res['old'][m]); n = statistics.median(x[0] for x in res['new'][m])
    ratios.append(n / o)
    same = all(abs(a - b) <= 1e-6 * abs(a) for a, b in zip(freq['old'][m], freq['new'][m]))
    print('%-30s %10.0f %10.0f %8.2f %s' % (m, o, n, n / o, same))
print('median ratio', statistics.median(ratios))
print('median correct old/new', statistics.median(statistics.median(x[0] for x in res['old'][m]) for m in meshes),
      statistics.median(statistics.median(x[0] for x in res['new'][m]) for m in meshes))
