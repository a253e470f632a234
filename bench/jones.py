#!/usr/bin/python3
"""Checks the type of every curve the catalogue bench tightened against
its catalogue file's by the Jones polynomial, which the engine's own
check (Alexander polynomials, determinants, linking numbers) does not
compute: 10_140 and 8_20 share every invariant the engine has, and
their Jones polynomials differ.

The polynomial is Regina's (Debian's regina-normal), of a planar diagram
read off a projection of the polygon along a random direction; a link's
is compared over every orientation of its components, and a curve whose
polynomial is the file's mirror image is reported as one (a ropelength
does not tell mirror images apart; the engine's check does not either).

  bench/jones.py [--db build/catalogue/jobs.db] [--catalogue DIR]
                 [--starts DIR] [--only NAME ...] [--all]

Each start's last job is checked (the one the table holds), every job
with --all.

Prints a line for each curve whose type is not the file's, then
"jones: N curves, S the file's, M its mirror image, D other"; the exit
status is 1 when D > 0, 2 on bad usage or a missing Regina."""

import argparse
import json
import math
import os
import random
import sqlite3
import sys

try:
    import regina
except ImportError:
    sys.stderr.write("bench/jones.py needs Regina's Python module: "
                     "apt-get install regina-normal (make bench-jones installs it)\n")
    sys.exit(2)


def parse_vect(text):
    """The components of a VECT curve, each a list of (x, y, z)."""
    words = []
    for line in text.splitlines():
        words += line.split('#')[0].split()
    if not words or words[0] != 'VECT':
        raise ValueError('not a VECT curve')
    lines, vertices = int(words[1]), int(words[2])
    counts = [abs(int(w)) for w in words[4:4 + lines]]
    at = 4 + 2 * lines
    xyz = [float(w) for w in words[at:at + 3 * vertices]]
    comps, first = [], 0
    for n in counts:
        comps.append([tuple(xyz[3 * (first + k):3 * (first + k) + 3]) for k in range(n)])
        first += n
    return comps


def frame(seed):
    """Two axes of a plane and its normal, drawn at random."""
    rng = random.Random(seed)
    d = [rng.gauss(0.0, 1.0) for _ in range(3)]
    n = math.sqrt(sum(x * x for x in d))
    d = [x / n for x in d]
    a = [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0]
    e1 = [a[1] * d[2] - a[2] * d[1], a[2] * d[0] - a[0] * d[2], a[0] * d[1] - a[1] * d[0]]
    n = math.sqrt(sum(x * x for x in e1))
    e1 = [x / n for x in e1]
    e2 = [d[1] * e1[2] - d[2] * e1[1], d[2] * e1[0] - d[0] * e1[2], d[0] * e1[1] - d[1] * e1[0]]
    return e1, e2, d


def planar_diagram(comps, seed):
    """The diagram of the projection as a PD code (each crossing's four
    strands counterclockwise from the incoming under-strand), and how
    many components cross nothing (a PD code cannot hold them)."""
    e1, e2, d = frame(seed)
    segs = []
    for c, pts in enumerate(comps):
        p = [(sum(q[k] * e1[k] for k in range(3)), sum(q[k] * e2[k] for k in range(3)),
              sum(q[k] * d[k] for k in range(3))) for q in pts]
        for i in range(len(p)):
            segs.append((c, i, len(p), p[i], p[(i + 1) % len(p)]))
    crossings = []
    for x, (ca, i, na, a0, a1) in enumerate(segs):
        box = (min(a0[0], a1[0]), max(a0[0], a1[0]), min(a0[1], a1[1]), max(a0[1], a1[1]))
        for cb, j, _, b0, b1 in segs[x + 1:]:
            if ca == cb and (j == i + 1 or (i == 0 and j == na - 1)):
                continue
            if (max(b0[0], b1[0]) < box[0] or min(b0[0], b1[0]) > box[1] or
                    max(b0[1], b1[1]) < box[2] or min(b0[1], b1[1]) > box[3]):
                continue
            r = (a1[0] - a0[0], a1[1] - a0[1])
            s = (b1[0] - b0[0], b1[1] - b0[1])
            den = r[0] * s[1] - r[1] * s[0]
            if abs(den) < 1e-15:
                continue
            q = (b0[0] - a0[0], b0[1] - a0[1])
            t = (q[0] * s[1] - q[1] * s[0]) / den
            u = (q[0] * r[1] - q[1] * r[0]) / den
            if 0.0 <= t < 1.0 and 0.0 <= u < 1.0:
                over = a0[2] + t * (a1[2] - a0[2]) > b0[2] + u * (b1[2] - b0[2])
                crossings.append(((ca, i + t, r), (cb, j + u, s), over))
    passes = {}
    for k, (pa, pb, over) in enumerate(crossings):
        passes.setdefault(pa[0], []).append((pa[1], k, over, pa[2]))
        passes.setdefault(pb[0], []).append((pb[1], k, not over, pb[2]))
    strands, base = {}, 0
    for c in sorted(passes):
        ps = sorted(passes[c])
        for idx, (_, k, over, direction) in enumerate(ps):
            incoming = base + (idx if idx > 0 else len(ps))
            strands.setdefault(k, {})['over' if over else 'under'] = (incoming, base + idx + 1,
                                                                     direction)
        base += len(ps)
    pd = []
    for k in range(len(crossings)):
        ui, uo, ud = strands[k]['under']
        oi, oo, od = strands[k]['over']
        left = ud[0] * od[1] - ud[1] * od[0] > 0.0
        pd.append([ui, oi, uo, oo] if left else [ui, oo, uo, oi])
    return pd, len(comps) - len(passes)


def poly(laurent):
    """A Regina Laurent polynomial as {exponent: coefficient}."""
    if laurent.isZero():
        return {}
    return {e: int(str(laurent[e])) for e in range(laurent.minExp(), laurent.maxExp() + 1)
            if int(str(laurent[e])) != 0}


def times_unknot(p):
    """p times the Jones polynomial of a split unknot, -x - 1/x (x = t^1/2)."""
    out = {}
    for e, c in p.items():
        for de in (1, -1):
            out[e + de] = out.get(e + de, 0) - c
    return {e: c for e, c in out.items() if c}


def jones(comps, seed=1):
    pd, apart = planar_diagram(comps, seed)
    p = poly(regina.Link.fromPD(pd).jones()) if pd else {0: 1}
    if not pd:
        apart -= 1  # the empty diagram stands for one unknot
    for _ in range(apart):
        p = times_unknot(p)
    return p


def orientations(comps):
    """The Jones polynomials of comps over every orientation of its
    components but the first (reversing them all changes nothing)."""
    out = []
    for mask in range(1 << max(len(comps) - 1, 0)):
        flipped = [c if k == 0 or not (mask >> (k - 1)) & 1 else c[::-1]
                   for k, c in enumerate(comps)]
        out.append(jones(flipped))
    return out


def mirror(p):
    return {-e: c for e, c in p.items()}


def text(p):
    return ' '.join(f'{c:+d}x^{e}' for e, c in sorted(p.items())) or '0'


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--db', default='build/catalogue/jobs.db',
                    help="the catalogue bench's job store (default %(default)s)")
    ap.add_argument('--catalogue', default='../shared/catalogue',
                    help='the catalogue files (default %(default)s)')
    ap.add_argument('--starts', help="also check the bench's starts in this directory "
                    "(build/catalogue/starts) against their files")
    ap.add_argument('--only', nargs='*', help='only these knots and links (catalogue names)')
    ap.add_argument('--all', action='store_true',
                    help='every job, not only the last of each start (the one the table holds)')
    a = ap.parse_args()
    if not os.path.exists(a.db):
        sys.stderr.write(f'bench/jones.py: {a.db}: no such job store (run bench/catalogue.mjs)\n')
        return 2
    latest = {}
    with sqlite3.connect(f'file:{a.db}?mode=ro', uri=True) as db:
        for jid, doc, curve in db.execute(
                "select id, doc, curve from jobs where state = 'done' order by id"):
            name = json.loads(doc)['name']
            # a start run again replaces its row in the table: its last job
            key = name if not a.all else jid
            latest[key] = (f'job {jid} {name}', name.split('@')[0], curve)
    curves = list(latest.values())
    if a.starts:
        for f in sorted(os.listdir(a.starts)):
            if f.endswith('.vect'):
                with open(os.path.join(a.starts, f)) as fh:
                    curves.append((f'start {f}', f.split('@')[0], fh.read()))
    files, same, mirrored, other, unchecked = {}, 0, 0, 0, 0
    for what, knot, curve in curves:
        if a.only and knot not in a.only:
            continue
        if knot not in files:
            try:
                with open(os.path.join(a.catalogue, f'{knot}.vect')) as fh:
                    files[knot] = orientations(parse_vect(fh.read()))
            except OSError as e:
                files[knot] = None
                print(f'{what}: not checked: {e.strerror}: {e.filename}', flush=True)
        want = files[knot]
        if want is None:
            unchecked += 1
            continue
        got = jones(parse_vect(curve))
        if got in want:
            same += 1
        elif got in [mirror(p) for p in want]:
            mirrored += 1
            print(f'{what}: the mirror image of {knot}', flush=True)
        else:
            other += 1
            print(f'{what}: Jones {text(got)}; {knot}.vect has {text(want[0])}', flush=True)
    print(f"jones: {same + mirrored + other} curves, {same} the file's, "
          f'{mirrored} its mirror image, {other} other' +
          (f'; {unchecked} with no catalogue file, not checked' if unchecked else ''))
    return 1 if other else 0


if __name__ == '__main__':
    sys.exit(main())
