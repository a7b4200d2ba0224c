/* util.h — small helpers shared by every module: messages, fatal errors,
 * aligned allocation, timers and a JSON writer for summary.json. */
#ifndef IBMDEM_UTIL_H
#define IBMDEM_UTIL_H

#include <stddef.h>
#include <stdio.h>

#define IBMDEM_VERSION "0.1.0"

/* Also send what msg, warn and die print on rank 0 to this file (the run's
 * log); NULL stops it. */
void msg_set_log(FILE *f);
/* Print on rank 0 only (stdout). */
void msg(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Print on rank 0 to stderr with a "warning: " prefix. */
void warn(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Fatal error detected by every rank at once (collective): rank 0 prints,
 * everybody finalises MPI and exits with status 1. */
void die(const char *fmt, ...) __attribute__((format(printf, 1, 2), noreturn));
/* Fatal error detected by one rank only: prints and calls MPI_Abort. */
void die_local(const char *fmt, ...) __attribute__((format(printf, 1, 2), noreturn));

/* 64-byte aligned, zeroed allocation; dies on failure.  Free with free(). */
void *xcalloc(size_t n, size_t size);

double wtime(void);
/* CPU time of the whole process (all threads), s: the benchmarks on a shared machine. */
double cputime(void);
/* Peak resident set size of this process in bytes (from /proc/self/status). */
long peak_rss_bytes(void);

/* Bytes of memory of this machine (INFINITY if unknown): input that needs
 * more is refused before the run. */
double physical_memory_bytes(void);

int mpi_rank(void);
int mpi_size(void);

/* Create a directory and its parents (like mkdir -p); 0 on success. */
int mkdir_p(const char *path);

#endif
