/* series.c — the time series of diagnostics: a CSV file written by rank 0,
 * one row per output step, flushed every few seconds so that a running job
 * can be watched, and made durable (fsync) before every checkpoint is
 * declared written (io_series_sync_all), so that the rows up to a checkpoint
 * survive a crash.  The checkpoint records the step of the last row before
 * it and a hash of the file's bytes up to that row (FNV-1a, 64 bits): a
 * restart checks that the file still holds exactly those rows, and cuts it
 * after them (the rows of the lost continuation, a row cut by the crash). */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io.h"
#include "util.h"

struct io_series {
    FILE *f;
    char path[IO_PATH_MAX + 64];
    int ncol;
    long last_step;     /* step of the last row written (-1: none) */
    uint64_t hash;      /* of every byte of the file */
    uint64_t hash_prev; /* of the bytes before the rows of the last step */
    double last_flush;
    io_series_t *next;  /* the open series (io_series_sync_all) */
};

static io_series_t *open_list = NULL;

#define FNV_BASIS 14695981039346656037ULL

static uint64_t fnv(uint64_t h, const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        h ^= (unsigned char)s[i];
        h *= 1099511628211ULL;
    }
    return h;
}

static void header_line(int ncol, const char *const *names, char *header, size_t n)
{
    header[0] = 0;
    for (int c = 0; c < ncol; c++) {
        strncat(header, names[c], n - strlen(header) - 2);
        strcat(header, c + 1 < ncol ? "," : "\n");
    }
}

/* The step of a complete row of ncol values (ends with a newline, ncol
 * numbers); -1 if the line is not one. */
static double row_step(const char *line, ssize_t len, int ncol)
{
    if (len < 2 || line[len - 1] != '\n') return -1;
    int commas = 0;
    for (ssize_t i = 0; i < len; i++) commas += line[i] == ',';
    if (commas != ncol - 1) return -1;
    char *end;
    double step = strtod(line, &end);
    if (end == line || *end != ',' || !(step >= 0) || step != floor(step)) return -1;
    return step;
}

/* Restart: keep the header and the rows with step <= r->step of the
 * existing file, check them against the checkpoint's record (the step of
 * the last row and the hash of the file up to it), cut the rest and leave
 * the file open at its end.  Returns the open file, or NULL when the file
 * does not exist or (with the reason in why) does not fit. */
static FILE *continue_file(io_series_t *s, const char *header, const io_series_resume_t *r, char *why, size_t nwhy)
{
    FILE *f = fopen(s->path, "r+");
    if (!f) {
        if (errno != ENOENT) snprintf(why, nwhy, "cannot open %s: %s", s->path, strerror(errno));
        return NULL;
    }
    char *line = NULL;
    size_t nline = 0;
    ssize_t len = getline(&line, &nline, f);
    if (len <= 0 || strcmp(line, header) != 0) {
        snprintf(why, nwhy, "%s: its columns are not those of this run: not the series of the run that wrote the "
                 "checkpoint", s->path);
        free(line);
        fclose(f);
        return NULL;
    }
    long keep = (long)len, lineno = 1, last = -1, nrow = 0;
    uint64_t h = fnv(FNV_BASIS, line, (size_t)len), hprev = h;
    while ((len = getline(&line, &nline, f)) > 0) {
        lineno++;
        const double step = row_step(line, len, s->ncol);
        if (step < 0 || step > (double)r->step || step < (double)last) break;
        if ((long)step != last) hprev = h;
        last = (long)step;
        h = fnv(h, line, (size_t)len);
        keep += (long)len;
        nrow++;
    }
    free(line);
    if (r->last_row >= 0 && last != r->last_row)
        snprintf(why, nwhy, "%s: its rows end at step %ld (line %ld %s), but the checkpoint of step %ld follows a "
                 "row of step %ld: rows are missing (not the file of the run that wrote the checkpoint?)",
                 s->path, last, lineno, len > 0 ? "is cut or out of order" : "is the last", r->step, r->last_row);
    else if (r->has_hash && h != r->hash)
        snprintf(why, nwhy, "%s: its %ld rows up to step %ld are not those the run wrote before the checkpoint of "
                 "step %ld (rows missing, changed or cut)",
                 s->path, nrow, last, r->step);
    else if (fflush(f) != 0 || ftruncate(fileno(f), keep) != 0 || fseek(f, 0, SEEK_END) != 0)
        snprintf(why, nwhy, "cannot cut %s after step %ld: %s", s->path, r->step, strerror(errno));
    if (why[0]) {
        fclose(f);
        return NULL;
    }
    s->last_step = last;
    s->hash = h;
    s->hash_prev = hprev;
    return f;
}

io_series_t *io_series_open(const char *path, int ncol, const char *const *names, const io_series_resume_t *r)
{
    io_series_t *s = calloc(1, sizeof *s);
    s->ncol = ncol;
    s->last_step = -1;
    snprintf(s->path, sizeof s->path, "%s", path);
    char why[IO_PATH_MAX + 512] = "";
    if (mpi_rank() == 0) {
        char header[4096];
        header_line(ncol, names, header, sizeof header);
        if (r) {
            s->f = continue_file(s, header, r, why, sizeof why);
            if (!s->f && !why[0] && r->last_row >= 0)
                warn("%s does not exist: it starts again after step %ld, the restart step\n", path, r->step);
        }
        if (!s->f && !why[0]) {
            s->f = fopen(path, "w");
            if (!s->f || fputs(header, s->f) < 0 || fflush(s->f) != 0)
                snprintf(why, sizeof why, "cannot write %s: %s", path, strerror(errno));
            s->hash = s->hash_prev = fnv(FNV_BASIS, header, strlen(header));
        }
        s->last_flush = wtime();
        s->next = open_list;
        open_list = s;
    }
    /* every rank stops together */
    MPI_Bcast(why, sizeof why, MPI_CHAR, 0, MPI_COMM_WORLD);
    if (why[0]) die("%s", why);
    return s;
}

void io_series_row(io_series_t *s, const double *v)
{
    if (!s->f) return;
    char line[64 * 200];
    size_t n = 0;
    for (int c = 0; c < s->ncol && n + 40 < sizeof line; c++) {
        double x = v[c];
        if (x == floor(x) && fabs(x) < 1e15)
            n += (size_t)snprintf(line + n, sizeof line - n, "%.0f", x);
        else
            n += (size_t)snprintf(line + n, sizeof line - n, "%.12g", x);
        line[n++] = c + 1 < s->ncol ? ',' : '\n';
    }
    const long step = (long)v[0];
    if (fault_armed("series-row", step)) { /* a crash in the middle of a row */
        fwrite(line, 1, n / 2, s->f);
        fflush(s->f);
        fault_exit("series-row", step);
    }
    if (fwrite(line, 1, n, s->f) != n) io_error("cannot write %s: %s", s->path, strerror(errno));
    if (step != s->last_step) s->hash_prev = s->hash;
    s->hash = fnv(s->hash, line, n);
    s->last_step = step;
    double now = wtime();
    if (now - s->last_flush > 2.0) {
        if (fflush(s->f) != 0 || ferror(s->f)) io_error("cannot write %s: %s", s->path, strerror(errno ? errno : EIO));
        s->last_flush = now;
    }
}

long io_series_last_step(const io_series_t *s) { return s ? s->last_step : -1; }

uint64_t io_series_hash(const io_series_t *s, long step)
{
    if (!s) return 0;
    return s->last_step <= step ? s->hash : s->hash_prev;
}

void io_series_sync_all(void)
{
    for (io_series_t *s = open_list; s; s = s->next)
        if (s->f) sync_stream(s->f, s->path);
}

void io_series_close(io_series_t *s)
{
    if (!s) return;
    for (io_series_t **p = &open_list; *p; p = &(*p)->next)
        if (*p == s) {
            *p = s->next;
            break;
        }
    if (s->f) {
        errno = 0;
        if (fflush(s->f) != 0 || ferror(s->f)) io_error("cannot write %s: %s", s->path, strerror(errno ? errno : EIO));
        if (fclose(s->f) != 0) io_error("cannot write %s: %s", s->path, strerror(errno ? errno : EIO));
    }
    free(s);
}
