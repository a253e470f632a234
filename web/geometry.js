// Curves in the page: reading and writing VECT, splitting flat coordinate
// arrays into components, and the torus knots and links the form offers.

// A polygon: { points: Float64Array of x y z ..., closed: boolean }.

export function parseVect(text) {
    // Comments run from '#' to the end of the line; the rest is numbers.
    const tokens = text.replace(/#[^\n]*/g, ' ').trim().split(/\s+/);
    let k = 0;
    if (!/VECT$/.test(tokens[k] || '')) throw new Error('not a VECT file');
    k++;
    const next = () => {
        if (k >= tokens.length) throw new Error('VECT file is truncated');
        const v = Number(tokens[k++]);
        if (!Number.isFinite(v)) throw new Error(`not a number: ${tokens[k - 1]}`);
        return v;
    };
    const npoly = next(), nvert = next(), ncolor = next();
    const counts = [];
    for (let i = 0; i < npoly; i++) counts.push(next());
    for (let i = 0; i < npoly; i++) next(); // colours per polyline
    const comps = [];
    let total = 0;
    for (const c of counts) {
        const n = Math.abs(c);
        const pts = new Float64Array(3 * n);
        for (let j = 0; j < 3 * n; j++) pts[j] = next();
        comps.push({ points: pts, closed: c < 0 });
        total += n;
    }
    if (total !== nvert) throw new Error('VECT vertex counts disagree');
    void ncolor;
    return comps;
}

export function writeVect(comps, comment) {
    const n = comps.reduce((s, c) => s + c.points.length / 3, 0);
    const lines = ['VECT'];
    if (comment) lines.push(`# ${comment}`);
    lines.push(`${comps.length} ${n} 0`);
    lines.push(comps.map((c) => (c.closed ? -1 : 1) * (c.points.length / 3)).join(' '));
    lines.push(comps.map(() => 0).join(' '));
    for (const c of comps) {
        for (let i = 0; i < c.points.length; i += 3) {
            lines.push(`${fmt(c.points[i])} ${fmt(c.points[i + 1])} ${fmt(c.points[i + 2])}`);
        }
    }
    return lines.join('\n') + '\n';
}

const fmt = (x) => (Math.abs(x) < 1e-12 ? '0' : x.toPrecision(10).replace(/\.?0+$/, ''));

// Frames carry all coordinates flat, with the layout given once.
export function splitFlat(coords, layout) {
    const comps = [];
    let off = 0;
    for (const c of layout) {
        const pts = new Float64Array(3 * c.vertices);
        for (let j = 0; j < pts.length; j++) {
            const v = coords[off + j];
            pts[j] = v == null ? NaN : v;
        }
        off += 3 * c.vertices;
        comps.push({ points: pts, closed: c.closed });
    }
    return comps;
}

const gcd = (a, b) => (b ? gcd(b, a % b) : a);

// The (p, q) torus knot winds p times around the torus' axis and q times
// through its hole; when d = gcd(p, q) > 1 it is a link of d parallel
// (p/d, q/d) curves.  The k-th is shifted by 2 pi k / p in the meridian
// angle: the first meets the circle at longitude 0 only at multiples of
// 2 pi / (p/d), so these shifts keep the components apart.
export function torusLink(p, q, n, R = 2, r = 1) {
    const d = gcd(p, q);
    const pp = p / d, qq = q / d;
    const comps = [];
    for (let k = 0; k < d; k++) {
        const pts = new Float64Array(3 * n);
        const shift = (2 * Math.PI * k) / p;
        for (let i = 0; i < n; i++) {
            const t = (2 * Math.PI * i) / n;
            const phi = pp * t, psi = qq * t + shift;
            const rho = R + r * Math.cos(psi);
            pts[3 * i] = rho * Math.cos(phi);
            pts[3 * i + 1] = rho * Math.sin(phi);
            pts[3 * i + 2] = r * Math.sin(psi);
        }
        comps.push({ points: pts, closed: true });
    }
    return comps;
}

// An estimate of a closed polygon's thickness, the way the server judges a
// start: the least polygonal radius of curvature (min edge / (2 tan(angle/2))
// at each vertex) and the smallest distance between vertices that is a local
// minimum along both strands (the discrete doubly critical self-distances).
export function thicknessEstimate(comps) {
    let minrad = Infinity;
    const all = [];
    comps.forEach((c, ci) => {
        const n = c.points.length / 3;
        const P = (i) => {
            const j = ((i % n) + n) % n;
            return [c.points[3 * j], c.points[3 * j + 1], c.points[3 * j + 2]];
        };
        for (let i = 0; i < n; i++) {
            if (!c.closed && (i === 0 || i === n - 1)) continue;
            const a = P(i - 1), b = P(i), e = P(i + 1);
            const u = sub(b, a), v = sub(e, b);
            const lu = norm(u), lv = norm(v);
            const cos = Math.max(-1, Math.min(1, dot(u, v) / (lu * lv)));
            const ang = Math.acos(cos);
            if (ang > 1e-12) minrad = Math.min(minrad, Math.min(lu, lv) / (2 * Math.tan(ang / 2)));
        }
        for (let i = 0; i < n; i++) all.push({ c: ci, i, n, closed: c.closed, p: P(i) });
    });
    const m = all.length;
    const dist = (a, b) => norm(sub(a.p, b.p));
    const index = new Map();
    all.forEach((v, k) => index.set(`${v.c}:${v.i}`, k));
    const neighbour = (k, step) => {
        const v = all[k];
        let j = v.i + step;
        if (v.closed) j = (j + v.n) % v.n;
        else if (j < 0 || j >= v.n) return -1;
        return index.get(`${v.c}:${j}`);
    };
    let dcsd = Infinity;
    for (let a = 0; a < m; a++) {
        for (let b = a + 1; b < m; b++) {
            const va = all[a], vb = all[b];
            if (va.c === vb.c) {
                const gap = Math.abs(va.i - vb.i);
                if (Math.min(gap, va.closed ? va.n - gap : gap) < 3) continue;
            }
            const d = dist(va, vb);
            if (d >= dcsd) continue;
            let critical = true;
            for (const [x, y] of [[neighbour(a, -1), b], [neighbour(a, 1), b], [a, neighbour(b, -1)], [a, neighbour(b, 1)]]) {
                if (x >= 0 && y >= 0 && dist(all[x], all[y]) < d) { critical = false; break; }
            }
            if (critical) dcsd = d;
        }
    }
    return { minrad, dcsd, thickness: Math.min(2 * minrad, dcsd) };
}

// Scales the polygon so that its estimated thickness clears the tube's
// diameter, and its curvature the stiffness bound, by the given margin.
export function scaleToFit(comps, radius, lambda, margin = 1.25) {
    const est = thicknessEstimate(comps);
    const need = Math.max((2 * radius) / est.dcsd, (Math.max(lambda, 1) * radius) / est.minrad);
    const s = need * margin;
    for (const c of comps) for (let j = 0; j < c.points.length; j++) c.points[j] *= s;
    return { scale: s, thickness: est.thickness * s, minrad: est.minrad * s };
}

function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
function norm(a) { return Math.hypot(a[0], a[1], a[2]); }
