/* Constraints on vertices (tk/pin.h). */
#include "tk/pin.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "tk/curve.h"

/* The kinds, in tk_pin_kind's order: their names and how many numbers. */
static const struct {
    const char *name;
    int count;
} KINDS[] = {{"free", 0}, {"point", 3}, {"plane", 4}, {"line", 6}};
#define NKINDS (sizeof KINDS / sizeof *KINDS)

const char *tk_pin_kind_name(tk_pin_kind kind)
{
    return (unsigned)kind < NKINDS ? KINDS[kind].name : "?";
}

int tk_pin_count(tk_pin_kind kind)
{
    return (unsigned)kind < NKINDS ? KINDS[kind].count : 0;
}

int tk_pin_kind_of(const char *name, size_t n)
{
    for (size_t k = 0; k < NKINDS; k++)
        if (strlen(KINDS[k].name) == n && strncasecmp(name, KINDS[k].name, n) == 0)
            return (int)k;
    return -1;
}

void tk_pin_numbers(const tk_pin *pin, double v[6])
{
    if (pin->kind == TK_PIN_POINT) {
        memcpy(v, pin->point, 3 * sizeof *v);
    } else if (pin->kind == TK_PIN_PLANE) {
        memcpy(v, pin->normal, 3 * sizeof *v);
        v[3] = pin->offset;
    } else if (pin->kind == TK_PIN_LINE) {
        memcpy(v, pin->point, 3 * sizeof *v);
        memcpy(v + 3, pin->normal, 3 * sizeof *v);
    }
}

void tk_pin_set_numbers(tk_pin *pin, const double *v)
{
    if (pin->kind == TK_PIN_POINT) {
        memcpy(pin->point, v, 3 * sizeof *v);
    } else if (pin->kind == TK_PIN_PLANE) {
        memcpy(pin->normal, v, 3 * sizeof *v);
        pin->offset = v[3];
    } else if (pin->kind == TK_PIN_LINE) {
        memcpy(pin->point, v, 3 * sizeof *v);
        memcpy(pin->normal, v + 3, 3 * sizeof *v);
    }
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static bool finite3(const double *a)
{
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

const tk_pin *tk_curve_pin_of(const tk_curve *c, size_t v)
{
    for (size_t i = 0; i < c->npins; i++)
        if (c->offset[c->pins[i].comp] + c->pins[i].vertex == v)
            return &c->pins[i];
    return NULL;
}

int tk_curve_pin_add(tk_curve *c, const tk_pin *pin, bool at_vertex, tk_error *err)
{
    if (pin->comp >= c->ncomp)
        return tk_error_set(err, TK_EINVAL,
                            "constraint %zu:%zu: the curve has no component %zu (it has %zu)",
                            pin->comp, pin->vertex, pin->comp, c->ncomp);
    size_t n = c->offset[pin->comp + 1] - c->offset[pin->comp];
    if (pin->vertex >= n)
        return tk_error_set(err, TK_EINVAL,
                            "constraint %zu:%zu: component %zu has no vertex %zu (it has %zu)",
                            pin->comp, pin->vertex, pin->comp, pin->vertex, n);
    size_t v = c->offset[pin->comp] + pin->vertex;
    if (tk_curve_pin_of(c, v))
        return tk_error_set(err, TK_EINVAL,
                            "constraint %zu:%zu: the vertex has a constraint already", pin->comp,
                            pin->vertex);
    if ((unsigned)pin->kind > TK_PIN_LINE)
        return tk_error_set(err, TK_EINVAL, "constraint %zu:%zu: no such kind", pin->comp,
                            pin->vertex);
    tk_pin p = *pin;
    if (p.kind == TK_PIN_POINT && at_vertex)
        memcpy(p.point, tk_curve_vertex(c, v), sizeof p.point);
    if (p.kind == TK_PIN_PLANE || p.kind == TK_PIN_LINE) {
        double norm = sqrt(dot3(p.normal, p.normal));
        const char *what = p.kind == TK_PIN_PLANE ? "normal" : "direction";
        if (!finite3(p.normal) || !(norm > 0.0) || !isfinite(norm))
            return tk_error_set(err, TK_EINVAL,
                                "constraint %zu:%zu: the %s %s is zero or not finite", p.comp,
                                p.vertex, tk_pin_kind_name(p.kind), what);
        /* a unit vector written and read back stays as it was */
        if (fabs(norm - 1.0) > 4 * DBL_EPSILON) {
            for (int k = 0; k < 3; k++)
                p.normal[k] /= norm;
            p.offset /= norm;
        }
    }
    if ((p.kind == TK_PIN_PLANE && !isfinite(p.offset)) ||
        ((p.kind == TK_PIN_POINT || p.kind == TK_PIN_LINE) && !finite3(p.point)))
        return tk_error_set(err, TK_EINVAL, "constraint %zu:%zu: a number is not finite",
                            p.comp, p.vertex);
    tk_pin *grown = realloc(c->pins, (c->npins + 1) * sizeof *grown);
    if (!grown)
        return tk_error_set(err, TK_ENOMEM, "out of memory for a constraint");
    c->pins = grown;
    /* kept in the order of their vertices, however they were added */
    size_t at = c->npins;
    while (at > 0 && (c->pins[at - 1].comp > p.comp ||
                      (c->pins[at - 1].comp == p.comp && c->pins[at - 1].vertex > p.vertex))) {
        c->pins[at] = c->pins[at - 1];
        at--;
    }
    c->pins[at] = p;
    c->npins++;
    return TK_OK;
}

/* The point of the pin's constraint nearest x. */
static void nearest(const tk_pin *pin, const double *x, double out[3])
{
    switch (pin->kind) {
    case TK_PIN_POINT:
        memcpy(out, pin->point, 3 * sizeof *out);
        return;
    case TK_PIN_PLANE: {
        double off = dot3(pin->normal, x) - pin->offset;
        for (int k = 0; k < 3; k++)
            out[k] = x[k] - off * pin->normal[k];
        return;
    }
    case TK_PIN_LINE: {
        double d[3] = {x[0] - pin->point[0], x[1] - pin->point[1], x[2] - pin->point[2]};
        double s = dot3(d, pin->normal);
        for (int k = 0; k < 3; k++)
            out[k] = pin->point[k] + s * pin->normal[k];
        return;
    }
    default:
        memcpy(out, x, 3 * sizeof *out);
    }
}

double tk_pin_distance(const tk_curve *c, const tk_pin *pin)
{
    const double *x = tk_curve_vertex(c, c->offset[pin->comp] + pin->vertex);
    double y[3];
    nearest(pin, x, y);
    double d[3] = {x[0] - y[0], x[1] - y[1], x[2] - y[2]};
    return sqrt(dot3(d, d));
}

void tk_curve_pins_snap(tk_curve *c)
{
    for (size_t i = 0; i < c->npins; i++) {
        double *x = tk_curve_vertex(c, c->offset[c->pins[i].comp] + c->pins[i].vertex);
        double y[3];
        nearest(&c->pins[i], x, y);
        memcpy(x, y, sizeof y);
    }
}

int tk_curve_pins_check(const tk_curve *c, double tolerance, tk_error *err)
{
    for (size_t i = 0; i < c->npins; i++) {
        double d = tk_pin_distance(c, &c->pins[i]);
        if (!(d <= tolerance)) {
            char text[256];
            tk_pin_format(&c->pins[i], text, sizeof text);
            return tk_error_set(err, TK_EINVAL,
                                "constraint %s: its vertex is %.3g from it (at most %.3g can be "
                                "closed by moving the vertex onto it)",
                                text, d, tolerance);
        }
    }
    return TK_OK;
}

int tk_curve_pins_settle(tk_curve *c, double tolerance, tk_error *err)
{
    int rc = tk_curve_pins_check(c, tolerance, err);
    if (!rc)
        tk_curve_pins_snap(c);
    return rc;
}

void tk_pin_project(const tk_pin *pin, double v[3])
{
    switch (pin->kind) {
    case TK_PIN_POINT:
        v[0] = v[1] = v[2] = 0.0;
        return;
    case TK_PIN_PLANE: {
        double s = dot3(pin->normal, v);
        for (int k = 0; k < 3; k++)
            v[k] -= s * pin->normal[k];
        return;
    }
    case TK_PIN_LINE: {
        double s = dot3(pin->normal, v);
        for (int k = 0; k < 3; k++)
            v[k] = s * pin->normal[k];
        return;
    }
    default:
        return;
    }
}

/* ---- text */

/* Reads `count` comma-separated numbers from *p; false when they are not
 * there or not numbers. */
static bool numbers(const char **p, double *out, int count)
{
    for (int k = 0; k < count; k++) {
        if (k > 0 && *(*p)++ != ',')
            return false;
        char *end;
        errno = 0;
        out[k] = strtod(*p, &end);
        if (end == *p || errno == ERANGE || !isfinite(out[k]))
            return false;
        *p = end;
    }
    return true;
}

int tk_pin_parse(const char *text, tk_pin *out, bool *at_vertex, tk_error *err)
{
    *out = (tk_pin){0};
    *at_vertex = false;
    const char *p = text;
    char *end;
    unsigned long long comp, vertex;
    errno = 0;
    comp = strtoull(p, &end, 10);
    bool ok = end != p && *p >= '0' && *p <= '9' && *end == ':' && errno == 0;
    if (ok) {
        p = end + 1;
        vertex = strtoull(p, &end, 10);
        ok = end != p && *p >= '0' && *p <= '9' && *end == '=' && errno == 0;
        p = end + 1;
    }
    if (!ok || comp > 1000000000ULL || vertex > 1000000000ULL)
        return tk_error_set(err, TK_EINVAL,
                            "constraint '%.64s': it starts COMP:VERTEX= (a component and a "
                            "vertex of it, counted from 0)",
                            text);
    out->comp = (size_t)comp;
    out->vertex = (size_t)vertex;
    /* "fixed" is a point where the vertex is, without numbers */
    size_t len = strcspn(p, ":");
    bool fixed = len == 5 && strncasecmp(p, "fixed", 5) == 0;
    int kind = fixed ? TK_PIN_POINT : tk_pin_kind_of(p, len);
    if (kind < 0)
        return tk_error_set(err, TK_EINVAL,
                            "constraint '%.64s': the kind is free, fixed, point:x,y,z, "
                            "plane:nx,ny,nz,d or line:px,py,pz,tx,ty,tz",
                            text);
    out->kind = (tk_pin_kind)kind;
    *at_vertex = fixed;
    int count = fixed ? 0 : KINDS[kind].count;
    const char *q = p + len;
    double v[6];
    bool good = count == 0 ? *q == '\0' : *q == ':' && (q++, numbers(&q, v, count)) && *q == '\0';
    if (!good) {
        static const char *const form[] = {"free", "point:x,y,z", "plane:nx,ny,nz,d",
                                           "line:px,py,pz,tx,ty,tz"};
        return tk_error_set(err, TK_EINVAL, "constraint '%.64s': %s is written %s", text,
                            fixed ? "fixed" : KINDS[kind].name, fixed ? "fixed" : form[kind]);
    }
    if (count)
        tk_pin_set_numbers(out, v);
    return TK_OK;
}

int tk_pin_format(const tk_pin *pin, char *buf, size_t size)
{
    int n = snprintf(buf, size, "%zu:%zu=%s", pin->comp, pin->vertex, tk_pin_kind_name(pin->kind));
    size_t at = n > 0 && (size_t)n < size ? (size_t)n : size;
    double v[6];
    tk_pin_numbers(pin, v);
    for (int k = 0; k < tk_pin_count(pin->kind) && at < size; k++) {
        int m = snprintf(buf + at, size - at, "%c%.17g", k == 0 ? ':' : ',', v[k]);
        if (m < 0)
            return -1;
        n += m;
        at = (size_t)m < size - at ? at + (size_t)m : size;
    }
    return n;
}
