! 3-D heat diffusion (explicit FTCS) with a 1-D MPI decomposition along z, instrumented for in-situ
! visualization with the Panoptes Fortran module: the lines marked "panoptes" are all it takes.
!   mpirun -np 2 heat_fortran heat.toml [steps]
program heat
  use mpi
  use panoptes                                                              ! panoptes
  implicit none
  integer, parameter :: nx = 40, ny = 36, nz = 32
  real(8), allocatable, target :: u(:, :, :), v(:, :, :)
  real(8), parameter :: alpha = 0.15d0
  integer :: rank, nranks, ierr, k0, k1, nzl, i, j, k, step, steps, up, down, gk
  character(len=256) :: config, arg
  real(8) :: x, y, z, x2, z2, xm, xp, ym, yp, zm, zp
  type(panoptes_t) :: viz                                                   ! panoptes

  call MPI_Init(ierr)
  call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks, ierr)
  config = 'heat.toml'
  if (command_argument_count() >= 1) call get_command_argument(1, config)
  steps = 60
  if (command_argument_count() >= 2) then
    call get_command_argument(2, arg)
    read (arg, *) steps
  end if
  k0 = nz * rank / nranks
  k1 = nz * (rank + 1) / nranks
  nzl = k1 - k0
  allocate(u(nx, ny, 0:nzl + 1), v(nx, ny, 0:nzl + 1))
  u = 0
  v = 0
  do k = 1, nzl
    do j = 1, ny
      do i = 1, nx
        x = (i - 1) - 0.3d0 * nx; y = (j - 1) - 0.5d0 * ny; z = (k - 1 + k0) - 0.5d0 * nz
        x2 = (i - 1) - 0.7d0 * nx; z2 = (k - 1 + k0) - 0.35d0 * nz
        if (x * x + y * y + z * z < 36) u(i, j, k) = u(i, j, k) + 1
        if (x2 * x2 + y * y + z2 * z2 < 20) u(i, j, k) = u(i, j, k) + 0.6d0
      end do
    end do
  end do
  up = merge(rank + 1, MPI_PROC_NULL, rank + 1 < nranks)
  down = merge(rank - 1, MPI_PROC_NULL, rank > 0)

  call panoptes_open(viz, config, MPI_COMM_WORLD)                           ! panoptes
  call panoptes_grid(viz, [nx, ny, nz], [0d0, 0d0, 0d0], [1d0, 1d0, 1d0])   ! panoptes
  call panoptes_block(viz, [0, 0, k0], [nx, ny, nzl], [0, 0, 1], [0, 0, 1]) ! panoptes

  do step = 0, steps
    call MPI_Sendrecv(u(:, :, nzl), nx * ny, MPI_DOUBLE_PRECISION, up, 0, u(:, :, 0), nx * ny, &
                      MPI_DOUBLE_PRECISION, down, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE, ierr)
    call MPI_Sendrecv(u(:, :, 1), nx * ny, MPI_DOUBLE_PRECISION, down, 1, u(:, :, nzl + 1), nx * ny, &
                      MPI_DOUBLE_PRECISION, up, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE, ierr)
    call panoptes_field(viz, 'T', u)                                        ! panoptes
    call panoptes_step(viz, step, dble(step))                               ! panoptes
    if (step == steps) exit
    do k = 1, nzl
      gk = k - 1 + k0
      do j = 1, ny
        do i = 1, nx
          xm = u(max(i - 1, 1), j, k); xp = u(min(i + 1, nx), j, k)
          ym = u(i, max(j - 1, 1), k); yp = u(i, min(j + 1, ny), k)
          zm = merge(u(i, j, k - 1), u(i, j, k), gk > 0)
          zp = merge(u(i, j, k + 1), u(i, j, k), gk < nz - 1)
          v(i, j, k) = u(i, j, k) + alpha * (xm + xp + ym + yp + zm + zp - 6 * u(i, j, k))
        end do
      end do
    end do
    u(:, :, 1:nzl) = v(:, :, 1:nzl)
  end do
  call panoptes_close(viz)                                                  ! panoptes
  if (rank == 0) print '(a, i0, a, i0, a)', 'heat_fortran: ', steps, ' steps on ', nranks, ' ranks done'
  call MPI_Finalize(ierr)
end program heat
