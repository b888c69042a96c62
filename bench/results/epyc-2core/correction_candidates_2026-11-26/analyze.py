import csv,sys,statistics,math
truth={}
for r in csv.DictReader(open(sys.argv[2])):
    if r['f1_truth_hz']: truth[r['shape']]=float(r['f1_truth_hz'])
rows=list(csv.DictReader(open(sys.argv[1])))
shapes={}
for r in rows:
    shapes.setdefault(r['shape'],[]).append(r)
K=int(sys.argv[3]) if len(sys.argv)>3 else 99
rules={
 'rank0':lambda c: float(c['rank']),
 'pred':lambda c: float(c['predicted']),
 'morph_target':lambda c: float(c['morph_target']),
 'mean_dev':lambda c: float(c['mean_dev']),
 'max_dev':lambda c: float(c['max_dev']),
 'outside':lambda c: float(c['outside']),
 'mt*proj':lambda c: float(c['morph_target'])/max(float(c['projected']),1e-3),
 'vol':lambda c: abs(math.log(float(c['volume_scale']))),
}
res={k:[] for k in rules}; res['oracle']=[]; res['median_f1']=[]
for s,cs in shapes.items():
    if s not in truth: continue
    t=truth[s]
    cs=[c for c in cs if int(c['rank'])<K and c['corrected_f1']!='nan']
    err=lambda c: abs(float(c['corrected_f1'])/t-1)
    line=[s]
    for name,key in rules.items():
        c=min(cs,key=key); res[name].append(err(c)); line.append(f"{name}={err(c)*100:.1f}({c['rank']})")
    o=min(cs,key=err); res['oracle'].append(err(o)); line.append(f"oracle={err(o)*100:.1f}({o['rank']})")
    mf=statistics.median([float(c['corrected_f1']) for c in cs]); res['median_f1'].append(abs(mf/t-1))
    print(' '.join(line))
for k,v in res.items(): print(f"{k:14s} median {statistics.median(v)*100:6.1f} %  mean {statistics.mean(v)*100:6.1f}")
