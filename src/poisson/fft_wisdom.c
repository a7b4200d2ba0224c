/* fft_wisdom.c — FFTW wisdom for the measuring planner of the FFT solver:
 * imported, merged over the ranks and written so that measured plans are the
 * same in every run (fft.c). */
#include <errno.h>
#include <fftw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fft_internal.h"
#include "util.h"

/* ---- FFTW wisdom: reproducible measured plans -------------------------------
 *
 * FFTW_MEASURE times candidate algorithms and keeps the fastest, so two runs
 * (or two ranks) may pick different algorithms for the same transform and
 * round differently.  FFTW's wisdom records each choice; a planner that finds
 * a problem in its wisdom makes that plan again without measuring (and FFTW
 * itself executes the plan rebuilt from wisdom, not the measured one).  So:
 *  1. the start wisdom is imported on every rank before the first plan: the
 *     checkpoint's copy on a restart (poisson_fftw_wisdom_preset; the file
 *     is then only written if missing), otherwise [poisson] fftw_wisdom
 *     (read by rank 0, broadcast);
 *  2. the plans are made with FFTW_MEASURE (only problems missing from the
 *     wisdom are measured);
 *  3. the ranks' wisdom is merged on rank 0 (later ranks' entries imported
 *     over rank 0's), broadcast, and every rank forgets its own and imports
 *     the merged one, so all ranks hold the same wisdom;
 *  4. the plans are made again from it (FFTW_WISDOM_ONLY: an entry missing
 *     is an error), so the plans executed are the ones any later run
 *     importing this wisdom makes: a rank whose own measurement lost the
 *     merge switches to the merged choice now, not only in the next run;
 *  5. rank 0 writes the file (temporary name, then rename) when it was
 *     missing or the merged wisdom is longer (new problems were measured).
 * The merged wisdom (poisson_fftw_wisdom_used) goes into every checkpoint
 * and the output folder.  With the same wisdom, every plan of every solver
 * (pressure, Helmholtz; all their steps) is the same in every run; a plan
 * made later for a field of another alignment class is estimated (same in
 * every run too).  The wisdom depends on the problem sizes, hence on the
 * rank count: a file may hold the wisdom of several grids and rank counts. */
static struct {
    int loaded;           /* the start wisdom has been imported */
    char path[4096];      /* the file it came from ("" none) */
    char *preset;         /* wisdom of a restart (poisson_fftw_wisdom_preset) */
    int may_write;        /* the start wisdom is the file's (or the file is missing): write it when grown */
    size_t file_len;      /* length of the file's wisdom (0: missing) */
    char *used;           /* merged wisdom after the last measured set-up */
} wis;

void poisson_fftw_wisdom_preset(const char *wisdom)
{
    free(wis.preset);
    wis.preset = NULL;
    if (wisdom && !(wis.preset = strdup(wisdom))) die("out of memory");
    wis.loaded = 0;
}

const char *poisson_fftw_wisdom_used(void) { return wis.used; }

/* The file's text (malloc'd), NULL if it does not exist; why (n chars) says
 * what else went wrong (then NULL is returned and why[0] != 0). */
static char *wisdom_file_read(const char *path, char *why, size_t n)
{
    why[0] = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        if (errno != ENOENT) snprintf(why, n, "cannot read %s: %s", path, strerror(errno));
        return NULL;
    }
    size_t cap = 1 << 16, len = 0;
    char *s = xcalloc(cap, 1);
    for (size_t r; (r = fread(s + len, 1, cap - 1 - len, f)) > 0;) {
        len += r;
        if (len + 1 == cap) {
            s = realloc(s, 2 * cap);
            if (!s) die("out of memory reading %s", path);
            cap *= 2;
        }
    }
    int err = ferror(f);
    fclose(f);
    s[len] = 0;
    if (err) {
        snprintf(why, n, "cannot read %s", path);
        free(s);
        return NULL;
    }
    return s;
}

int poisson_fftw_wisdom_check(const char *path, char *why, size_t n)
{
    struct stat st;
    if (!path[0]) return snprintf(why, n, "empty path"), 1;
    if (stat(path, &st) == 0) {
        if (!S_ISREG(st.st_mode)) return snprintf(why, n, "%s is not a regular file", path), 1;
        char *s = wisdom_file_read(path, why, n);
        if (!s) return 1;
        /* importing is the only complete check (format, FFTW version and
         * build); harmless: the wisdom is loaded from scratch before planning */
        int ok = fftw_import_wisdom_from_string(s);
        free(s);
        if (!ok)
            return snprintf(why, n, "%s is not FFTW wisdom of this FFTW build (%s) and planner set; delete it to measure again", path,
                            fftw_version),
                   1;
        return 0;
    }
    if (errno != ENOENT) return snprintf(why, n, "%s: %s", path, strerror(errno)), 1;
    /* missing: it will be created, so its folder must be writable */
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash == dir)
        dir[1] = 0;
    else if (slash)
        *slash = 0;
    else
        snprintf(dir, sizeof dir, ".");
    if (access(dir, W_OK | X_OK) != 0)
        return snprintf(why, n, "cannot create %s: folder %s: %s", path, dir, strerror(errno)), 1;
    return 0;
}

/* Text of rank 0 (NULL allowed) to every rank of comm; NULL stays NULL. */
static char *bcast_text(const char *text, MPI_Comm comm)
{
    int me;
    MPI_Comm_rank(comm, &me);
    long len = me == 0 ? (text ? (long)strlen(text) : -1) : 0;
    MPI_Bcast(&len, 1, MPI_LONG, 0, comm);
    if (len < 0) return NULL;
    if (len > 2147483646L) die("poisson fft: FFTW wisdom of %ld bytes", len);
    char *s = xcalloc((size_t)len + 1, 1);
    if (me == 0) memcpy(s, text, (size_t)len);
    MPI_Bcast(s, (int)len, MPI_CHAR, 0, comm);
    return s;
}

/* Step 1: every rank forgets its wisdom and imports the start wisdom (once
 * per process and file). */
void fft_wisdom_start(const char *path, MPI_Comm comm)
{
    if (wis.loaded && !strcmp(path, wis.path)) return;
    fftw_forget_wisdom();
    wis.loaded = 1;
    snprintf(wis.path, sizeof wis.path, "%s", path);
    wis.file_len = 0;
    wis.may_write = 0;
    int me;
    MPI_Comm_rank(comm, &me);
    if (wis.preset) {
        if (!fftw_import_wisdom_from_string(wis.preset))
            die("poisson fft: the FFTW wisdom of the checkpoint is not wisdom of this FFTW build (%s)", fftw_version);
        /* the file is left as it is, unless it is missing */
        int missing = me == 0 && path[0] && access(path, F_OK) != 0;
        MPI_Bcast(&missing, 1, MPI_INT, 0, comm);
        wis.may_write = missing;
        return;
    }
    if (!path[0]) return;
    char why[4400] = "", *text0 = me == 0 ? wisdom_file_read(path, why, sizeof why) : NULL;
    int bad = why[0] != 0;
    MPI_Bcast(&bad, 1, MPI_INT, 0, comm);
    if (bad) die("poisson.fftw_wisdom: %s", why);
    char *text = bcast_text(text0, comm);
    free(text0);
    wis.may_write = 1;
    if (!text) return;
    if (!fftw_import_wisdom_from_string(text))
        die("poisson.fftw_wisdom: %s is not FFTW wisdom of this FFTW build (%s) and planner set; delete it to measure again", path,
            fftw_version);
    wis.file_len = strlen(text);
    free(text);
}

/* Step 3: merge the ranks' wisdom on rank 0 and give it to every rank. */
void fft_wisdom_merge(MPI_Comm comm)
{
    int me, P;
    MPI_Comm_rank(comm, &me);
    MPI_Comm_size(comm, &P);
    char *mine = fftw_export_wisdom_to_string();
    if (!mine) die("poisson fft: FFTW could not export its wisdom");
    int len = (int)strlen(mine) + 1, *lens = NULL, *displ = NULL;
    char *all = NULL;
    if (me == 0) {
        lens = xcalloc((size_t)P, sizeof(int));
        displ = xcalloc((size_t)P, sizeof(int));
    }
    MPI_Gather(&len, 1, MPI_INT, lens, 1, MPI_INT, 0, comm);
    if (me == 0) {
        long tot = 0;
        for (int r = 0; r < P; r++) displ[r] = (int)tot, tot += lens[r];
        if (tot > 2147483647L) die("poisson fft: FFTW wisdom of %ld bytes", tot);
        all = xcalloc((size_t)tot, 1);
    }
    MPI_Gatherv(mine, len, MPI_CHAR, all, lens, displ, MPI_CHAR, 0, comm);
    free(mine);
    char *merged = NULL;
    if (me == 0) {
        for (int r = 1; r < P; r++)
            if (!fftw_import_wisdom_from_string(all + displ[r])) die("poisson fft: FFTW could not import rank %d's wisdom", r);
        merged = fftw_export_wisdom_to_string();
        if (!merged) die("poisson fft: FFTW could not export its wisdom");
    }
    free(all);
    free(lens);
    free(displ);
    char *text = bcast_text(merged, comm);
    free(merged);
    fftw_forget_wisdom();
    if (!fftw_import_wisdom_from_string(text)) die("poisson fft: FFTW could not import the merged wisdom");
    free(wis.used);
    wis.used = text;
}

/* Step 5: rank 0 writes the file under a temporary name, then renames it. */
void fft_wisdom_write(MPI_Comm comm)
{
    size_t len = strlen(wis.used);
    if (!wis.may_write || !wis.path[0] || len <= wis.file_len) return;
    int me;
    MPI_Comm_rank(comm, &me);
    wis.file_len = len;
    if (me != 0) return;
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", wis.path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    int ok = f && fwrite(wis.used, 1, len, f) == len;
    if (f) ok = fclose(f) == 0 && ok;
    if (!ok || rename(tmp, wis.path) != 0) {
        remove(tmp);
        die_local("poisson.fftw_wisdom: cannot write %s: %s", wis.path, strerror(errno));
    }
}

