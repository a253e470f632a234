// A film of a run: its frames at equal flow time, as in the paper ("each
// frame represents a constant amount of simulation time"), not at equal
// steps: the flow's steps shrink as the tube closes in, so frames at equal
// steps would race through the first moves and crawl at the end.

// The flow time at each frame's step, read off the job's stored steps
// (history entries with step and flow_time, in step order): linearly
// between the two entries around the step (the history is thinned), the
// first or last entry's beyond them.  Entries stored before the flow time
// was kept have none: null then.
export function frameFlowTimes(frameSteps, history) {
    const known = history.filter((h) => Number.isFinite(h.flow_time));
    if (!known.length) return null;
    return frameSteps.map((step) => {
        let lo = 0, hi = known.length - 1;
        if (step <= known[lo].step) return known[lo].flow_time;
        if (step >= known[hi].step) return known[hi].flow_time;
        while (hi - lo > 1) {
            const mid = (lo + hi) >> 1;
            if (known[mid].step <= step) lo = mid; else hi = mid;
        }
        const a = known[lo], b = known[hi];
        return a.flow_time + (b.flow_time - a.flow_time) * (step - a.step) / (b.step - a.step);
    });
}

// The frames for `count` film frames at equal flow time from the first
// frame's to the last's: for each time, the index of the frame whose
// flow time is nearest (a frame may repeat where frames are sparser than
// the film's time step).  `times` ascending.
export function equalTimeFrames(times, count) {
    const n = times.length;
    if (!n) return [];
    const t0 = times[0], t1 = times[n - 1];
    const picks = [];
    let j = 0;
    for (let k = 0; k < count; k++) {
        const t = count > 1 ? t0 + (t1 - t0) * k / (count - 1) : t1;
        while (j + 1 < n && times[j + 1] <= t) j++;
        picks.push(j + 1 < n && times[j + 1] - t < t - times[j] ? j + 1 : j);
    }
    return picks;
}

// The WebM type this browser's recorder makes, or null.
export function webmType() {
    if (typeof MediaRecorder === 'undefined') return null;
    return ['video/webm;codecs=vp9', 'video/webm;codecs=vp8', 'video/webm']
        .find((t) => MediaRecorder.isTypeSupported(t)) ?? null;
}

// Records `canvas` while show(k) draws film frame k, k = 0 .. count - 1,
// `fps` a second, with the browser's own recorder; resolves to the WebM
// blob.  The stream samples the canvas `fps` times a second; each frame
// stays on it a sample's time after it is shown: a video frame each, or
// two where drawing took longer.
export async function recordCanvas(canvas, count, fps, show) {
    const type = webmType();
    if (!type || !canvas.captureStream) throw new Error('this browser cannot record the view');
    const stream = canvas.captureStream(fps);
    const recorder = new MediaRecorder(stream, { mimeType: type });
    const chunks = [];
    recorder.ondataavailable = (e) => { if (e.data.size) chunks.push(e.data); };
    const stopped = new Promise((res, rej) => {
        recorder.onstop = res;
        recorder.onerror = (e) => rej(e.error ?? new Error('the recorder failed'));
    });
    const pause = () => new Promise((r) => setTimeout(r, 1000 / fps));
    // frames drawn before the recorder has started, or after it was told to
    // stop, are lost: it starts first (a recorder may wait for a first frame
    // to start, so the first is drawn before; a second at most), and ends a
    // frame's time after the last
    const started = new Promise((r) => { recorder.onstart = r; });
    show(0);
    recorder.start();
    await Promise.race([started, new Promise((r) => setTimeout(r, 1000))]);
    // each frame on the screen (two animation frames: drawn, then shown)
    // before its time on the canvas starts, so that a loaded machine's
    // compositor does not skip it
    const shown = () => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
    for (let k = 0; k < count; k++) {
        show(k);
        await shown();
        await pause();
    }
    await pause();
    recorder.stop();
    await stopped;
    for (const t of stream.getTracks()) t.stop();
    return new Blob(chunks, { type: 'video/webm' });
}
