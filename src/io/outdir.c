/* outdir.c — the output folder of a run: created on rank 0, with a log file
 * that receives everything rank 0 prints and the resolved input. */
#include <errno.h>
#include <string.h>

#include "io.h"
#include "util.h"

void io_outdir_open(io_outdir_t *o, const char *dir, int append, MPI_Comm comm)
{
    memset(o, 0, sizeof *o);
    snprintf(o->dir, sizeof o->dir, "%s", dir);
    int rank, err = 0;
    char why[IO_PATH_MAX + 256] = "";
    MPI_Comm_rank(comm, &rank);
    if (rank == 0) {
        if (mkdir_p(dir) != 0) {
            err = 1;
            snprintf(why, sizeof why, "%s", strerror(errno));
        } else {
            char path[IO_PATH_MAX + 16];
            io_outdir_path(o, "log.txt", path, sizeof path);
            o->log = fopen(path, append ? "a" : "w");
            if (!o->log) {
                err = 1;
                snprintf(why, sizeof why, "cannot write log.txt: %s", strerror(errno));
            }
        }
    }
    /* every rank must take the same decision */
    MPI_Bcast(&err, 1, MPI_INT, 0, comm);
    MPI_Bcast(why, sizeof why, MPI_CHAR, 0, comm);
    if (err) die("output folder %s: %s", dir, why);
    msg_set_log(o->log);
}

void io_outdir_path(const io_outdir_t *o, const char *name, char *buf, size_t n)
{
    snprintf(buf, n, "%s/%s", o->dir, name);
}

void io_outdir_write_input(const io_outdir_t *o, const cfg_t *cfg)
{
    if (mpi_rank() != 0) return;
    char path[IO_PATH_MAX + 16];
    io_outdir_path(o, "input.ini", path, sizeof path);
    FILE *f = fopen(path, "w");
    if (!f) {
        warn("cannot write %s: %s\n", path, strerror(errno));
        return;
    }
    cfg_write_resolved(cfg, f);
    fclose(f);
}

void io_outdir_close(io_outdir_t *o)
{
    msg_set_log(NULL);
    if (o->log) fclose(o->log);
    o->log = NULL;
}
