// The two plots, drawn as SVG: ropelength against step, and the contact map.

const NS = 'http://www.w3.org/2000/svg';

function el(name, attrs = {}, text) {
    const e = document.createElementNS(NS, name);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
    if (text != null) e.textContent = text;
    return e;
}

// About `count` round tick values covering [lo, hi].
function ticks(lo, hi, count = 5) {
    if (!(hi > lo)) return [lo];
    const raw = (hi - lo) / count;
    const mag = 10 ** Math.floor(Math.log10(raw));
    const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => s >= raw) || 10 * mag;
    const out = [];
    for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(+v.toPrecision(12));
    return out;
}

const short = (v) => {
    const a = Math.abs(v);
    if (a >= 1e4) return `${+(v / 1000).toPrecision(3)}k`;
    return `${+v.toPrecision(4)}`;
};

// mark: a step to point out (the replay's), or null.
export function drawHistory(svg, steps, mark = null) {
    svg.replaceChildren();
    const W = 360, H = 170, L = 44, R = 10, T = 10, B = 24;
    const pts = (steps || []).filter((s) => Number.isFinite(s.ropelength));
    if (pts.length === 0) {
        svg.append(el('text', { x: W / 2, y: H / 2, 'text-anchor': 'middle', class: 'nodata' }, 'no steps yet'));
        return;
    }
    const x0 = pts[0].step, x1 = Math.max(pts[pts.length - 1].step, x0 + 1);
    let y0 = Math.min(...pts.map((s) => s.ropelength)), y1 = Math.max(...pts.map((s) => s.ropelength));
    if (y1 - y0 < 1e-9 * Math.max(1, Math.abs(y1))) { y0 -= 1; y1 += 1; }
    const pad = (y1 - y0) * 0.05;
    y0 -= pad; y1 += pad;
    const sx = (x) => L + ((x - x0) / (x1 - x0)) * (W - L - R);
    const sy = (y) => H - B - ((y - y0) / (y1 - y0)) * (H - T - B);
    for (const v of ticks(y0, y1, 4)) {
        svg.append(el('line', { x1: L, x2: W - R, y1: sy(v), y2: sy(v), class: 'grid' }));
        svg.append(el('text', { x: L - 4, y: sy(v) + 3, 'text-anchor': 'end' }, short(v)));
    }
    for (const v of ticks(x0, x1, 5)) {
        svg.append(el('line', { x1: sx(v), x2: sx(v), y1: H - B, y2: H - B + 3, class: 'axis' }));
        svg.append(el('text', { x: sx(v), y: H - B + 13, 'text-anchor': 'middle' }, short(v)));
    }
    svg.append(el('line', { x1: L, x2: L, y1: T, y2: H - B, class: 'axis' }));
    svg.append(el('line', { x1: L, x2: W - R, y1: H - B, y2: H - B, class: 'axis' }));
    svg.append(el('text', { x: W - R, y: H - 2, 'text-anchor': 'end' }, 'step'));
    if (mark != null && mark >= x0 && mark <= x1) {
        svg.append(el('line', { x1: sx(mark), x2: sx(mark), y1: T, y2: H - B, class: 'marker' }));
    }
    // Where the run took another curve (an escape's deformation of the best,
    // or the best put back: `restarts` changes) the figures jump: the line
    // breaks there and a dashed tick says why.
    const jump = (i) => i > 0 && pts[i].restarts !== pts[i - 1].restarts;
    for (let i = 1; i < pts.length; i++) {
        if (!jump(i)) continue;
        const tick = el('line', { x1: sx(pts[i].step), x2: sx(pts[i].step), y1: T, y2: H - B, class: 'restart' });
        tick.append(el('title', {}, `step ${pts[i].step}: another curve (an escape, or the best so far put back)`));
        svg.append(tick);
    }
    const d = pts.map((s, i) => `${i && !jump(i) ? 'L' : 'M'}${sx(s.step).toFixed(1)},${sy(s.ropelength).toFixed(1)}`).join('');
    svg.append(el('path', { d, class: 'curve' }));
    const last = pts[pts.length - 1];
    svg.append(el('circle', { cx: sx(last.step), cy: sy(last.ropelength), r: 3, fill: 'var(--accent)' }));
    const label = el('text', { x: W - R, y: T + 10, 'text-anchor': 'end', style: 'fill: var(--ink); font-weight: 600' },
        `${last.ropelength.toFixed(3)} at step ${last.step}`);
    svg.append(label);
}

// One mark per strut at (a, b) = the arclengths of its ends with a <= b, its
// mirror image faintly below the diagonal, kinks on the diagonal, and the
// components' boundaries as dashed lines.  Two open components (a clasp,
// the paper's Figure 6) have a map of their own: each axis the arclength
// along one of them.
export function drawContactMap(svg, contacts, opts = {}) {
    return openPair(contacts) ? drawOpenPairMap(svg, contacts, opts) : drawWholeMap(svg, contacts, opts);
}

// Two open components whose struts all join one to the other.
export function openPair(contacts) {
    const comps = contacts?.components || [];
    return comps.length === 2 && comps.every((c) => !c.closed) &&
        (contacts.struts || []).every((s) => s.edges[0][0] !== s.edges[1][0]);
}

// One strut's mark on a contact map: a circle with its title, telling
// onHover when the pointer is on it.
function strutMark(cx, cy, r, fill, i, title, onHover) {
    const mark = el('circle', { cx, cy, r, fill, class: 'strut-mark', 'data-index': i });
    mark.append(el('title', {}, title));
    if (onHover) {
        mark.addEventListener('mouseenter', () => onHover(i));
        mark.addEventListener('mouseleave', () => onHover(-1));
    }
    return mark;
}

// Zoomed on the contacts, as the paper's enlarged plot: both axes at one
// scale, from a little before the first contact along each rope.
function drawOpenPairMap(svg, contacts, { colour, onHover } = {}) {
    svg.replaceChildren();
    const S = 360, M = 30, E = 8;
    const [c0, c1] = contacts.components;
    const struts = contacts.struts || [];
    // each end's arclength along its own component
    const ends = struts.map((s) => {
        const first = s.edges[0][0] === 0 ? 0 : 1;
        return [s.arclength[first] - c0.start, s.arclength[1 - first] - c1.start];
    });
    let [a0, a1, b0, b1] = [0, c0.length, 0, c1.length];
    if (ends.length) {
        a0 = Math.min(...ends.map((e) => e[0])); a1 = Math.max(...ends.map((e) => e[0]));
        b0 = Math.min(...ends.map((e) => e[1])); b1 = Math.max(...ends.map((e) => e[1]));
        const pad = 0.15 * Math.max(a1 - a0, b1 - b0, 1e-9);
        [a0, a1, b0, b1] = [Math.max(0, a0 - pad), Math.min(c0.length, a1 + pad),
            Math.max(0, b0 - pad), Math.min(c1.length, b1 + pad)];
    }
    const span = S - M - E, most = Math.max(a1 - a0, b1 - b0);
    const sx = (v) => M + ((v - a0) / most) * span;
    const Y = (v) => E + span - ((v - b0) / most) * span;
    const w = ((a1 - a0) / most) * span, h = ((b1 - b0) / most) * span;
    svg.append(el('rect', { x: M, y: E + span - h, width: w, height: h, fill: '#fff', stroke: '#b8c0cc' }));
    for (const v of ticks(a0, a1, 4))
        svg.append(el('text', { x: sx(v), y: S - M + 13, 'text-anchor': 'middle' }, short(v)));
    for (const v of ticks(b0, b1, 4))
        svg.append(el('text', { x: M - 4, y: Y(v) + 3, 'text-anchor': 'end' }, short(v)));
    svg.append(el('text', { x: M + span, y: S - 4, 'text-anchor': 'end' }, 'arclength along component 0'));
    svg.append(el('text', { x: 10, y: E + span / 2, 'text-anchor': 'middle', transform: `rotate(-90 10 ${E + span / 2})`,
        class: 'axis-title' }, 'along component 1'));
    if (!struts.length)
        svg.append(el('text', { x: M + span / 2, y: E + span / 2, 'text-anchor': 'middle', class: 'nodata' }, 'no contacts yet'));
    const r = struts.length > 400 ? 2 : 3;
    const out = [];
    struts.forEach((s, i) => {
        const [a, b] = ends[i];
        const mark = strutMark(sx(a), Y(b), r, colour ? colour(s, i) : '#2563eb', i,
            `strut ${i}: ${a.toFixed(3)} along component 0, ${b.toFixed(3)} along component 1, force ${fmtForce(s.force)}`, onHover);
        svg.append(mark);
        out.push(mark);
    });
    return out;
}

function drawWholeMap(svg, contacts, { colour, onHover } = {}) {
    svg.replaceChildren();
    const S = 360, M = 30, E = 8;
    const comps = contacts?.components || [];
    const total = comps.reduce((s, c) => Math.max(s, c.start + c.length), 0);
    if (!(total > 0)) {
        svg.append(el('text', { x: S / 2, y: S / 2, 'text-anchor': 'middle', class: 'nodata' }, 'no curve yet'));
        return [];
    }
    const span = S - M - E;
    const sc = (v) => M + (v / total) * span;
    const Y = (v) => E + span - (v / total) * span; // upwards, like a graph
    svg.append(el('rect', { x: M, y: E, width: span, height: span, fill: '#fff', stroke: '#b8c0cc' }));
    for (const v of ticks(0, total, 4)) {
        svg.append(el('text', { x: sc(v), y: S - M + 13, 'text-anchor': 'middle' }, short(v)));
        svg.append(el('text', { x: M - 4, y: Y(v) + 3, 'text-anchor': 'end' }, short(v)));
    }
    svg.append(el('text', { x: M + span, y: S - 4, 'text-anchor': 'end' }, 'arclength'));
    svg.append(el('line', { x1: sc(0), y1: Y(0), x2: sc(total), y2: Y(total), class: 'diagonal' }));
    for (const c of comps) {
        if (c.start <= 0) continue;
        svg.append(el('line', { x1: sc(c.start), x2: sc(c.start), y1: E, y2: E + span, class: 'boundary' }));
        svg.append(el('line', { y1: Y(c.start), y2: Y(c.start), x1: M, x2: M + span, class: 'boundary' }));
    }
    const struts = contacts.struts || [];
    if (!struts.length && !(contacts.kinks || []).length) {
        svg.append(el('text', { x: M + span / 2, y: E + span / 2, 'text-anchor': 'middle', class: 'nodata' }, 'no contacts yet'));
    }
    const r = struts.length > 400 ? 2 : 3;
    const mirrors = el('g');
    const marks = el('g');
    const out = [];
    struts.forEach((s, i) => {
        const [a0, b0] = s.arclength;
        const a = Math.min(a0, b0), b = Math.max(a0, b0);
        const fill = colour ? colour(s, i) : '#2563eb';
        mirrors.append(el('circle', { cx: sc(b), cy: Y(a), r, fill, class: 'strut-mirror' }));
        const mark = strutMark(sc(a), Y(b), r, fill, i,
            `strut ${i}: ${a.toFixed(3)} – ${b.toFixed(3)}, force ${fmtForce(s.force)}`, onHover);
        marks.append(mark);
        out.push(mark);
    });
    svg.append(mirrors, marks);
    for (const k of contacts.kinks || []) {
        const x = sc(k.arclength), y = Y(k.arclength), h = 5;
        const tri = el('path', { d: `M${x},${y - h}L${x + h},${y + h * 0.7}L${x - h},${y + h * 0.7}Z`, class: 'kink-mark' });
        tri.append(el('title', {}, `kink at vertex ${k.vertex} of component ${k.comp}, arclength ${k.arclength.toFixed(3)}`));
        svg.append(tri);
    }
    return out;
}

export const fmtForce = (f) => (f == null || !Number.isFinite(f) ? '–' : f === 0 ? '0' : f.toPrecision(4));
