/* tightknot service: the browser boundary (see http.h). */
#include "http.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

/* Whether the comma-separated list holds item (len bytes), ignoring case. */
static bool listed(const char *list, const char *item, size_t len)
{
    for (const char *p = list; p && *p; p += strcspn(p, ",") + (p[strcspn(p, ",")] == ',')) {
        size_t n = strcspn(p, ",");
        if (n == len && !strncasecmp(p, item, len))
            return true;
    }
    return false;
}

/* An allowed other origin the request comes from, or NULL. */
const char *tk_allowed_origin(const tk_api *a, conn *c)
{
    const char *origin = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Origin");
    return origin && listed(a->cfg.allow_origins, origin, strlen(origin)) ? origin : NULL;
}

/* MHD_get_connection_values's iterator: counts the Host headers. */
static result count_host(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    (void)kind, (void)value;
    if (!strcasecmp(key, MHD_HTTP_HEADER_HOST))
        (*(int *)cls)++;
    return MHD_YES;
}

/* A page in a browser can send requests to any address, loopback too,
 * and read the answers under a name of its own that resolves here (DNS
 * rebinding).  So the Host must be one this daemon serves, and a page's
 * request (with an Origin) must come from the daemon's own origin or one
 * allowed with --allow-origin, scheme and all.  An HTTP/1.1 request names
 * exactly one Host (RFC 9112, 3.2): with none or two, a proxy in front
 * and this daemon may each read another. */
unsigned tk_boundary(const tk_api *a, conn *c, const char *version, char *why, size_t size)
{
    const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_HOST);
    const char *origin = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Origin");
    int hosts = 0;
    MHD_get_connection_values(c, MHD_HEADER_KIND, count_host, &hosts);
    if (hosts > 1 || (hosts == 0 && strcmp(version, MHD_HTTP_VERSION_1_0))) {
        snprintf(why, size, "an HTTP/1.1 request names exactly one Host (this one names %d)",
                 hosts);
        return 400;
    }
    if (host) { /* the name without its port; [v6] whole */
        size_t n = host[0] == '[' ? strcspn(host, "]") + 1 : strcspn(host, ":");
        if (!listed(a->hosts, host, n)) {
            snprintf(why, size, "this server does not serve the host '%.*s' (it serves %s; "
                     "name more with --host)", (int)(n < 200 ? n : 200), host, a->hosts);
            return 421;
        }
    }
    /* the daemon's own origin: its scheme, then the Host */
    const char *scheme = a->tls_cert ? "https://" : "http://";
    size_t sn = strlen(scheme);
    if (!origin || (host && !strncasecmp(origin, scheme, sn) && !strcasecmp(origin + sn, host)) ||
        tk_allowed_origin(a, c))
        return 0;
    snprintf(why, size, "requests from pages at '%.200s' are not allowed here (the daemon's "
             "own page is; allow others with --allow-origin)", origin);
    return 403;
}

