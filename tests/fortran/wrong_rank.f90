! Must NOT compile: a rank-1 array where lantern_set_positions wants x(3, n). The test
! fortran.wrong_rank_is_a_compile_error expects the compiler to name the generic.
program wrong_rank
  use, intrinsic :: iso_c_binding
  use lantern
  implicit none
  real(c_double), target :: x(30)
  type(lantern_particle_set) :: set
  x = 0
  call lantern_set_positions(set, x)
end program wrong_rank
