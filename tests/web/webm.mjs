// What a WebM file holds, read from its bytes (EBML, as Matroska lays it
// out): its video frames (SimpleBlocks and Blocks) and the time from the
// first frame to the last, so that a film's frame count and duration can
// be checked without a decoder.

import assert from 'node:assert/strict';

const SEGMENT = 0x18538067, CLUSTER = 0x1f43b675, BLOCK_GROUP = 0xa0, INFO = 0x1549a966;
const TIMECODE = 0xe7, TIMECODE_SCALE = 0x2ad7b1, SIMPLE_BLOCK = 0xa3, BLOCK = 0xa1;
const DOC_TYPE = 0x4282;
const MASTERS = new Set([SEGMENT, CLUSTER, BLOCK_GROUP, INFO, 0x1a45dfa3]);

// A variable-length integer at b[at]: its value (the marker bit kept for
// an element ID), its length, and whether it is the "unknown" size.
function vint(b, at, keepMarker) {
    const first = b[at];
    let len = 1;
    while (len <= 8 && !(first & (0x80 >> (len - 1)))) len++;
    if (len > 8) throw new Error(`not EBML at byte ${at}`);
    let value = keepMarker ? first : first & (0xff >> len);
    let ones = (first & (0xff >> len)) === 0xff >> len;
    for (let i = 1; i < len; i++) {
        value = value * 256 + b[at + i];
        ones = ones && b[at + i] === 0xff;
    }
    return { value, len, unknown: !keepMarker && ones };
}

const uint = (b, at, n) => { let v = 0; for (let i = 0; i < n; i++) v = v * 256 + b[at + i]; return v; };

// { docType, frames, firstMs, lastMs, durationMs }
export function readWebm(bytes) {
    const b = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
    let at = 0, cluster = 0, scale = 1e6, frames = 0, first = null, last = null, docType = '';
    while (at < b.length) {
        const id = vint(b, at, true);
        const size = vint(b, at + id.len, false);
        const body = at + id.len + size.len;
        if (MASTERS.has(id.value)) { at = body; continue; } // into it (its size may be unknown)
        if (size.unknown) throw new Error(`element ${id.value.toString(16)} of unknown size`);
        if (id.value === TIMECODE) cluster = uint(b, body, size.value);
        else if (id.value === TIMECODE_SCALE) scale = uint(b, body, size.value);
        else if (id.value === DOC_TYPE) docType = String.fromCharCode(...b.subarray(body, body + size.value));
        else if (id.value === SIMPLE_BLOCK || id.value === BLOCK) {
            const track = vint(b, body, false);
            const rel = (b[body + track.len] << 24 >> 16) | b[body + track.len + 1]; // int16
            const t = (cluster + rel) * scale / 1e6;
            frames++;
            first = first === null ? t : Math.min(first, t);
            last = last === null ? t : Math.max(last, t);
        }
        at = body + size.value;
    }
    return { docType, frames, firstMs: first, lastMs: last, durationMs: last - first };
}

// A film of `count` frames at `fps` a second, as the page records it: a
// WebM with a video frame for each film frame, or two where drawing one
// took longer than a sample's time (the stream samples the canvas `fps`
// times a second; each frame stays on it that long once shown), over at
// least 0.9 of the nominal time: no frame is shown for less than its
// 1/fps.  There is no upper bound: the recorder stamps frames in real
// time, and a loaded machine spaces them wider (7.9 s for 1.2 s nominal
// beside the thread sanitizer's suite), which says nothing of the page.
export function assertFilm(bytes, count, fps, what) {
    const webm = readWebm(bytes);
    console.log(`${what}: ${webm.frames} video frames over ${webm.durationMs} ms for ${count} film frames`);
    assert.equal(webm.docType, 'webm');
    assert.ok(webm.frames >= 0.9 * count && webm.frames <= 2.5 * count,
        `${webm.frames} video frames for ${count} film frames`);
    const nominal = (count - 1) * 1000 / fps;
    assert.ok(webm.durationMs >= 0.9 * nominal,
        `${webm.durationMs} ms for ${count} frames at ${fps} a second (${nominal} ms)`);
}
