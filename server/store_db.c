/* tightknot service: what the store's backends share (store_db.h): rows,
 * parameters, and the connections, kept for reuse. */
#include "store_db.h"

#include <assert.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <unistd.h>

#include "store.h"

void rows_free(rows *r)
{
    for (size_t k = 0; r->cell && k < r->n * r->ncol; k++)
        free(r->cell[k].p);
    free(r->cell);
    *r = (rows){0};
}

bool rows_add(rows *r, size_t j, const void *p, size_t len)
{
    if (j == 0) {
        struct cell *grown = realloc(r->cell, (r->n + 1) * r->ncol * sizeof *grown);
        if (!grown)
            return false;
        r->cell = grown;
        memset(r->cell + r->n++ * r->ncol, 0, r->ncol * sizeof *r->cell);
    }
    struct cell *k = &r->cell[(r->n - 1) * r->ncol + j];
    k->len = len;
    if (p && (k->p = malloc(len + 1)) != NULL) {
        memcpy(k->p, p, len);
        k->p[len] = '\0';
    }
    return !p || k->p;
}

const char *rows_cell(const rows *r, size_t i, size_t j)
{
    return r->cell[i * r->ncol + j].p;
}

int64_t rows_int(const rows *r, size_t i, size_t j)
{
    return rows_cell(r, i, j) ? strtoll(rows_cell(r, i, j), NULL, 10) : 0;
}

char *rows_steal(rows *r, size_t i, size_t j)
{
    char *p = r->cell[i * r->ncol + j].p;
    r->cell[i * r->ncol + j].p = NULL;
    return p;
}

bool db_script(const backend *db, void *c, const char *sql)
{
    return !sql || db->script(c, sql);
}

bool db_vquery(const backend *db, void *c, rows *out, const char *sql, const char *types,
                   va_list ap)
{
    rows mine = {0}, *r = out ? out : &mine;
    *r = (rows){0};
    assert(strlen(types) <= MAX_PARAMS);
    if (!sql)
        return true;
    params p = {.n = 0};
    for (; types[p.n] && p.n < MAX_PARAMS; p.n++) {
        char t = p.type[p.n] = types[p.n];
        p.value[p.n] = p.number[p.n];
        p.length[p.n] = 0;
        if (t == 'i')
            snprintf(p.number[p.n], 32, "%lld", (long long)(p.ints[p.n] = va_arg(ap, int64_t)));
        else if (t == 'd')
            snprintf(p.number[p.n], 32, "%.17g", p.reals[p.n] = va_arg(ap, double));
        else
            p.value[p.n] = va_arg(ap, const char *);
        if (t == 'b')
            p.length[p.n] = (int)va_arg(ap, size_t);
        else if (t == 'x' && p.value[p.n])
            p.length[p.n] = (int)strlen(p.value[p.n]);
    }
    bool ok = db->run(c, r, sql, &p);
    if (!ok && out)
        rows_free(out);
    rows_free(&mine);
    return ok;
}

bool db_query(const backend *db, void *c, rows *out, const char *sql, const char *types, ...)
{
    va_list ap;
    va_start(ap, types);
    bool ok = db_vquery(db, c, out, sql, types, ap);
    va_end(ap);
    return ok;
}

/* ---- connections ---- */

int store_failed(const tk_store *s, void *c, tk_error *err, const char *what)
{
    const char *m = s->db->error(c);
    size_t n = strcspn(m, "\n");
    return tk_error_set(err, TK_EIO, "job store: %s: %.*s", what, (int)n, n ? m : "no answer");
}

/* The lock only guards the list. */
void *store_take(tk_store *s, tk_error *err)
{
    pthread_mutex_lock(&s->lock);
    void *c = s->nidle ? s->idle[--s->nidle] : NULL;
    pthread_mutex_unlock(&s->lock);
    return c ? c : s->db->connect(s->where, s->label, false, err);
}

void store_give(tk_store *s, void *c)
{
    bool keep = s->db->release(c);
    pthread_mutex_lock(&s->lock);
    if (keep && s->nidle < IDLE_MAX) {
        s->idle[s->nidle++] = c;
        c = NULL;
    }
    pthread_mutex_unlock(&s->lock);
    if (c)
        s->db->disconnect(c);
}

int store_written(tk_store *s, int rc, const tk_error *err)
{
    pthread_mutex_lock(&s->lock);
    s->writes++;
    if (rc == TK_OK || rc == TK_EIO || rc == TK_ENOMEM)
        snprintf(s->write_error, sizeof s->write_error, "%s", rc ? err->message : "");
    pthread_mutex_unlock(&s->lock);
    return rc;
}

/* ---- opening ---- */

int tk_store_open(const char *where, double lease, tk_store **out, tk_error *err)
{
    *out = NULL;
    tk_store *s = calloc(1, sizeof *s);
    if (!s || !(s->where = strdup(where))) {
        free(s);
        return tk_error_set(err, TK_ENOMEM, "out of memory");
    }
    s->pg = !strncmp(where, "postgresql://", 13) || !strncmp(where, "postgres://", 11);
    s->db = s->pg ? tk_store_pg() : tk_store_sqlite();
    s->db->label(where, s->label, sizeof s->label);
    s->lease = lease;
    pthread_mutex_init(&s->lock, NULL);
    char host[64] = "host";
    gethostname(host, sizeof host - 1);
    unsigned long long nonce = 0;
    if (getrandom(&nonce, sizeof nonce, 0) != (ssize_t)sizeof nonce)
        nonce = (unsigned long long)(uintptr_t)s ^ (unsigned long long)getpid();
    snprintf(s->holder, sizeof s->holder, "%.63s:%ld:%016llx", host, (long)getpid(), nonce);
    void *c = s->db->connect(where, s->label, true, err);
    if (c && s->db->setup(c)) {
        s->idle[s->nidle++] = c;
        *out = s;
        return TK_OK;
    }
    if (c) {
        tk_error_set(err, TK_EIO, "cannot set up the job store %s: %.200s", s->label,
                     s->db->error(c));
        store_give(s, c); /* rolls back a part done */
    }
    tk_store_close(&s);
    return TK_EIO;
}

void tk_store_close(tk_store **p)
{
    tk_store *s = p ? *p : NULL;
    if (!s)
        return;
    while (s->nidle)
        s->db->disconnect(s->idle[--s->nidle]);
    for (size_t i = 0; i < RECENT_MAX; i++)
        json_decref(s->recent[i].doc);
    pthread_mutex_destroy(&s->lock);
    free(s->where);
    free(s);
    *p = NULL;
}

bool tk_store_shared(const tk_store *s)
{
    return s->pg;
}

const char *tk_store_holder(const tk_store *s)
{
    return s->holder;
}

const char *tk_store_label(const tk_store *s)
{
    return s->label;
}
