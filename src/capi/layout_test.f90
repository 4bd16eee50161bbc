! Arrays as real Fortran codes hold them, through the Panoptes module (issue 28): run by layout_test.sh,
! which compares the databases frame for frame.
!   layout_test xyz     CONFIG   x-fastest u(i,j,k) real(8), ghosts where a neighbour exists
!   layout_test zxy     CONFIG   z-fastest v(k,i,j) real(8), layout='zxy'
!   layout_test sleeve  CONFIG   real(4) z-fastest array with a 3-layer sleeve and x padding, passed as a
!                                section (strides into the original array), real(4) grid/time, integer(8) steps
!   layout_test errors  CONFIG   wrong shapes and layouts are refused with ierr and a message naming both
!                                shapes; nothing is bound, nothing crashes
! Ranks are split 2 x 2 in x and y (or 1 x 1 with one rank). xyz: ghost values come from the same
! analytic field as owned ones, i.e. a FULL halo (edges and corners valid, declared so with
! panoptes_halo). zxy and sleeve: a FACE-ONLY halo, as most codes exchange it: the edge/corner ghosts
! (outside the owned range in both x and y) hold stale garbage (1e30) and are declared not valid, so
! Panoptes must fetch them from their owners; the frames must still equal xyz's.
program layout_test
  use mpi
  use panoptes
  use, intrinsic :: iso_fortran_env, only: int64, real32, real64, error_unit
  implicit none
  integer, parameter :: nx = 30, ny = 26, nz = 22, snaps = 3, sleeve = 3
  character(len=16) :: mode
  character(len=512) :: config
  integer :: rank, nranks, ierr, px, py, cx, cy, g, s
  logical :: face_only
  integer :: off(3), ext(3), glo(3), ghi(3)
  real(real64), allocatable, target :: u(:, :, :), v(:, :, :)
  real(real32), allocatable, target :: w(:, :, :)
  type(panoptes_t) :: viz

  call MPI_Init(ierr)
  call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks, ierr)
  call get_command_argument(1, mode)
  call get_command_argument(2, config)
  px = merge(2, 1, nranks == 4)
  py = merge(2, 1, nranks == 4)
  if (px * py /= nranks) call fail('run with 1 or 4 ranks')
  cx = mod(rank, px)
  cy = rank / px
  off = [nx * cx / px, ny * cy / py, 0]
  ext = [nx * (cx + 1) / px - off(1), ny * (cy + 1) / py - off(2), nz]
  g = 2  ! the session's need on split axes (it fetches what is missing otherwise)
  glo = [merge(g, 0, cx > 0), merge(g, 0, cy > 0), 0]
  ghi = [merge(g, 0, cx < px - 1), merge(g, 0, cy < py - 1), 0]

  call panoptes_errors(PANOPTES_ERRORS_RANK0)
  call panoptes_open(viz, config, MPI_COMM_WORLD)
  if (mode == 'errors') then
    call errors()
    call MPI_Finalize(ierr)
    stop
  end if
  if (mode == 'sleeve') then
    call panoptes_grid(viz, [nx, ny, nz], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0])  ! real(4)
  else
    call panoptes_grid(viz, [nx, ny, nz], [0d0, 0d0, 0d0], [1d0, 1d0, 1d0])  ! real(8)
  end if
  call panoptes_block(viz, off, ext, glo, ghi)
  face_only = mode /= 'xyz'
  call panoptes_halo(viz, [-1, -1, -1], [-1, -1, -1], edges_valid=.not. face_only)

  ! Index ranges below are GLOBAL 0-based point indices: i = off(1)-glo(1) .. off(1)+ext(1)-1+ghi(1), etc.
  select case (trim(mode))
  case ('xyz')
    allocate(u(off(1) - glo(1):off(1) + ext(1) - 1 + ghi(1), off(2) - glo(2):off(2) + ext(2) - 1 + ghi(2), 0:nz - 1))
  case ('zxy')
    allocate(v(0:nz - 1, off(1) - glo(1):off(1) + ext(1) - 1 + ghi(1), off(2) - glo(2):off(2) + ext(2) - 1 + ghi(2)))
  case ('sleeve')
    ! A deeper sleeve than declared on every side, plus 5 padding points on the fastest axis: only the
    ! section of the declared ghosted block is handed over.
    allocate(w(-sleeve:nz - 1 + sleeve + 5, off(1) - glo(1) - sleeve:off(1) + ext(1) - 1 + ghi(1) + sleeve, &
               off(2) - glo(2) - sleeve:off(2) + ext(2) - 1 + ghi(2) + sleeve))
    w = -1e30  ! any read outside the section would wreck the picture
  case default
    call fail('unknown mode '//trim(mode))
  end select

  do s = 0, snaps - 1
    select case (trim(mode))
    case ('xyz')
      call fill_xyz(u, s)
      call panoptes_field(viz, 'T', u)
      call panoptes_step(viz, s, 0.5d0 * s)                 ! integer(4), real(8)
    case ('zxy')
      call fill_zxy(v, s)
      call panoptes_field(viz, 'T', v, layout='zxy')
      call panoptes_step(viz, s, 0.5d0 * s)
    case ('sleeve')
      call fill_sleeve(s)
      call panoptes_field(viz, 'T', w(0:nz - 1, off(1) - glo(1):off(1) + ext(1) - 1 + ghi(1), &
                                      off(2) - glo(2):off(2) + ext(2) - 1 + ghi(2)), layout='zxy')
      if (.not. panoptes_due(viz, int(s, int64), 0.5 * s)) call fail('snapshot not due')  ! integer(8), real(4)
      call panoptes_snapshot(viz, 0.5 * s)                  ! forced, real(4)
    end select
  end do
  call panoptes_close(viz)
  if (rank == 0) print '(a, a, a, i0, a)', 'layout_test ', trim(mode), ': ', nranks, ' rank(s) done'
  call MPI_Finalize(ierr)

contains

  ! The field at global point (i, j, k), snapshot s: two blobs moving with s.
  real(real64) function f(i, j, k, s)
    integer, intent(in) :: i, j, k, s
    real(real64) :: x, y, z
    x = i - 0.3d0 * nx - 2 * s
    y = j - 0.55d0 * ny
    z = k - 0.5d0 * nz
    f = exp(-(x * x + y * y + z * z) / 40d0) + 0.6d0 * exp(-((i - 0.7d0 * nx)**2 + y * y + (k - 0.3d0 * nz - s)**2) / 25d0)
  end function

  ! An edge or corner ghost of a face-only halo exchange: outside the owned range in x and in y.
  logical function stale(i, j)
    integer, intent(in) :: i, j
    stale = face_only .and. (i < off(1) .or. i >= off(1) + ext(1)) .and. (j < off(2) .or. j >= off(2) + ext(2))
  end function

  subroutine fill_xyz(a, s)
    real(real64), intent(out) :: a(off(1) - glo(1):, off(2) - glo(2):, 0:)
    integer, intent(in) :: s
    integer :: i, j, k
    do k = lbound(a, 3), ubound(a, 3)
      do j = lbound(a, 2), ubound(a, 2)
        do i = lbound(a, 1), ubound(a, 1)
          a(i, j, k) = f(i, j, k, s)
        end do
      end do
    end do
  end subroutine

  subroutine fill_zxy(a, s)
    real(real64), intent(out) :: a(0:, off(1) - glo(1):, off(2) - glo(2):)
    integer, intent(in) :: s
    integer :: i, j, k
    do j = lbound(a, 3), ubound(a, 3)
      do i = lbound(a, 2), ubound(a, 2)
        do k = lbound(a, 1), ubound(a, 1)
          a(k, i, j) = merge(1d30, f(i, j, k, s), stale(i, j))
        end do
      end do
    end do
  end subroutine

  subroutine fill_sleeve(s)
    integer, intent(in) :: s
    integer :: i, j, k
    do j = off(2) - glo(2), off(2) + ext(2) - 1 + ghi(2)
      do i = off(1) - glo(1), off(1) + ext(1) - 1 + ghi(1)
        do k = 0, nz - 1
          w(k, i, j) = merge(1e30, real(f(i, j, k, s), real32), stale(i, j))
        end do
      end do
    end do
  end subroutine

  ! Every refusal: a non-zero ierr, a message naming what was given and what was expected, and the
  ! session still usable (a correct call afterwards works).
  subroutine errors()
    real(real64), allocatable, target :: a(:, :, :), b(:, :, :)
    character(len=:), allocatable :: msg
    integer :: rc
    call panoptes_grid(viz, [nx, ny, nz], [0d0, 0d0, 0d0], [1d0, 1d0, 1d0])
    call panoptes_block(viz, [0, 0, 0], [nx, ny, nz], [0, 0, 0], [0, 0, 0])
    ! z-fastest array declared with the default layout 'xyz'
    allocate(a(nz, nx, ny))
    a = 0
    call panoptes_field(viz, 'T', a, ierr=rc)
    msg = panoptes_error_message()
    call expect(rc == PANOPTES_ERROR_USAGE, 'z-fastest array with layout xyz accepted')
    call expect(index(msg, 'has shape (22, 30, 26)') > 0 .and. index(msg, 'is the shape (30, 26, 22)') > 0 .and. &
                index(msg, 'fits layout "zxy"') > 0, 'message: '//msg)
    ! an array one point short in y (a half-size or off-by-one array)
    allocate(b(nx, ny - 1, nz))
    b = 0
    call panoptes_field(viz, 'T', b, ierr=rc)
    msg = panoptes_error_message()
    call expect(rc == PANOPTES_ERROR_USAGE .and. index(msg, '(30, 25, 22)') > 0 .and. index(msg, '(30, 26, 22)') > 0, &
                'short array: '//msg)
    ! a section that does not cover the block
    call panoptes_field(viz, 'T', a(1:nz, 1:nx:2, :), layout='zxy', ierr=rc)
    msg = panoptes_error_message()
    call expect(rc == PANOPTES_ERROR_USAGE .and. index(msg, '(22, 15, 26)') > 0, 'half section: '//msg)
    ! not a layout
    call panoptes_field(viz, 'T', a, layout='zxx', ierr=rc)
    msg = panoptes_error_message()
    call expect(rc == PANOPTES_ERROR_USAGE .and. index(msg, 'layout "zxx"') > 0, 'bad layout: '//msg)
    ! valid ghosts beyond the stored ones
    call panoptes_halo(viz, [0, 0, 1], [0, 0, 0], ierr=rc)
    msg = panoptes_error_message()
    call expect(rc == PANOPTES_ERROR_USAGE .and. index(msg, 'axis z') > 0, 'halo: '//msg)
    ! nothing was bound: a snapshot says which field is missing
    call panoptes_snapshot(viz, 0d0, ierr=rc)
    msg = panoptes_error_message()
    call expect(rc /= 0 .and. index(msg, '"T"') > 0, 'snapshot without a field: '//msg)
    ! and the right call still works
    call panoptes_field(viz, 'T', a, layout='zxy', ierr=rc)
    call expect(rc == 0, 'zxy refused: '//panoptes_error_message())
    call panoptes_close(viz, ierr=rc)
    if (rank == 0) print '(a)', 'layout_test errors: every refusal as expected'
  end subroutine

  subroutine expect(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (.not. ok) call fail(what)
  end subroutine

  subroutine fail(what)
    character(len=*), intent(in) :: what
    integer :: e
    write (error_unit, '(a)') 'layout_test: FAIL: '//what
    call MPI_Abort(MPI_COMM_WORLD, 1, e)
  end subroutine

end program layout_test
