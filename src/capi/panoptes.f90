! module panoptes: the C API for Fortran.
! Sections (each marked "! --- name ---" below):
!   names          public names, return codes, the session handle
!   c bindings     the C API's functions as bind(c) interfaces
!   generics       one name per routine over real(4)/real(8) and integer(4)/integer(8)
!   errors         the last message, which ranks print, check
!   session        panoptes_open
!   grids          uniform, rectilinear, spherical, Yin-Yang; patch, resample
!   decomposition  this rank's block and its halo
!   fields         arrays bound in place, their strides measured
!   steps          process, due, snapshot
!   close          panoptes_close
!
! Fortran interface to the Panoptes C API (include/panoptes.h) through iso_c_binding. Standard Fortran
! 2008 only (no compiler-specific descriptor layout): this source is installed as
! share/panoptes/fortran/panoptes.f90, so any compiler (gfortran, Intel, NVHPC, Cray, Fujitsu...) can
! build the module for itself and link it to libpanoptes.
!
!   use panoptes
!   type(panoptes_t) :: viz
!   call panoptes_open(viz, 'viz.toml', MPI_COMM_WORLD)
!   call panoptes_grid(viz, [nx, ny, nz], [0d0, 0d0, 0d0], [h, h, h])   ! real(4) or real(8)
!   ! or a grid that is not a uniform box (1-D coordinate arrays, real(4) or real(8); resampled in situ):
!   !   call panoptes_grid_rectilinear(viz, x, y, z) / panoptes_grid_spherical(viz, r, theta, phi)
!   !   call panoptes_grid_yinyang(viz, r, theta, phi); call panoptes_patch(viz, 0 or 1)
!   call panoptes_block(viz, offset, extent, ghost_lo, ghost_hi)        ! 0-based offsets, STORED ghosts
!   call panoptes_halo(viz, valid_lo, valid_hi)                         ! optional: ghosts kept up to date
!   do step = ...
!     call panoptes_field(viz, 'T', v, layout='zxy')  ! v(k,i,j): z fastest; sections and padding allowed
!                                                     ! (optional args: ierr, layout; or 'zxy' 4th)
!     call panoptes_step(viz, step, time)             ! integer(4|8) step, real(4|8) time
!   end do
!   call panoptes_close(viz)
!
! Errors: every routine has an optional integer ierr (0 = success, else PANOPTES_ERROR_*); the library
! prints the message once to stderr (panoptes_errors chooses which ranks print) and never stops the
! program itself. Without ierr a failed call ends the program with STOP 1 (no ERROR STOP, no backtrace).
!
! Arrays are used in place, never copied: panoptes_field keeps the address and strides of the actual
! argument and reads it at each snapshot. Its dummy argument is INTENT(INOUT) on purpose: the compiler
! then accepts only a variable (a whole array, a section or a pointer), never an expression or a
! vector-subscripted section, which it would pass as a temporary that is freed when the call returns.
! Give the array the TARGET (or POINTER) attribute and keep it allocated while it is bound.
! --- names ---
module panoptes
  use, intrinsic :: iso_c_binding
  use, intrinsic :: iso_fortran_env, only: int32, int64, real32, real64
  implicit none
  private
  public :: panoptes_grid_rectilinear, panoptes_grid_spherical, panoptes_grid_yinyang, panoptes_patch, &
            panoptes_resample
  public :: panoptes_t, panoptes_open, panoptes_grid, panoptes_block, panoptes_halo, panoptes_field, &
            panoptes_step, panoptes_due, panoptes_snapshot, panoptes_close, panoptes_errors, &
            panoptes_error_message
  public :: PANOPTES_COMM_WORLD, PANOPTES_OK, PANOPTES_ERROR_CONFIG, PANOPTES_ERROR_USAGE, PANOPTES_ERROR_RUN, &
            PANOPTES_ERRORS_ALL, PANOPTES_ERRORS_RANK0, PANOPTES_ERRORS_NONE

  integer, parameter :: PANOPTES_COMM_WORLD = -1
  integer, parameter :: PANOPTES_OK = 0, PANOPTES_ERROR_CONFIG = 1, PANOPTES_ERROR_USAGE = 2, PANOPTES_ERROR_RUN = 3
  !> Which ranks print error messages (panoptes_errors): all, prefixed with their rank; rank 0 only; none.
  integer, parameter :: PANOPTES_ERRORS_ALL = 0, PANOPTES_ERRORS_RANK0 = 1, PANOPTES_ERRORS_NONE = 2
  integer(c_int), parameter :: F32 = 0, F64 = 1

  !> A session handle.
  type :: panoptes_t
    type(c_ptr) :: handle = c_null_ptr
  end type

  ! --- c bindings ---
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
    integer(c_int) function c_set_grid_rectilinear(s, dims, x, y, z) bind(c, name='panoptes_set_grid_rectilinear')
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: s
      integer(c_int), intent(in) :: dims(3)
      real(c_double), intent(in) :: x(*), y(*), z(*)
    end function
    integer(c_int) function c_set_grid_spherical(s, dims, r, theta, phi) bind(c, name='panoptes_set_grid_spherical')
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: s
      integer(c_int), intent(in) :: dims(3)
      real(c_double), intent(in) :: r(*), theta(*), phi(*)
    end function
    integer(c_int) function c_set_grid_yinyang(s, dims, r, theta, phi) bind(c, name='panoptes_set_grid_yinyang')
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: s
      integer(c_int), intent(in) :: dims(3)
      real(c_double), intent(in) :: r(*), theta(*), phi(*)
    end function
    integer(c_int) function c_set_patch(s, patch) bind(c, name='panoptes_set_patch')
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      integer(c_int), value :: patch
    end function
    integer(c_int) function c_set_resample(s, points, outside) bind(c, name='panoptes_set_resample')
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: s
      integer(c_int), value :: points
      real(c_double), value :: outside
    end function
    integer(c_int) function c_set_block(s, offset, extent, glo, ghi) bind(c, name='panoptes_set_block')
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      integer(c_int), intent(in) :: offset(3), extent(3), glo(3), ghi(3)
    end function
    integer(c_int) function c_set_halo(s, vlo, vhi, edges) bind(c, name='panoptes_set_halo')
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      integer(c_int), intent(in) :: vlo(3), vhi(3)
      integer(c_int), value :: edges
    end function
    integer(c_int) function c_set_field_layout(s, name, data, type, layout, extents, strides) &
        bind(c, name='panoptes_set_field_layout')
      import :: c_int, c_ptr, c_char, c_long_long
      type(c_ptr), value :: s, data
      character(kind=c_char), intent(in) :: name(*), layout(*)
      integer(c_int), value :: type
      integer(c_long_long), intent(in) :: extents(3), strides(3)
    end function
    integer(c_int) function c_process(s, step, time, taken) bind(c, name='panoptes_process')
      import :: c_int, c_ptr, c_long_long, c_double
      type(c_ptr), value :: s
      integer(c_long_long), value :: step
      real(c_double), value :: time
      integer(c_int), intent(out) :: taken
    end function
    integer(c_int) function c_due(s, step, time, due) bind(c, name='panoptes_due')
      import :: c_int, c_ptr, c_long_long, c_double
      type(c_ptr), value :: s
      integer(c_long_long), value :: step
      real(c_double), value :: time
      integer(c_int), intent(out) :: due
    end function
    integer(c_int) function c_snapshot(s, time) bind(c, name='panoptes_snapshot')
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: s
      real(c_double), value :: time
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
    subroutine c_set_error_output(mode) bind(c, name='panoptes_set_error_output')
      import :: c_int
      integer(c_int), value :: mode
    end subroutine
    integer(c_size_t) function c_strlen(p) bind(c, name='strlen')
      import :: c_ptr, c_size_t
      type(c_ptr), value :: p
    end function
  end interface

  ! --- generics ---
  !> The global grid: origin and spacing real(4) or real(8).
  interface panoptes_grid
    module procedure grid_r4, grid_r8
  end interface
  !> A rectilinear grid: strictly increasing coordinates x(nx), y(ny), z(nz), real(4) or real(8).
  interface panoptes_grid_rectilinear
    module procedure rectilinear_r4, rectilinear_r8
  end interface
  !> A spherical shell: radii r(nr), colatitudes theta(ntheta) in [0, pi] and longitudes phi(nphi) in
  !> radians, each strictly increasing; arrays indexed (r, theta, phi), r fastest (see panoptes.h).
  interface panoptes_grid_spherical
    module procedure spherical_r4, spherical_r8
  end interface
  !> A Yin-Yang grid: the coordinates of ONE patch (both patches share them); select a block's patch
  !> with panoptes_patch.
  interface panoptes_grid_yinyang
    module procedure yinyang_r4, yinyang_r8
  end interface
  !> Binds a field: a real(4) or real(8) 3-D array (or section) INCLUDING its stored ghost layers, in the
  !> axis order `layout` (default 'xyz': first index x).
  !> Optional arguments: ierr 4th and layout 5th, as before layout existed (old code passes ierr
  !> positionally), or by keyword in any order; field_r4_order / field_r8_order take the layout 4th
  !> positionally, as issue 28's module did: `call panoptes_field(viz, 'T', v, 'zxy'[, ierr])`. The two
  !> kinds of specifics differ in the type of the 4th argument and in its name (`order` is required
  !> there, and the others have no `order`), so every call resolves to exactly one.
  interface panoptes_field
    module procedure field_r4, field_r8, field_r4_order, field_r8_order
  end interface
  !> Renders a snapshot if the schedule asks for one at (step, time): integer(4|8) step, real(4|8) time.
  interface panoptes_step
    module procedure step_i4_r4, step_i4_r8, step_i8_r4, step_i8_r8
  end interface
  !> Whether the schedule asks for a snapshot at (step, time), without rendering.
  interface panoptes_due
    module procedure due_i4_r4, due_i4_r8, due_i8_r4, due_i8_r8
  end interface
  !> Renders and stores a snapshot now, whatever the schedule (time real(4) or real(8)).
  interface panoptes_snapshot
    module procedure snapshot_r4, snapshot_r8
  end interface

contains

  ! --- errors ---
  !> The message of the last error ('' if none).
  function panoptes_error_message() result(msg)
    character(len=:), allocatable :: msg
    character(kind=c_char), pointer :: chars(:)
    type(c_ptr) :: p
    integer :: n, i
    p = c_last_error()
    n = int(c_strlen(p))
    allocate(character(len=n) :: msg)
    if (n == 0) return
    call c_f_pointer(p, chars, [n])
    do i = 1, n
      msg(i:i) = chars(i)
    end do
  end function

  !> Which ranks print error messages: PANOPTES_ERRORS_ALL (default; prefixed with the rank when there
  !> are several), PANOPTES_ERRORS_RANK0 or PANOPTES_ERRORS_NONE. Also: environment PANOPTES_ERRORS=all|rank0|none.
  subroutine panoptes_errors(mode)
    integer, intent(in) :: mode
    call c_set_error_output(int(mode, c_int))
  end subroutine

  ! The library has printed the message already (as panoptes_errors says).
  subroutine check(rc, ierr)
    integer(c_int), intent(in) :: rc
    integer, intent(out), optional :: ierr
    if (present(ierr)) then
      ierr = int(rc)
    else if (rc /= 0) then
      stop 1
    end if
  end subroutine

  ! --- session ---
  !> Creates a session from a TOML file; comm is an MPI communicator (or PANOPTES_COMM_WORLD).
  subroutine panoptes_open(s, config_file, comm, ierr)
    type(panoptes_t), intent(out) :: s
    character(len=*), intent(in) :: config_file
    integer, intent(in) :: comm
    integer, intent(out), optional :: ierr
    call check(c_create(trim(config_file)//c_null_char, 1_c_int, int(comm, c_int), s%handle), ierr)
  end subroutine

  ! --- grids ---
  subroutine grid_r4(s, dims, origin, spacing, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: dims(3)
    real(real32), intent(in) :: origin(3), spacing(3)
    integer, intent(out), optional :: ierr
    call check(c_set_grid(s%handle, int(dims, c_int), real(origin, c_double), real(spacing, c_double)), ierr)
  end subroutine

  subroutine grid_r8(s, dims, origin, spacing, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: dims(3)
    real(real64), intent(in) :: origin(3), spacing(3)
    integer, intent(out), optional :: ierr
    call check(c_set_grid(s%handle, int(dims, c_int), real(origin, c_double), real(spacing, c_double)), ierr)
  end subroutine

  ! The non-uniform grid calls share one path: coordinates as real(c_double), dims from their sizes.
  subroutine source_grid(s, kind, a, b, c, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: kind
    real(c_double), intent(in) :: a(:), b(:), c(:)
    integer, intent(out), optional :: ierr
    integer(c_int) :: dims(3)
    dims = [int(size(a), c_int), int(size(b), c_int), int(size(c), c_int)]
    select case (kind)
    case (0)
      call check(c_set_grid_rectilinear(s%handle, dims, a, b, c), ierr)
    case (1)
      call check(c_set_grid_spherical(s%handle, dims, a, b, c), ierr)
    case default
      call check(c_set_grid_yinyang(s%handle, dims, a, b, c), ierr)
    end select
  end subroutine

  subroutine rectilinear_r4(s, x, y, z, ierr)
    type(panoptes_t), intent(in) :: s
    real(real32), intent(in) :: x(:), y(:), z(:)
    integer, intent(out), optional :: ierr
    call source_grid(s, 0, real(x, c_double), real(y, c_double), real(z, c_double), ierr)
  end subroutine
  subroutine rectilinear_r8(s, x, y, z, ierr)
    type(panoptes_t), intent(in) :: s
    real(real64), intent(in) :: x(:), y(:), z(:)
    integer, intent(out), optional :: ierr
    call source_grid(s, 0, real(x, c_double), real(y, c_double), real(z, c_double), ierr)
  end subroutine
  subroutine spherical_r4(s, r, theta, phi, ierr)
    type(panoptes_t), intent(in) :: s
    real(real32), intent(in) :: r(:), theta(:), phi(:)
    integer, intent(out), optional :: ierr
    call source_grid(s, 1, real(r, c_double), real(theta, c_double), real(phi, c_double), ierr)
  end subroutine
  subroutine spherical_r8(s, r, theta, phi, ierr)
    type(panoptes_t), intent(in) :: s
    real(real64), intent(in) :: r(:), theta(:), phi(:)
    integer, intent(out), optional :: ierr
    call source_grid(s, 1, real(r, c_double), real(theta, c_double), real(phi, c_double), ierr)
  end subroutine
  subroutine yinyang_r4(s, r, theta, phi, ierr)
    type(panoptes_t), intent(in) :: s
    real(real32), intent(in) :: r(:), theta(:), phi(:)
    integer, intent(out), optional :: ierr
    call source_grid(s, 2, real(r, c_double), real(theta, c_double), real(phi, c_double), ierr)
  end subroutine
  subroutine yinyang_r8(s, r, theta, phi, ierr)
    type(panoptes_t), intent(in) :: s
    real(real64), intent(in) :: r(:), theta(:), phi(:)
    integer, intent(out), optional :: ierr
    call source_grid(s, 2, real(r, c_double), real(theta, c_double), real(phi, c_double), ierr)
  end subroutine

  !> Yin-Yang: the patch (0 = Yin, 1 = Yang) that the following panoptes_block and panoptes_field calls
  !> describe; a rank may hold a block of each patch.
  subroutine panoptes_patch(s, patch, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: patch
    integer, intent(out), optional :: ierr
    call check(c_set_patch(s%handle, int(patch, c_int)), ierr)
  end subroutine

  !> Non-uniform grids: points along the longest axis of the uniform grid they are resampled onto
  !> (0 = the source's largest dimension) and the value outside the grid's domain (default 0).
  subroutine panoptes_resample(s, longest_axis_points, outside_value, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: longest_axis_points
    real(real64), intent(in), optional :: outside_value
    integer, intent(out), optional :: ierr
    real(c_double) :: v
    v = 0
    if (present(outside_value)) v = outside_value
    call check(c_set_resample(s%handle, int(longest_axis_points, c_int), v), ierr)
  end subroutine

  ! --- decomposition ---
  !> This rank's owned points (0-based offset, extent) and the ghost layers its arrays STORE below / above.
  subroutine panoptes_block(s, offset, extent, ghost_lo, ghost_hi, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: offset(3), extent(3), ghost_lo(3), ghost_hi(3)
    integer, intent(out), optional :: ierr
    call check(c_set_block(s%handle, int(offset, c_int), int(extent, c_int), int(ghost_lo, c_int), &
                           int(ghost_hi, c_int)), ierr)
  end subroutine

  !> Of the stored ghost layers, those the halo exchange keeps up to date (-1 = all stored), and whether it
  !> fills edge and corner ghosts too (edges_valid, default .false.: face-only halos).
  subroutine panoptes_halo(s, valid_lo, valid_hi, edges_valid, ierr)
    type(panoptes_t), intent(in) :: s
    integer, intent(in) :: valid_lo(3), valid_hi(3)
    logical, intent(in), optional :: edges_valid
    integer, intent(out), optional :: ierr
    integer(c_int) :: edges
    edges = 0
    if (present(edges_valid)) then
      if (edges_valid) edges = 1
    end if
    call check(c_set_halo(s%handle, int(valid_lo, c_int), int(valid_hi, c_int), edges), ierr)
  end subroutine

  ! --- fields ---
  ! Elements between two addresses (the array's own strides, whatever the compiler's descriptor).
  integer(c_long_long) function distance(p, q, bytes)
    type(c_ptr), intent(in) :: p, q
    integer, intent(in) :: bytes
    distance = int((transfer(q, 0_c_intptr_t) - transfer(p, 0_c_intptr_t)) / bytes, c_long_long)
  end function

  subroutine bind_array(s, name, data, type, layout, extents, strides, ierr)
    type(panoptes_t), intent(in) :: s
    character(len=*), intent(in) :: name
    type(c_ptr), intent(in) :: data
    integer(c_int), intent(in) :: type
    character(len=*), intent(in), optional :: layout
    integer(c_long_long), intent(in) :: extents(3), strides(3)
    integer, intent(out), optional :: ierr
    character(len=8) :: order
    ! Without layout= the C side takes 'xyz' only where the shape rules out every other order.
    order = ''
    if (present(layout)) order = layout
    call check(c_set_field_layout(s%handle, trim(name)//c_null_char, data, type, trim(order)//c_null_char, &
                                  extents, strides), ierr)
  end subroutine

  subroutine field_r4(s, name, a, ierr, layout)
    type(panoptes_t), intent(in) :: s
    character(len=*), intent(in) :: name
    real(real32), target, intent(inout) :: a(:, :, :)
    character(len=*), intent(in), optional :: layout
    integer, intent(out), optional :: ierr
    integer(c_long_long) :: n(3), st(3)
    type(c_ptr) :: p
    n = shape(a, c_long_long)
    st = 0
    p = c_null_ptr
    if (all(n > 0)) then
      p = c_loc(a(1, 1, 1))
      if (n(1) > 1) st(1) = distance(p, c_loc(a(2, 1, 1)), 4)
      if (n(2) > 1) st(2) = distance(p, c_loc(a(1, 2, 1)), 4)
      if (n(3) > 1) st(3) = distance(p, c_loc(a(1, 1, 2)), 4)
    end if
    call bind_array(s, name, p, F32, layout, n, st, ierr)
  end subroutine

  subroutine field_r8(s, name, a, ierr, layout)
    type(panoptes_t), intent(in) :: s
    character(len=*), intent(in) :: name
    real(real64), target, intent(inout) :: a(:, :, :)
    character(len=*), intent(in), optional :: layout
    integer, intent(out), optional :: ierr
    integer(c_long_long) :: n(3), st(3)
    type(c_ptr) :: p
    n = shape(a, c_long_long)
    st = 0
    p = c_null_ptr
    if (all(n > 0)) then
      p = c_loc(a(1, 1, 1))
      if (n(1) > 1) st(1) = distance(p, c_loc(a(2, 1, 1)), 8)
      if (n(2) > 1) st(2) = distance(p, c_loc(a(1, 2, 1)), 8)
      if (n(3) > 1) st(3) = distance(p, c_loc(a(1, 1, 2)), 8)
    end if
    call bind_array(s, name, p, F64, layout, n, st, ierr)
  end subroutine

  subroutine field_r4_order(s, name, a, order, ierr)
    type(panoptes_t), intent(in) :: s
    character(len=*), intent(in) :: name
    real(real32), target, intent(inout) :: a(:, :, :)
    character(len=*), intent(in) :: order
    integer, intent(out), optional :: ierr
    call field_r4(s, name, a, ierr, order)
  end subroutine

  subroutine field_r8_order(s, name, a, order, ierr)
    type(panoptes_t), intent(in) :: s
    character(len=*), intent(in) :: name
    real(real64), target, intent(inout) :: a(:, :, :)
    character(len=*), intent(in) :: order
    integer, intent(out), optional :: ierr
    call field_r8(s, name, a, ierr, order)
  end subroutine

  ! --- steps ---
  subroutine do_step(s, step, time, taken, ierr)
    type(panoptes_t), intent(in) :: s
    integer(c_long_long), intent(in) :: step
    real(c_double), intent(in) :: time
    logical, intent(out), optional :: taken
    integer, intent(out), optional :: ierr
    integer(c_int) :: t
    t = 0
    call check(c_process(s%handle, step, time, t), ierr)
    if (present(taken)) taken = t /= 0
  end subroutine

  subroutine step_i4_r4(s, step, time, taken, ierr)
    type(panoptes_t), intent(in) :: s
    integer(int32), intent(in) :: step
    real(real32), intent(in) :: time
    logical, intent(out), optional :: taken
    integer, intent(out), optional :: ierr
    call do_step(s, int(step, c_long_long), real(time, c_double), taken, ierr)
  end subroutine
  subroutine step_i4_r8(s, step, time, taken, ierr)
    type(panoptes_t), intent(in) :: s
    integer(int32), intent(in) :: step
    real(real64), intent(in) :: time
    logical, intent(out), optional :: taken
    integer, intent(out), optional :: ierr
    call do_step(s, int(step, c_long_long), real(time, c_double), taken, ierr)
  end subroutine
  subroutine step_i8_r4(s, step, time, taken, ierr)
    type(panoptes_t), intent(in) :: s
    integer(int64), intent(in) :: step
    real(real32), intent(in) :: time
    logical, intent(out), optional :: taken
    integer, intent(out), optional :: ierr
    call do_step(s, int(step, c_long_long), real(time, c_double), taken, ierr)
  end subroutine
  subroutine step_i8_r8(s, step, time, taken, ierr)
    type(panoptes_t), intent(in) :: s
    integer(int64), intent(in) :: step
    real(real64), intent(in) :: time
    logical, intent(out), optional :: taken
    integer, intent(out), optional :: ierr
    call do_step(s, int(step, c_long_long), real(time, c_double), taken, ierr)
  end subroutine

  logical function do_due(s, step, time, ierr)
    type(panoptes_t), intent(in) :: s
    integer(c_long_long), intent(in) :: step
    real(c_double), intent(in) :: time
    integer, intent(out), optional :: ierr
    integer(c_int) :: d
    d = 0
    call check(c_due(s%handle, step, time, d), ierr)
    do_due = d /= 0
  end function

  logical function due_i4_r4(s, step, time, ierr)
    type(panoptes_t), intent(in) :: s
    integer(int32), intent(in) :: step
    real(real32), intent(in) :: time
    integer, intent(out), optional :: ierr
    due_i4_r4 = do_due(s, int(step, c_long_long), real(time, c_double), ierr)
  end function
  logical function due_i4_r8(s, step, time, ierr)
    type(panoptes_t), intent(in) :: s
    integer(int32), intent(in) :: step
    real(real64), intent(in) :: time
    integer, intent(out), optional :: ierr
    due_i4_r8 = do_due(s, int(step, c_long_long), real(time, c_double), ierr)
  end function
  logical function due_i8_r4(s, step, time, ierr)
    type(panoptes_t), intent(in) :: s
    integer(int64), intent(in) :: step
    real(real32), intent(in) :: time
    integer, intent(out), optional :: ierr
    due_i8_r4 = do_due(s, int(step, c_long_long), real(time, c_double), ierr)
  end function
  logical function due_i8_r8(s, step, time, ierr)
    type(panoptes_t), intent(in) :: s
    integer(int64), intent(in) :: step
    real(real64), intent(in) :: time
    integer, intent(out), optional :: ierr
    due_i8_r8 = do_due(s, int(step, c_long_long), real(time, c_double), ierr)
  end function

  subroutine snapshot_r4(s, time, ierr)
    type(panoptes_t), intent(in) :: s
    real(real32), intent(in) :: time
    integer, intent(out), optional :: ierr
    call check(c_snapshot(s%handle, real(time, c_double)), ierr)
  end subroutine
  subroutine snapshot_r8(s, time, ierr)
    type(panoptes_t), intent(in) :: s
    real(real64), intent(in) :: time
    integer, intent(out), optional :: ierr
    call check(c_snapshot(s%handle, real(time, c_double)), ierr)
  end subroutine

  ! --- close ---
  !> Finalizes (database complete) and frees the session.
  subroutine panoptes_close(s, ierr)
    type(panoptes_t), intent(inout) :: s
    integer, intent(out), optional :: ierr
    integer(c_int) :: rc
    rc = c_finalize(s%handle)
    call c_destroy(s%handle)
    s%handle = c_null_ptr
    call check(rc, ierr)
  end subroutine

end module panoptes
