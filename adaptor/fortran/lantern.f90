! Fortran 2003 module `lantern`: Lantern's C API (adaptor/include/lantern/lantern.h) for Fortran
! simulation codes, through iso_c_binding.
!
! The C structs are mirrored by bind(C) types (lantern_array, lantern_particles), the status and
! datatype codes by named constants. On top of them:
!   * lantern_open / lantern_publish / lantern_set_box / lantern_execute / lantern_close, each a
!     function returning the lantern_status (LANTERN_OK on success);
!   * lantern_error_message(ctx) and lantern_status_string(status) as allocatable strings;
!   * a lantern_particle_set and setters that fill it from the simulation's own arrays:
!     x(3,n) interleaved (lantern_set_positions), x(n,3) as three components
!     (lantern_set_position_components), rank-1 per-particle arrays (lantern_set_field), and
!     arrays of derived types (lantern_set_positions_strided / lantern_set_field_strided with the
!     stride c_sizeof(atoms(1))). A shape or length problem found by a setter is reported by the
!     next lantern_publish (LANTERN_ERR_INVALID_ARGUMENT, message naming the array);
!   * bonds (lantern_publish_bonds in C): lantern_set_bonds(set, pairs, ghost_count, listing)
!     puts a pairs(2, m) bond list into the set, and lantern_set_bond_types its types(m);
!     lantern_publish then publishes the particles and the bonds. Indices are 0-based, as in C
!     (entry j of the particle arrays is index j - 1): Lantern borrows the array and cannot shift
!     it. With ghost_count = g the last g entries of every particle array are ghosts (other
!     ranks' atoms, bond ends only; give their ids). lantern_bonds mirrors the C struct for
!     filling by hand (lantern_publish_bonds).
!
! Borrowing: Lantern reads the arrays in place (no copy) until the next publish or close, so they
! must have the TARGET attribute and stay allocated and unmoved until then. The setters take
! assumed-shape `target` dummies (not `contiguous`: for such a dummy the compiler silently passes
! a non-contiguous section as a temporary copy, which dies when the setter returns) and hand C the
! caller's own memory with the section's steps in bytes, so pos(1:nlocal, :) of a pos(nmax, 3),
! x(:, 1:n:2) or a(1:n:3) are borrowed where they lie. An actual argument that is an expression
! (real(x, c_double), x + 0) is a temporary whatever the dummy: pass a variable. Generic
! interfaces make a wrong rank or kind a compile-time error.
!
! MPI: lantern_open takes the communicator's Fortran handle: MPI_COMM_WORLD or any communicator
! from `use mpi`; with `use mpi_f08` pass comm%MPI_VAL; LANTERN_COMM_WORLD needs no MPI module.
! Threads: one thread at a time per context, as in C. Units: the simulation's.
module lantern
  use, intrinsic :: iso_c_binding
  implicit none
  private

  ! lantern_status
  integer(c_int), parameter, public :: LANTERN_OK = 0, LANTERN_ERR_NULL_ARGUMENT = 1, &
    LANTERN_ERR_INVALID_ARGUMENT = 2, LANTERN_ERR_CONFIG = 3, LANTERN_ERR_IO = 4, &
    LANTERN_ERR_GL = 5, LANTERN_ERR_MPI = 6, LANTERN_ERR_OUT_OF_MEMORY = 7, &
    LANTERN_ERR_INTERNAL = 8
  ! lantern_datatype
  integer(c_int), parameter, public :: LANTERN_TYPE_NONE = 0, LANTERN_FLOAT32 = 1, &
    LANTERN_FLOAT64 = 2, LANTERN_INT32 = 3, LANTERN_INT64 = 4
  integer, parameter, public :: LANTERN_COMM_WORLD = -1
  ! lantern_bond_listing
  integer(c_int), parameter, public :: LANTERN_BONDS_LISTED_ONCE = 0, &
    LANTERN_BONDS_LISTED_BY_BOTH = 1
  ! The optional per-particle arrays, for lantern_set_field (Fortran only).
  integer, parameter, public :: LANTERN_FIELD_RADIUS = 1, LANTERN_FIELD_SCALAR = 2, &
    LANTERN_FIELD_TYPE = 3, LANTERN_FIELD_ID = 4, LANTERN_FIELD_MASK = 5

  ! struct lantern_array: element i at data + i * stride_bytes (0: tightly packed).
  type, bind(C), public :: lantern_array
    type(c_ptr) :: data = c_null_ptr
    integer(c_int) :: type = LANTERN_TYPE_NONE
    integer(c_int64_t) :: stride_bytes = 0
  end type lantern_array

  ! struct lantern_particles (same fields, same order).
  type, bind(C), public :: lantern_particles
    integer(c_int64_t) :: count = 0
    type(lantern_array) :: position, position_x, position_y, position_z
    type(lantern_array) :: radius, scalar, type, id, mask
    integer(c_int64_t) :: mask_bits = 0
  end type lantern_particles

  ! struct lantern_bonds (same fields, same order): first/second are 0-based particle indices.
  type, bind(C), public :: lantern_bonds
    integer(c_int64_t) :: count = 0
    type(lantern_array) :: first, second, type
    integer(c_int64_t) :: ghost_count = 0
    integer(c_int) :: listing = LANTERN_BONDS_LISTED_ONCE
  end type lantern_bonds

  ! An open context (lantern_context *), plus the message of a check made on the Fortran side.
  type, public :: lantern_context
    private
    type(c_ptr) :: handle = c_null_ptr
    character(len=:), allocatable :: error
  end type lantern_context

  ! What one lantern_publish hands over, filled by the lantern_set_* setters. `particles` may
  ! also be filled by hand.
  type, public :: lantern_particle_set
    type(lantern_particles) :: particles
    type(lantern_bonds) :: bonds  ! with has_bonds: published after the particles
    logical :: has_bonds = .false.
    logical, private :: counted = .false.
    character(len=:), allocatable, private :: error
  end type lantern_particle_set

  public :: lantern_open, lantern_publish, lantern_set_box, lantern_execute, lantern_close
  public :: lantern_error_message, lantern_status_string, lantern_version
  public :: lantern_set_positions, lantern_set_position_components, lantern_set_positions_strided
  public :: lantern_set_field, lantern_set_field_strided
  public :: lantern_publish_bonds, lantern_set_bonds, lantern_set_bond_types

  interface lantern_publish
    module procedure publish_set, publish_particles
  end interface lantern_publish
  interface lantern_execute
    module procedure execute_i4, execute_i8
  end interface lantern_execute
  ! pairs(2, m): the 0-based particle indices of bond k in pairs(:, k).
  interface lantern_set_bonds
    module procedure set_bonds_i4, set_bonds_i8
  end interface lantern_set_bonds
  ! types(m): the type of bond k.
  interface lantern_set_bond_types
    module procedure set_bond_types_i4, set_bond_types_i8
  end interface lantern_set_bond_types
  ! x(3, n): x, y, z of particle j in x(:, j).
  interface lantern_set_positions
    module procedure set_positions_f4, set_positions_f8
  end interface lantern_set_positions
  ! x(n, 3): component k of particle j in x(j, k).
  interface lantern_set_position_components
    module procedure set_components_f4, set_components_f8
  end interface lantern_set_position_components
  ! first: x of the first particle (y, z follow it), stride_bytes apart, count particles.
  interface lantern_set_positions_strided
    module procedure set_strided_positions_f4, set_strided_positions_f8
  end interface lantern_set_positions_strided
  ! a(n): one optional per-particle array (LANTERN_FIELD_*), real or integer as the field wants.
  interface lantern_set_field
    module procedure set_field_f4, set_field_f8, set_field_i4, set_field_i8
  end interface lantern_set_field
  ! first: the field of the first particle, stride_bytes apart (arrays of derived types).
  interface vector_array
    module procedure vector_f4, vector_f8, vector_i4, vector_i8
  end interface vector_array
  interface lantern_set_field_strided
    module procedure set_strided_field_f4, set_strided_field_f8, set_strided_field_i4, &
      set_strided_field_i8
  end interface lantern_set_field_strided

  interface
    integer(c_int) function c_open(config, comm, ctx) bind(C, name="lantern_open")
      import :: c_int, c_char, c_ptr
      character(kind=c_char), intent(in) :: config(*)
      integer(c_int), value :: comm
      type(c_ptr), intent(out) :: ctx
    end function c_open
    integer(c_int) function c_publish(ctx, particles) bind(C, name="lantern_publish")
      import :: c_int, c_ptr, lantern_particles
      type(c_ptr), value :: ctx
      type(lantern_particles), intent(in) :: particles
    end function c_publish
    integer(c_int) function c_publish_bonds(ctx, bonds) bind(C, name="lantern_publish_bonds")
      import :: c_int, c_ptr, lantern_bonds
      type(c_ptr), value :: ctx
      type(lantern_bonds), intent(in) :: bonds
    end function c_publish_bonds
    integer(c_int) function c_set_box(ctx, low, high, periodic) bind(C, name="lantern_set_box")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: ctx
      real(c_double), intent(in) :: low(3), high(3)
      integer(c_int), intent(in) :: periodic(3)
    end function c_set_box
    integer(c_int) function c_set_triclinic_box(ctx, low, high, tilt, periodic) &
      bind(C, name="lantern_set_triclinic_box")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: ctx
      real(c_double), intent(in) :: low(3), high(3), tilt(3)
      integer(c_int), intent(in) :: periodic(3)
    end function c_set_triclinic_box
    integer(c_int) function c_execute(ctx, step, time) bind(C, name="lantern_execute")
      import :: c_int, c_ptr, c_int64_t, c_double
      type(c_ptr), value :: ctx
      integer(c_int64_t), value :: step
      real(c_double), value :: time
    end function c_execute
    integer(c_int) function c_close(ctx) bind(C, name="lantern_close")
      import :: c_int, c_ptr
      type(c_ptr), value :: ctx
    end function c_close
    type(c_ptr) function c_error_message(ctx) bind(C, name="lantern_error_message")
      import :: c_ptr
      type(c_ptr), value :: ctx
    end function c_error_message
    type(c_ptr) function c_status_string(status) bind(C, name="lantern_status_string")
      import :: c_ptr, c_int
      integer(c_int), value :: status
    end function c_status_string
    type(c_ptr) function c_version() bind(C, name="lantern_version")
      import :: c_ptr
    end function c_version
    integer(c_size_t) function c_strlen(s) bind(C, name="strlen")
      import :: c_size_t, c_ptr
      type(c_ptr), value :: s
    end function c_strlen
  end interface

contains

  ! ---- strings ------------------------------------------------------------------------------

  ! A NUL-terminated C string as a Fortran string ("" for NULL).
  function from_c_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: n, i
    if (.not. c_associated(p)) then
      s = ''
      return
    end if
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate (character(len=n) :: s)
    do i = 1, n
      s(i:i) = chars(i)
    end do
  end function from_c_string

  function to_c_string(s) result(chars)
    character(len=*), intent(in) :: s
    character(kind=c_char) :: chars(len(s) + 1)
    integer :: i
    do i = 1, len(s)
      chars(i) = s(i:i)
    end do
    chars(len(s) + 1) = c_null_char
  end function to_c_string

  function int_text(i) result(s)
    integer(c_int64_t), intent(in) :: i
    character(len=:), allocatable :: s
    character(len=24) :: buffer
    write (buffer, '(i0)') i
    s = trim(buffer)
  end function int_text

  ! ---- the C API ----------------------------------------------------------------------------

  ! Opens a context (collective). config: a YAML path or document; comm: the Fortran handle of
  ! the communicator (mpi_f08: comm%MPI_VAL) or LANTERN_COMM_WORLD. On failure ctx holds only the
  ! message: read it with lantern_error_message(ctx), then lantern_close(ctx).
  integer(c_int) function lantern_open(config, comm, ctx) result(status)
    character(len=*), intent(in) :: config
    integer, intent(in) :: comm
    type(lantern_context), intent(out) :: ctx
    status = c_open(to_c_string(config), int(comm, c_int), ctx%handle)
  end function lantern_open

  ! Borrows the particles of a set (see the setters); local.
  integer(c_int) function publish_set(ctx, set) result(status)
    type(lantern_context), intent(inout) :: ctx
    type(lantern_particle_set), intent(in) :: set
    if (allocated(ctx%error)) deallocate (ctx%error)
    if (allocated(set%error)) then
      ctx%error = set%error
      status = LANTERN_ERR_INVALID_ARGUMENT
      return
    end if
    if (.not. set%has_bonds) then
      status = c_publish(ctx%handle, set%particles)
      return
    end if
    if (set%bonds%ghost_count > set%particles%count) then
      ctx%error = 'ghost_count: '//int_text(set%bonds%ghost_count)//' ghosts, but the arrays '// &
                  'hold only '//int_text(set%particles%count)//' particles'
      status = LANTERN_ERR_INVALID_ARGUMENT
      return
    end if
    block  ! the ghosts are the last entries of the arrays, never counted
      type(lantern_particles) :: owned
      owned = set%particles
      owned%count = owned%count - set%bonds%ghost_count
      status = c_publish(ctx%handle, owned)
    end block
    if (status == LANTERN_OK) status = c_publish_bonds(ctx%handle, set%bonds)
  end function publish_set

  ! Borrows bonds described by hand (after lantern_publish), exactly as lantern_publish_bonds in C.
  integer(c_int) function lantern_publish_bonds(ctx, bonds) result(status)
    type(lantern_context), intent(inout) :: ctx
    type(lantern_bonds), intent(in) :: bonds
    if (allocated(ctx%error)) deallocate (ctx%error)
    status = c_publish_bonds(ctx%handle, bonds)
  end function lantern_publish_bonds

  ! Borrows particles described by hand, exactly as lantern_publish in C.
  integer(c_int) function publish_particles(ctx, particles) result(status)
    type(lantern_context), intent(inout) :: ctx
    type(lantern_particles), intent(in) :: particles
    if (allocated(ctx%error)) deallocate (ctx%error)
    status = c_publish(ctx%handle, particles)
  end function publish_particles

  ! The simulation box's corners; periodic per axis (absent: not periodic). With tilt =
  ! [xy, xz, yz], a triclinic box in LAMMPS's restricted form (lantern_set_triclinic_box: edge
  ! vectors (lx, 0, 0), (xy, ly, 0), (xz, yz, lz) from low, l = high - low). Local.
  integer(c_int) function lantern_set_box(ctx, low, high, periodic, tilt) result(status)
    type(lantern_context), intent(inout) :: ctx
    real(c_double), intent(in) :: low(3), high(3)
    logical, intent(in), optional :: periodic(3)
    real(c_double), intent(in), optional :: tilt(3)
    integer(c_int) :: flags(3)
    if (allocated(ctx%error)) deallocate (ctx%error)
    flags = 0
    if (present(periodic)) where (periodic) flags = 1
    if (present(tilt)) then
      status = c_set_triclinic_box(ctx%handle, low, high, tilt, flags)
    else
      status = c_set_box(ctx%handle, low, high, flags)
    end if
  end function lantern_set_box

  ! The simulation reached `step` at `time`; renders on scheduled steps (then collective).
  integer(c_int) function execute_i8(ctx, step, time) result(status)
    type(lantern_context), intent(inout) :: ctx
    integer(c_int64_t), intent(in) :: step
    real(c_double), intent(in) :: time
    if (allocated(ctx%error)) deallocate (ctx%error)
    status = c_execute(ctx%handle, step, time)
  end function execute_i8

  integer(c_int) function execute_i4(ctx, step, time) result(status)
    type(lantern_context), intent(inout) :: ctx
    integer(c_int32_t), intent(in) :: step
    real(c_double), intent(in) :: time
    status = execute_i8(ctx, int(step, c_int64_t), time)
  end function execute_i4

  ! Flushes outputs and frees the context (collective); ctx is closed afterwards.
  integer(c_int) function lantern_close(ctx) result(status)
    type(lantern_context), intent(inout) :: ctx
    if (allocated(ctx%error)) deallocate (ctx%error)
    status = c_close(ctx%handle)
    ctx%handle = c_null_ptr
  end function lantern_close

  ! The last error of ctx, naming the argument or key at fault; "" if none.
  function lantern_error_message(ctx) result(message)
    type(lantern_context), intent(in) :: ctx
    character(len=:), allocatable :: message
    if (allocated(ctx%error)) then
      message = ctx%error
    else
      message = from_c_string(c_error_message(ctx%handle))
    end if
  end function lantern_error_message

  ! "LANTERN_ERR_IO: a file could not be read or written", for logs.
  function lantern_status_string(status) result(text)
    integer(c_int), intent(in) :: status
    character(len=:), allocatable :: text
    text = from_c_string(c_status_string(status))
  end function lantern_status_string

  ! The library's version, "major.minor.patch".
  function lantern_version() result(text)
    character(len=:), allocatable :: text
    text = from_c_string(c_version())
  end function lantern_version

  ! ---- setters ------------------------------------------------------------------------------

  ! Records the first problem found in a set; lantern_publish reports it.
  subroutine fail(set, message)
    type(lantern_particle_set), intent(inout) :: set
    character(len=*), intent(in) :: message
    if (.not. allocated(set%error)) set%error = message
  end subroutine fail

  ! Sets the count from the positions, clearing any positions given before.
  subroutine count_positions(set, n)
    type(lantern_particle_set), intent(inout) :: set
    integer(c_int64_t), intent(in) :: n
    set%particles%count = n
    set%counted = .true.
    set%particles%position = lantern_array()
    set%particles%position_x = lantern_array()
    set%particles%position_y = lantern_array()
    set%particles%position_z = lantern_array()
  end subroutine count_positions

  ! c_loc of an element, or NULL for an empty array (c_loc of nothing is not allowed).
  type(c_ptr) function address_or_null(n, first) result(p)
    integer(c_int64_t), intent(in) :: n
    type(c_ptr), intent(in) :: first
    p = c_null_ptr
    if (n > 0) p = first
  end function address_or_null

  ! a(n) as a lantern_array: its first element and its step in bytes (the element's size for
  ! fewer than 2). One per kind, through the generic vector_array.
  type(lantern_array) function vector_f8(a, datatype, element_bytes) result(v)
    real(c_double), intent(in), target :: a(:)
    integer(c_int), intent(in) :: datatype
    integer(c_size_t), intent(in) :: element_bytes
    v = lantern_array(c_null_ptr, datatype, int(element_bytes, c_int64_t))
    if (size(a) > 0) v%data = c_loc(a(1))
    if (size(a) > 1) v%stride_bytes = bytes_between(v%data, c_loc(a(2)))
  end function vector_f8

  type(lantern_array) function vector_f4(a, datatype, element_bytes) result(v)
    real(c_float), intent(in), target :: a(:)
    integer(c_int), intent(in) :: datatype
    integer(c_size_t), intent(in) :: element_bytes
    v = lantern_array(c_null_ptr, datatype, int(element_bytes, c_int64_t))
    if (size(a) > 0) v%data = c_loc(a(1))
    if (size(a) > 1) v%stride_bytes = bytes_between(v%data, c_loc(a(2)))
  end function vector_f4

  type(lantern_array) function vector_i8(a, datatype, element_bytes) result(v)
    integer(c_int64_t), intent(in), target :: a(:)
    integer(c_int), intent(in) :: datatype
    integer(c_size_t), intent(in) :: element_bytes
    v = lantern_array(c_null_ptr, datatype, int(element_bytes, c_int64_t))
    if (size(a) > 0) v%data = c_loc(a(1))
    if (size(a) > 1) v%stride_bytes = bytes_between(v%data, c_loc(a(2)))
  end function vector_i8

  type(lantern_array) function vector_i4(a, datatype, element_bytes) result(v)
    integer(c_int32_t), intent(in), target :: a(:)
    integer(c_int), intent(in) :: datatype
    integer(c_size_t), intent(in) :: element_bytes
    v = lantern_array(c_null_ptr, datatype, int(element_bytes, c_int64_t))
    if (size(a) > 0) v%data = c_loc(a(1))
    if (size(a) > 1) v%stride_bytes = bytes_between(v%data, c_loc(a(2)))
  end function vector_i4

  ! Bytes from the element at a to the element at b: a section's step as the compiler laid it out.
  integer(c_int64_t) function bytes_between(a, b) result(d)
    type(c_ptr), intent(in) :: a, b
    d = int(transfer(b, 0_c_intptr_t) - transfer(a, 0_c_intptr_t), c_int64_t)
  end function bytes_between

  ! x(rows, n) from `first`: x, y and z of a particle row_step bytes apart (they must be adjacent),
  ! particles stride bytes apart.
  subroutine interleaved(set, rows, n, first, datatype, element_bytes, row_step, stride)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: rows
    integer(c_int64_t), intent(in) :: n, element_bytes, row_step, stride
    type(c_ptr), intent(in) :: first
    integer(c_int), intent(in) :: datatype
    if (rows /= 3) then
      call fail(set, 'lantern_set_positions: x has '//int_text(int(rows, c_int64_t))// &
                ' rows, not 3: give x(3, n), or x(n, 3) to lantern_set_position_components')
      return
    end if
    if (row_step /= element_bytes) then
      call fail(set, 'lantern_set_positions: x''s rows are '//int_text(row_step)// &
                ' bytes apart, not adjacent (a section such as x(3:1:-1, :)): give x(3, n) '// &
                'with x, y and z next to each other')
      return
    end if
    call count_positions(set, n)
    set%particles%position = lantern_array(address_or_null(n, first), datatype, stride)
  end subroutine interleaved

  subroutine set_positions_f8(set, x)
    type(lantern_particle_set), intent(inout) :: set
    real(c_double), intent(in), target :: x(:, :)
    type(c_ptr) :: first
    integer(c_int64_t) :: element, row_step, stride
    element = int(c_sizeof(0.0_c_double), c_int64_t)
    first = c_null_ptr
    row_step = element
    stride = 3*element
    if (size(x) > 0) first = c_loc(x(1, 1))
    if (size(x) > 0 .and. size(x, 1) > 1) row_step = bytes_between(first, c_loc(x(2, 1)))
    if (size(x) > 0 .and. size(x, 2) > 1) stride = bytes_between(first, c_loc(x(1, 2)))
    call interleaved(set, size(x, 1), int(size(x, 2), c_int64_t), first, LANTERN_FLOAT64, element, &
                     row_step, stride)
  end subroutine set_positions_f8

  subroutine set_positions_f4(set, x)
    type(lantern_particle_set), intent(inout) :: set
    real(c_float), intent(in), target :: x(:, :)
    type(c_ptr) :: first
    integer(c_int64_t) :: element, row_step, stride
    element = int(c_sizeof(0.0_c_float), c_int64_t)
    first = c_null_ptr
    row_step = element
    stride = 3*element
    if (size(x) > 0) first = c_loc(x(1, 1))
    if (size(x) > 0 .and. size(x, 1) > 1) row_step = bytes_between(first, c_loc(x(2, 1)))
    if (size(x) > 0 .and. size(x, 2) > 1) stride = bytes_between(first, c_loc(x(1, 2)))
    call interleaved(set, size(x, 1), int(size(x, 2), c_int64_t), first, LANTERN_FLOAT32, element, &
                     row_step, stride)
  end subroutine set_positions_f4

  ! x(n, columns): component k of the particles from first(k), step bytes apart.
  subroutine components(set, columns, n, first, datatype, step)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: columns
    integer(c_int64_t), intent(in) :: n, step
    type(c_ptr), intent(in) :: first(3)
    integer(c_int), intent(in) :: datatype
    if (columns /= 3) then
      call fail(set, 'lantern_set_position_components: x has '// &
                int_text(int(columns, c_int64_t))// &
                ' columns, not 3: give x(n, 3), or x(3, n) to lantern_set_positions')
      return
    end if
    call count_positions(set, n)
    set%particles%position_x = lantern_array(address_or_null(n, first(1)), datatype, step)
    set%particles%position_y = lantern_array(address_or_null(n, first(2)), datatype, step)
    set%particles%position_z = lantern_array(address_or_null(n, first(3)), datatype, step)
  end subroutine components

  subroutine set_components_f8(set, x)
    type(lantern_particle_set), intent(inout) :: set
    real(c_double), intent(in), target :: x(:, :)
    type(c_ptr) :: first(3)
    integer(c_int64_t) :: step
    integer :: k
    first = c_null_ptr
    step = int(c_sizeof(0.0_c_double), c_int64_t)
    if (size(x, 1) > 0 .and. size(x, 2) == 3) first = [(c_loc(x(1, k)), k=1, 3)]
    if (size(x, 1) > 1 .and. size(x, 2) == 3) step = bytes_between(first(1), c_loc(x(2, 1)))
    call components(set, size(x, 2), int(size(x, 1), c_int64_t), first, LANTERN_FLOAT64, step)
  end subroutine set_components_f8

  subroutine set_components_f4(set, x)
    type(lantern_particle_set), intent(inout) :: set
    real(c_float), intent(in), target :: x(:, :)
    type(c_ptr) :: first(3)
    integer(c_int64_t) :: step
    integer :: k
    first = c_null_ptr
    step = int(c_sizeof(0.0_c_float), c_int64_t)
    if (size(x, 1) > 0 .and. size(x, 2) == 3) first = [(c_loc(x(1, k)), k=1, 3)]
    if (size(x, 1) > 1 .and. size(x, 2) == 3) step = bytes_between(first(1), c_loc(x(2, 1)))
    call components(set, size(x, 2), int(size(x, 1), c_int64_t), first, LANTERN_FLOAT32, step)
  end subroutine set_components_f4

  subroutine set_strided_positions_f8(set, first, stride_bytes, count)
    type(lantern_particle_set), intent(inout) :: set
    real(c_double), intent(in), target :: first
    integer(c_size_t), intent(in) :: stride_bytes
    integer, intent(in) :: count
    call count_positions(set, int(count, c_int64_t))
    set%particles%position = lantern_array(address_or_null(int(count, c_int64_t), c_loc(first)), &
                                           LANTERN_FLOAT64, int(stride_bytes, c_int64_t))
  end subroutine set_strided_positions_f8

  subroutine set_strided_positions_f4(set, first, stride_bytes, count)
    type(lantern_particle_set), intent(inout) :: set
    real(c_float), intent(in), target :: first
    integer(c_size_t), intent(in) :: stride_bytes
    integer, intent(in) :: count
    call count_positions(set, int(count, c_int64_t))
    set%particles%position = lantern_array(address_or_null(int(count, c_int64_t), c_loc(first)), &
                                           LANTERN_FLOAT32, int(stride_bytes, c_int64_t))
  end subroutine set_strided_positions_f4

  ! Puts `a` into the set's field, after checking that the field takes this kind of element and
  ! that the length matches the positions.
  subroutine field(set, which, n, a, real_elements)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: which
    integer(c_int64_t), intent(in) :: n
    type(lantern_array), intent(in) :: a
    logical, intent(in) :: real_elements
    character(len=6), parameter :: names(5) = ['radius', 'scalar', 'type  ', 'id    ', 'mask  ']
    character(len=:), allocatable :: name
    if (which < 1 .or. which > 5) then
      call fail(set, 'lantern_set_field: unknown field '//int_text(int(which, c_int64_t))// &
                ' (give LANTERN_FIELD_RADIUS, _SCALAR, _TYPE, _ID or _MASK)')
      return
    end if
    name = trim(names(which))
    if (real_elements .neqv. which <= LANTERN_FIELD_SCALAR) then
      if (which <= LANTERN_FIELD_SCALAR) then
        call fail(set, name//': give a real(c_float) or real(c_double) array')
      else
        call fail(set, name//': give an integer(c_int32_t) or integer(c_int64_t) array')
      end if
      return
    end if
    if (.not. set%counted) then
      call fail(set, name//': set the positions first (they give the particle count)')
      return
    end if
    if (n /= set%particles%count) then
      call fail(set, name//': '//int_text(n)//' elements, but there are '// &
                int_text(set%particles%count)//' particles (positions)')
      return
    end if
    select case (which)
    case (LANTERN_FIELD_RADIUS)
      set%particles%radius = a
    case (LANTERN_FIELD_SCALAR)
      set%particles%scalar = a
    case (LANTERN_FIELD_TYPE)
      set%particles%type = a
    case (LANTERN_FIELD_ID)
      set%particles%id = a
    case (LANTERN_FIELD_MASK)
      set%particles%mask = a
    end select
  end subroutine field

  subroutine set_field_f8(set, which, a)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: which
    real(c_double), intent(in), target :: a(:)
    call field(set, which, int(size(a), c_int64_t), vector_array(a, LANTERN_FLOAT64, c_sizeof(0.0_c_double)), .true.)
  end subroutine set_field_f8

  subroutine set_field_f4(set, which, a)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: which
    real(c_float), intent(in), target :: a(:)
    call field(set, which, int(size(a), c_int64_t), vector_array(a, LANTERN_FLOAT32, c_sizeof(0.0_c_float)), .true.)
  end subroutine set_field_f4

  subroutine set_field_i8(set, which, a)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: which
    integer(c_int64_t), intent(in), target :: a(:)
    call field(set, which, int(size(a), c_int64_t), vector_array(a, LANTERN_INT64, c_sizeof(0_c_int64_t)), .false.)
  end subroutine set_field_i8

  subroutine set_field_i4(set, which, a)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: which
    integer(c_int32_t), intent(in), target :: a(:)
    call field(set, which, int(size(a), c_int64_t), vector_array(a, LANTERN_INT32, c_sizeof(0_c_int32_t)), .false.)
  end subroutine set_field_i4

  subroutine set_strided_field_f8(set, which, first, stride_bytes)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: which
    real(c_double), intent(in), target :: first
    integer(c_size_t), intent(in) :: stride_bytes
    call field(set, which, set%particles%count, &
               lantern_array(c_loc(first), LANTERN_FLOAT64, stride_bytes), .true.)
  end subroutine set_strided_field_f8

  subroutine set_strided_field_f4(set, which, first, stride_bytes)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: which
    real(c_float), intent(in), target :: first
    integer(c_size_t), intent(in) :: stride_bytes
    call field(set, which, set%particles%count, &
               lantern_array(c_loc(first), LANTERN_FLOAT32, stride_bytes), .true.)
  end subroutine set_strided_field_f4

  subroutine set_strided_field_i8(set, which, first, stride_bytes)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: which
    integer(c_int64_t), intent(in), target :: first
    integer(c_size_t), intent(in) :: stride_bytes
    call field(set, which, set%particles%count, &
               lantern_array(c_loc(first), LANTERN_INT64, stride_bytes), .false.)
  end subroutine set_strided_field_i8

  subroutine set_strided_field_i4(set, which, first, stride_bytes)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: which
    integer(c_int32_t), intent(in), target :: first
    integer(c_size_t), intent(in) :: stride_bytes
    call field(set, which, set%particles%count, &
               lantern_array(c_loc(first), LANTERN_INT32, stride_bytes), .false.)
  end subroutine set_strided_field_i4

  ! Puts a bond list into the set: pairs (rows, m), which must be (2, m), seen as two columns
  ! from `first` and `second`, stride bytes apart, the ghost count and the listing
  ! (LANTERN_BONDS_LISTED_ONCE when absent).
  subroutine bond_list(set, rows, m, first, second, stride, datatype, ghost_count, listing)
    type(lantern_particle_set), intent(inout) :: set
    integer, intent(in) :: rows
    integer(c_int64_t), intent(in) :: m
    type(c_ptr), intent(in) :: first, second
    integer(c_int64_t), intent(in) :: stride
    integer(c_int), intent(in) :: datatype
    integer, intent(in), optional :: ghost_count
    integer(c_int), intent(in), optional :: listing
    if (rows /= 2) then
      call fail(set, 'bonds: pairs has '//int_text(int(rows, c_int64_t))// &
                ' rows, not 2 (give pairs(2, m))')
      return
    end if
    set%has_bonds = .true.
    set%bonds%count = m
    set%bonds%first = lantern_array(first, datatype, stride)
    set%bonds%second = lantern_array(second, datatype, stride)
    set%bonds%ghost_count = 0
    if (present(ghost_count)) set%bonds%ghost_count = int(ghost_count, c_int64_t)
    if (set%bonds%ghost_count < 0) &
      call fail(set, 'ghost_count: '//int_text(set%bonds%ghost_count)//' is negative')
    set%bonds%listing = LANTERN_BONDS_LISTED_ONCE
    if (present(listing)) set%bonds%listing = listing
  end subroutine bond_list

  subroutine set_bonds_i4(set, pairs, ghost_count, listing)
    type(lantern_particle_set), intent(inout) :: set
    integer(c_int32_t), intent(in), target :: pairs(:, :)
    integer, intent(in), optional :: ghost_count
    integer(c_int), intent(in), optional :: listing
    type(c_ptr) :: first, second
    integer(c_int64_t) :: stride
    first = c_null_ptr
    second = c_null_ptr
    stride = 2*c_sizeof(0_c_int32_t)
    if (size(pairs) > 0) first = c_loc(pairs(1, 1))
    if (size(pairs) > 0 .and. size(pairs, 1) > 1) second = c_loc(pairs(2, 1))
    if (size(pairs) > 0 .and. size(pairs, 2) > 1) stride = bytes_between(first, c_loc(pairs(1, 2)))
    call bond_list(set, size(pairs, 1), int(size(pairs, 2), c_int64_t), first, second, stride, &
                   LANTERN_INT32, ghost_count, listing)
  end subroutine set_bonds_i4

  subroutine set_bonds_i8(set, pairs, ghost_count, listing)
    type(lantern_particle_set), intent(inout) :: set
    integer(c_int64_t), intent(in), target :: pairs(:, :)
    integer, intent(in), optional :: ghost_count
    integer(c_int), intent(in), optional :: listing
    type(c_ptr) :: first, second
    integer(c_int64_t) :: stride
    first = c_null_ptr
    second = c_null_ptr
    stride = 2*c_sizeof(0_c_int64_t)
    if (size(pairs) > 0) first = c_loc(pairs(1, 1))
    if (size(pairs) > 0 .and. size(pairs, 1) > 1) second = c_loc(pairs(2, 1))
    if (size(pairs) > 0 .and. size(pairs, 2) > 1) stride = bytes_between(first, c_loc(pairs(1, 2)))
    call bond_list(set, size(pairs, 1), int(size(pairs, 2), c_int64_t), first, second, stride, &
                   LANTERN_INT64, ghost_count, listing)
  end subroutine set_bonds_i8

  subroutine bond_types(set, m, a)
    type(lantern_particle_set), intent(inout) :: set
    integer(c_int64_t), intent(in) :: m
    type(lantern_array), intent(in) :: a
    if (.not. set%has_bonds) then
      call fail(set, 'bond types: set the bonds first (lantern_set_bonds)')
    else if (m /= set%bonds%count) then
      call fail(set, 'bond types: '//int_text(m)//' elements, but there are '// &
                int_text(set%bonds%count)//' bonds')
    else
      set%bonds%type = a
    end if
  end subroutine bond_types

  subroutine set_bond_types_i4(set, types)
    type(lantern_particle_set), intent(inout) :: set
    integer(c_int32_t), intent(in), target :: types(:)
    call bond_types(set, int(size(types), c_int64_t), vector_array(types, LANTERN_INT32, c_sizeof(0_c_int32_t)))
  end subroutine set_bond_types_i4

  subroutine set_bond_types_i8(set, types)
    type(lantern_particle_set), intent(inout) :: set
    integer(c_int64_t), intent(in), target :: types(:)
    call bond_types(set, int(size(types), c_int64_t), vector_array(types, LANTERN_INT64, c_sizeof(0_c_int64_t)))
  end subroutine set_bond_types_i8

end module lantern
