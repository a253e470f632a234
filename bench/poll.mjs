// Paced polling: CLIENTS clients each GET URL once every PERIOD ms for
// SECONDS seconds (an open loop: a slow answer does not slow the pace),
// the way many pages or scripts watch their jobs.  Prints the requests
// per second made and the p50/p99/max latency in ms.
//   node bench/poll.mjs URL CLIENTS PERIOD_MS SECONDS
import http from 'node:http';

const [url, clients = '200', period = '100', seconds = '10'] = process.argv.slice(2);
const agent = new http.Agent({ keepAlive: true, maxSockets: Number(clients) });
const latencies = [];
let failures = 0;
const end = Date.now() + Number(seconds) * 1000;

function get() {
    return new Promise((resolve) => {
        const start = process.hrtime.bigint();
        http.get(url, { agent }, (res) => {
            res.resume();
            res.on('end', () => {
                if (res.statusCode !== 200) failures++;
                latencies.push(Number(process.hrtime.bigint() - start) / 1e6);
                resolve();
            });
        }).on('error', () => {
            failures++;
            resolve();
        });
    });
}

async function client(offset) {
    await new Promise((r) => setTimeout(r, offset));
    let next = Date.now();
    while (Date.now() < end) {
        get();
        next += Number(period);
        await new Promise((r) => setTimeout(r, Math.max(0, next - Date.now())));
    }
}

await Promise.all(Array.from({ length: Number(clients) }, (_, i) => client((i * Number(period)) / Number(clients))));
await new Promise((r) => setTimeout(r, 500));
latencies.sort((a, b) => a - b);
const q = (p) => latencies[Math.min(latencies.length - 1, Math.floor(p * latencies.length))] ?? NaN;
console.log(`${(latencies.length / Number(seconds)).toFixed(1)} ${q(0.5).toFixed(2)}ms ${q(0.99).toFixed(2)}ms ${(latencies.at(-1) ?? NaN).toFixed(2)}ms ${failures}`);
agent.destroy();
