! A Yin-Yang grid through the Panoptes Fortran module (issue 33), one process without MPI: run by
! grid_test.sh, which renders the same data through the C API (ctypes, src/capi/grid_reference.py)
! and requires every frame to be bitwise equal.
!   grid_test yinyang CONFIG OUT   both patches in this process: Yin as u(r, theta, phi) (layout 'xyz'),
!                                  Yang as w(phi, r, theta) (layout 'zxy'); an analytic shell field at
!                                  two times. Writes OUT/coords.bin (r, theta, phi, real(8)) and
!                                  OUT/field_<snapshot>.bin (Yin then Yang, r fastest, real(8)).
!   grid_test errors  CONFIG OUT   bad coordinates and patches are refused with ierr, nothing stops.
program grid_test
  use panoptes
  use, intrinsic :: iso_fortran_env, only: real64, error_unit
  implicit none
  integer, parameter :: nr = 7, nth = 18, nph = 40, snaps = 2
  real(real64), parameter :: pi = acos(-1.0_real64), r_in = 0.35_real64, r_out = 1.0_real64
  character(len=16) :: mode
  character(len=512) :: config, out
  real(real64) :: r(nr), th(nth), ph(nph), dt, dp, t
  real(real64), allocatable, target :: u(:, :, :), w(:, :, :), yang(:, :, :)
  type(panoptes_t) :: viz
  integer :: i, j, k, s, unit, ierr

  call get_command_argument(1, mode)
  call get_command_argument(2, config)
  call get_command_argument(3, out)
  ! A Yin-Yang patch: theta in [pi/4, 3pi/4] and phi in [-3pi/4, 3pi/4], two spacings of overlap each side.
  dt = (pi / 2) / (nth - 5)
  dp = (1.5_real64 * pi) / (nph - 5)
  do i = 1, nr
    r(i) = r_in + (r_out - r_in) * (i - 1) / (nr - 1)
  end do
  do j = 1, nth
    th(j) = pi / 4 - 2 * dt + (j - 1) * dt
  end do
  do k = 1, nph
    ph(k) = -0.75_real64 * pi - 2 * dp + (k - 1) * dp
  end do

  if (trim(mode) == 'errors') then
    call errors()
    stop
  end if
  if (trim(mode) /= 'yinyang') call fail('mode '//trim(mode)//'; expected yinyang or errors')

  open(newunit=unit, file=trim(out)//'/coords.bin', access='stream', form='unformatted', status='replace')
  write(unit) r, th, ph
  close(unit)

  call panoptes_open(viz, config, PANOPTES_COMM_WORLD)
  call panoptes_grid_yinyang(viz, r, th, ph)
  call panoptes_resample(viz, 48, 0.0_real64)
  allocate(u(nr, nth, nph), w(nph, nr, nth), yang(nr, nth, nph))
  call panoptes_patch(viz, 0)
  call panoptes_block(viz, [0, 0, 0], [nr, nth, nph], [0, 0, 0], [0, 0, 0])
  call panoptes_field(viz, 'T', u)
  call panoptes_patch(viz, 1)
  call panoptes_block(viz, [0, 0, 0], [nr, nth, nph], [0, 0, 0], [0, 0, 0])
  call panoptes_field(viz, 'T', w, layout='zxy')
  do s = 0, snaps - 1
    t = 0.7_real64 * s
    do k = 1, nph
      do j = 1, nth
        do i = 1, nr
          u(i, j, k) = field(r(i), th(j), ph(k), .false., t)
          yang(i, j, k) = field(r(i), th(j), ph(k), .true., t)
          w(k, i, j) = yang(i, j, k)
        end do
      end do
    end do
    call panoptes_snapshot(viz, t)
    open(newunit=unit, file=trim(out)//'/field_'//achar(48 + s)//'.bin', access='stream', form='unformatted', &
         status='replace')
    write(unit) u, yang
    close(unit)
  end do
  call panoptes_close(viz)
  print '(a)', 'grid_test: 2 snapshots of a Yin-Yang grid written'

contains

  ! An analytic shell field of WORLD position: a radial profile times low-degree harmonics drifting with t.
  ! Yang's local frame maps to the world by (x, y, z) -> (-x, z, y).
  real(real64) function field(rr, theta, phi, is_yang, time)
    real(real64), intent(in) :: rr, theta, phi, time
    logical, intent(in) :: is_yang
    real(real64) :: x, y, z, a, b, c
    a = rr * sin(theta) * cos(phi)
    b = rr * sin(theta) * sin(phi)
    c = rr * cos(theta)
    if (is_yang) then
      x = -a; y = c; z = b
    else
      x = a; y = b; z = c
    end if
    field = sin(pi * (rr - r_in) / (r_out - r_in)) * &
            (0.5_real64 + 0.4_real64 * (3 * z * z / (rr * rr) - 1) + &
             0.6_real64 * ((x * x - y * y) * cos(2 * time) + 2 * x * y * sin(2 * time)) / (rr * rr))
  end function

  subroutine errors()
    real(real64) :: bad(nr)
    integer :: n
    n = 0
    call panoptes_errors(PANOPTES_ERRORS_ALL)
    call panoptes_open(viz, config, PANOPTES_COMM_WORLD)
    bad = r
    bad(3) = bad(2)
    call panoptes_grid_spherical(viz, bad, th, ph, ierr)
    call expect(ierr == PANOPTES_ERROR_USAGE, 'non-monotonic r accepted')
    call expect(index(panoptes_error_message(), 'r coordinates are not strictly increasing') > 0, &
                'message: '//panoptes_error_message())
    n = n + 1
    call panoptes_grid_yinyang(viz, r, th(4:nth - 3), ph, ierr)
    call expect(ierr == PANOPTES_ERROR_USAGE, 'a Yin-Yang patch narrower than pi/2 accepted')
    call expect(index(panoptes_error_message(), 'leave a gap') > 0, 'message: '//panoptes_error_message())
    n = n + 1
    call panoptes_grid_spherical(viz, r, th, ph, ierr)
    call expect(ierr == PANOPTES_OK, 'a good spherical grid refused: '//panoptes_error_message())
    call panoptes_patch(viz, 1, ierr)
    call expect(ierr == PANOPTES_ERROR_USAGE, 'a patch of a spherical grid accepted')
    call expect(index(panoptes_error_message(), 'only a Yin-Yang grid has patches') > 0, &
                'message: '//panoptes_error_message())
    n = n + 1
    call panoptes_resample(viz, 1, ierr=ierr)
    call expect(ierr == PANOPTES_ERROR_USAGE, 'a resampling to 1 point accepted')
    n = n + 1
    ! real(4) coordinates take the same path.
    call panoptes_grid_rectilinear(viz, real(r, 4), real(th, 4), real(ph, 4), ierr)
    call expect(ierr == PANOPTES_OK, 'real(4) rectilinear coordinates refused: '//panoptes_error_message())
    call panoptes_close(viz, ierr)
    print '(a, i0, a)', 'grid_test: ', n, ' refusals, every refusal as expected'
  end subroutine

  subroutine expect(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (.not. ok) call fail(what)
  end subroutine

  subroutine fail(what)
    character(len=*), intent(in) :: what
    write(error_unit, '(a)') 'grid_test: FAIL: '//what
    stop 1
  end subroutine
end program
