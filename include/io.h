/* io.h — everything a run writes or reads besides the case file.
 *
 * One job per file in src/io/:
 *   outdir.c      the output folder, its log file and the resolved input
 *   series.c      the time series of diagnostics (CSV, one row per output step)
 *   h5.c          parallel HDF5: grid fields as x-slab hyperslabs, attributes
 *   snapshot.c    field snapshots (one HDF5 file each) and the XDMF index for ParaView
 *   checkpoint.c  checkpoint files (atomic write, header, pruning) and the input fingerprint
 *   summary.c     summary.json, the machine-readable results of a run
 *   progress.c    the progress line on a terminal
 *
 * Every function is collective over the grid's communicator unless it says
 * "rank 0": then only rank 0 does the work and the other ranks return at once.
 */
#ifndef IBMDEM_IO_H
#define IBMDEM_IO_H

#include <hdf5.h>
#include <stdint.h>
#include <stdio.h>

#include "config.h"
#include "grid.h"

#define IO_PATH_MAX 4096

/* ---- output folder (outdir.c) --------------------------------------------- */

typedef struct {
    char dir[IO_PATH_MAX];
    FILE *log;   /* rank 0: DIR/log.txt */
    int lock_fd; /* rank 0: DIR/.ibmdem.lock, held for the run */
} io_outdir_t;

/* Open the output folder of a run (collective): create DIR and its parents,
 * take its lock (one run at a time in a folder), and for a new run (restart
 * = 0) check that it holds no output of an earlier run — the files ibmdem
 * writes, and the names of `extra` (NULL-terminated, may be NULL) — or
 * delete those (overwrite); open DIR/log.txt (appended to on a restart) and send to it
 * everything rank 0 prints with msg, warn and die.  Returns 0, or on every
 * rank 2 (refused: another run holds the folder, earlier outputs, a path the
 * system refuses) or 1 (a system error), with the reason in why. */
int io_outdir_open(io_outdir_t *o, const char *dir, int restart, int overwrite, const char *const *extra, char *why,
                   size_t nwhy, MPI_Comm comm);
/* "DIR/name" into buf. */
void io_outdir_path(const io_outdir_t *o, const char *name, char *buf, size_t n);
/* Rank 0: DIR/input.ini = the resolved input (cfg_write_resolved). */
void io_outdir_write_input(const io_outdir_t *o, const cfg_t *cfg);
/* Rank 0: delete DIR/<prefix><number><suffix> for every number >= first
 * (on a restart, the files the lost continuation wrote after the checkpoint). */
void io_outdir_remove_numbered(const io_outdir_t *o, const char *prefix, const char *suffix, long first);
/* Collective: 1 on every rank if any rank recorded an I/O error (io_error,
 * util.h), with its message in why; 0 otherwise. */
int io_check_errors(MPI_Comm comm, char *why, size_t nwhy);
/* Close the log and release the lock. */
void io_outdir_close(io_outdir_t *o);

/* ---- time series (series.c) ---------------------------------------------- */

typedef struct io_series io_series_t;

/* A restart's record of a series (from the checkpoint): the restart step,
 * the step of the last row before the checkpoint (-1: none) and the hash of
 * the file up to that row (has_hash = 0: not known). */
typedef struct {
    long step, last_row;
    uint64_t hash;
    int has_hash;
} io_series_resume_t;

/* Collective; rank 0 writes PATH, a CSV file with a header line of the `ncol`
 * column names; column 0 must be "step".  r == NULL: a new file.  Otherwise
 * (a restart) the existing PATH is continued: its rows with step <= r->step
 * are kept, and must be exactly those the run had written when it wrote the
 * checkpoint (the last one of step r->last_row, the hash r->hash); the rest
 * (the lost continuation, a row cut by a crash) is cut off.  A file with
 * other columns or other rows stops the run; a missing file starts anew
 * (with a warning). */
io_series_t *io_series_open(const char *path, int ncol, const char *const *names, const io_series_resume_t *r);
/* Rank 0: one row of ncol values (integers are written without decimals). */
void io_series_row(io_series_t *s, const double *values);
/* Step of the last row written (-1: none). */
long io_series_last_step(const io_series_t *s);
/* Rank 0: hash of the file up to its last row of step <= `step` (the rows a
 * checkpoint of that step follows: the last step's, or those before it). */
uint64_t io_series_hash(const io_series_t *s, long step);
/* Rank 0: flush and fsync every open series (before a checkpoint). */
void io_series_sync_all(void);
void io_series_close(io_series_t *s);

/* ---- parallel HDF5 (h5.c) -------------------------------------------------- */

/* Create (truncate) / open read-only an HDF5 file with the MPI-IO driver.
 * io_h5_create stops the run on failure; io_h5_open returns a negative id.
 * The writers below record a failed write as an I/O error (io_error) and
 * go on, so that every rank makes the same collective calls. */
hid_t io_h5_create(const char *path, MPI_Comm comm);
/* The same with a file-access property list of the caller's (MPI-IO). */
hid_t io_h5_create_with(const char *path, MPI_Comm comm, hid_t fapl);
hid_t io_h5_open(const char *path, MPI_Comm comm);
/* Close; a file opened for writing is first flushed to the disk (fsync). */
void io_h5_close(hid_t file);
/* Collective: 1 if a floating-point dataset of the file holds a NaN or an
 * infinity (its path, e.g. "/fluid/u", into where), else 0.  Each rank reads
 * a share of every dataset. */
int io_h5_check_finite(hid_t file, MPI_Comm comm, char *where, size_t n);

/* The interior of a grid field (i = 0..nx-1, j = 0..ny-1, k = 0..nz-1, no
 * ghosts) as dataset `name` of shape [nx][ny][nz] — the memory order, k
 * fastest — every rank writing its x-slab collectively.  The values are
 * copied bit for bit: this is the checkpoint layout.  For a face variable,
 * index i is the face on the high side of cell i (grid.h). */
void io_h5_write_field(hid_t loc, const char *name, const grid_t *g, const double *f);
/* Read such a dataset into the interior of f (ghosts untouched).  Returns 0,
 * or -1 (on every rank) if it is missing or its shape is not the grid's. */
int io_h5_read_field(hid_t loc, const char *name, const grid_t *g, double *f);

/* A cell quantity of ncomp components given on each rank's slab as
 * buf[((k*ny + j)*nxl + i)*ncomp + c], written as dataset [nz][ny][nx] (or
 * [nz][ny][nx][ncomp]): x fastest, the order XDMF and ParaView expect. */
void io_h5_write_cells_xfast(hid_t loc, const char *name, const grid_t *g, int ncomp, const double *buf);

/* Small arrays and attributes: every rank passes the same values. */
void io_h5_write_array(hid_t loc, const char *name, long n, const double *v);
/* A row-major [n][m] array (e.g. particle positions [n][3]). */
void io_h5_write_matrix(hid_t loc, const char *name, long n, int m, const double *v);
/* Returns the number of values read (<= nmax; n×m for a matrix), or -1 if missing. */
long io_h5_read_array(hid_t loc, const char *name, long nmax, double *v);
/* A sphere packing file (the DEM's layout: datasets position [n][3] and
 * radius [n], optional others): 1 if path names an HDF5 file (.h5, .hdf5). */
int io_is_h5_path(const char *path);
/* Opens it read-only and returns the file with *n the number of spheres;
 * a file that cannot be opened or lacks position/radius stops the run with
 * cfg_fail(cfg, section, key, ...). */
hid_t io_h5_open_packing(cfg_t *cfg, const char *section, const char *key, const char *path, long *n);
void io_h5_write_text(hid_t loc, const char *name, const char *text);
char *io_h5_read_text(hid_t loc, const char *name); /* malloc'd; NULL if missing */
void io_h5_attr_double(hid_t loc, const char *name, double v);
void io_h5_attr_long(hid_t loc, const char *name, long v);
void io_h5_attr_string(hid_t loc, const char *name, const char *v);
/* Return 0, or -1 if the attribute is missing. */
int io_h5_get_attr_double(hid_t loc, const char *name, double *v);
int io_h5_get_attr_long(hid_t loc, const char *name, long *v);
/* A 64-bit hash known to rank 0 (sent to the others), as 16 hex digits. */
void io_h5_attr_hash(hid_t loc, const char *name, uint64_t h, MPI_Comm comm);
int io_h5_get_attr_hash(hid_t loc, const char *name, uint64_t *h);

/* ---- field snapshots + XDMF (snapshot.c) ------------------------------------- */

typedef struct io_snapshots io_snapshots_t;

/* Snapshots of grid `g` into DIR/fields_NNNNN.h5, indexed by DIR/fields.xmf.
 * `first` is the index of the next snapshot (0 for a new run; a restart
 * passes the count stored in the checkpoint, and the entries of fields.xmf
 * before it are kept). */
io_snapshots_t *io_snapshots_create(const grid_t *g, const char *dir, int first);
/* Start the next snapshot: creates its file with the mesh (cell faces x, y, z;
 * a 2-D grid is written as one cell in z, of the smallest in-plane width). */
void io_snapshot_begin(io_snapshots_t *s, double time, long step);
/* A cell-centred scalar grid field. */
void io_snapshot_cell_scalar(io_snapshots_t *s, const char *name, const double *f);
/* A staggered vector (u[d] on the faces normal to d; u[2] may be NULL in 2-D),
 * interpolated to the cell centres: the average of the two faces of the cell,
 * which is linear interpolation since a centre is midway between its faces.
 * The ghost faces must be valid (boundary conditions applied). */
void io_snapshot_face_vector(io_snapshots_t *s, const char *name, double *const u[3]);
/* Close the file and rewrite DIR/fields.xmf (rank 0), so the index is valid
 * whenever the run stops. */
void io_snapshot_end(io_snapshots_t *s);
int io_snapshots_count(const io_snapshots_t *s);
/* Rank 0: rewrite DIR/fields.xmf now (a restart: the snapshots before `first`). */
void io_snapshots_write_index(const io_snapshots_t *s);
void io_snapshots_free(io_snapshots_t *s);

/* ---- checkpoints (checkpoint.c) ---------------------------------------------- */

#define IO_CHECKPOINT_FORMAT 1

typedef struct {
    double time;
    long step;
    uint64_t fingerprint; /* io_input_fingerprint of the resolved input */
    int nranks;           /* rank count of the run that wrote it (exactness needs the same) */
    char *input;          /* the resolved input text (malloc'd by io_checkpoint_open) */
} io_checkpoint_header_t;

/* Start DIR/checkpoint_SSSSSSSS.h5 (S = step): written to a temporary name
 * and renamed by io_checkpoint_end, so a run killed while writing leaves the
 * previous checkpoint intact.  The header goes in root attributes. */
hid_t io_checkpoint_begin(const char *dir, const io_checkpoint_header_t *h, MPI_Comm comm);
/* Close (fsync), and if no rank had an I/O error rename it to its final name
 * and fsync the folder: only then is the checkpoint written (its path into
 * `path`, may be NULL); rank 0 then deletes the oldest checkpoint_*.h5 of DIR
 * beyond the `keep` newest (keep <= 0: keep all).  Returns 0, or -1 on every
 * rank after an I/O error (io_error: the temporary file is deleted, the
 * previous checkpoint stays the newest). */
int io_checkpoint_end(hid_t file, const char *dir, long step, int keep, char *path, size_t npath, MPI_Comm comm);
/* Rank 0: delete the oldest checkpoint_*.h5 of DIR beyond the `keep` newest
 * (keep <= 0: none). */
void io_checkpoint_prune(const char *dir, int keep);
/* Open a checkpoint, read its header and check that every floating-point
 * dataset is finite.  Returns the file (close with io_h5_close), or stops
 * the run with a message naming the file (and the dataset) if it cannot be
 * read, is not an ibmdem checkpoint or holds a NaN or an infinity. */
hid_t io_checkpoint_open(const char *path, io_checkpoint_header_t *h, MPI_Comm comm);
void io_checkpoint_header_free(io_checkpoint_header_t *h);

/* FNV-1a 64-bit hash of the resolved input (text of cfg_write_resolved),
 * over its "section.key = value" lines with comments and the origin notes
 * removed, skipping the keys that `skip` matches (section.key, or section.*
 * for a whole section): the run-control keys, which a restart may change. */
uint64_t io_input_fingerprint(const char *resolved, const char *const *skip);
/* Call fn for every key (section.key) whose value differs between two
 * resolved inputs (missing on one side counts), except the skipped ones;
 * returns the number of differences. */
int io_input_diff(const char *a, const char *b, const char *const *skip,
                  void (*fn)(const char *key, const char *va, const char *vb, void *ctx), void *ctx);
/* The resolved input as a string (malloc'd). */
char *io_resolved_input(const cfg_t *cfg);

/* ---- summary.json (summary.c) --------------------------------------------------- */

typedef struct io_summary io_summary_t;

/* Keys are dotted paths ("fluid.kinetic_energy"); each dot opens a nested
 * object.  Setting a key again replaces its value; insertion order is kept.
 * Non-finite numbers are written as null (JSON has no NaN). */
io_summary_t *io_summary_create(void);
void io_summary_string(io_summary_t *s, const char *key, const char *v);
void io_summary_double(io_summary_t *s, const char *key, double v);
void io_summary_long(io_summary_t *s, const char *key, long v);
void io_summary_bool(io_summary_t *s, const char *key, int v);
/* Rank 0: write the JSON object to PATH (whole or not at all: a temporary
 * file renamed); returns 0, or -1 after io_error. */
int io_summary_write(const io_summary_t *s, const char *path);
void io_summary_free(io_summary_t *s);

/* ---- progress line (progress.c) -------------------------------------------------- */

typedef struct {
    int active;        /* rank 0 and stdout is a terminal */
    double wall0;      /* wall time at the start */
    double frac0;      /* progress at the start (a restart does not start at 0) */
    long step0;
    double last;       /* wall time of the last refresh */
    int shown;         /* length of the line on screen (0: none) */
} io_progress_t;

/* The line (simulated time, percent, steps/s, ETA) is redrawn in place with
 * \r at most every 0.25 s, on rank 0.  mode 0 (auto): only when stdout is a
 * terminal and the program was not started by mpirun — Open MPI gives its
 * processes a pseudo-terminal whatever mpirun's own output is, so isatty
 * cannot tell there; 1: always; 2: never. */
void io_progress_start(io_progress_t *p, double frac, long step, int mode);
/* frac = progress in [0, 1] (the largest of the fractions of t_end,
 * max_steps and wall_limit). */
void io_progress_update(io_progress_t *p, double time, long step, double frac);
/* Erase the line (before other output, and at the end). */
void io_progress_clear(io_progress_t *p);

#endif
