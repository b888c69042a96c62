import json, subprocess, sys, statistics
meshes = sys.argv[2:]
bins = {'old': './shapedb.old', 'new': './shapedb.new2'}
res = {b: {m: [] for m in meshes} for b in bins}
for rep in range(int(sys.argv[1])):
    for m in meshes:
        for b, exe in (bins.items() if rep % 2 == 0 else reversed(list(bins.items()))):
            out = subprocess.run([exe, 'query', 'default12.db', 'real/' + m, '--correct', '--json', '--no-fidelity'], capture_output=True, text=True).stdout
            q = json.loads(out)['queries'][0]
            res[b][m].append(q['timing_us']['correct'] / 1000)
for m in meshes:
    print('%-30s old %s\n%-30s new %s' % (m, sorted(round(x) for x in res['old'][m]), '', sorted(round(x) for x in res['new'][m])))
