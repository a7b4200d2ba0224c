/* checkpoint.c — checkpoint files and the fingerprint of the input.
 *
 * A checkpoint is an HDF5 file DIR/checkpoint_SSSSSSSS.h5 (S = step).  Root
 * attributes: format, ibmdem_version, time, step, nranks, fingerprint; the
 * dataset "input" holds the resolved input text.  The physics parts of the
 * run add one group each (the fluid: /fluid with u, v, w, p) — see sim.c.
 * The file is written under a temporary name and renamed when complete. */
#include <dirent.h>
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "util.h"

static void checkpoint_name(const char *dir, long step, const char *suffix, char *buf, size_t n)
{
    snprintf(buf, n, "%s/checkpoint_%08ld.h5%s", dir, step, suffix);
}

hid_t io_checkpoint_begin(const char *dir, const io_checkpoint_header_t *h, MPI_Comm comm)
{
    char tmp[IO_PATH_MAX + 64];
    checkpoint_name(dir, h->step, ".tmp", tmp, sizeof tmp);
    hid_t f = io_h5_create(tmp, comm);
    char fp[32];
    snprintf(fp, sizeof fp, "%016" PRIx64, h->fingerprint);
    io_h5_attr_long(f, "format", IO_CHECKPOINT_FORMAT);
    io_h5_attr_string(f, "ibmdem_version", IBMDEM_VERSION);
    io_h5_attr_double(f, "time", h->time);
    io_h5_attr_long(f, "step", h->step);
    io_h5_attr_long(f, "nranks", h->nranks);
    io_h5_attr_string(f, "fingerprint", fp);
    io_h5_write_text(f, "input", h->input ? h->input : "");
    return f;
}

typedef struct {
    long step;
    char name[256];
} ckpt_entry_t;

static int cmp_step(const void *a, const void *b)
{
    long x = ((const ckpt_entry_t *)a)->step, y = ((const ckpt_entry_t *)b)->step;
    return (x > y) - (x < y);
}

/* Delete the oldest checkpoints of dir beyond the `keep` newest. */
void io_checkpoint_prune(const char *dir, int keep)
{
    if (keep <= 0 || mpi_rank() != 0) return;
    DIR *d = opendir(dir);
    if (!d) return;
    ckpt_entry_t *list = NULL;
    int n = 0, cap = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        long step;
        char tail[8] = "";
        if (sscanf(e->d_name, "checkpoint_%ld.h%7s", &step, tail) != 2 || strcmp(tail, "5") != 0) continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 16;
            list = realloc(list, (size_t)cap * sizeof *list);
        }
        list[n].step = step;
        snprintf(list[n].name, sizeof list[n].name, "%s", e->d_name);
        n++;
    }
    closedir(d);
    qsort(list, (size_t)n, sizeof *list, cmp_step);
    for (int i = 0; i < n - keep; i++) {
        char path[IO_PATH_MAX + 300];
        snprintf(path, sizeof path, "%s/%s", dir, list[i].name);
        if (remove(path) != 0) warn("cannot delete the old checkpoint %s: %s\n", path, strerror(errno));
    }
    free(list);
}

int io_checkpoint_end(hid_t file, const char *dir, long step, int keep, char *path, size_t npath, MPI_Comm comm)
{
    char tmp[IO_PATH_MAX + 64], final[IO_PATH_MAX + 64], why[IO_PATH_MAX + 1024] = "";
    fault_point("checkpoint-data", step); /* killed while the data is being written */
    io_h5_close(file);                    /* flushed to the disk: MPI_File_sync */
    checkpoint_name(dir, step, ".tmp", tmp, sizeof tmp);
    checkpoint_name(dir, step, "", final, sizeof final);
    int rank;
    MPI_Comm_rank(comm, &rank);
    if (io_check_errors(comm, why, sizeof why)) {
        /* not a checkpoint: the previous one stays the newest */
        if (rank == 0) remove(tmp);
        return -1;
    }
    fault_point("checkpoint-written", step); /* complete under its temporary name */
    int err = 0;
    if (rank == 0) {
        err = rename(tmp, final) != 0;
        if (err) io_error("cannot rename %s to %s: %s", tmp, final, strerror(errno));
        else err = fsync_dir(dir) != 0; /* the new name is durable */
    }
    MPI_Bcast(&err, 1, MPI_INT, 0, comm);
    if (err) return -1;
    fault_point("checkpoint-renamed", step);
    io_checkpoint_prune(dir, keep);
    if (path) snprintf(path, npath, "%s", final);
    return 0;
}

hid_t io_checkpoint_open(const char *path, io_checkpoint_header_t *h, MPI_Comm comm)
{
    memset(h, 0, sizeof *h);
    hid_t f = io_h5_open(path, comm);
    if (f < 0) die("%s: cannot open the checkpoint (missing, unreadable or not an HDF5 file)", path);
    long format = 0, nranks = 0;
    char fp[32] = "";
    if (io_h5_get_attr_long(f, "format", &format) || io_h5_get_attr_double(f, "time", &h->time) ||
        io_h5_get_attr_long(f, "step", &h->step) || io_h5_get_attr_long(f, "nranks", &nranks))
        die("%s: not an ibmdem checkpoint (no format, time, step or nranks attribute)", path);
    if (format != IO_CHECKPOINT_FORMAT)
        die("%s: checkpoint format %ld, this ibmdem reads format %d", path, format, IO_CHECKPOINT_FORMAT);
    if (H5Aexists(f, "fingerprint") > 0) {
        hid_t a = H5Aopen(f, "fingerprint", H5P_DEFAULT);
        hid_t t = H5Tcopy(H5T_C_S1);
        H5Tset_size(t, sizeof fp);
        H5Aread(a, t, fp);
        H5Tclose(t);
        H5Aclose(a);
    }
    h->fingerprint = strtoull(fp, NULL, 16);
    h->nranks = (int)nranks;
    h->input = io_h5_read_text(f, "input");
    /* a state with a NaN or an infinity in it cannot be continued */
    char where[512];
    if (io_h5_check_finite(f, comm, where, sizeof where) || !isfinite(h->time))
        die("%s: %s holds non-finite values (NaN or infinity): not a state a run can continue from; restart from "
            "an earlier checkpoint",
            path, isfinite(h->time) ? where : "the attribute time");
    return f;
}

void io_checkpoint_header_free(io_checkpoint_header_t *h)
{
    free(h->input);
    h->input = NULL;
}

/* ---- the resolved input and its fingerprint --------------------------------- */

char *io_resolved_input(const cfg_t *cfg)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    cfg_write_resolved(cfg, f);
    fclose(f);
    return text;
}

typedef struct {
    char key[256]; /* section.key */
    char value[1024];
} kv_t;

static int skipped(const char *key, const char *const *skip)
{
    for (int i = 0; skip && skip[i]; i++) {
        size_t n = strlen(skip[i]);
        if (n >= 2 && !strcmp(skip[i] + n - 2, ".*")) {
            if (!strncmp(key, skip[i], n - 1)) return 1;
        } else if (!strcmp(key, skip[i])) {
            return 1;
        }
    }
    return 0;
}

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    size_t n = strlen(s);
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\n' || s[n - 1] == '\r')) s[--n] = 0;
    return s;
}

/* Parse the "key = value" lines of a resolved input (the format written by
 * cfg_write_resolved: sorted by section and key, "; origin" notes after the
 * value for defaults and --set), dropping the skipped keys. */
static kv_t *parse_resolved(const char *text, const char *const *skip, int *n)
{
    kv_t *kv = NULL;
    int m = 0, cap = 0;
    char section[128] = "";
    const char *p = text ? text : "";
    while (*p) {
        const char *eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) : strlen(p);
        char line[1400];
        snprintf(line, sizeof line, "%.*s", (int)(len < sizeof line - 1 ? len : sizeof line - 1), p);
        p += len + (eol ? 1 : 0);
        char *s = trim(line);
        if (!*s || *s == ';' || *s == '#') continue;
        if (*s == '[') {
            char *e = strchr(s, ']');
            if (e) *e = 0;
            snprintf(section, sizeof section, "%s", s + 1);
            continue;
        }
        char *eq = strchr(s, '=');
        if (!eq) continue;
        *eq = 0;
        char *val = eq + 1;
        char *note = strstr(val, " ; ");
        if (note && (!strcmp(note + 3, "default") || !strcmp(note + 3, "--set"))) *note = 0;
        if (m == cap) {
            cap = cap ? 2 * cap : 64;
            kv = realloc(kv, (size_t)cap * sizeof *kv);
        }
        snprintf(kv[m].key, sizeof kv[m].key, "%s.%s", section, trim(s));
        snprintf(kv[m].value, sizeof kv[m].value, "%s", trim(val));
        if (skipped(kv[m].key, skip)) continue;
        m++;
    }
    *n = m;
    return kv;
}

uint64_t io_input_fingerprint(const char *resolved, const char *const *skip)
{
    int n;
    kv_t *kv = parse_resolved(resolved, skip, &n);
    uint64_t h = 14695981039346656037ULL; /* FNV-1a offset basis */
    for (int i = 0; i < n; i++) {
        const char *parts[4] = {kv[i].key, "=", kv[i].value, "\n"};
        for (int q = 0; q < 4; q++)
            for (const unsigned char *c = (const unsigned char *)parts[q]; *c; c++) {
                h ^= *c;
                h *= 1099511628211ULL; /* FNV prime */
            }
    }
    free(kv);
    return h;
}

int io_input_diff(const char *a, const char *b, const char *const *skip,
                  void (*fn)(const char *key, const char *va, const char *vb, void *ctx), void *ctx)
{
    int na, nb, ndiff = 0;
    kv_t *ka = parse_resolved(a, skip, &na), *kb = parse_resolved(b, skip, &nb);
    for (int i = 0; i < na; i++) {
        int found = 0;
        for (int j = 0; j < nb && !found; j++)
            if (!strcmp(ka[i].key, kb[j].key)) {
                found = 1;
                if (strcmp(ka[i].value, kb[j].value)) {
                    ndiff++;
                    if (fn) fn(ka[i].key, ka[i].value, kb[j].value, ctx);
                }
            }
        if (!found) {
            ndiff++;
            if (fn) fn(ka[i].key, ka[i].value, NULL, ctx);
        }
    }
    for (int j = 0; j < nb; j++) {
        int found = 0;
        for (int i = 0; i < na && !found; i++) found = !strcmp(ka[i].key, kb[j].key);
        if (!found) {
            ndiff++;
            if (fn) fn(kb[j].key, NULL, kb[j].value, ctx);
        }
    }
    free(ka);
    free(kb);
    return ndiff;
}
