/* tightknot service: what the store's two backends share (store_db.h). */
#include "store_db.h"

#include <assert.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void rows_free(rows *r)
{
    for (size_t k = 0; r->cell && k < r->n * r->ncol; k++)
        free(r->cell[k]);
    free(r->cell);
    free(r->len);
    *r = (rows){0};
}

bool rows_add(rows *r, size_t j, const void *p, size_t len)
{
    if (j == 0) {
        size_t m = (r->n + 1) * r->ncol;
        char **cell = realloc(r->cell, m * sizeof *cell);
        r->cell = cell ? cell : r->cell;
        size_t *lens = cell ? realloc(r->len, m * sizeof *lens) : NULL;
        if (!lens)
            return false;
        r->len = lens;
        memset(r->cell + r->n * r->ncol, 0, r->ncol * sizeof *r->cell);
        r->n++;
    }
    size_t k = (r->n - 1) * r->ncol + j;
    r->len[k] = len;
    if (p && (r->cell[k] = malloc(len + 1)) != NULL) {
        memcpy(r->cell[k], p, len);
        r->cell[k][len] = '\0';
    }
    return !p || r->cell[k];
}

const char *rows_cell(const rows *r, size_t i, size_t j)
{
    return r->cell[i * r->ncol + j];
}

int64_t rows_int(const rows *r, size_t i, size_t j)
{
    return rows_cell(r, i, j) ? strtoll(rows_cell(r, i, j), NULL, 10) : 0;
}

char *rows_steal(rows *r, size_t i, size_t j)
{
    char *p = r->cell[i * r->ncol + j];
    r->cell[i * r->ncol + j] = NULL;
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

