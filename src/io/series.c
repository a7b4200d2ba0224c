/* series.c — the time series of diagnostics: a CSV file written by rank 0,
 * one row per output step, flushed every few seconds so that a running job
 * can be watched (and the file is complete when it stops). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "util.h"

struct io_series {
    FILE *f;
    int ncol;
    double last_flush;
};

/* Keep the header and the rows with step <= restart_step of an existing file
 * whose header is `header`; returns the kept text (malloc'd) or NULL. */
static char *kept_rows(const char *path, const char *header, long restart_step)
{
    FILE *f = fopen(path, "r");
    if (!f) return NULL;
    size_t cap = 1 << 16, len = 0;
    char *out = malloc(cap), *line = NULL;
    size_t nline = 0;
    ssize_t r;
    int first = 1, ok = 1;
    out[0] = 0;
    while ((r = getline(&line, &nline, f)) > 0) {
        if (first) {
            first = 0;
            if (strcmp(line, header) != 0) { ok = 0; break; } /* other columns: start anew */
        } else {
            char *end;
            double step = strtod(line, &end);
            if (end == line || step > (double)restart_step) break;
        }
        if (len + (size_t)r + 1 > cap) {
            while (len + (size_t)r + 1 > cap) cap *= 2;
            out = realloc(out, cap);
        }
        memcpy(out + len, line, (size_t)r + 1);
        len += (size_t)r;
    }
    free(line);
    fclose(f);
    if (!ok || first) {
        free(out);
        return NULL;
    }
    return out;
}

io_series_t *io_series_open(const char *path, int ncol, const char *const *names, long restart_step)
{
    io_series_t *s = calloc(1, sizeof *s);
    s->ncol = ncol;
    if (mpi_rank() != 0) return s;
    char header[4096] = "";
    for (int c = 0; c < ncol; c++) {
        strncat(header, names[c], sizeof header - strlen(header) - 2);
        strcat(header, c + 1 < ncol ? "," : "\n");
    }
    char *kept = restart_step >= 0 ? kept_rows(path, header, restart_step) : NULL;
    s->f = fopen(path, "w");
    if (!s->f) die_local("cannot write %s", path);
    fputs(kept ? kept : header, s->f);
    free(kept);
    fflush(s->f);
    s->last_flush = wtime();
    return s;
}

void io_series_row(io_series_t *s, const double *v)
{
    if (!s->f) return;
    for (int c = 0; c < s->ncol; c++) {
        double x = v[c];
        if (x == floor(x) && fabs(x) < 1e15)
            fprintf(s->f, "%.0f", x);
        else
            fprintf(s->f, "%.12g", x);
        fputc(c + 1 < s->ncol ? ',' : '\n', s->f);
    }
    double now = wtime();
    if (now - s->last_flush > 2.0) {
        fflush(s->f);
        s->last_flush = now;
    }
}

void io_series_close(io_series_t *s)
{
    if (!s) return;
    if (s->f) fclose(s->f);
    free(s);
}
