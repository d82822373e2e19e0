! The Fortran module against the C API: struct layouts equal C's; the same lattice published
! through every setter (x(3,n), x(n,3), arrays of a derived type, float32, a hand-filled
! lantern_particles) gives the same image bytes; shape and length problems and C errors come
! back as statuses with messages naming the array or key; bonds (lantern_set_bonds, ghosts, a
! hand-filled lantern_bonds) draw cylinders and are refused naming the bond. Serial.
program fortran_binding_test
  use, intrinsic :: iso_c_binding
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use lantern
  implicit none

  interface
    integer(c_size_t) function sizeof_array() bind(C, name="lantern_test_sizeof_array")
      import :: c_size_t
    end function sizeof_array
    integer(c_size_t) function sizeof_particles() bind(C, name="lantern_test_sizeof_particles")
      import :: c_size_t
    end function sizeof_particles
    integer(c_size_t) function offsetof_mask_bits() bind(C, name="lantern_test_offsetof_mask_bits")
      import :: c_size_t
    end function offsetof_mask_bits
    integer(c_size_t) function offsetof_id() bind(C, name="lantern_test_offsetof_id")
      import :: c_size_t
    end function offsetof_id
    integer(c_size_t) function sizeof_bonds() bind(C, name="lantern_test_sizeof_bonds")
      import :: c_size_t
    end function sizeof_bonds
    integer(c_size_t) function offsetof_listing() bind(C, name="lantern_test_offsetof_listing")
      import :: c_size_t
    end function offsetof_listing
  end interface

  type, bind(C) :: atom
    integer(c_int64_t) :: id
    real(c_double) :: x(3)
    integer(c_int32_t) :: type
  end type atom

  integer, parameter :: nside = 4, n = nside**3
  real(c_double), target :: x(3, n), xn(n, 3), x4(4, n), xbig(n + 7, 3), x2(3, 2*n)
  real(c_float), target :: xf(3, n)
  integer(c_int32_t), target :: types(n), short_types(5), ints(n), tbig(2*n)
  integer(c_int64_t), target :: mask(n)
  type(atom), target :: atoms(n)
  type(lantern_particles), target :: layout
  type(lantern_particle_set) :: set
  type(lantern_particles) :: by_hand
  integer :: failures = 0, i
  character(len=:), allocatable :: reference

  ! ---- layouts ----
  call expect(c_sizeof(lantern_array()) == sizeof_array(), 'sizeof(lantern_array) equals C''s')
  call expect(c_sizeof(layout) == sizeof_particles(), 'sizeof(lantern_particles) equals C''s')
  call expect(byte_offset(c_loc(layout%mask_bits)) == offsetof_mask_bits(), &
              'offsetof(lantern_particles, mask_bits) equals C''s')
  call expect(byte_offset(c_loc(layout%id)) == offsetof_id(), 'offsetof(lantern_particles, id)')

  ! ---- one lattice, five ways ----
  do i = 1, n
    ! Spacings 1, 2, 3 and types mod 5: swapping two axes would change the image.
    x(:, i) = real([mod(i - 1, nside), 2*mod((i - 1)/nside, nside), 3*((i - 1)/(nside*nside))], &
                   c_double)
    xn(i, :) = x(:, i)
    types(i) = int(mod(i - 1, 5), c_int32_t)
    atoms(i) = atom(int(i, c_int64_t), x(:, i), types(i))
  end do
  xf = real(x, c_float)

  call lantern_set_positions(set, x)
  call lantern_set_field(set, LANTERN_FIELD_TYPE, types)
  reference = render(set, 'interleaved')
  call expect(len(reference) > 100, 'x(3,n) rendered an image')

  set = lantern_particle_set()
  call lantern_set_position_components(set, xn)
  call lantern_set_field(set, LANTERN_FIELD_TYPE, types)
  call expect(render(set, 'components') == reference, 'x(n,3) gives the x(3,n) image')

  set = lantern_particle_set()
  call lantern_set_positions_strided(set, atoms(1)%x(1), c_sizeof(atoms(1)), n)
  call lantern_set_field_strided(set, LANTERN_FIELD_TYPE, atoms(1)%type, c_sizeof(atoms(1)))
  call lantern_set_field_strided(set, LANTERN_FIELD_ID, atoms(1)%id, c_sizeof(atoms(1)))
  call expect(render(set, 'derived') == reference, 'an array of a derived type gives it too')
  call expect(c_associated(set%particles%position%data, c_loc(atoms(1)%x(1))), &
              'the derived type is borrowed in place')

  set = lantern_particle_set()
  call lantern_set_positions(set, xf)
  call lantern_set_field(set, LANTERN_FIELD_TYPE, types)
  call expect(render(set, 'float32') == reference, 'float32 positions give it too')
  call expect(c_associated(set%particles%position%data, c_loc(xf(1, 1))), &
              'x(3,n) is borrowed in place')

  set = lantern_particle_set()
  by_hand%count = n
  by_hand%position = lantern_array(c_loc(x), LANTERN_FLOAT64, 0)
  by_hand%type = lantern_array(c_loc(types), LANTERN_INT32, 0)
  set%particles = by_hand
  call expect(render(set, 'by_hand') == reference, 'a hand-filled lantern_particles gives it')

  ! ---- sections, borrowed where they lie (through `contiguous` dummies, the compiler passed them
  ! as temporary copies, freed when the setter returned: C then read freed memory) ----
  set = lantern_particle_set()
  xbig = -1
  xbig(1:n, :) = xn
  tbig = 99
  tbig(1:2*n:2) = types
  call lantern_set_position_components(set, xbig(1:n, :))
  call lantern_set_field(set, LANTERN_FIELD_TYPE, tbig(1:2*n:2))
  call expect(render(set, 'sections') == reference, &
              'pos(1:n, :) of pos(n + 7, 3) and types(1:2n:2) give the image')
  call expect(c_associated(set%particles%position_x%data, c_loc(xbig(1, 1))) .and. &
              c_associated(set%particles%position_z%data, c_loc(xbig(1, 3))) .and. &
              c_associated(set%particles%type%data, c_loc(tbig(1))), &
              'sections are borrowed in place')
  set = lantern_particle_set()
  x2 = -1
  x2(:, 1:2*n:2) = x
  call lantern_set_positions(set, x2(:, 1:2*n:2))
  call lantern_set_field(set, LANTERN_FIELD_TYPE, types)
  call expect(render(set, 'every_other') == reference, 'x(:, 1:2n:2) gives the image')
  call expect(c_associated(set%particles%position%data, c_loc(x2(1, 1))), &
              'x(:, 1:2n:2) is borrowed in place')
  set = lantern_particle_set()
  call lantern_set_positions(set, x(3:1:-1, :))
  call expect_refusal(set, 'not adjacent', 'x(3:1:-1, :) is refused')

  ! ---- problems a setter finds, reported by lantern_publish ----
  set = lantern_particle_set()
  call lantern_set_positions(set, x4)
  call expect_refusal(set, '4 rows, not 3', 'x(4,n) is refused')
  set = lantern_particle_set()
  call lantern_set_positions(set, x)
  call lantern_set_field(set, LANTERN_FIELD_TYPE, short_types)
  call expect_refusal(set, 'type: 5 elements, but there are 64 particles', 'a short array')
  set = lantern_particle_set()
  call lantern_set_positions(set, x)
  call lantern_set_field(set, LANTERN_FIELD_RADIUS, ints)
  call expect_refusal(set, 'radius: give a real', 'an integer radius is refused')
  set = lantern_particle_set()
  call lantern_set_field(set, LANTERN_FIELD_TYPE, types)
  call expect_refusal(set, 'set the positions first', 'a field before the positions')
  set = lantern_particle_set()
  call lantern_set_positions(set, x)
  mask = 1
  call lantern_set_field(set, LANTERN_FIELD_MASK, mask)
  set%particles%mask_bits = 1
  call expect(c_associated(set%particles%mask%data, c_loc(mask(1))) .and. &
              set%particles%mask%type == LANTERN_INT64, 'the mask is borrowed in place')

  call c_errors()
  call bonds()

  if (failures > 0) then
    print '(i0,a)', failures, ' check(s) failed'
    error stop 1
  end if
  print '(a)', 'fortran_binding_test: all checks passed'

contains

  subroutine expect(condition, what)
    logical, intent(in) :: condition
    character(len=*), intent(in) :: what
    if (condition) then
      print '(a)', 'ok    '//what
    else
      print '(a)', 'FAIL  '//what
      failures = failures + 1
    end if
  end subroutine expect

  integer(c_size_t) function byte_offset(p)
    type(c_ptr), intent(in) :: p
    byte_offset = int(transfer(p, 0_c_intptr_t) - transfer(c_loc(layout), 0_c_intptr_t), c_size_t)
  end function byte_offset

  function config(label, bonded) result(text)
    character(len=*), intent(in) :: label
    logical, intent(in), optional :: bonded
    character(len=:), allocatable :: text, extra
    extra = ''
    if (present(bonded)) then
      if (bonded) extra = 'bonds: {radius: 0.2, color: by_type}, '
    end if
    text = 'gl: none'//new_line('a')//'scenes:'//new_line('a')// &
           '  - {width: 40, height: 40, radius: 0.5, color: {by: type}, '//extra// &
           'output: {pattern: "fortran_bindings/'//label//'_{step:06d}.png"}}'//new_line('a')
  end function config

  ! Publishes the set in a fresh context, renders step 0, returns the image file's bytes.
  ! With bonded_config the scene draws bonds; by_hand: bonds published after the set.
  function render(set, label, bonded_config, by_hand) result(bytes)
    type(lantern_particle_set), intent(in) :: set
    character(len=*), intent(in) :: label
    logical, intent(in), optional :: bonded_config
    type(lantern_bonds), intent(in), optional :: by_hand
    character(len=:), allocatable :: bytes
    type(lantern_context) :: ctx
    integer :: status, unit, size_bytes
    bytes = ''
    status = lantern_open(config(label, bonded_config), LANTERN_COMM_WORLD, ctx)
    if (status == LANTERN_OK) status = lantern_publish(ctx, set)
    if (status == LANTERN_OK .and. present(by_hand)) status = lantern_publish_bonds(ctx, by_hand)
    if (status == LANTERN_OK) status = lantern_execute(ctx, 0, 0.0_c_double)
    if (status /= LANTERN_OK) print '(a)', label//': '//lantern_error_message(ctx)
    status = lantern_close(ctx)
    open (newunit=unit, file='fortran_bindings/'//label//'_000000.png', access='stream', &
          form='unformatted', status='old', iostat=status)
    if (status /= 0) return
    inquire (unit=unit, size=size_bytes)
    deallocate (bytes)
    allocate (character(len=size_bytes) :: bytes)
    read (unit) bytes
    close (unit)
  end function render

  subroutine expect_refusal(set, text, what)
    type(lantern_particle_set), intent(in) :: set
    character(len=*), intent(in) :: text, what
    type(lantern_context) :: ctx
    integer :: status
    status = lantern_open(config('refused'), LANTERN_COMM_WORLD, ctx)
    status = lantern_publish(ctx, set)
    call expect(status == LANTERN_ERR_INVALID_ARGUMENT .and. &
                index(lantern_error_message(ctx), text) > 0, &
                what//' ('//lantern_error_message(ctx)//')')
    status = lantern_close(ctx)
  end subroutine expect_refusal

  ! A zigzag chain of 8 atoms; bonds between neighbours. The same bonds through the int32 and
  ! int64 setters and by hand give one image, which differs from the unbonded one; a ghost is a
  ! bond end only; bad bonds come back from C naming the bond.
  subroutine bonds()
    integer, parameter :: m = 8
    real(c_double), target :: cx(3, m)
    integer(c_int32_t), target :: ct(m), pairs4(2, m - 1), bad(2, 1), kinds(m - 1)
    integer(c_int64_t), target :: ids(m), pairs8(2, m - 1)
    type(lantern_bonds), target :: hand, bond_layout
    type(lantern_context) :: ctx
    character(len=:), allocatable :: plain, bonded, ghosted
    integer :: k, status
    call expect(c_sizeof(bond_layout) == sizeof_bonds(), 'sizeof(lantern_bonds) equals C''s')
    call expect(transfer(c_loc(bond_layout%listing), 0_c_intptr_t) - &
                transfer(c_loc(bond_layout), 0_c_intptr_t) == int(offsetof_listing(), &
                                                                     c_intptr_t), &
                'offsetof(lantern_bonds, listing) equals C''s')
    do k = 1, m
      cx(:, k) = [2.0_c_double*(k - 1), merge(1.0_c_double, 0.0_c_double, mod(k, 2) == 0), &
                  0.0_c_double]
      ct(k) = int(mod(k, 3), c_int32_t)
      ids(k) = 100 + k
    end do
    do k = 1, m - 1  ! 0-based indices, as in C
      pairs4(:, k) = [k - 1, k]
      kinds(k) = int(mod(k, 2), c_int32_t)
    end do
    pairs8 = int(pairs4, c_int64_t)

    set = lantern_particle_set()
    call lantern_set_positions(set, cx)
    call lantern_set_field(set, LANTERN_FIELD_TYPE, ct)
    plain = render(set, 'chain_plain', bonded_config=.true.)
    call lantern_set_bonds(set, pairs4)
    call lantern_set_bond_types(set, kinds)
    bonded = render(set, 'chain_i4', bonded_config=.true.)
    call expect(len(bonded) > 100 .and. bonded /= plain, 'bonds change the image')
    call expect(c_associated(set%bonds%first%data, c_loc(pairs4(1, 1))) .and. &
                c_associated(set%bonds%second%data, c_loc(pairs4(2, 1))) .and. &
                set%bonds%first%stride_bytes == 8, 'pairs(2, m) is borrowed as two columns')
    call lantern_set_bonds(set, pairs8)
    call expect(render(set, 'chain_i8', bonded_config=.true.) == bonded, &
                'int64 pairs give the int32 image')

    set = lantern_particle_set()
    call lantern_set_positions(set, cx)
    call lantern_set_field(set, LANTERN_FIELD_TYPE, ct)
    hand%count = m - 1
    hand%first = lantern_array(c_loc(pairs4(1, 1)), LANTERN_INT32, 8)
    hand%second = lantern_array(c_loc(pairs4(2, 1)), LANTERN_INT32, 8)
    hand%type = lantern_array(c_loc(kinds), LANTERN_INT32, 0)
    call expect(render(set, 'chain_hand', bonded_config=.true., by_hand=hand) == bonded, &
                'a hand-filled lantern_bonds gives the same image')

    ! The last atom as a ghost: its sphere is gone, the half-bond to it stays.
    set = lantern_particle_set()
    call lantern_set_positions(set, cx)
    call lantern_set_field(set, LANTERN_FIELD_TYPE, ct)
    call lantern_set_field(set, LANTERN_FIELD_ID, ids)
    call lantern_set_bonds(set, pairs4, ghost_count=1)
    call lantern_set_bond_types(set, kinds)
    ghosted = render(set, 'chain_ghost', bonded_config=.true.)
    call expect(len(ghosted) > 100 .and. ghosted /= bonded .and. ghosted /= plain, &
                'a ghost is drawn as a bond end only')
    call lantern_set_bonds(set, pairs4, ghost_count=9)
    call expect_refusal(set, 'ghost_count: 9 ghosts, but the arrays hold only 8', &
                        'more ghosts than particles')

    set = lantern_particle_set()
    call lantern_set_positions(set, cx)
    bad(:, 1) = [0, 8]
    call lantern_set_bonds(set, bad)
    call expect_refusal(set, 'bonds.second[0]: 8 is not below', 'a bond index out of range')
    set = lantern_particle_set()
    call lantern_set_positions(set, cx)
    call lantern_set_bond_types(set, kinds)
    call expect_refusal(set, 'set the bonds first', 'bond types before bonds')

    status = lantern_open(config('bonds_c'), LANTERN_COMM_WORLD, ctx)
    status = lantern_publish_bonds(ctx, hand)
    call expect(status /= LANTERN_OK, 'bonds without particles are refused ('// &
                lantern_error_message(ctx)//')')
    status = lantern_close(ctx)
  end subroutine bonds

  subroutine c_errors()
    type(lantern_context) :: ctx
    integer :: status
    status = lantern_open('scenes:'//new_line('a')//'  - {widht: 10}'//new_line('a'), &
                          LANTERN_COMM_WORLD, ctx)
    call expect(status == LANTERN_ERR_CONFIG .and. index(lantern_error_message(ctx), 'widht') > 0, &
                'a misspelt key: LANTERN_ERR_CONFIG naming it ('//lantern_error_message(ctx)//')')
    status = lantern_close(ctx)
    call expect(index(lantern_status_string(LANTERN_ERR_IO), 'LANTERN_ERR_IO: ') == 1, &
                'lantern_status_string names the status')
    call expect(len(lantern_version()) >= 5, 'lantern_version: '//lantern_version())
    status = lantern_open(config('box'), LANTERN_COMM_WORLD, ctx)
    status = lantern_set_box(ctx, [0d0, 0d0, 0d0], [1d0, -1d0, 1d0])
    call expect(status == LANTERN_ERR_INVALID_ARGUMENT .and. len(lantern_error_message(ctx)) > 0, &
                'a C refusal comes back with its message ('//lantern_error_message(ctx)//')')
    status = lantern_set_box(ctx, [0d0, 0d0, 0d0], [1d0, 1d0, 1d0], [.true., .true., .false.])
    call expect(status == LANTERN_OK, 'a valid box after a refused one')
    status = lantern_set_box(ctx, [0d0, 0d0, 0d0], [1d0, 1d0, 1d0], tilt=[0.5d0, ieee_value(1d0, &
                             ieee_quiet_nan), 0d0])
    call expect(status == LANTERN_ERR_INVALID_ARGUMENT .and. &
                index(lantern_error_message(ctx), 'tilt[1] (xz)') > 0, &
                'a triclinic box with a NaN tilt is refused, naming it ('// &
                lantern_error_message(ctx)//')')
    status = lantern_set_box(ctx, [0d0, 0d0, 0d0], [1d0, 1d0, 1d0], [.true., .true., .true.], &
                             [0.5d0, -0.25d0, 0d0])
    call expect(status == LANTERN_OK, 'a triclinic box')
    status = lantern_close(ctx)
  end subroutine c_errors

end program fortran_binding_test
