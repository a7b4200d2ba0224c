/* util.c — messages, fatal errors, allocation, timers. */
#define _POSIX_C_SOURCE 200809L
#include "util.h"

#include <errno.h>
#include <fcntl.h>
#include <mpi.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>
#include <math.h>

int mpi_rank(void)
{
    int init = 0, r = 0;
    MPI_Initialized(&init);
    if (init) MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}

int mpi_size(void)
{
    int init = 0, s = 1;
    MPI_Initialized(&init);
    if (init) MPI_Comm_size(MPI_COMM_WORLD, &s);
    return s;
}

static FILE *log_file = NULL;
static char log_path[4096];

void msg_set_log(FILE *f, const char *path)
{
    log_file = f;
    snprintf(log_path, sizeof log_path, "%s", f && path ? path : "");
}

/* The log failed: one error, then nothing more is written to it. */
static void log_failed(void)
{
    io_error("cannot write %s: %s", log_path, strerror(errno ? errno : EIO));
    log_file = NULL;
}

/* Print to `out` and, on rank 0, to the log file. */
static void print_tee(FILE *out, const char *prefix, const char *fmt, va_list ap)
{
    va_list ap2;
    va_copy(ap2, ap);
    fputs(prefix, out);
    vfprintf(out, fmt, ap);
    fflush(out);
    if (log_file) {
        errno = 0;
        if (fputs(prefix, log_file) < 0 || vfprintf(log_file, fmt, ap2) < 0 || fflush(log_file) != 0 ||
            ferror(log_file))
            log_failed();
    }
    va_end(ap2);
}

void msg_sync_log(void)
{
    if (log_file && sync_stream(log_file, log_path)) log_file = NULL;
}

void msg(const char *fmt, ...)
{
    if (mpi_rank() != 0) return;
    va_list ap;
    va_start(ap, fmt);
    print_tee(stdout, "", fmt, ap);
    va_end(ap);
}

void warn(const char *fmt, ...)
{
    if (mpi_rank() != 0) return;
    va_list ap;
    va_start(ap, fmt);
    print_tee(stderr, "warning: ", fmt, ap);
    va_end(ap);
}

void die(const char *fmt, ...)
{
    if (mpi_rank() == 0) {
        va_list ap;
        va_start(ap, fmt);
        print_tee(stderr, "error: ", fmt, ap);
        va_end(ap);
        fputs("\n", stderr);
        if (log_file) {
            fputs("\n", log_file);
            sync_stream(log_file, log_path);
        }
    }
    mpi_finish(1);
}

static int finalize_unsafe = 0;
void mpi_finalize_unsafe(void) { finalize_unsafe = 1; }

void mpi_finish(int status)
{
    int init = 0, fin = 0;
    MPI_Initialized(&init);
    MPI_Finalized(&fin);
    if (init && !fin) {
        int unsafe = finalize_unsafe;
        MPI_Allreduce(MPI_IN_PLACE, &unsafe, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
        if (unsafe) {
            fflush(NULL);
            MPI_Barrier(MPI_COMM_WORLD);
            _exit(status);
        }
        MPI_Finalize();
    }
    exit(status);
}

void die_local(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char text[2048];
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    fprintf(stderr, "error (rank %d): %s\n", mpi_rank(), text);
    fflush(stderr);
    if (log_file) {
        fprintf(log_file, "error (rank %d): %s\n", mpi_rank(), text);
        fflush(log_file);
    }
    int init = 0;
    MPI_Initialized(&init);
    if (init) MPI_Abort(MPI_COMM_WORLD, 1);
    exit(1);
}

void *xcalloc(size_t n, size_t size)
{
    if (size > 0 && n > SIZE_MAX / size) die_local("out of memory (%zu × %zu bytes)", n, size);
    size_t bytes = n * size;
    if (bytes == 0) bytes = 64;
    void *p = NULL;
    if (posix_memalign(&p, 64, bytes) != 0 || !p) die_local("out of memory (%zu bytes)", bytes);
    memset(p, 0, bytes);
    return p;
}

#ifdef IBMDEM_CPU_TIMERS
/* A measurement build (make BUILD=build-cpu EXTRA_CFLAGS=-DIBMDEM_CPU_TIMERS): the
 * timers of the run (the cost.* of summary.json, time.wall_limit) read the
 * calling thread's CPU clock, which other jobs on a shared machine disturb
 * far less than the wall clock (one rank, no threads: the process's CPU time). */
double wtime(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
#else
double wtime(void) { return MPI_Wtime(); }
#endif

double cputime(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

long peak_rss_bytes(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return -1;
    char line[256];
    long kb = -1;
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, "VmHWM:", 6)) {
            kb = strtol(line + 6, NULL, 10);
            break;
        }
    fclose(f);
    return kb < 0 ? -1 : kb * 1024;
}

double physical_memory_bytes(void)
{
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? (double)pages * (double)size : INFINITY;
}

int mkdir_p(const char *path)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", path);
    size_t len = strlen(buf);
    if (len && buf[len - 1] == '/') buf[len - 1] = 0;
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/') continue;
        *p = 0;
        if (mkdir(buf, 0755) != 0 && errno != EEXIST) return -1;
        *p = '/';
    }
    if (mkdir(buf, 0755) != 0 && errno != EEXIST) return -1;
    return 0;
}

/* ---- I/O errors ------------------------------------------------------------ */

static char io_err[1024];

void io_error(const char *fmt, ...)
{
    if (io_err[0]) return; /* the first one is the cause */
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(io_err, sizeof io_err, fmt, ap);
    va_end(ap);
    if (!io_err[0]) snprintf(io_err, sizeof io_err, "I/O error");
}

const char *io_error_message(void) { return io_err; }

static char recovery[4200];
void io_recovery_note(const char *text) { snprintf(recovery, sizeof recovery, "%s", text ? text : ""); }

void io_error_collective(const char *fmt, ...)
{
    char text[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    io_error("%s", text);
    if (mpi_size() > 1)
        die_local("%s\n  parallel HDF5 cannot go on after a failed write on one rank: every rank stops now%s%s", text,
                  recovery[0] ? "\n  " : "", recovery);
}
void io_error_clear(void) { io_err[0] = 0; }

int sync_stream(FILE *f, const char *path)
{
    errno = 0;
    if (fflush(f) != 0 || ferror(f) || fsync(fileno(f)) != 0) {
        io_error("cannot write %s: %s", path, strerror(errno ? errno : EIO));
        return -1;
    }
    return 0;
}

FILE *atomic_open(const char *path, char *tmp, size_t ntmp)
{
    if ((size_t)snprintf(tmp, ntmp, "%s.tmp", path) >= ntmp) {
        io_error("cannot write %s: %s", path, strerror(ENAMETOOLONG));
        return NULL;
    }
    FILE *f = fopen(tmp, "w");
    if (!f) io_error("cannot write %s: %s", tmp, strerror(errno));
    return f;
}

int atomic_commit(FILE *f, const char *tmp, const char *path)
{
    if (!f) return -1;
    int rc = sync_stream(f, tmp);
    errno = 0;
    if (fclose(f) != 0 && rc == 0) {
        io_error("cannot write %s: %s", tmp, strerror(errno ? errno : EIO));
        rc = -1;
    }
    if (rc == 0 && rename(tmp, path) != 0) {
        io_error("cannot rename %s to %s: %s", tmp, path, strerror(errno));
        rc = -1;
    }
    if (rc) remove(tmp);
    return rc;
}

int fsync_path(const char *path)
{
    int fd = open(path, O_RDONLY);
    if (fd < 0 || fsync(fd) != 0) {
        io_error("cannot sync %s: %s", path, strerror(errno));
        if (fd >= 0) close(fd);
        return -1;
    }
    close(fd);
    return 0;
}

int fsync_dir(const char *dir) { return fsync_path(dir); }

/* ---- fault injection (tests) ------------------------------------------------ */

int fault_armed(const char *name, long step)
{
    static int read = 0, any_step = 0, fired = 0;
    static char point[64];
    static long at = -1;
    if (!read) {
        read = 1;
        const char *e = getenv("IBMDEM_FAULT");
        if (e && *e) {
            snprintf(point, sizeof point, "%s", e);
            char *s = strchr(point, '@');
            if (s) {
                *s = 0;
                at = strtol(s + 1, NULL, 10);
            } else {
                any_step = 1;
            }
        }
    }
    if (!point[0] || fired || strcmp(point, name) != 0) return 0;
    if (!any_step && step != at) return 0;
    fired = 1;
    return 1;
}

void fault_exit(const char *name, long step)
{
    fprintf(stderr, "IBMDEM_FAULT: exit at %s (step %ld)\n", name, step);
    fflush(stderr);
    _exit(86);
}

void fault_point(const char *name, long step)
{
    if (fault_armed(name, step)) fault_exit(name, step);
}
