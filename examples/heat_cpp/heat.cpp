// 3-D heat diffusion (explicit FTCS) with a 1-D MPI decomposition along x, in C++, instrumented for
// in-situ visualization with Panoptes' C++ header: the lines marked "panoptes" are all it takes.
// The array is stored z fastest, u[i][j][k] (as many C and C++ codes do): its layout is declared, so
// Panoptes reads it through strides, without a copy.
//   mpirun -np 2 heat_cpp heat.toml [steps]
#include <mpi.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <utility>
#include <vector>

#include <panoptes.hpp>  // panoptes

namespace {
constexpr int NX = 40, NY = 36, NZ = 32;
}

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const char* config = argc > 1 ? argv[1] : "heat.toml";
  const int steps = argc > 2 ? std::atoi(argv[2]) : 60;
  // Owned x-planes [i0, i1) plus one ghost plane on each side (the stencil's halo).
  const int i0 = NX * rank / size, i1 = NX * (rank + 1) / size, nxl = i1 - i0;
  const long long plane = (long long)NY * NZ;  // one x-plane: NY * NZ values, z fastest
  std::vector<double> u(std::size_t(plane * (nxl + 2)), 0.0), v = u;
  auto at = [&](int i, int j, int k) { return std::size_t(plane * (i + 1) + (long long)j * NZ + k); };  // i local, -1 .. nxl
  for (int i = 0; i < nxl; ++i)
    for (int j = 0; j < NY; ++j)
      for (int k = 0; k < NZ; ++k) {
        const double x = i + i0 - 0.3 * NX, y = j - 0.5 * NY, z = k - 0.5 * NZ;
        const double x2 = i + i0 - 0.7 * NX, z2 = k - 0.35 * NZ;
        u[at(i, j, k)] = (x * x + y * y + z * z < 36 ? 1.0 : 0.0) + (x2 * x2 + y * y + z2 * z2 < 20 ? 0.6 : 0.0);
      }
  const int up = rank + 1 < size ? rank + 1 : MPI_PROC_NULL, down = rank > 0 ? rank - 1 : MPI_PROC_NULL;
  const double alpha = 0.15, dt = 1.0;

  try {
    panoptes::Session viz(config, MPI_COMM_WORLD);                                  // panoptes
    viz.set_grid({NX, NY, NZ}, {0, 0, 0}, {1, 1, 1});                              // panoptes
    viz.set_block({i0, 0, 0}, {nxl, NY, NZ}, {1, 0, 0}, {1, 0, 0});                // panoptes
    // The array u[i][j][k] over the ghosted block: dimensions (x, y, z), strides (NY*NZ, NZ, 1).
    const std::array<long long, 3> extents{nxl + 2, NY, NZ}, strides{plane, NZ, 1};  // panoptes
    for (int step = 0; step <= steps; ++step) {
      MPI_Sendrecv(&u[at(nxl - 1, 0, 0)], int(plane), MPI_DOUBLE, up, 0, &u[at(-1, 0, 0)], int(plane), MPI_DOUBLE, down,
                   0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      MPI_Sendrecv(&u[at(0, 0, 0)], int(plane), MPI_DOUBLE, down, 1, &u[at(nxl, 0, 0)], int(plane), MPI_DOUBLE, up, 1,
                   MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      viz.set_field("T", u.data(), "xyz", extents, strides, u.size());             // panoptes: size checked
      viz.process(step, step * dt);                                                // panoptes
      if (step == steps) break;
      for (int i = 0; i < nxl; ++i)
        for (int j = 0; j < NY; ++j)
          for (int k = 0; k < NZ; ++k) {
            const std::size_t c = at(i, j, k);
            const int gi = i + i0;
            // Insulated (zero-flux) boundaries: a missing neighbour counts as the point itself.
            const double xm = gi > 0 ? u[c - plane] : u[c], xp = gi < NX - 1 ? u[c + plane] : u[c];
            const double ym = j > 0 ? u[c - NZ] : u[c], yp = j < NY - 1 ? u[c + NZ] : u[c];
            const double zm = k > 0 ? u[c - 1] : u[c], zp = k < NZ - 1 ? u[c + 1] : u[c];
            v[c] = u[c] + alpha * (xm + xp + ym + yp + zm + zp - 6 * u[c]);
          }
      std::swap(u, v);  // the buffers swap: set_field rebinds at the next step
    }
    viz.finalize();                                                                // panoptes
  } catch (const panoptes::Error&) {  // the library printed the message on stderr already
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  if (rank == 0) std::printf("heat_cpp: %d steps on %d ranks done\n", steps, size);
  MPI_Finalize();
  return 0;
}
