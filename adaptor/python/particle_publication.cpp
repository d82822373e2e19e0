#include "particle_publication.h"

namespace py = pybind11;

namespace lantern_python {
namespace {

std::string shape_text(const std::vector<int64_t> &shape) {
  if (shape.empty()) return "() (a 0-d array: one number, not an array of particles)";
  std::string s = "(";
  for (size_t axis = 0; axis < shape.size(); ++axis)
    s += (axis ? ", " : "") + std::to_string(shape[axis]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

// The byte stride of one axis as the C API takes it (positive, at least one element), or throws.
// A stride over an axis of extent <= 1 is never used: it becomes the element size.
int64_t usable_stride(const BorrowedBuffer &b, size_t axis, const std::string &what) {
  if (b.shape()[axis] <= 1) return b.itemsize();
  const int64_t s = b.strides()[axis];
  if (s == 0)
    throw py::value_error(b.name() + ": " + what +
                          " stride is 0 (a broadcast view repeats one element); publish an "
                          "array that holds every particle");
  if (s < 0)
    throw py::value_error(b.name() + ": " + what + " stride is negative (" + std::to_string(s) +
                          " bytes, a reversed view), which Lantern cannot borrow; publish the "
                          "array in its original order");
  if (s < b.itemsize())
    throw py::value_error(b.name() + ": " + what + " stride of " + std::to_string(s) +
                          " bytes is not a whole element (" + std::to_string(b.itemsize()) +
                          " bytes): the elements overlap");
  return s;
}

}  // namespace

void ParticlePublication::record(const char *name, const lantern_array &a) {
  pointers_.emplace_back(name, reinterpret_cast<uintptr_t>(a.data));
}

void ParticlePublication::positions(const py::object &object) {
  held_.push_back(BorrowedBuffer::borrow(object, "position", ElementKind::kReal));
  const BorrowedBuffer &b = held_.back();
  if (b.shape().size() != 2 || b.shape()[1] != 3)
    throw py::value_error("position: shape " + shape_text(b.shape()) +
                          " is not (n, 3); give x, y, z of each particle in a row, or "
                          "position_x/y/z");
  particles_.count = b.shape()[0];
  counted_ = true;
  const int64_t row = usable_stride(b, 0, "row");
  const int64_t component = b.strides()[1];
  if (component == b.itemsize() && row >= 3 * b.itemsize()) {  // x, y, z adjacent: interleaved
    particles_.position = {b.data(), b.type(), row};
    record("position", particles_.position);
    return;
  }
  // x, y, z a fixed stride apart (e.g. a Fortran-ordered array): three component views.
  usable_stride(b, 1, "component");
  lantern_array *parts[3] = {&particles_.position_x, &particles_.position_y,
                             &particles_.position_z};
  const char *names[3] = {"position_x", "position_y", "position_z"};
  for (int k = 0; k < 3; ++k) {
    *parts[k] = {b.data() + k * component, b.type(), row};
    record(names[k], *parts[k]);
  }
}

lantern_array ParticlePublication::one_dimensional(const py::object &object, const char *name,
                                                   ElementKind kind) {
  if (object.is_none()) return {};
  held_.push_back(BorrowedBuffer::borrow(object, name, kind));
  const BorrowedBuffer &b = held_.back();
  if (b.shape().size() != 1)
    throw py::value_error(std::string(name) + ": shape " + shape_text(b.shape()) +
                          " is not one-dimensional (n,)");
  const int64_t n = b.shape()[0];
  if (!counted_) {  // position_x sets the count for position_y/z and the rest
    particles_.count = n;
    counted_ = true;
  } else if (n != particles_.count) {
    throw py::value_error(std::string(name) + ": " + std::to_string(n) +
                          " elements, but there are " + std::to_string(particles_.count) +
                          " particles (positions)");
  }
  const lantern_array a{b.data(), b.type(), usable_stride(b, 0, "element")};
  record(name, a);
  return a;
}

// The bond list: an (m, 2) integer array whose columns are each bond's two atoms (indices into
// the published rows, ghosts included), borrowed as two strided views, and its (m,) types.
void ParticlePublication::describe_bonds(const PublishArguments &args) {
  if (args.ghost_count < 0)
    throw py::value_error("ghost_count: " + std::to_string(args.ghost_count) + " is negative");
  if (args.ghost_count > particles_.count)
    throw py::value_error("ghost_count: " + std::to_string(args.ghost_count) +
                          " ghosts, but the arrays hold only " + std::to_string(particles_.count) +
                          " rows");
  if (args.bonds_listed == "once") {
    bonds_.listing = LANTERN_BONDS_LISTED_ONCE;
  } else if (args.bonds_listed == "by_both") {
    bonds_.listing = LANTERN_BONDS_LISTED_BY_BOTH;
  } else {
    throw py::value_error("bonds_listed: '" + args.bonds_listed +
                          "' is neither 'once' nor 'by_both'");
  }
  if (args.bonds.is_none() && !args.bond_type.is_none())
    throw py::value_error("bond_type: given without bonds");
  has_bonds_ = !args.bonds.is_none() || args.ghost_count > 0;
  bonds_.ghost_count = args.ghost_count;
  particles_.count -= args.ghost_count;  // the ghosts are the last rows, never counted
  if (args.bonds.is_none()) return;
  held_.push_back(BorrowedBuffer::borrow(args.bonds, "bonds", ElementKind::kInteger));
  const BorrowedBuffer &b = held_.back();
  if (b.shape().size() != 2 || b.shape()[1] != 2)
    throw py::value_error("bonds: shape " + shape_text(b.shape()) +
                          " is not (m, 2); give the two atoms of each bond in a row");
  bonds_.count = b.shape()[0];
  const int64_t row = usable_stride(b, 0, "row");
  const int64_t column = usable_stride(b, 1, "column");
  bonds_.first = {b.data(), b.type(), row};
  bonds_.second = {b.data() + column, b.type(), row};
  record("bonds.first", bonds_.first);
  record("bonds.second", bonds_.second);
  if (args.bond_type.is_none()) return;
  held_.push_back(BorrowedBuffer::borrow(args.bond_type, "bond_type", ElementKind::kInteger));
  const BorrowedBuffer &t = held_.back();
  if (t.shape().size() != 1 || t.shape()[0] != bonds_.count)
    throw py::value_error("bond_type: shape " + shape_text(t.shape()) + " is not (" +
                          std::to_string(bonds_.count) + ",), one type per bond");
  bonds_.type = {t.data(), t.type(), usable_stride(t, 0, "element")};
  record("bond_type", bonds_.type);
}

ParticlePublication ParticlePublication::describe(const PublishArguments &args) {
  ParticlePublication p;
  const bool separate =
      !args.position_x.is_none() || !args.position_y.is_none() || !args.position_z.is_none();
  if (!args.position.is_none() && separate)
    throw py::value_error("position: give either position or position_x/y/z, not both");
  if (separate &&
      (args.position_x.is_none() || args.position_y.is_none() || args.position_z.is_none()))
    throw py::value_error("position_x/y/z: give all three components");
  if (!args.position.is_none()) {
    p.positions(args.position);
  } else if (separate) {
    p.particles_.position_x = p.one_dimensional(args.position_x, "position_x", ElementKind::kReal);
    p.particles_.position_y = p.one_dimensional(args.position_y, "position_y", ElementKind::kReal);
    p.particles_.position_z = p.one_dimensional(args.position_z, "position_z", ElementKind::kReal);
  } else {
    p.counted_ = true;  // no positions: zero particles, so every other array must be empty
  }
  p.particles_.radius = p.one_dimensional(args.radius, "radius", ElementKind::kReal);
  p.particles_.scalar = p.one_dimensional(args.scalar, "scalar", ElementKind::kReal);
  p.particles_.type = p.one_dimensional(args.type, "type", ElementKind::kInteger);
  p.particles_.id = p.one_dimensional(args.id, "id", ElementKind::kInteger);
  p.particles_.mask = p.one_dimensional(args.mask, "mask", ElementKind::kInteger);
  p.particles_.mask_bits = args.mask_bits;
  p.describe_bonds(args);
  return p;
}

}  // namespace lantern_python
