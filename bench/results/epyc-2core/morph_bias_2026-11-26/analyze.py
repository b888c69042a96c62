import csv, sys, statistics as st
from collections import defaultdict
rows = []
for f in sys.argv[1:]:
    rows += list(csv.DictReader(open(f)))
by = defaultdict(list)
for r in rows:
    by[r['variant']].append(r)
def med(xs):
    xs=[float(x) for x in xs if x not in ('',None)]
    return st.median(xs) if xs else float('nan')
print(f"{'variant':16s} {'n':>3s} {'med signed%':>11s} {'med abs%':>9s} {'pos':>5s} {'meanTgtDist':>11s} {'worstQ':>7s} {'projected':>9s} {'incr':>5s} {'volScale':>8s} {'corr ms':>8s} {'unscaled%':>9s}")
for v in sorted(by):
    if v=='truth': continue
    R=by[v]
    e=[float(r['f1_error']) for r in R]
    uns=[ (float(r['f1_hz'])*float(r['volume_scale'])-float(r['f1_truth_hz']))/float(r['f1_truth_hz']) for r in R if r['volume_scale']]
    print(f"{v:16s} {len(R):3d} {100*st.median(e):11.2f} {100*st.median([abs(x) for x in e]):9.2f} {sum(x>0 for x in e):2d}/{len(e):2d} {med(r['mean_target_distance'] for r in R):11.4f} {med(r['worst_quality'] for r in R):7.3f} {med(r['projected'] for r in R):9.3f} {med(r['increments'] for r in R):5.1f} {med(r['volume_scale'] for r in R):8.4f} {med(r['correct_us'] for r in R)/1e3 if R[0]['correct_us'] else float('nan'):8.0f} {100*st.median(uns) if uns else float('nan'):9.2f}")
