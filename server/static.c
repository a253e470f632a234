/* tightknot service: the page's files, served from --web (see http.h). */
#include "http.h"

#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

result tk_get_static(tk_api *a, conn *c, const call *k)
{
    const char *url = k->url;
    static const char *const types[][2] = {
        {".html", "text/html; charset=utf-8"}, {".js", "text/javascript; charset=utf-8"},
        {".mjs", "text/javascript; charset=utf-8"}, {".css", "text/css; charset=utf-8"},
        {".svg", "image/svg+xml"}, {".png", "image/png"}, {".json", "application/json"},
        {".vect", "text/plain; charset=utf-8"}, {".txt", "text/plain; charset=utf-8"}};
    if (!a->web)
        return PROBLEM(a, c, 404, "no page here: this server was started without --web");
    const char *rel = strcmp(url, "/") ? url : "/index.html";
    /* plain names below the root: no parent steps, no hidden files (the
     * root is joined as a directory, so no neighbour "web.bak" either) */
    if (rel[0] != '/' || strstr(rel, "/.") || strstr(rel, "..") || strchr(rel, '\\') ||
        strlen(rel) > 512)
        return PROBLEM(a, c, 404, "no such file");
    char path[1200];
    snprintf(path, sizeof path, "%s%s", a->web, rel);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) || !S_ISREG(st.st_mode)) {
        if (fd >= 0)
            close(fd);
        return PROBLEM(a, c, 404, "no such file: %.200s", url);
    }
    struct MHD_Response *r = MHD_create_response_from_fd((uint64_t)st.st_size, fd);
    const char *dot = strrchr(path, '.'), *type = "application/octet-stream";
    for (size_t i = 0; dot && i < sizeof types / sizeof types[0]; i++)
        type = strcmp(dot, types[i][0]) ? type : types[i][1];
    if (!r) {
        close(fd);
        return MHD_NO;
    }
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
    result ret = MHD_queue_response(c, 200, r);
    MHD_destroy_response(r);
    atomic_fetch_add(&a->responses[0], 1);
    return ret;
}
