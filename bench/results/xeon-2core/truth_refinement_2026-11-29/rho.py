import csv, sys, statistics
def ranks(x):
    idx = sorted(range(len(x)), key=lambda i: x[i]); r = [0.0]*len(x); i = 0
    while i < len(x):
        j = i
        while j + 1 < len(x) and x[idx[j+1]] == x[idx[i]]: j += 1
        for k in range(i, j+1): r[idx[k]] = (i + j) / 2
        i = j + 1
    return r
def spearman(a, b):
    ra, rb = ranks(a), ranks(b); ma, mb = statistics.mean(ra), statistics.mean(rb)
    num = sum((x-ma)*(y-mb) for x, y in zip(ra, rb))
    den = (sum((x-ma)**2 for x in ra) * sum((y-mb)**2 for y in rb)) ** 0.5
    return num / den
def main():
    for path in sys.argv[1:]:
      rows = list(csv.DictReader(open(path)))
      for method in ('centroid-voxel-corrected', 'centroid-voxel'):
          rs = [r for r in rows if r['method'] == method and r['status'] == 'ok' and r['predicted_error'] and r['f1_error']]
          m = [abs(float(r['f1_error'])) for r in rs]; p = [float(r['predicted_error']) for r in rs]
          print(f"{path:70s} {method:26s} n={len(rs):3d} rho={spearman(p, m):.3f} median|err|={statistics.median(m)*100:.2f}%")

if __name__ == '__main__':
    main()
