! panoptes_field's optional arguments in every form codes use (issue 42, point 9), one process without
! MPI; compiled and run by positional_test.sh. Before issue 28 the 4th positional argument was ierr;
! issue 28 put `layout` there, and old code `call panoptes_field(viz, 'T', u, ierr)` stopped compiling
! with gfortran's bare "no specific subroutine for the generic". Both positional forms and the keyword
! forms must compile and mean what they say:
!   snapshot 0: u(x, y, z) bound with ierr positional (the old form);
!   snapshot 1: v(z, x, y) = the same values, layout 'zxy' positional (the form since issue 28);
!   snapshot 2: v with the keywords, in another order;   snapshot 3: u as real(4), ierr positional.
! The script requires frames 0..2 to be identical (3 differs by rounding to real(4) at most).
program positional_test
  use panoptes
  use, intrinsic :: iso_fortran_env, only: real32, real64, error_unit
  implicit none
  integer, parameter :: nx = 12, ny = 10, nz = 8
  real(real64), allocatable, target :: u(:, :, :), v(:, :, :), short(:, :, :)
  real(real32), allocatable, target :: u4(:, :, :)
  character(len=512) :: config
  type(panoptes_t) :: viz
  integer :: i, j, k, ierr

  call get_command_argument(1, config)
  allocate(u(nx, ny, nz), v(nz, nx, ny), short(nx, ny, nz - 1), u4(nx, ny, nz))
  do k = 1, nz
    do j = 1, ny
      do i = 1, nx
        u(i, j, k) = exp(-((i - 6.5d0)**2 + (j - 4.5d0)**2 + (k - 3.5d0)**2) / 8)
        v(k, i, j) = u(i, j, k)
      end do
    end do
  end do
  u4 = real(u, real32)
  short = 0

  call panoptes_open(viz, config, PANOPTES_COMM_WORLD)
  call panoptes_grid(viz, [nx, ny, nz], [0d0, 0d0, 0d0], [1d0, 1d0, 1d0])
  call panoptes_block(viz, [0, 0, 0], [nx, ny, nz], [0, 0, 0], [0, 0, 0])

  ! The old positional form: ierr 4th, and a refusal reported through it (no STOP).
  ierr = -1
  call panoptes_field(viz, 'T', short, ierr)
  call expect(ierr == PANOPTES_ERROR_USAGE, 'a short array, ierr positional: refused through ierr')
  ierr = -1
  call panoptes_field(viz, 'T', u, ierr)
  call expect(ierr == 0, 'u, ierr positional')
  call panoptes_snapshot(viz, 0d0, ierr)
  call expect(ierr == 0, 'snapshot 0')

  ! layout positional (4th), with and without ierr; a wrong layout refused through the 5th.
  ierr = -1
  call panoptes_field(viz, 'T', v, 'xyz', ierr)
  call expect(ierr == PANOPTES_ERROR_USAGE, 'v in layout xyz, positional: refused through ierr')
  call panoptes_field(viz, 'T', v, 'zxy')
  call panoptes_field(viz, 'T', v, 'zxy', ierr)
  call expect(ierr == 0, 'v, layout positional')
  call panoptes_snapshot(viz, 1d0, ierr)
  call expect(ierr == 0, 'snapshot 1')

  ! Keywords in any order, and ierr positional with layout by keyword.
  call panoptes_field(viz, 'T', v, layout='zxy', ierr=ierr)
  call expect(ierr == 0, 'v, keywords')
  call panoptes_field(viz, 'T', v, ierr=ierr, layout='zxy')
  call expect(ierr == 0, 'v, keywords reversed')
  call panoptes_field(viz, 'T', v, ierr, layout='zxy')
  call expect(ierr == 0, 'v, ierr positional and layout keyword')
  call panoptes_snapshot(viz, 2d0, ierr)
  call expect(ierr == 0, 'snapshot 2')

  call panoptes_field(viz, 'T', u4, ierr)
  call expect(ierr == 0, 'u real(4), ierr positional')
  call panoptes_snapshot(viz, 3d0)
  call panoptes_close(viz, ierr)
  call expect(ierr == 0, 'close')
  print '(a)', 'positional_test: every form as expected'

contains

  subroutine expect(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (.not. ok) then
      write(error_unit, '(a, i0)') 'positional_test: FAIL: '//what//'; ierr = ', ierr
      stop 1
    end if
  end subroutine

end program
