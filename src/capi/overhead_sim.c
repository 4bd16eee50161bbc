/* A CPU-bound "simulation" for capi.overhead_vs_os (overhead_test.py): 3-D diffusion on one thread per
 * rank (as many MPI codes run), 1-D decomposition along z with halo planes, instrumented through the C
 * API. With "off" every panoptes_* call is skipped, so the same binary (same libraries loaded, same
 * MPI start-up) measures the code's own CPU time; the driver compares the difference with the line
 * panoptes_finalize prints. The halo planes are exchanged every HALO_EVERY steps only (the snapshot
 * steps), and the code waits for its neighbours sleeping, not in MPI's busy wait: on a loaded machine
 * the ranks drift apart and a spinning wait turned the drift into 10-20 % of the code's CPU time, a
 * different amount in every run, which the comparison of two runs cannot tell from overhead.
 * ALPHA (default 0.1) is the diffusion number: insitu_overhead_bench takes a smaller one for its long
 * run, so that its snapshots see the field of a 5,000-step run at 0.1 (the march's cost follows how far
 * the blob has spread).
 *   overhead_sim CONFIG on|off NX NY NZ STEPS HALO_EVERY [ALPHA]                                     */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "panoptes.h"

static void check(int rc) {
  if (rc != PANOPTES_OK) {
    fprintf(stderr, "overhead_sim: panoptes: %s\n", panoptes_last_error());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
}

/* Completes the requests polling every 0.1 ms, sleeping in between. */
static void wait_sleeping(int n, MPI_Request* requests) {
  int done = 0;
  const struct timespec pause = {0, 100000};
  for (;;) {
    MPI_Testall(n, requests, &done, MPI_STATUSES_IGNORE);
    if (done) return;
    nanosleep(&pause, NULL);
  }
}

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  if ((argc != 8 && argc != 9) || (strcmp(argv[2], "on") != 0 && strcmp(argv[2], "off") != 0)) {
    fprintf(stderr, "usage: overhead_sim CONFIG on|off NX NY NZ STEPS HALO_EVERY [ALPHA]\n");
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  const int viz_on = strcmp(argv[2], "on") == 0;
  const int NX = atoi(argv[3]), NY = atoi(argv[4]), NZ = atoi(argv[5]), steps = atoi(argv[6]);
  const int halo_every = atoi(argv[7]) > 0 ? atoi(argv[7]) : 1;
  int rank, size;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int k0 = NZ * rank / size, k1 = NZ * (rank + 1) / size, nzl = k1 - k0;
  const size_t plane = (size_t)NX * NY;
  double* u = calloc(plane * (nzl + 2), sizeof(double));
  double* v = calloc(plane * (nzl + 2), sizeof(double));
  if (!u || !v) MPI_Abort(MPI_COMM_WORLD, 3);
  for (int k = 0; k < nzl; ++k)
    for (int j = 0; j < NY; ++j)
      for (int i = 0; i < NX; ++i) {
        const double x = i - 0.4 * NX, y = j - 0.5 * NY, z = k + k0 - 0.5 * NZ, r = 0.15 * NX;
        u[plane * (k + 1) + (size_t)j * NX + i] = x * x + y * y + z * z < r * r ? 1.0 : 0.0;
      }
  const int up = rank + 1 < size ? rank + 1 : MPI_PROC_NULL, down = rank > 0 ? rank - 1 : MPI_PROC_NULL;
  const double alpha = argc == 9 ? atof(argv[8]) : 0.1;
  if (!(alpha > 0 && alpha <= 1.0 / 6)) {
    fprintf(stderr, "overhead_sim: ALPHA %s; expected a diffusion number in (0, 1/6] (stable)\n", argv[8]);
    MPI_Abort(MPI_COMM_WORLD, 2);
  }

  panoptes_session* viz = NULL;
  if (viz_on) {
    const int dims[3] = {NX, NY, NZ}, offset[3] = {0, 0, k0}, extent[3] = {NX, NY, nzl};
    const int ghost_lo[3] = {0, 0, 1}, ghost_hi[3] = {0, 0, 1};
    const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
    check(panoptes_create(argv[1], 1, PANOPTES_COMM_WORLD, &viz));
    check(panoptes_set_grid(viz, dims, origin, spacing));
    check(panoptes_set_block(viz, offset, extent, ghost_lo, ghost_hi));
  }
  for (int step = 0; step <= steps; ++step) {
    if (step % halo_every == 0) {
      MPI_Request r[4];
      MPI_Irecv(u, (int)plane, MPI_DOUBLE, down, 0, MPI_COMM_WORLD, &r[0]);
      MPI_Irecv(u + plane * (nzl + 1), (int)plane, MPI_DOUBLE, up, 1, MPI_COMM_WORLD, &r[1]);
      MPI_Isend(u + plane * nzl, (int)plane, MPI_DOUBLE, up, 0, MPI_COMM_WORLD, &r[2]);
      MPI_Isend(u + plane, (int)plane, MPI_DOUBLE, down, 1, MPI_COMM_WORLD, &r[3]);
      wait_sleeping(4, r);
    }
    if (viz_on) {
      check(panoptes_set_field_n(viz, "T", u, PANOPTES_FLOAT64, NULL, plane * (nzl + 2)));
      check(panoptes_process(viz, step, step, NULL));
    }
    if (step == steps) break;
    for (int k = 1; k <= nzl; ++k)
      for (int j = 0; j < NY; ++j)
        for (int i = 0; i < NX; ++i) {
          const size_t c = plane * k + (size_t)j * NX + i;
          const int gk = k - 1 + k0;
          const double xm = i > 0 ? u[c - 1] : u[c], xp = i < NX - 1 ? u[c + 1] : u[c];
          const double ym = j > 0 ? u[c - NX] : u[c], yp = j < NY - 1 ? u[c + NX] : u[c];
          const double zm = gk > 0 ? u[c - plane] : u[c], zp = gk < NZ - 1 ? u[c + plane] : u[c];
          v[c] = u[c] + alpha * (xm + xp + ym + yp + zm + zp - 6 * u[c]);
        }
    double* t = u;
    u = v;
    v = t;
  }
  if (viz_on) {
    check(panoptes_finalize(viz));
    panoptes_destroy(viz);
  }
  free(u);
  free(v);
  MPI_Request barrier; /* MPI_Finalize would spin while the other ranks finish */
  MPI_Ibarrier(MPI_COMM_WORLD, &barrier);
  wait_sleeping(1, &barrier);
  MPI_Finalize();
  return 0;
}
