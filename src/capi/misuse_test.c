/* The misuse suite of the C API under MPI (issue 42): each case is a mistake a real code makes on
 * some of its ranks. Every rank must get an error from its next Panoptes call, naming the cause, within
 * 10 s, and no rank may hang (ctest's timeout is the hang detector); the database stays readable
 * (misuse_test.sh runs `panoptes info` on it).
 *   misuse_test CASE DIR     (2-4 ranks, rank 1 misbehaving; CASE as listed in main)                                        */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "panoptes.h"

enum { NX = 12, NY = 10, NZ = 8 };

static int rank, size, failures;
static double started;

static void fail(const char* what) {
  fprintf(stderr, "misuse_test: rank %d: FAIL: %s (last error: %s)\n", rank, what, panoptes_last_error());
  ++failures;
}

/* rc must be an error whose message contains `want`, within 10 s of the case's start. */
static void expect_error(int rc, const char* want, const char* what) {
  const double waited = MPI_Wtime() - started;
  if (rc == PANOPTES_OK) fail(what);
  else if (!strstr(panoptes_last_error(), want)) {
    fprintf(stderr, "misuse_test: rank %d: FAIL: %s: the message does not say \"%s\"\n", rank, what, want);
    ++failures;
  } else if (waited > 10) {
    fprintf(stderr, "misuse_test: rank %d: FAIL: %s: the error came after %.1f s\n", rank, what, waited);
    ++failures;
  } else {
    printf("misuse_test: rank %d: %s: error after %.2f s: %s\n", rank, what, waited, panoptes_last_error());
  }
}

static void expect_ok(int rc, const char* what) {
  if (rc != PANOPTES_OK) fail(what);
}

static char config[1024];

/* The usual set-up: 2 slabs along z, a ghost layer each side, one field T. */
static panoptes_session* start(const char* dir, const double origin_x, int dims_z) {
  snprintf(config, sizeof config,
           "[output]\ndir = \"%s\"\nmode = \"overwrite\"\n[image]\nwidth = 32\nheight = 32\n"
           "[rig]\nspec = \"fibonacci:3\"\n[schedule]\nevery_steps = 2\n[resources]\nmpi_timeout = 3\n"
           "[[task]]\nname = \"t\"\ntype = \"volume\"\nfield = \"T\"\n",
           dir);
  panoptes_session* s = NULL;
  expect_ok(panoptes_create(config, 0, PANOPTES_COMM_WORLD, &s), "create");
  const int k0 = NZ * rank / size, k1 = NZ * (rank + 1) / size;
  const int dims[3] = {NX, NY, dims_z}, offset[3] = {0, 0, k0}, extent[3] = {NX, NY, k1 - k0};
  const int glo[3] = {0, 0, rank > 0}, ghi[3] = {0, 0, rank + 1 < size};
  const double origin[3] = {origin_x, 0, 0}, spacing[3] = {1, 1, 1};
  expect_ok(panoptes_set_grid(s, dims, origin, spacing), "set_grid");
  expect_ok(panoptes_set_block(s, offset, extent, glo, ghi), "set_block");
  return s;
}

static double field[NX * NY * (NZ + 2)];
static long long kCount;  /* this rank's ghosted block: its slab and a ghost layer on each inner side */

static void bind(panoptes_session* s) {
  expect_ok(panoptes_set_field_n(s, "T", field, PANOPTES_FLOAT64, NULL, kCount), "set_field_n");
}

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  panoptes_set_error_output(PANOPTES_ERRORS_NONE);
  if (argc != 3 || size < 2 || size > 4) {
    if (rank == 0) fprintf(stderr, "usage: mpirun -np 2..4 misuse_test CASE DIR (rank 1 misbehaves)\n");
    MPI_Finalize();
    return 2;
  }
  for (int i = 0; i < NX * NY * (NZ + 2); ++i) field[i] = sin(0.3 * i);
  kCount = (long long)NX * NY * (NZ * (rank + 1) / size - NZ * rank / size + (rank > 0) + (rank + 1 < size));
  const char* c = argv[1];
  const char* dir = argv[2];
  int taken = 0;
  started = MPI_Wtime();
  if (!strcmp(c, "short_array")) {
    /* Rank 1 hands an array one plane short (ierr ignored, as codes do): every rank's next call fails,
     * naming rank 1; with the right array the run then goes on. */
    panoptes_session* s = start(dir, 0, NZ);
    bind(s);
    expect_ok(panoptes_process(s, 0, 0.0, &taken), "step 0");
    if (rank == 1) panoptes_set_field_n(s, "T", field, PANOPTES_FLOAT64, NULL, kCount - NX * NY);
    else bind(s);
    expect_error(panoptes_process(s, 1, 0.1, &taken), rank == 1 ? "field \"T\" is not bound" : "rank 1 refused process()",
                 "step 1 after rank 1's short array");
    bind(s);
    expect_ok(panoptes_process(s, 2, 0.2, &taken), "step 2 with the right array");
    if (!taken) fail("step 2 was not taken");
    expect_ok(panoptes_finalize(s), "finalize");
    panoptes_destroy(s);
  } else if (!strcmp(c, "grid_dims")) {
    /* The ranks declare different global grids: the first call names the dims. */
    panoptes_session* s = start(dir, 0, rank == 0 ? NZ : NZ + 2);
    bind(s);
    expect_error(panoptes_process(s, 0, 0.0, &taken), "grid dims z", "different grid dims");
    expect_error(panoptes_process(s, 1, 0.1, &taken), "grid dims z", "the next call");
    panoptes_destroy(s);
  } else if (!strcmp(c, "origin")) {
    /* A mismatched origin used to be ignored silently (rank 0's was used). */
    panoptes_session* s = start(dir, rank == 0 ? 0.0 : 1.0, NZ);
    bind(s);
    expect_error(panoptes_process(s, 0, 0.0, &taken), "grid origin x", "different origins");
    panoptes_destroy(s);
  } else if (!strcmp(c, "extra_snapshot")) {
    /* Rank 0 takes one snapshot more than rank 1: it used to hang, or end in "stopped by signal 5". */
    panoptes_session* s = start(dir, 0, NZ);
    bind(s);
    expect_ok(panoptes_process(s, 0, 0.0, &taken), "step 0");
    if (rank == 0) expect_error(panoptes_snapshot(s, 0.05), "out of step", "rank 0's extra snapshot");
    else expect_error(panoptes_process(s, 1, 0.1, &taken), "out of step", "rank 1's next step");
    expect_error(panoptes_finalize(s), "out of step", "finalize after the ranks fell out of step");
    panoptes_destroy(s);
  } else if (!strcmp(c, "skipped_step")) {
    /* Rank 1 skips one step's panoptes_process (a due one). */
    panoptes_session* s = start(dir, 0, NZ);
    bind(s);
    expect_ok(panoptes_process(s, 0, 0.0, &taken), "step 0");
    expect_ok(panoptes_process(s, 1, 0.1, &taken), "step 1");
    if (rank != 1) expect_error(panoptes_process(s, 2, 0.2, &taken), "out of step", "the others at step 2");
    expect_error(panoptes_process(s, 3, 0.3, &taken), "out of step", "step 3");
    panoptes_destroy(s);
  } else if (!strcmp(c, "times")) {
    /* The ranks pass different times for the same step (an every_time schedule would disagree on due). */
    panoptes_session* s = start(dir, 0, NZ);
    bind(s);
    expect_ok(panoptes_process(s, 0, 0.0, &taken), "step 0");
    expect_error(panoptes_process(s, 1, rank == 0 ? 0.1 : 0.1000001, &taken), "different times", "different times");
    panoptes_destroy(s);
  } else if (!strcmp(c, "config")) {
    /* One rank's configuration is refused: every rank's panoptes_create fails. */
    panoptes_session* s = NULL;
    const int rc = panoptes_create(rank == 1 ? "[image]\nwidth = -3\n" : "[[task]]\nname = \"t\"\nfield = \"T\"\n", 0,
                                   PANOPTES_COMM_WORLD, &s);
    expect_error(rc, rank == 1 ? "image.width" : "rank 1 failed", "create with rank 1's bad configuration");
    if (s) fail("a session was returned");
  } else if (!strcmp(c, "missing_rank")) {
    /* Rank 1 stops calling Panoptes and waits elsewhere: rank 0 reports it within mpi_timeout (3 s) and
     * goes on; rank 1's next call meets rank 0's pending agreement and learns it is out of step. */
    panoptes_session* s = start(dir, 0, NZ);
    bind(s);
    expect_ok(panoptes_process(s, 0, 0.0, &taken), "step 0");
    if (rank != 1) expect_error(panoptes_process(s, 1, 0.1, &taken), "did not come", "the others waiting for rank 1");
    MPI_Barrier(MPI_COMM_WORLD);  /* rank 1 waits here, in the code's own collective */
    if (rank == 1) expect_error(panoptes_process(s, 2, 0.2, &taken), "out of step", "rank 1 after skipping");
    expect_error(panoptes_finalize(s), "the session stopped", "finalize");
    panoptes_destroy(s);
  } else {
    if (rank == 0) fprintf(stderr, "misuse_test: unknown case %s\n", c);
    MPI_Finalize();
    return 2;
  }
  int all = 0;
  MPI_Allreduce(&failures, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0) printf("misuse_test %s: %s\n", c, all ? "FAILED" : "every rank got its error in time");
  MPI_Finalize();
  return all ? 1 : 0;
}
