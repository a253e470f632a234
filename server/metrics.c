/* tightknot service: health, for a watchdog, and metrics, for Prometheus
 * (see http.h). */
#define _GNU_SOURCE
#include "http.h"

#include <stdio.h>
#include <time.h>

result tk_get_health(tk_api *a, conn *c, const call *k)
{
    (void)k;
    tk_pool_stats s;
    tk_pool_stats_get(a->pool, &s);
    size_t counts[TK_JOB_STATES];
    char reason[TK_ERROR_MESSAGE_SIZE + 64];
    tk_error err;
    /* a store that cannot take jobs: 503 saying why, for a watchdog */
    if (!tk_store_health(a->store, reason, sizeof reason) ||
        (tk_store_counts(a->store, counts, &err) &&
         snprintf(reason, sizeof reason, "%s", err.message)))
        return problem(a, c, 503, json_pack("{s:s}", "health", "degraded"), NULL, "%s", reason);
    return send_json(a, c, 200, json_pack("{s:s, s:I, s:I, s:I, s:I, s:I}", "status", "ok",
                                          "workers", (json_int_t)s.workers, "running",
                                          (json_int_t)s.running, "queued",
                                          (json_int_t)counts[TK_JOB_QUEUED], "queue_limit",
                                          (json_int_t)s.queue_limit, "uptime",
                                          (json_int_t)(time(NULL) - a->started)), NULL, NULL);
}

result tk_get_metrics(tk_api *a, conn *c, const call *k)
{
    (void)k;
    tk_pool_stats s;
    tk_pool_stats_get(a->pool, &s);
    size_t counts[TK_JOB_STATES];
    tk_error err;
    int rc = tk_store_counts(a->store, counts, &err);
    if (rc)
        return store_problem(a, c, rc, &err);
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return MHD_NO;
    fputs("# HELP tightknot_jobs Jobs in the store by state.\n# TYPE tightknot_jobs gauge\n", f);
    for (int i = 0; i < TK_JOB_STATES; i++)
        fprintf(f, "tightknot_jobs{state=\"%s\"} %zu\n", tk_job_states[i], counts[i]);
    const struct { const char *name, *type, *help; double value; } gauges[] = {
        {"queue_length", "gauge", "Jobs waiting for a worker.", (double)counts[TK_JOB_QUEUED]},
        {"queue_limit", "gauge", "Queued jobs beyond which submissions get 429.",
         (double)s.queue_limit},
        {"workers", "gauge", "Worker threads.", (double)s.workers},
        {"workers_busy", "gauge", "Workers running a job.", (double)s.running},
        {"steps_total", "counter", "Flow steps taken since start.", (double)s.steps_total},
        {"jobs_ended_total", "counter", "Jobs run here to done, failed or cancelled since start.",
         (double)s.jobs_ended},
        {"worker_busy_seconds_total", "counter",
         "Seconds the workers spent running jobs since start (over workers x seconds: "
         "utilisation).", s.busy_seconds},
        {"steps_per_second", "gauge", "Steps per second over the running jobs.",
         s.steps_per_second},
        {"http_body_bytes_held", "gauge",
         "Bytes of request bodies held now, all connections (at most --max-body-total).",
         (double)tk_limits_held(a)}};
    for (size_t i = 0; i < sizeof gauges / sizeof gauges[0]; i++)
        fprintf(f, "# HELP tightknot_%s %s\n# TYPE tightknot_%s %s\ntightknot_%s %.17g\n",
                gauges[i].name, gauges[i].help, gauges[i].name, gauges[i].type, gauges[i].name,
                gauges[i].value);
    fputs("# HELP tightknot_http_responses_total HTTP responses by status class.\n"
          "# TYPE tightknot_http_responses_total counter\n", f);
    for (int i = 0; i < 4; i++)
        fprintf(f, "tightknot_http_responses_total{code=\"%dxx\"} %llu\n", i + 2,
                atomic_load(&a->responses[i]));
    fclose(f);
    return send_buffer(a, c, 200, "text/plain; version=0.0.4; charset=utf-8", buf, len, NULL);
}
