// The daemon's HTTP/JSON API (openapi.yaml), seen from the page.  Every
// failure becomes an ApiError carrying the RFC 9457 problem, so that the
// page can show the server's own explanation (`detail`, `line`, `option`).

export class ApiError extends Error {
    constructor(status, problem) {
        super(problem?.detail || problem?.title || `HTTP ${status}`);
        this.status = status;
        this.problem = problem || { title: `HTTP ${status}`, status };
    }
}

// A server started with --tokens answers 401 without a token: the page
// asks for one and keeps it for the session (this tab) only.
const TOKEN_KEY = 'tightknot.token';

async function request(method, path, options = {}, asked = false) {
    const { json, text, signal } = options;
    const init = { method, headers: { Accept: 'application/json' }, signal, cache: 'no-store' };
    const token = sessionStorage.getItem(TOKEN_KEY);
    if (token) init.headers.Authorization = `Bearer ${token}`;
    if (json !== undefined) {
        init.headers['Content-Type'] = 'application/json';
        init.body = JSON.stringify(json);
    } else if (text !== undefined) {
        init.headers['Content-Type'] = 'text/plain';
        init.body = text;
    }
    let res;
    try {
        res = await fetch(path, init);
    } catch (e) {
        if (e.name === 'AbortError') throw e;
        throw new ApiError(0, { title: 'The service is not reachable', detail: String(e.message || e) });
    }
    const type = res.headers.get('Content-Type') || '';
    let body = null;
    if (type.includes('json')) {
        try { body = await res.json(); } catch { body = null; }
    } else {
        body = await res.text();
    }
    if (res.status === 401 && !asked) {
        // another request may have asked meanwhile
        const now = sessionStorage.getItem(TOKEN_KEY);
        if (now && now !== token) return request(method, path, options, true);
        const given = window.prompt(`${body?.detail || 'This server needs a token.'}\nYour token:`);
        if (given) {
            sessionStorage.setItem(TOKEN_KEY, given.trim());
            return request(method, path, options, true);
        }
    }
    if (!res.ok) {
        const problem = body && typeof body === 'object' ? body
            : { title: res.statusText || `HTTP ${res.status}`, status: res.status, detail: typeof body === 'string' ? body.trim() : '' };
        throw new ApiError(res.status, problem);
    }
    return body;
}

export const api = {
    health: (o) => request('GET', '/v1/health', o),
    catalogue: (o) => request('GET', '/v1/catalogue', o),
    catalogueKnot: (name, o) => request('GET', `/v1/catalogue/${encodeURIComponent(name)}`, o),
    submit: (body, o) => request('POST', '/v1/jobs', { ...o, json: body }),
    jobs: ({ offset = 0, limit = 50 } = {}, o) => request('GET', `/v1/jobs?offset=${offset}&limit=${limit}`, o),
    job: (id, o) => request('GET', `/v1/jobs/${id}`, o),
    cancel: (id, o) => request('DELETE', `/v1/jobs/${id}`, o),
    struts: (id, o) => request('GET', `/v1/jobs/${id}/struts`, o),
    vect: (id, o) => request('GET', `/v1/jobs/${id}/vect`, o),
    history: (id, limit = 1000, o) => request('GET', `/v1/jobs/${id}/history?limit=${limit}`, o),
    frames: (id, offset, limit, o) => request('GET', `/v1/jobs/${id}/frames?offset=${offset}&limit=${limit}`, o),
};

export const TERMINAL = new Set(['done', 'failed', 'cancelled']);
