/* util.c — messages, fatal errors, allocation, timers. */
#define _POSIX_C_SOURCE 200809L
#include "util.h"

#include <errno.h>
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
void msg_set_log(FILE *f) { log_file = f; }

/* Print to `out` and, on rank 0, to the log file. */
static void print_tee(FILE *out, const char *prefix, const char *fmt, va_list ap)
{
    va_list ap2;
    va_copy(ap2, ap);
    fputs(prefix, out);
    vfprintf(out, fmt, ap);
    fflush(out);
    if (log_file) {
        fputs(prefix, log_file);
        vfprintf(log_file, fmt, ap2);
        fflush(log_file);
    }
    va_end(ap2);
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
            fflush(log_file);
        }
    }
    int init = 0, fin = 0;
    MPI_Initialized(&init);
    MPI_Finalized(&fin);
    if (init && !fin) {
        MPI_Barrier(MPI_COMM_WORLD);
        MPI_Finalize();
    }
    exit(1);
}

void die_local(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "error (rank %d): ", mpi_rank());
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
    fflush(stderr);
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

double wtime(void) { return MPI_Wtime(); }

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
