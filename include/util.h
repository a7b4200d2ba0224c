/* util.h — small helpers shared by every module: messages, fatal errors,
 * aligned allocation, timers and a JSON writer for summary.json. */
#ifndef IBMDEM_UTIL_H
#define IBMDEM_UTIL_H

#include <stddef.h>
#include <stdio.h>

#define IBMDEM_VERSION "0.1.0"

/* Also send what msg, warn and die print on rank 0 to this file (the run's
 * log, named `path` in error messages); NULL stops it.  A failed write to it
 * is an I/O error (io_error). */
void msg_set_log(FILE *f, const char *path);
/* Flush the log and make it durable (fsync); a failure is an I/O error. */
void msg_sync_log(void);
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

/* Wall-clock seconds (MPI_Wtime); the calling thread's CPU seconds in a build with
 * EXTRA_CFLAGS=-DIBMDEM_CPU_TIMERS (src/core/util.c). */
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

/* ---- I/O errors ------------------------------------------------------------
 * A write that fails (a full disk, a quota, a lost file system) must not be
 * silent: the writer records it with io_error (the first one is kept, with
 * its path and reason) and carries on with what it must still do together
 * with the other ranks; the run driver checks after every step
 * (io_check_errors, io.h) and stops with exit status 1. */
void io_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* The first error recorded on this rank ("" if none). */
const char *io_error_message(void);
/* Forget it (after it was reported). */
void io_error_clear(void);
/* A failed write to a file written collectively by every rank (parallel
 * HDF5): one rank alone; parallel HDF5 cannot go on from there (its ranks
 * would wait for each other forever).  On one rank, io_error; on more, the
 * job stops at once (exit status 1) with the message and the recovery note. */
void io_error_collective(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* What to say when the run stops that way (the newest checkpoint). */
void io_recovery_note(const char *text);

/* An HDF5 file failed to close: HDF5 1.10 keeps it half closed and crashes
 * when it closes it again at MPI_Finalize.  After this call, die and
 * mpi_finish leave without MPI_Finalize (every rank, after a barrier). */
void mpi_finalize_unsafe(void);
/* The end of the program: MPI_Finalize (when it is safe) and exit(status). */
void mpi_finish(int status) __attribute__((noreturn));

/* Write a file whole or not at all: atomic_open opens PATH.tmp (its name into
 * tmp, of size ntmp) for writing; atomic_commit checks every write, flushes
 * and fsyncs it, closes it and renames it to PATH (readers see the old file or
 * the new one, never a part).  atomic_commit returns 0, or -1 after io_error
 * (the temporary file removed); atomic_open returns NULL after io_error. */
FILE *atomic_open(const char *path, char *tmp, size_t ntmp);
int atomic_commit(FILE *f, const char *tmp, const char *path);
/* fsync a directory (its entries: files created, renamed or removed in it),
 * or a closed file; 0 or -1 after io_error. */
int fsync_dir(const char *dir);
int fsync_path(const char *path);
/* fflush, check and fsync an open stream; 0 or -1 after io_error naming path. */
int sync_stream(FILE *f, const char *path);

/* ---- fault injection (tests) ------------------------------------------------
 * IBMDEM_FAULT=NAME[@STEP] in the environment makes the program _exit(86) on
 * every rank when it reaches the point NAME (at step STEP, or at the first
 * time without @STEP): a kill at a chosen moment, e.g. inside a checkpoint
 * write.  The points are listed in docs/user-guide.md ("Outputs: what is
 * promised"). */
void fault_point(const char *name, long step);
/* Non-zero if IBMDEM_FAULT names this point and step (once): the caller
 * prepares the damage and calls fault_exit. */
int fault_armed(const char *name, long step);
void fault_exit(const char *name, long step) __attribute__((noreturn));

#endif
