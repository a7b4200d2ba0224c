/* summary.c — summary.json: the machine-readable results of a run.  Entries
 * are dotted keys ("fluid.kinetic_energy"), each dot opening a nested
 * object; parts of the run add their own entries (sim.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "util.h"

typedef struct {
    char *key;
    char *json; /* value already encoded as JSON */
} sum_entry_t;

struct io_summary {
    sum_entry_t *e;
    int n, cap;
};

io_summary_t *io_summary_create(void) { return calloc(1, sizeof(io_summary_t)); }

static void set(io_summary_t *s, const char *key, char *json)
{
    for (int i = 0; i < s->n; i++)
        if (!strcmp(s->e[i].key, key)) {
            free(s->e[i].json);
            s->e[i].json = json;
            return;
        }
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 32;
        s->e = realloc(s->e, (size_t)s->cap * sizeof *s->e);
    }
    s->e[s->n].key = strdup(key);
    s->e[s->n].json = json;
    s->n++;
}

void io_summary_string(io_summary_t *s, const char *key, const char *v)
{
    size_t cap = 2 * strlen(v) + 8 * 6 + 3, n = 0;
    char *out = malloc(cap);
    out[n++] = '"';
    /* JSON is UTF-8: a byte that is not (a file name may hold any) is U+FFFD */
    const size_t len = strlen(v);
    for (const unsigned char *c = (const unsigned char *)v; *c; c++) {
        if (n + 8 > cap) out = realloc(out, cap *= 2);
        const size_t u = cfg_utf8_char((const char *)c, len - (size_t)(c - (const unsigned char *)v));
        if (*c == '"' || *c == '\\') {
            out[n++] = '\\';
            out[n++] = (char)*c;
        } else if (*c < 0x20 || *c == 0x7F) {
            n += (size_t)sprintf(out + n, "\\u%04x", *c);
        } else if (u == 0) {
            n += (size_t)sprintf(out + n, "\\ufffd");
        } else {
            for (size_t k = 0; k < u; k++) out[n++] = (char)c[k];
            c += u - 1;
        }
    }
    out[n++] = '"';
    out[n] = 0;
    set(s, key, out);
}

void io_summary_double(io_summary_t *s, const char *key, double v)
{
    char buf[40];
    if (isfinite(v))
        snprintf(buf, sizeof buf, "%.17g", v);
    else
        snprintf(buf, sizeof buf, "null");
    set(s, key, strdup(buf));
}

void io_summary_long(io_summary_t *s, const char *key, long v)
{
    char buf[32];
    snprintf(buf, sizeof buf, "%ld", v);
    set(s, key, strdup(buf));
}

void io_summary_bool(io_summary_t *s, const char *key, int v) { set(s, key, strdup(v ? "true" : "false")); }

/* Length of the common leading path (whole components) of two dotted keys. */
static size_t prefix_components(const char *a, const char *b, int *ncomp)
{
    size_t last = 0;
    int n = 0;
    for (size_t i = 0;; i++) {
        if (a[i] != b[i] || !a[i]) break;
        if (a[i] == '.') {
            last = i + 1;
            n++;
        }
    }
    *ncomp = n;
    return last;
}

static void indent(FILE *f, int depth)
{
    for (int i = 0; i < depth; i++) fputs("  ", f);
}

/* Write entries [lo, hi) that all share the first `depth` components, as the
 * members of one object.  Entries with the same next component are grouped
 * (the first occurrence fixes the position of the group). */
static void write_object(FILE *f, sum_entry_t **e, int n, int depth)
{
    int *done = calloc((size_t)n, sizeof *done);
    int first = 1;
    for (int i = 0; i < n; i++) {
        if (done[i]) continue;
        /* the component at this depth */
        const char *k = e[i]->key;
        for (int d = 0; d < depth; d++) k = strchr(k, '.') + 1;
        const char *dot = strchr(k, '.');
        size_t clen = dot ? (size_t)(dot - k) : strlen(k);
        fputs(first ? "\n" : ",\n", f);
        first = 0;
        indent(f, depth + 1);
        fprintf(f, "\"%.*s\": ", (int)clen, k);
        if (!dot) {
            fputs(e[i]->json, f);
            done[i] = 1;
            continue;
        }
        /* gather every entry with the same component at this depth */
        sum_entry_t **sub = malloc((size_t)n * sizeof *sub);
        int m = 0;
        for (int j = i; j < n; j++) {
            if (done[j]) continue;
            int nc;
            prefix_components(e[i]->key, e[j]->key, &nc);
            if (nc >= depth + 1) {
                sub[m++] = e[j];
                done[j] = 1;
            }
        }
        fputs("{", f);
        write_object(f, sub, m, depth + 1);
        fputs("\n", f);
        indent(f, depth + 1);
        fputs("}", f);
        free(sub);
    }
    free(done);
}

int io_summary_write(const io_summary_t *s, const char *path)
{
    if (mpi_rank() != 0) return 0;
    char tmp[IO_PATH_MAX + 80];
    FILE *f = atomic_open(path, tmp, sizeof tmp);
    if (!f) return -1;
    sum_entry_t **e = malloc((size_t)(s->n + 1) * sizeof *e);
    for (int i = 0; i < s->n; i++) e[i] = &s->e[i];
    fputs("{", f);
    write_object(f, e, s->n, 0);
    fputs("\n}\n", f);
    free(e);
    return atomic_commit(f, tmp, path);
}

void io_summary_free(io_summary_t *s)
{
    if (!s) return;
    for (int i = 0; i < s->n; i++) {
        free(s->e[i].key);
        free(s->e[i].json);
    }
    free(s->e);
    free(s);
}
