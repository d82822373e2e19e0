/* The C sizes and offsets that the Fortran module's bind(C) mirrors must reproduce. */
#include <lantern/lantern.h>
#include <stddef.h>

size_t lantern_test_sizeof_array(void) {
  return sizeof(lantern_array);
}
size_t lantern_test_sizeof_particles(void) {
  return sizeof(lantern_particles);
}
size_t lantern_test_offsetof_mask_bits(void) {
  return offsetof(lantern_particles, mask_bits);
}
size_t lantern_test_offsetof_id(void) {
  return offsetof(lantern_particles, id);
}
size_t lantern_test_sizeof_bonds(void) {
  return sizeof(lantern_bonds);
}
size_t lantern_test_offsetof_listing(void) {
  return offsetof(lantern_bonds, listing);
}
