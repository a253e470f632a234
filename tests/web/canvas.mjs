// Reading the page's 3-D canvas back, for both browsers' tests: the share
// of pixels that differ from the background, the number of distinct
// colours (quantised), and a coarse 64 x 48 thumbnail to compare pictures
// with.  Runs inside the page: pass it to page.evaluate.
export function canvasStatsInPage() {
    window.tightknot.view.renderNow();
    const src = document.querySelector('#view3d canvas');
    const w = src.width, h = src.height;
    const c = document.createElement('canvas');
    c.width = w; c.height = h;
    const g = c.getContext('2d', { willReadFrequently: true });
    g.drawImage(src, 0, 0);
    const d = g.getImageData(0, 0, w, h).data;
    const bg = [d[0], d[1], d[2]];
    let other = 0;
    const colours = new Set();
    for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 12) other++;
        colours.add(((d[i] >> 3) << 10) | ((d[i + 1] >> 3) << 5) | (d[i + 2] >> 3));
    }
    const t = document.createElement('canvas');
    t.width = 64; t.height = 48;
    const tg = t.getContext('2d', { willReadFrequently: true });
    tg.drawImage(src, 0, 0, 64, 48);
    const thumb = Array.from(tg.getImageData(0, 0, 64, 48).data);
    return { w, h, share: other / (w * h), colours: colours.size, thumb };
}
