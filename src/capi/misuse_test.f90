! The misuse suite through the Fortran module (issue 42), 2 ranks; run by misuse_test.sh with a config
! file (mpi_timeout = 3). Codes check ierr rarely: here it is passed and ignored where codes ignore it.
!   misuse_test_f short_array CONFIG  rank 1 hands an array one plane short: every rank's next
!                                     panoptes_step fails naming rank 1; the right array then works
!   misuse_test_f skipped_step CONFIG rank 1 skips one panoptes_step: both ranks' next call fails
! Every expected error must come within 10 s of the start; ctest's timeout catches a hang.
program misuse_test_f
  use mpi
  use panoptes
  use, intrinsic :: iso_fortran_env, only: real64, error_unit
  implicit none
  integer, parameter :: nx = 12, ny = 10, nz = 8
  character(len=16) :: mode
  character(len=512) :: config
  integer :: rank, nranks, ierr, rc, k0, k1, glo, ghi, failures, total
  real(real64), allocatable, target :: u(:, :, :), short(:, :, :)
  real(real64) :: started
  logical :: taken
  type(panoptes_t) :: viz

  call MPI_Init(ierr)
  call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks, ierr)
  call get_command_argument(1, mode)
  call get_command_argument(2, config)
  failures = 0
  started = MPI_Wtime()
  call panoptes_errors(PANOPTES_ERRORS_NONE)
  call panoptes_open(viz, config, MPI_COMM_WORLD)
  k0 = nz * rank / nranks
  k1 = nz * (rank + 1) / nranks
  glo = merge(1, 0, rank > 0)
  ghi = merge(1, 0, rank < nranks - 1)
  call panoptes_grid(viz, [nx, ny, nz], [0d0, 0d0, 0d0], [1d0, 1d0, 1d0])
  call panoptes_block(viz, [0, 0, k0], [nx, ny, k1 - k0], [0, 0, glo], [0, 0, ghi])
  allocate(u(nx, ny, k1 - k0 + glo + ghi), short(nx, ny, k1 - k0 + glo + ghi - 1))
  call random_number(u)
  short = 0
  call panoptes_field(viz, 'T', u, ierr=rc)
  call panoptes_step(viz, 0, 0d0, taken, rc)
  call expect(rc == 0 .and. taken, 'step 0')

  select case (trim(mode))
  case ('short_array')
    if (rank == 1) then
      call panoptes_field(viz, 'T', short, ierr=rc)  ! refused; the code goes on as if it were not
    else
      call panoptes_field(viz, 'T', u, ierr=rc)
    end if
    call panoptes_step(viz, 1, 0.1d0, taken, rc)
    if (rank == 1) then
      call expect_error(rc, 'field "T" is not bound', 'step 1 after the short array')
    else
      call expect_error(rc, 'rank 1 refused', 'step 1 after rank 1''s short array')
    end if
    call panoptes_field(viz, 'T', u, ierr=rc)
    call panoptes_step(viz, 2, 0.2d0, taken, rc)
    call expect(rc == 0 .and. taken, 'step 2 with the right array')
    call panoptes_close(viz, rc)
    call expect(rc == 0, 'close')
  case ('skipped_step')
    if (rank == 0) then
      call panoptes_step(viz, 1, 0.1d0, taken, rc)
      call expect_error(rc, 'out of step', 'rank 0 at step 1')
    end if
    call panoptes_step(viz, 2, 0.2d0, taken, rc)
    call expect_error(rc, 'out of step', 'step 2')
    call panoptes_close(viz, rc)
    call expect_error(rc, 'the session stopped', 'close after the ranks fell out of step')
  case default
    call expect(.false., 'unknown mode '//trim(mode))
  end select

  call MPI_Allreduce(failures, total, 1, MPI_INTEGER, MPI_SUM, MPI_COMM_WORLD, ierr)
  if (rank == 0 .and. total == 0) print '(a)', 'misuse_test_f '//trim(mode)//': every rank got its error in time'
  call MPI_Finalize(ierr)
  if (total /= 0) stop 1

contains

  subroutine expect(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (.not. ok) then
      write(error_unit, '(a, i0, a)') 'misuse_test_f: rank ', rank, ': FAIL: '//what//' ('//panoptes_error_message()//')'
      failures = failures + 1
    end if
  end subroutine

  subroutine expect_error(code, want, what)
    integer, intent(in) :: code
    character(len=*), intent(in) :: want, what
    character(len=:), allocatable :: msg
    msg = panoptes_error_message()
    if (code == 0 .or. index(msg, want) == 0 .or. MPI_Wtime() - started > 10) then
      write(error_unit, '(a, i0, a, f6.2, a)') 'misuse_test_f: rank ', rank, ': FAIL: '//what//' (after ', &
        MPI_Wtime() - started, ' s: '//msg//'; expected "'//want//'")'
      failures = failures + 1
    else
      write(*, '(a, i0, a, f6.2, a)') 'misuse_test_f: rank ', rank, ': '//what//': error after ', MPI_Wtime() - started, &
        ' s: '//msg
    end if
  end subroutine

end program misuse_test_f
