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

// A server started with --tokens answers 401 without a token: the page's
// sign-in field keeps one for the session (this tab) only, and every
// request sends it.  A 401 is told apart: "token needed" when none was
// sent, "wrong token" when the one sent was refused; listeners (the
// sign-in box) hear which, and nothing asks again by itself.
const TOKEN_KEY = 'tightknot.token';
const listeners = new Set();

export const auth = {
    token: () => sessionStorage.getItem(TOKEN_KEY),
    signIn(token) {
        sessionStorage.setItem(TOKEN_KEY, token.trim());
        for (const f of listeners) f('signed-in');
    },
    signOut() {
        sessionStorage.removeItem(TOKEN_KEY);
        for (const f of listeners) f('signed-out');
    },
    onChange: (f) => listeners.add(f),
};

function headersFor(init) {
    const token = auth.token();
    if (token) init.headers.Authorization = `Bearer ${token}`;
    return token;
}

async function request(method, path, options = {}) {
    const { json, text, signal } = options;
    const init = { method, headers: { Accept: 'application/json' }, signal, cache: 'no-store' };
    const token = headersFor(init);
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
    if (res.status === 401) {
        const why = token ? 'wrong-token' : 'token-needed';
        for (const f of listeners) f(why);
        throw new ApiError(401, { ...(body && typeof body === 'object' ? body : {}), status: 401,
            title: token ? 'Wrong token' : 'Token needed',
            detail: token ? 'the server refused this token: sign in with another'
                : 'this server needs a token: sign in with yours' });
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

// A job's file fetched with the token (a bare link would send none), as a
// blob for the page to save.
export async function fetchFile(path) {
    const init = { headers: {}, cache: 'no-store' };
    const token = headersFor(init);
    const res = await fetch(path, init);
    if (res.status === 401) {
        for (const f of listeners) f(token ? 'wrong-token' : 'token-needed');
        throw new ApiError(401, { title: token ? 'Wrong token' : 'Token needed', status: 401 });
    }
    if (!res.ok) throw new ApiError(res.status, { title: res.statusText || `HTTP ${res.status}`, status: res.status });
    return res.blob();
}

export const TERMINAL = new Set(['done', 'failed', 'cancelled']);
