! A small MD-style Fortran code rendered in situ through the Fortran module `lantern`: particles
! of a derived type sit on a lattice, split over the MPI ranks, and drift for a few steps; Lantern
! borrows the atoms array (never copying it) and renders the steps its schedule picks.
!
! Usage: mpiexec -n 2 lattice_md [CONFIG]
!   CONFIG: a YAML path; by default one scene rendering the last step into lattice_000004.png.
program lattice_md
  use, intrinsic :: iso_c_binding
  use mpi
  use lantern
  implicit none

  ! The simulation's own particle record; Lantern reads x and type in place (stride: the record).
  type, bind(C) :: atom
    real(c_double) :: x(3)
    real(c_double) :: v(3)
    integer(c_int32_t) :: type
  end type atom

  integer, parameter :: nside = 8, nsteps = 4
  type(atom), allocatable, target :: atoms(:)
  type(lantern_context) :: ctx
  type(lantern_particle_set) :: set
  character(len=:), allocatable :: config
  character(len=512) :: argument
  integer :: ierr, rank, nranks, n, step

  call mpi_init(ierr)
  call mpi_comm_rank(MPI_COMM_WORLD, rank, ierr)
  call mpi_comm_size(MPI_COMM_WORLD, nranks, ierr)
  call create_atoms(rank, nranks, atoms)
  n = size(atoms)

  config = 'schedule: {steps: [4]}'//new_line('a')// &
           'scenes:'//new_line('a')// &
           '  - {width: 96, height: 96, radius: 0.5, color: {by: type},'// &
           ' output: {pattern: "lattice_{step:06d}.png"}}'//new_line('a')
  if (command_argument_count() >= 1) then
    call get_command_argument(1, argument)
    config = trim(argument)
  end if

  ! With `use mpi_f08`, pass MPI_COMM_WORLD%MPI_VAL.
  call check(lantern_open(config, MPI_COMM_WORLD, ctx), 'lantern_open')
  ! Published once: the atoms array is updated in place and never reallocated.
  if (n > 0) then
    call lantern_set_positions_strided(set, atoms(1)%x(1), c_sizeof(atoms(1)), n)
    call lantern_set_field_strided(set, LANTERN_FIELD_TYPE, atoms(1)%type, c_sizeof(atoms(1)))
  end if
  call check(lantern_publish(ctx, set), 'lantern_publish')
  do step = 0, nsteps
    if (step > 0) call advance(atoms)
    call check(lantern_execute(ctx, step, real(step, c_double)), 'lantern_execute')
  end do
  call check(lantern_close(ctx), 'lantern_close')
  if (rank == 0) print '(a,i0,a,i0,a)', 'lattice_md: ', nside**3, ' particles on ', nranks, &
    ' ranks rendered'
  call mpi_finalize(ierr)

contains

  ! This rank's particles: global index g = 0 .. nside^3 - 1 with mod(g, nranks) == rank, each at
  ! its lattice point with a velocity of multiples of 1/8 (so every position is exact in binary).
  subroutine create_atoms(rank, nranks, atoms)
    integer, intent(in) :: rank, nranks
    type(atom), allocatable, intent(out) :: atoms(:)
    integer :: g, i
    allocate (atoms((nside**3 - rank + nranks - 1)/nranks))
    i = 0
    do g = rank, nside**3 - 1, nranks
      i = i + 1
      atoms(i)%x = real([mod(g, nside), mod(g/nside, nside), g/(nside*nside)], c_double)
      atoms(i)%v = [0.25_c_double*mod(g, 3), 0.125_c_double*mod(g, 2), -0.25_c_double*mod(g, 5)]
      atoms(i)%type = int(mod(g, 3), c_int32_t)
    end do
  end subroutine create_atoms

  subroutine advance(atoms)
    type(atom), intent(inout) :: atoms(:)
    integer :: i
    do i = 1, size(atoms)
      atoms(i)%x = atoms(i)%x + atoms(i)%v
    end do
  end subroutine advance

  subroutine check(status, what)
    integer(c_int), intent(in) :: status
    character(len=*), intent(in) :: what
    integer :: ierr
    if (status == LANTERN_OK) return
    print '(a)', 'lattice_md: '//what//': '//lantern_status_string(status)//': '// &
      lantern_error_message(ctx)
    call mpi_abort(MPI_COMM_WORLD, 1, ierr)
  end subroutine check

end program lattice_md
