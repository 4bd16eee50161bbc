/* 3-D heat diffusion (explicit FTCS) with a 1-D MPI decomposition along z, instrumented for in-situ
 * visualization with Panoptes: the lines marked "panoptes" are all it takes.
 *   mpirun -np 2 heat_c heat.toml [steps]                                                          */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>

#include "panoptes.h" /* panoptes */

#define NX 40
#define NY 36
#define NZ 32

static void check(int rc, panoptes_session* s) {
  (void)s;
  if (rc != PANOPTES_OK) {
    fprintf(stderr, "heat_c: panoptes: %s\n", panoptes_last_error());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
}

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank, size;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const char* config = argc > 1 ? argv[1] : "heat.toml";
  const int steps = argc > 2 ? atoi(argv[2]) : 60;
  /* Owned planes [k0, k1) plus one ghost plane on each side (the stencil's halo). */
  const int k0 = NZ * rank / size, k1 = NZ * (rank + 1) / size, nzl = k1 - k0;
  const size_t plane = (size_t)NX * NY;
  double* u = calloc(plane * (nzl + 2), sizeof(double));
  double* v = calloc(plane * (nzl + 2), sizeof(double));
  for (int k = 0; k < nzl; ++k)
    for (int j = 0; j < NY; ++j)
      for (int i = 0; i < NX; ++i) {
        const double x = i - 0.3 * NX, y = j - 0.5 * NY, z = k + k0 - 0.5 * NZ;
        const double x2 = i - 0.7 * NX, z2 = k + k0 - 0.35 * NZ;
        u[plane * (k + 1) + (size_t)j * NX + i] = (x * x + y * y + z * z < 36 ? 1.0 : 0.0) +
                                                  (x2 * x2 + y * y + z2 * z2 < 20 ? 0.6 : 0.0);
      }
  const int up = rank + 1 < size ? rank + 1 : MPI_PROC_NULL, down = rank > 0 ? rank - 1 : MPI_PROC_NULL;
  const double alpha = 0.15, dt = 1.0;

  panoptes_session* viz;                                                              /* panoptes */
  check(panoptes_create(config, 1, PANOPTES_COMM_WORLD, &viz), viz);                  /* panoptes */
  const int dims[3] = {NX, NY, NZ}, offset[3] = {0, 0, k0}, extent[3] = {NX, NY, nzl}; /* panoptes */
  const int ghost_lo[3] = {0, 0, 1}, ghost_hi[3] = {0, 0, 1};                          /* panoptes */
  const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};                         /* panoptes */
  check(panoptes_set_grid(viz, dims, origin, spacing), viz);                          /* panoptes */
  check(panoptes_set_block(viz, offset, extent, ghost_lo, ghost_hi), viz);            /* panoptes */

  for (int step = 0; step <= steps; ++step) {
    /* Halo exchange of the boundary planes. */
    MPI_Sendrecv(u + plane * nzl, (int)plane, MPI_DOUBLE, up, 0, u, (int)plane, MPI_DOUBLE, down, 0, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
    MPI_Sendrecv(u + plane, (int)plane, MPI_DOUBLE, down, 1, u + plane * (nzl + 1), (int)plane, MPI_DOUBLE, up, 1,
                 MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    check(panoptes_set_field_n(viz, "T", u, PANOPTES_FLOAT64, NULL, plane * (nzl + 2)), viz); /* panoptes */
    check(panoptes_process(viz, step, step * dt, NULL), viz);                         /* panoptes */
    if (step == steps) break;
    for (int k = 1; k <= nzl; ++k)
      for (int j = 0; j < NY; ++j)
        for (int i = 0; i < NX; ++i) {
          const size_t c = plane * k + (size_t)j * NX + i;
          const int gk = k - 1 + k0;
          /* Insulated (zero-flux) boundaries: a missing neighbour counts as the point itself. */
          const double xm = i > 0 ? u[c - 1] : u[c], xp = i < NX - 1 ? u[c + 1] : u[c];
          const double ym = j > 0 ? u[c - NX] : u[c], yp = j < NY - 1 ? u[c + NX] : u[c];
          const double zm = gk > 0 ? u[c - plane] : u[c], zp = gk < NZ - 1 ? u[c + plane] : u[c];
          v[c] = u[c] + alpha * (xm + xp + ym + yp + zm + zp - 6 * u[c]);
        }
    double* t = u;
    u = v;
    v = t;
  }
  check(panoptes_finalize(viz), viz);                                                 /* panoptes */
  panoptes_destroy(viz);                                                              /* panoptes */
  if (rank == 0) printf("heat_c: %d steps on %d ranks done\n", steps, size);
  free(u);
  free(v);
  MPI_Finalize();
  return 0;
}
