/* outdir.c — the output folder of a run: created on rank 0, locked for the
 * run (DIR/.ibmdem.lock), with a log file that receives everything rank 0
 * prints and the resolved input.  A new run does not mix its files with
 * those of an earlier run: it refuses the folder, or (overwrite) deletes
 * them first; a restart continues in place. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <fnmatch.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io.h"
#include "util.h"

/* The files ibmdem writes into an output folder (fnmatch patterns; the same
 * names with .tmp are files being written).  Keep in sync with the table of
 * docs/user-guide.md "Outputs". */
static const char *const output_patterns[] = {
    "log.txt",         "input.ini",          "series.csv",       "summary.json",        "fftw.wisdom",
    "fields.xmf",      "fields_[0-9]*.h5",   "checkpoint_[0-9]*.h5",
    "spheres.xmf",     "spheres.csv",        "spheres_[0-9]*.h5", "particles.xdmf",      "particles_[0-9]*.h5",
    "porenet.xmf",     "porenet_[0-9]*.h5",  NULL};

/* Other names the parts of the run write (e.g. [packing] output). */
static const char *const *extra_names = NULL;

static int is_output(const char *name)
{
    char base[512];
    snprintf(base, sizeof base, "%s", name);
    size_t n = strlen(base);
    if (n > 4 && !strcmp(base + n - 4, ".tmp")) base[n - 4] = 0;
    for (int i = 0; output_patterns[i]; i++)
        if (fnmatch(output_patterns[i], base, 0) == 0) return 1;
    for (int i = 0; extra_names && extra_names[i]; i++)
        if (!strcmp(extra_names[i], base)) return 1;
    return 0;
}

/* Names of the outputs of an earlier run in dir (malloc'd array, *n of them). */
static char **list_outputs(const char *dir, int *n)
{
    DIR *d = opendir(dir);
    char **list = NULL;
    int m = 0, cap = 0;
    struct dirent *e;
    while (d && (e = readdir(d))) {
        if (!is_output(e->d_name)) continue;
        if (m == cap) list = realloc(list, (size_t)(cap = cap ? 2 * cap : 32) * sizeof *list);
        list[m++] = strdup(e->d_name);
    }
    if (d) closedir(d);
    *n = m;
    return list;
}

static void free_list(char **list, int n)
{
    for (int i = 0; i < n; i++) free(list[i]);
    free(list);
}

/* Rank 0: hold DIR/.ibmdem.lock for the run (released by the system when the
 * process ends, however it ends).  Returns the descriptor, or -1 with the
 * reason in why. */
static int take_lock(const char *dir, char *why, size_t nwhy)
{
    char path[IO_PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/.ibmdem.lock", dir);
    int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
        snprintf(why, nwhy, "cannot create %s: %s", path, strerror(errno));
        return -1;
    }
    struct flock l = {.l_type = F_WRLCK, .l_whence = SEEK_SET, .l_start = 0, .l_len = 0};
    if (fcntl(fd, F_SETLK, &l) != 0) {
        char who[128] = "";
        ssize_t r = pread(fd, who, sizeof who - 1, 0);
        who[r > 0 ? r : 0] = 0;
        char *nl = strchr(who, '\n');
        if (nl) *nl = 0;
        if (errno == EACCES || errno == EAGAIN)
            snprintf(why, nwhy, "another run writes into this folder (%s%s): two runs into one folder would mix "
                     "their files", who[0] ? "process " : "", who);
        else
            snprintf(why, nwhy, "cannot lock %s: %s", path, strerror(errno));
        close(fd);
        return -1;
    }
    char host[128] = "?", line[200];
    gethostname(host, sizeof host - 1);
    int len = snprintf(line, sizeof line, "%ld on %s\n", (long)getpid(), host);
    if (ftruncate(fd, 0) != 0 || pwrite(fd, line, (size_t)len, 0) != len) {
        /* the lock holds without its note */
    }
    return fd;
}

/* Rank 0: a new run into dir: refuse the outputs of an earlier run, or delete them. */
static int earlier_outputs(const char *dir, int overwrite, int *removed, char *why, size_t nwhy)
{
    int n;
    char **list = list_outputs(dir, &n);
    int rc = 0;
    if (n > 0 && !overwrite) {
        char names[400] = "";
        for (int i = 0; i < n && i < 4; i++) {
            strncat(names, i ? ", " : "", sizeof names - strlen(names) - 1);
            strncat(names, list[i], sizeof names - strlen(names) - 1);
        }
        snprintf(why, nwhy, "holds the outputs of an earlier run (%s%s; %d file%s): continue it with --restart "
                 "CHECKPOINT, choose another folder, or set output.overwrite = true to delete them first",
                 names, n > 4 ? ", ..." : "", n, n > 1 ? "s" : "");
        rc = 2;
    } else if (n > 0) {
        for (int i = 0; i < n && !rc; i++) {
            char path[IO_PATH_MAX + 300];
            snprintf(path, sizeof path, "%s/%s", dir, list[i]);
            if (remove(path) != 0 && errno != ENOENT) {
                snprintf(why, nwhy, "cannot delete %s (output.overwrite): %s", path, strerror(errno));
                rc = 1;
            }
        }
        *removed = rc ? 0 : n;
    }
    free_list(list, n);
    return rc;
}

/* Rank 0, a restart: delete the files a killed run left half written
 * (NAME.tmp, never read: the complete NAME is the previous version). */
static void remove_unfinished(const char *dir)
{
    int n;
    char **list = list_outputs(dir, &n);
    for (int i = 0; i < n; i++) {
        size_t len = strlen(list[i]);
        if (len < 4 || strcmp(list[i] + len - 4, ".tmp") != 0) continue;
        char path[IO_PATH_MAX + 300];
        snprintf(path, sizeof path, "%s/%s", dir, list[i]);
        remove(path);
    }
    free_list(list, n);
}

int io_outdir_open(io_outdir_t *o, const char *dir, int restart, int overwrite, const char *const *extra, char *why,
                   size_t nwhy, MPI_Comm comm)
{
    memset(o, 0, sizeof *o);
    extra_names = extra;
    o->lock_fd = -1;
    snprintf(o->dir, sizeof o->dir, "%s", dir);
    int rank, rc = 0, removed = 0;
    why[0] = 0;
    MPI_Comm_rank(comm, &rank);
    if (rank == 0) {
        if (mkdir_p(dir) != 0) {
            rc = errno == ENAMETOOLONG || errno == ENOTDIR ? 2 : 1;
            snprintf(why, nwhy, "cannot create the folder: %s", strerror(errno));
        } else if ((o->lock_fd = take_lock(dir, why, nwhy)) < 0) {
            rc = 2;
        } else if (!restart) {
            rc = earlier_outputs(dir, overwrite, &removed, why, nwhy);
        } else {
            remove_unfinished(dir);
        }
        if (!rc) {
            char path[IO_PATH_MAX + 16];
            io_outdir_path(o, "log.txt", path, sizeof path);
            o->log = fopen(path, restart ? "a" : "w");
            if (!o->log) {
                rc = 1;
                snprintf(why, nwhy, "cannot write %s: %s", path, strerror(errno));
            }
        }
    }
    /* every rank must take the same decision */
    MPI_Bcast(&rc, 1, MPI_INT, 0, comm);
    MPI_Bcast(why, (int)nwhy, MPI_CHAR, 0, comm);
    if (rc) return rc;
    char path[IO_PATH_MAX + 16];
    io_outdir_path(o, "log.txt", path, sizeof path);
    msg_set_log(o->log, path);
    if (removed) msg("output.overwrite: deleted %d file%s of an earlier run from %s\n", removed, removed > 1 ? "s" : "", dir);
    return 0;
}

void io_outdir_path(const io_outdir_t *o, const char *name, char *buf, size_t n)
{
    snprintf(buf, n, "%s/%s", o->dir, name);
}

void io_outdir_write_input(const io_outdir_t *o, const cfg_t *cfg)
{
    if (mpi_rank() != 0) return;
    char path[IO_PATH_MAX + 16], tmp[IO_PATH_MAX + 32];
    io_outdir_path(o, "input.ini", path, sizeof path);
    FILE *f = atomic_open(path, tmp, sizeof tmp);
    if (!f) return;
    cfg_write_resolved(cfg, f);
    atomic_commit(f, tmp, path);
}

/* Rank 0: delete the files of dir whose name is prefix + number + suffix
 * with number >= first (a restart: what the lost continuation wrote). */
void io_outdir_remove_numbered(const io_outdir_t *o, const char *prefix, const char *suffix, long first)
{
    if (mpi_rank() != 0) return;
    DIR *d = opendir(o->dir);
    struct dirent *e;
    const size_t np = strlen(prefix), ns = strlen(suffix);
    int removed = 0;
    while (d && (e = readdir(d))) {
        const char *name = e->d_name;
        size_t len = strlen(name);
        if (len <= np + ns || strncmp(name, prefix, np) != 0 || strcmp(name + len - ns, suffix) != 0) continue;
        char *end;
        long k = strtol(name + np, &end, 10);
        if (end != name + len - ns || end == name + np || k < first) continue;
        char path[IO_PATH_MAX + 300];
        snprintf(path, sizeof path, "%s/%s", o->dir, name);
        if (remove(path) == 0) removed++;
        else io_error("cannot delete %s: %s", path, strerror(errno));
    }
    if (d) closedir(d);
    if (removed) msg("restart: deleted %d file%s %s*%s numbered %ld and above (written after the checkpoint)\n", removed,
                     removed > 1 ? "s" : "", prefix, suffix, first);
}

int io_check_errors(MPI_Comm comm, char *why, size_t nwhy)
{
    int rank, size;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    /* the lowest rank that has an error, if any (one reduction per check) */
    int who = io_error_message()[0] ? rank : size;
    MPI_Allreduce(MPI_IN_PLACE, &who, 1, MPI_INT, MPI_MIN, comm);
    if (who == size) return 0;
    if (rank == who) snprintf(why, nwhy, "%s", io_error_message());
    MPI_Bcast(why, (int)nwhy, MPI_CHAR, who, comm);
    return 1;
}

void io_outdir_close(io_outdir_t *o)
{
    msg_set_log(NULL, NULL);
    if (o->log) {
        errno = 0;
        if (fflush(o->log) != 0 || ferror(o->log) || fclose(o->log) != 0) {
            char path[IO_PATH_MAX + 16];
            io_outdir_path(o, "log.txt", path, sizeof path);
            io_error("cannot write %s: %s", path, strerror(errno ? errno : EIO));
        }
    }
    o->log = NULL;
    if (o->lock_fd >= 0) close(o->lock_fd); /* releases the lock */
    o->lock_fd = -1;
}
