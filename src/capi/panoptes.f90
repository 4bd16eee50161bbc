! Fortran 2008 interface to the Panoptes C API (include/panoptes.h) through iso_c_binding.
! Every routine has an optional integer ierr: 0 on success; without ierr an error stops the program
! with the message of panoptes_last_error.
!
!   use panoptes
!   type(panoptes_t) :: viz
!   call panoptes_open(viz, 'viz.toml', MPI_COMM_WORLD)
!   call panoptes_grid(viz, [nx, ny, nz], [0d0, 0d0, 0d0], [h, h, h])
!   call panoptes_block(viz, offset, extent, ghost_lo, ghost_hi)      ! 0-based offsets
!   do step = ...
!     call panoptes_field(viz, 'T', t)     ! t(:,:,:) real(4) or real(8), INCLUDING its ghost layers
!     call panoptes_step(viz, step, time)
!   end do
!   call panoptes_close(viz)
module panoptes
  use, intrinsic :: iso_c_binding
  implicit none
  private
  public :: panoptes_t, panoptes_open, panoptes_grid, panoptes_block, panoptes_field, panoptes_step, &
            panoptes_close, panoptes_error_message, PANOPTES_COMM_WORLD

  integer, parameter :: PANOPTES_COMM_WORLD = -1
  integer(c_int), parameter :: F32 = 0, F64 = 1

  !> A session handle.
  type :: panoptes_t
    type(c_ptr) :: handle = c_null_ptr
  end type

  interface
    integer(c_int) function c_create(config, is_file, comm, out) bind(c, name='panoptes_create')
      import :: c_int, c_char, c_ptr
      character(kind=c_char), intent(in) :: config(*)
      integer(c_int), value :: is_file, comm
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function c_set_grid(s, dims, origin, spacing) bind(c, name='panoptes_set_grid')
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: s
      integer(c_int), intent(in) :: dims(3)
      real(c_double), intent(in) :: origin(3), spacing(3)
    end function
    integer(c_int) function c_set_block(s, offset, extent, glo, ghi) bind(c, name='panoptes_set_block')
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      integer(c_int), intent(in) :: offset(3), extent(3), glo(3), ghi(3)
    end function
    integer(c_int) function c_set_field(s, name, data, type, strides) bind(c, name='panoptes_set_field')
      import :: c_int, c_ptr, c_char
      type(c_ptr), value :: s, data, strides
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int), value :: type
    end function
    integer(c_int) function c_process(s, step, time, taken) bind(c, name='panoptes_process')
      import :: c_int, c_ptr, c_long_long, c_double
      type(c_ptr), value :: s
      integer(c_long_long), value :: step
      real(c_double), value :: time
      integer(c_int), intent(out) :: taken
    end function
    integer(c_int) function c_finalize(s) bind(c, name='panoptes_finalize')
      import :: c_int, c_ptr
      type(c_ptr), value :: s
    end function
    subroutine c_destroy(s) bind(c, name='panoptes_destroy')
      import :: c_ptr
      type(c_ptr), value :: s
    end subroutine
    type(c_ptr) function c_last_error() bind(c, name='panoptes_last_error')
      import :: c_ptr
    end function
    integer(c_size_t) function c_strlen(p) bind(c, name='strlen')
      import :: c_ptr, c_size_t
      type(c_ptr), value :: p
    end function
  end interface

  !> Binds a field (real(4) or real(8) 3-D array including its ghost layers, x fastest).
  interface panoptes_field
    module procedure field_r4, field_r8
  end interface

contains

  !> The message of the last error ('' if none).
  function panoptes_error_message() result(msg)
    character(len=:), allocatable :: msg
    character(kind=c_char), pointer :: chars(:)
    type(c_ptr) :: p
    integer :: n, i
    p = c_last_error()
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate(character(len=n) :: msg)
    do i = 1, n
      msg(i:i) = chars(i)
    end do
  end function

  subroutine check(rc, ierr)
    integer(c_int), intent(in) :: rc
    integer, intent(out), optional :: ierr
    if (present(ierr)) then
      ierr = int(rc)
    else if (rc /= 0) then
      write (*, '(a)') 'panoptes: error: '//panoptes_error_message()
      error stop 1
    end if
  end subroutine

  !> Creates a session from a TOML file; comm is an MPI communicator (or PANOPTES_COMM_WORLD).
  subroutine panoptes_open(s, config_file, comm, ierr)
    type(panoptes_t), intent(out) :: s
    character(len=*), intent(in) :: config_file
    integer, intent(in) :: comm
    integer, intent(out), optional :: ierr
    call check(c_create(trim(config_file)//c_null_char, 1_c_int, int(comm, c_int), s%handle), ierr)
  end subroutine

  !> The global grid: dims points per axis, origin and spacing.
  subroutine panoptes_grid(s, dims, origin, spacing, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: dims(3)
    double precision, intent(in) :: origin(3), spacing(3)
    integer, intent(out), optional :: ierr
    call check(c_set_grid(s%handle, int(dims, c_int), real(origin, c_double), real(spacing, c_double)), ierr)
  end subroutine

  !> This rank's owned points (0-based offset, extent) and stored ghost layers below / above.
  subroutine panoptes_block(s, offset, extent, ghost_lo, ghost_hi, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: offset(3), extent(3), ghost_lo(3), ghost_hi(3)
    integer, intent(out), optional :: ierr
    call check(c_set_block(s%handle, int(offset, c_int), int(extent, c_int), int(ghost_lo, c_int), &
                           int(ghost_hi, c_int)), ierr)
  end subroutine

  subroutine field_r4(s, name, a, ierr)
    type(panoptes_t), intent(in) :: s
    character(len=*), intent(in) :: name
    real(c_float), contiguous, target, intent(in) :: a(:, :, :)
    integer, intent(out), optional :: ierr
    call check(c_set_field(s%handle, trim(name)//c_null_char, c_loc(a), F32, c_null_ptr), ierr)
  end subroutine

  subroutine field_r8(s, name, a, ierr)
    type(panoptes_t), intent(in) :: s
    character(len=*), intent(in) :: name
    real(c_double), contiguous, target, intent(in) :: a(:, :, :)
    integer, intent(out), optional :: ierr
    call check(c_set_field(s%handle, trim(name)//c_null_char, c_loc(a), F64, c_null_ptr), ierr)
  end subroutine

  !> Renders a snapshot if the schedule asks for one at (step, time); taken tells whether it did.
  subroutine panoptes_step(s, step, time, taken, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: step
    double precision, intent(in) :: time
    logical, intent(out), optional :: taken
    integer, intent(out), optional :: ierr
    integer(c_int) :: t
    call check(c_process(s%handle, int(step, c_long_long), real(time, c_double), t), ierr)
    if (present(taken)) taken = t /= 0
  end subroutine

  !> Finalizes (database complete) and frees the session.
  subroutine panoptes_close(s, ierr)
    type(panoptes_t), intent(inout) :: s
    integer, intent(out), optional :: ierr
    call check(c_finalize(s%handle), ierr)
    call c_destroy(s%handle)
    s%handle = c_null_ptr
  end subroutine

end module panoptes
