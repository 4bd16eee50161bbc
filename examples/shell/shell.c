/* A convection-like field in a spherical shell on a Yin-Yang grid, instrumented for in-situ visualization
 * with the Panoptes C API (issue 33): the lines marked "panoptes" are all it takes. No solver: the field
 * is analytic (hot plumes rising from the inner boundary and cold sheets sinking from the outer one,
 * drifting in longitude and pulsing with time, over a conductive radial profile), so the example runs in
 * seconds and the pictures show what a geodynamo or mantle code would hand over.
 * Ranks: 1 holds both patches; 2 or more split them, each patch in longitude slabs.
 *   mpirun -np 2 shell outside.toml [steps] [nr]     (outside.toml: a Yin-Yang rig around the sphere;
 *   mpirun -np 2 shell inside.toml  [steps] [nr]      inside.toml: rings of cameras inside the shell) */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>

#include <panoptes.h> /* panoptes */

#define PI 3.14159265358979323846
#define NPLUMES 9

static const double R_IN = 0.35, R_OUT = 1.0;

static void check(int rc, panoptes_session* s) {
  (void)s;
  if (rc != PANOPTES_OK) MPI_Abort(MPI_COMM_WORLD, 1); /* the library printed the message */
}

/* Unit vectors of the plumes (hot, rising) and sheets (cold, sinking), fixed pseudo-random directions. */
static double plume_dir[NPLUMES][3];
static void make_plumes(void) {
  for (int p = 0; p < NPLUMES; ++p) { /* a golden-angle spiral: spread, not random */
    const double z = 1 - (2 * p + 1.0) / NPLUMES, lon = 2.399963229728653 * p, s = sqrt(1 - z * z);
    plume_dir[p][0] = s * cos(lon);
    plume_dir[p][1] = s * sin(lon);
    plume_dir[p][2] = z;
  }
}

/* Temperature anomaly at world point (x, y, z) and time t: roughly in [-1, 1]. */
static double temperature(double x, double y, double z, double t) {
  const double r = sqrt(x * x + y * y + z * z), h = (r - R_IN) / (R_OUT - R_IN);
  const double ux = x / r, uy = y / r, uz = z / r;
  double v = 0.35 * (1 - 2 * h); /* conductive profile: hot inside, cold outside */
  for (int p = 0; p < NPLUMES; ++p) {
    /* Each plume drifts in longitude (about the z axis) at its own rate. */
    const double a = 0.25 * t * (p % 2 ? 1.0 : -0.7), c = cos(a), s = sin(a);
    const double px = c * plume_dir[p][0] - s * plume_dir[p][1], py = s * plume_dir[p][0] + c * plume_dir[p][1];
    const double cosang = ux * px + uy * py + uz * plume_dir[p][2];
    const double width = p % 3 == 2 ? 0.02 : 0.035, pulse = 1 + 0.3 * sin(0.8 * t + p);
    const double stem = exp(-(1 - cosang) / width);
    if (p % 3 == 2) v -= 0.9 * pulse * stem * h * sqrt(h);               /* a cold sheet from the top */
    else v += 1.1 * pulse * stem * (1 - h) * (0.4 + 0.6 * sin(PI * h)); /* a hot plume from the core */
  }
  return v * sin(PI * h); /* zero on both boundaries: the shell fades into the void */
}

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const char* config = argc > 1 ? argv[1] : "outside.toml";
  const int steps = argc > 2 ? atoi(argv[2]) : 24;
  const int nr = argc > 3 ? atoi(argv[3]) : 24;
  if (steps < 1 || nr < 4 || nr > 512) {
    if (rank == 0) fprintf(stderr, "shell: usage: shell CONFIG [steps >= 1] [nr in 4..512]\n");
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  /* One Yin-Yang patch: colatitude [pi/4, 3pi/4] and longitude [-3pi/4, 3pi/4] with two cells of overlap. */
  const int nth = 2 * nr, nph = 6 * nr;
  double *r = malloc(sizeof(double) * nr), *th = malloc(sizeof(double) * nth), *ph = malloc(sizeof(double) * nph);
  const double dth = (PI / 2) / (nth - 5), dph = (1.5 * PI) / (nph - 5);
  for (int i = 0; i < nr; ++i) r[i] = R_IN + (R_OUT - R_IN) * i / (nr - 1);
  for (int j = 0; j < nth; ++j) th[j] = PI / 4 - 2 * dth + j * dth;
  for (int k = 0; k < nph; ++k) ph[k] = -0.75 * PI - 2 * dph + k * dph;
  make_plumes();

  /* This rank's blocks: one rank holds both patches; otherwise patch = rank % 2, sliced in longitude. */
  const int nblocks = size == 1 ? 2 : 1;
  int patch[2], k0[2], nk[2];
  for (int b = 0; b < nblocks; ++b) {
    patch[b] = size == 1 ? b : rank % 2;
    const int share = size == 1 ? 1 : (size - patch[b] + 1) / 2, slot = size == 1 ? 0 : rank / 2;
    k0[b] = nph * slot / share;
    nk[b] = nph * (slot + 1) / share - k0[b];
  }
  double* u[2] = {NULL, NULL};

  panoptes_session* viz;                                                           /* panoptes */
  check(panoptes_create(config, 1, PANOPTES_COMM_WORLD, &viz), viz);               /* panoptes */
  const int dims[3] = {nr, nth, nph};                                              /* panoptes */
  check(panoptes_set_grid_yinyang(viz, dims, r, th, ph), viz);                     /* panoptes */
  for (int b = 0; b < nblocks; ++b) {
    const size_t n = (size_t)nr * nth * nk[b];
    u[b] = malloc(sizeof(double) * n);
    const int offset[3] = {0, 0, k0[b]}, extent[3] = {nr, nth, nk[b]}, none[3] = {0, 0, 0}; /* panoptes */
    check(panoptes_set_patch(viz, patch[b]), viz);                                           /* panoptes */
    check(panoptes_set_block(viz, offset, extent, none, none), viz);                         /* panoptes */
    check(panoptes_set_field_n(viz, "T", u[b], PANOPTES_FLOAT64, NULL, (long long)n), viz);  /* panoptes */
  }

  for (int step = 0; step <= steps; ++step) {
    const double t = 0.25 * step;
    for (int b = 0; b < nblocks; ++b)
      for (int k = 0; k < nk[b]; ++k)
        for (int j = 0; j < nth; ++j)
          for (int i = 0; i < nr; ++i) {
            const double sp = sin(ph[k0[b] + k]), cp = cos(ph[k0[b] + k]), st = sin(th[j]), ct = cos(th[j]);
            double x = r[i] * st * cp, y = r[i] * st * sp, z = r[i] * ct;
            if (patch[b] == 1) { /* Yang's frame to the world: (x, y, z) -> (-x, z, y) */
              const double yy = y;
              x = -x;
              y = z;
              z = yy;
            }
            u[b][((size_t)k * nth + j) * nr + i] = temperature(x, y, z, t);
          }
    check(panoptes_process(viz, step, t, NULL), viz);                              /* panoptes */
  }
  check(panoptes_finalize(viz), viz);                                              /* panoptes */
  panoptes_destroy(viz);                                                           /* panoptes */
  if (rank == 0) printf("shell: %d steps of a %dx%dx%d Yin-Yang grid on %d ranks done\n", steps, nr, nth, nph, size);
  for (int b = 0; b < nblocks; ++b) free(u[b]);
  free(r);
  free(th);
  free(ph);
  MPI_Finalize();
  return 0;
}
