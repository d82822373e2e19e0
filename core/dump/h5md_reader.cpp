#include "core/dump/h5md_reader.h"

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <new>
#include <optional>

#include "core/common/collective_status.h"
#include "core/common/quoted_text.h"
#include "core/dump/h5md_layout.h"
#include "core/dump/hdf5_handle.h"

namespace lantern {
namespace {

std::vector<hsize_t> shape_of(hid_t dataset, const std::string &what) {
  const H5Handle space = own_space(H5Dget_space(dataset), what + ": dataspace");
  const int rank = H5Sget_simple_extent_ndims(space.get());
  h5_check(rank, what + ": dataspace rank");
  std::vector<hsize_t> dims(static_cast<size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

std::string shape_text(const std::vector<hsize_t> &dims) {
  std::string s = "[";
  for (size_t i = 0; i < dims.size(); ++i) s += (i ? "][" : "") + std::to_string(dims[i]);
  return s + "]";
}

bool link_exists(hid_t base, const std::string &path) {
  // Check each component: H5Lexists fails (rather than returning 0) on a missing parent.
  size_t pos = 0;
  while (pos != std::string::npos) {
    pos = path.find('/', pos + 1);
    const std::string prefix = path.substr(0, pos);
    if (prefix.empty() || prefix == "/") continue;
    if (H5Lexists(base, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
  }
  return true;
}

bool is_group(hid_t base, const std::string &path) {
  H5O_info_t info;
  return link_exists(base, path) &&
         H5Oget_info_by_name(base, path.c_str(), &info, H5P_DEFAULT) >= 0 &&
         info.type == H5O_TYPE_GROUP;
}

// Reads a whole 1-D dataset converted to T.
template <typename T>
std::vector<T> read_all(hid_t dataset, hid_t mem_type, hsize_t n, const std::string &what) {
  std::vector<T> out(n);
  if (n > 0)
    h5_check(H5Dread(dataset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()),
             what + ": read");
  return out;
}

// Reads the first n values of a 1-D dataset converted to T.
template <typename T>
std::vector<T> read_first(hid_t dataset, hid_t mem_type, hsize_t n, const std::string &what) {
  std::vector<T> out(n);
  if (n == 0) return out;
  const H5Handle file_space = own_space(H5Dget_space(dataset), what + ": dataspace");
  const hsize_t start = 0;
  h5_check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &start, nullptr, &n, nullptr),
           what + ": select");
  const H5Handle mem_space = own_space(H5Screate_simple(1, &n, nullptr), what + ": memspace");
  h5_check(H5Dread(dataset, mem_type, mem_space.get(), file_space.get(), H5P_DEFAULT, out.data()),
           what + ": read");
  return out;
}

// The first group under /particles, preferring "all" (Lantern's own name).
std::string particle_group(hid_t file) {
  if (!is_group(file, h5md::kParticles))
    throw Hdf5Error("not an H5MD particle file: no /particles group");
  if (is_group(file, std::string(h5md::kParticles) + "/" + h5md::kGroupName))
    return std::string(h5md::kParticles) + "/" + h5md::kGroupName;
  const H5Handle g = own_group(H5Gopen2(file, h5md::kParticles, H5P_DEFAULT), "/particles");
  H5G_info_t info;
  h5_check(H5Gget_info(g.get(), &info), "/particles: list");
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    char name[256] = {0};
    if (H5Lget_name_by_idx(g.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof(name),
                           H5P_DEFAULT) < 0)
      continue;
    const std::string path = std::string(h5md::kParticles) + "/" + name;
    if (is_group(file, path)) return path;
  }
  throw Hdf5Error("/particles has no particle group");
}

// One per-particle element: value [frames][N] (time-dependent) or [N] (fixed).
struct Field {
  H5Handle value;
  bool per_frame = true;
};

// A list of pairs under /connectivity: value [frames][B][2] with its steps, or [B][2].
struct BondList {
  std::string where;  // the value dataset's path, for messages
  H5Handle value;
  bool per_frame = false;
  hsize_t pairs = 0;                       // B
  std::map<int64_t, hsize_t> row_of_step;  // per_frame: the value row of each step
  std::optional<int64_t> fill;
};

// Bond lists larger than this are refused rather than allocated (a corrupt shape).
constexpr hsize_t kMaxBonds = hsize_t(1) << 32;

// The path of the object a connectivity element's particles_group attribute names: an object
// reference (H5MD 1.1), or a string (the group's path, or its name under /particles).
std::string particles_group_of(hid_t file, const std::string &path) {
  const std::string what = path + ": " + h5md::kParticlesGroupAttribute;
  if (H5Aexists_by_name(file, path.c_str(), h5md::kParticlesGroupAttribute, H5P_DEFAULT) <= 0)
    throw Hdf5Error(what + ": missing (H5MD names the particle group of a connectivity list)");
  const H5Handle attr = own_attr(
      H5Aopen_by_name(file, path.c_str(), h5md::kParticlesGroupAttribute, H5P_DEFAULT, H5P_DEFAULT),
      what);
  const H5Handle type = own_type(H5Aget_type(attr.get()), what + ": type");
  const H5Handle space = own_space(H5Aget_space(attr.get()), what + ": dataspace");
  if (H5Sget_simple_extent_npoints(space.get()) != 1)
    throw Hdf5Error(what + ": not a single value");
  const H5T_class_t cls = H5Tget_class(type.get());
  if (cls == H5T_REFERENCE) {
    if (H5Tequal(type.get(), H5T_STD_REF_OBJ) <= 0)
      throw Hdf5Error(what + ": not an object reference");
    hobj_ref_t ref{};
    h5_check(H5Aread(attr.get(), H5T_STD_REF_OBJ, &ref), what + ": read");
    const hid_t target = H5Rdereference2(attr.get(), H5P_DEFAULT, H5R_OBJECT, &ref);
    if (target < 0) throw Hdf5Error(what + ": a dangling object reference");
    const H5Handle object(target, H5Oclose);
    char name[1024] = {0};
    if (H5Iget_name(object.get(), name, sizeof name) <= 0)
      throw Hdf5Error(what + ": refers to an object without a name");
    return name;
  }
  if (cls == H5T_STRING && !H5Tis_variable_str(type.get())) {
    const size_t width = H5Tget_size(type.get());
    std::vector<char> text(width + 1, '\0');
    h5_check(H5Aread(attr.get(), type.get(), text.data()), what + ": read");
    const std::string name(text.data());
    return name.rfind('/', 0) == 0 ? name : std::string(h5md::kParticles) + "/" + name;
  }
  throw Hdf5Error(what + ": neither an object reference nor a string");
}

}  // namespace

struct H5mdReader::Impl {
  std::string path, group;
  H5Handle file;
  H5Handle position;
  std::optional<Field> species, id, scalar, radius;
  H5Handle edges, offset;  // [frames][3] or [3]; invalid when absent
  bool edges_per_frame = false, offset_per_frame = false;
  bool edges_matrix = false;  // edges [frames][3][3] or [3][3]: a triclinic box's edge vectors
  std::array<bool, 3> periodic{false, false, false};
  int64_t n = 0;  // rows of the per-particle datasets (N_max when the count varies)
  std::vector<FrameInfo> frames;
  // Rows that hold no particle: an `id` equal to its declared fill value (H5MD), or, in a file
  // without ids, a position that is all NaN where NaN is the declared fill value.
  // Not used with Lantern's counts (rows below the count are particles, whatever their id).
  std::optional<int64_t> id_fill;
  bool nan_position_fill = false;
  bool has_counts = false;
  // Lantern's files: the frames that are complete (the length of particle_count/time, the last
  // dataset a frame extends). A frame whose dump failed may have left other datasets one frame
  // longer; only the complete frames are read. Unset for other writers' files, whose datasets
  // must agree exactly.
  std::optional<hsize_t> complete;
  std::optional<BondList> bonds;
  std::string bonds_problem;  // why the bond list found cannot be used ("" when it can)
  bool bonds_found = false;

  void find_complete_frames();
  // Frames of a file (or dataset) whose first axis is `length`.
  hsize_t frame_axis(hsize_t length) const { return complete ? *complete : length; }
  // Whether a first axis of `length` holds the frames of one `expected` long.
  bool frames_fit(hsize_t length, hsize_t expected) const {
    return complete ? length >= *complete : length == expected;
  }

  void check_h5md() const;
  void open_position();
  void open_counts();
  void find_fill_values();
  void drop_fill_rows(size_t index, int64_t begin, ParticleFrame *f) const;
  std::optional<Field> open_field(const char *name) const;
  void open_box();
  void open_bonds();
  BondList open_bond_list(const std::string &path, bool per_frame) const;
  void read_rows(hid_t dataset, bool per_frame, size_t frame, int64_t begin, int64_t end, int cols,
                 hid_t mem_type, void *out, const std::string &what) const;
  // A triclinic box's tilt {xy, xz, yz} from the edges matrix of `frame`; its edge lengths in
  // *lengths. Throws Hdf5Error for edge vectors not in LAMMPS's restricted form.
  std::array<double, 3> read_tilt(size_t frame, std::array<double, 3> *lengths) const;
  std::optional<std::array<double, 3>> read_vec3(hid_t dataset, bool per_frame, size_t frame,
                                                 const std::string &what) const;
};

void H5mdReader::Impl::check_h5md() const {
  if (!is_group(file.get(), "/h5md")) throw Hdf5Error("not an H5MD file: no /h5md group");
  if (H5Aexists_by_name(file.get(), "/h5md", "version", H5P_DEFAULT) <= 0)
    throw Hdf5Error("not an H5MD file: /h5md has no version attribute");
}

void H5mdReader::Impl::open_position() {
  const std::string base = group + "/" + h5md::kPosition;
  if (!link_exists(file.get(), base + "/value"))
    throw Hdf5Error("missing dataset " + base + "/value");
  position =
      own_dataset(H5Dopen2(file.get(), (base + "/value").c_str(), H5P_DEFAULT), base + "/value");
  const auto dims = shape_of(position.get(), base + "/value");
  if (dims.size() != 3 || dims[2] != 3)
    throw Hdf5Error(base + "/value has shape " + shape_text(dims) + ", expected [frames][N][3]");
  n = static_cast<int64_t>(dims[1]);
  if (!link_exists(file.get(), base + "/step"))
    throw Hdf5Error("missing dataset " + base + "/step");
  const H5Handle step =
      own_dataset(H5Dopen2(file.get(), (base + "/step").c_str(), H5P_DEFAULT), base + "/step");
  const hsize_t f = frame_axis(dims[0]);
  if (dims[0] < f)
    throw Hdf5Error(base + "/value has " + std::to_string(dims[0]) + " frames but " +
                    h5md::kParticleCount + " has " + std::to_string(f));
  const auto sdims = shape_of(step.get(), base + "/step");
  if (sdims.size() != 1 || !frames_fit(sdims[0], dims[0]))
    throw Hdf5Error(base + "/step has shape " + shape_text(sdims) + " but " + base + "/value has " +
                    std::to_string(dims[0]) + " frames");
  const auto steps = read_first<int64_t>(step.get(), H5T_NATIVE_INT64, f, base + "/step");
  std::vector<double> times(f, 0.0);
  if (link_exists(file.get(), base + "/time")) {
    const H5Handle time =
        own_dataset(H5Dopen2(file.get(), (base + "/time").c_str(), H5P_DEFAULT), base + "/time");
    const auto tdims = shape_of(time.get(), base + "/time");
    if (tdims.size() != 1 || !frames_fit(tdims[0], dims[0]))
      throw Hdf5Error(base + "/time has shape " + shape_text(tdims) + " but " + base +
                      "/value has " + std::to_string(dims[0]) + " frames");
    times = read_first<double>(time.get(), H5T_NATIVE_DOUBLE, f, base + "/time");
  }
  for (size_t f = 0; f < steps.size(); ++f) frames.push_back({steps[f], times[f], n});
}

void H5mdReader::Impl::find_complete_frames() {
  const std::string path = std::string(h5md::kParticleCount) + "/time";
  if (!link_exists(file.get(), path)) return;
  const H5Handle time = own_dataset(H5Dopen2(file.get(), path.c_str(), H5P_DEFAULT), path);
  const auto dims = shape_of(time.get(), path);
  if (dims.size() != 1)
    throw Hdf5Error(path + " has shape " + shape_text(dims) + ", expected [frames]");
  complete = dims[0];
}

// Lantern's per-frame particle counts (/observables/particle_count): the frame's particles are
// rows [0, count). Without it every row may hold a particle.
void H5mdReader::Impl::open_counts() {
  const std::string path = std::string(h5md::kParticleCount) + "/value";
  if (!link_exists(file.get(), path)) return;
  const H5Handle value = own_dataset(H5Dopen2(file.get(), path.c_str(), H5P_DEFAULT), path);
  const auto dims = shape_of(value.get(), path);
  if (dims.size() != 1 || !frames_fit(dims[0], frames.size()))
    throw Hdf5Error(path + " has shape " + shape_text(dims) + " but position/value has " +
                    std::to_string(frames.size()) + " frames");
  const auto counts = read_first<int64_t>(value.get(), H5T_NATIVE_INT64, frames.size(), path);
  for (size_t f = 0; f < counts.size(); ++f) {
    if (counts[f] < 0 || counts[f] > n)
      throw Hdf5Error(path + "[" + std::to_string(f) + "] = " + std::to_string(counts[f]) +
                      " is outside [0, " + std::to_string(n) + "] (the rows of position/value)");
    frames[f].count = counts[f];
  }
  has_counts = true;
}

// The declared fill value of a dataset as T, if the writer set one.
template <typename T>
std::optional<T> user_fill_value(hid_t dataset, hid_t mem_type, const std::string &what) {
  const H5Handle dcpl = own_plist(H5Dget_create_plist(dataset), what + ": creation list");
  H5D_fill_value_t defined = H5D_FILL_VALUE_UNDEFINED;
  h5_check(H5Pfill_value_defined(dcpl.get(), &defined), what + ": fill value");
  if (defined != H5D_FILL_VALUE_USER_DEFINED) return std::nullopt;
  T value{};
  h5_check(H5Pget_fill_value(dcpl.get(), mem_type, &value), what + ": fill value");
  return value;
}

void H5mdReader::Impl::find_fill_values() {
  if (has_counts) return;
  if (id && id->per_frame)
    id_fill = user_fill_value<int64_t>(id->value.get(), H5T_NATIVE_INT64, group + "/id/value");
  if (!id_fill) {
    const auto fill =
        user_fill_value<double>(position.get(), H5T_NATIVE_DOUBLE, group + "/position/value");
    nan_position_fill = fill && std::isnan(*fill);
  }
}

std::optional<Field> H5mdReader::Impl::open_field(const char *name) const {
  const std::string base = group + "/" + name;
  if (!link_exists(file.get(), base)) return std::nullopt;
  Field f;
  f.per_frame = is_group(file.get(), base);
  const std::string path = f.per_frame ? base + "/value" : base;
  if (!link_exists(file.get(), path)) throw Hdf5Error("missing dataset " + path);
  f.value = own_dataset(H5Dopen2(file.get(), path.c_str(), H5P_DEFAULT), path);
  const auto dims = shape_of(f.value.get(), path);
  const std::vector<hsize_t> want = f.per_frame ? std::vector<hsize_t>{frames.size(), hsize_t(n)}
                                                : std::vector<hsize_t>{hsize_t(n)};
  const bool fits = f.per_frame
                        ? dims.size() == 2 && dims[1] == want[1] && frames_fit(dims[0], want[0])
                        : dims == want;
  if (!fits)
    throw Hdf5Error(path + " has shape " + shape_text(dims) + " but position/value is " +
                    shape_text({frames.size(), hsize_t(n), 3}) + " (expected " + shape_text(want) +
                    ")");
  return f;
}

void H5mdReader::Impl::open_box() {
  const std::string box = group + "/" + h5md::kBox;
  if (!is_group(file.get(), box)) return;
  if (H5Aexists_by_name(file.get(), box.c_str(), "boundary", H5P_DEFAULT) > 0) {
    const H5Handle attr =
        own_attr(H5Aopen_by_name(file.get(), box.c_str(), "boundary", H5P_DEFAULT, H5P_DEFAULT),
                 box + "/boundary");
    const H5Handle type = own_type(H5Aget_type(attr.get()), box + "/boundary: type");
    const H5Handle space = own_space(H5Aget_space(attr.get()), box + "/boundary: space");
    if (H5Tget_class(type.get()) == H5T_STRING && !H5Tis_variable_str(type.get()) &&
        H5Sget_simple_extent_npoints(space.get()) == 3) {
      const size_t width = H5Tget_size(type.get());
      std::vector<char> text(width * 3 + 1, '\0');
      h5_check(H5Aread(attr.get(), type.get(), text.data()), box + "/boundary: read");
      for (int a = 0; a < 3; ++a) periodic[a] = std::strncmp(&text[a * width], "periodic", 8) == 0;
    }
  }
  auto open_vec3 = [&](const char *name, H5Handle *out, bool *per_frame, bool *matrix) {
    const std::string base = box + "/" + name;
    if (!link_exists(file.get(), base)) return;
    *per_frame = is_group(file.get(), base);
    const std::string path = *per_frame ? base + "/value" : base;
    if (!link_exists(file.get(), path)) throw Hdf5Error("missing dataset " + path);
    *out = own_dataset(H5Dopen2(file.get(), path.c_str(), H5P_DEFAULT), path);
    const auto dims = shape_of(out->get(), path);
    // H5MD gives a triclinic box's edges as a D x D matrix (its edge vectors as rows).
    const size_t inner = *per_frame ? 1 : 0;
    if (matrix && dims.size() == inner + 2 && dims[inner] == 3 && dims[inner + 1] == 3)
      *matrix = true;
    const std::vector<hsize_t> want =
        *per_frame ? std::vector<hsize_t>{frames.size(), 3} : std::vector<hsize_t>{3};
    const bool fits = *per_frame ? dims.size() == (matrix && *matrix ? 3 : 2) && dims[1] == 3 &&
                                       frames_fit(dims[0], want[0])
                                 : dims == want || (matrix && *matrix);
    if (!fits)
      throw Hdf5Error(path + " has shape " + shape_text(dims) + ", expected " + shape_text(want) +
                      (matrix ? " (a box's edge lengths) or that by 3 (its edge vectors)" : ""));
  };
  open_vec3("edges", &edges, &edges_per_frame, &edges_matrix);
  open_vec3("offset", &offset, &offset_per_frame, nullptr);
}

void H5mdReader::Impl::read_rows(hid_t dataset, bool per_frame, size_t frame, int64_t begin,
                                 int64_t end, int cols, hid_t mem_type, void *out,
                                 const std::string &what) const {
  const hsize_t rows = static_cast<hsize_t>(end - begin);
  if (rows == 0) return;
  std::vector<hsize_t> start, count;
  if (per_frame) {
    start.push_back(frame);
    count.push_back(1);
  }
  start.push_back(static_cast<hsize_t>(begin));
  count.push_back(rows);
  if (cols > 1) {
    start.push_back(0);
    count.push_back(static_cast<hsize_t>(cols));
  }
  const H5Handle file_space = own_space(H5Dget_space(dataset), what + ": dataspace");
  h5_check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                               count.data(), nullptr),
           what + ": select");
  const hsize_t elements = rows * static_cast<hsize_t>(cols);
  const H5Handle mem_space =
      own_space(H5Screate_simple(1, &elements, nullptr), what + ": memspace");
  h5_check(H5Dread(dataset, mem_type, mem_space.get(), file_space.get(), H5P_DEFAULT, out),
           what + ": cannot read frame " + std::to_string(frame));
}

std::array<double, 3> H5mdReader::Impl::read_tilt(size_t frame,
                                                  std::array<double, 3> *lengths) const {
  const std::string what = group + "/box/edges";
  double e[9];  // rows a, b, c
  read_rows(edges.get(), edges_per_frame, frame, 0, 3, 3, H5T_NATIVE_DOUBLE, e, what);
  // LAMMPS's restricted form: a along x, b in the xy plane (Lantern's triclinic boxes).
  if (e[1] != 0.0 || e[2] != 0.0 || e[5] != 0.0)
    throw Hdf5Error(what + ": frame " + std::to_string(frame) +
                    ": the edge vectors must have a along x and b in the xy plane (a = [" +
                    std::to_string(e[0]) + ", " + std::to_string(e[1]) + ", " +
                    std::to_string(e[2]) + "], b_z = " + std::to_string(e[5]) + ")");
  *lengths = {e[0], e[4], e[8]};
  return {e[3], e[6], e[7]};  // xy = b_x, xz = c_x, yz = c_y
}

std::optional<std::array<double, 3>> H5mdReader::Impl::read_vec3(hid_t dataset, bool per_frame,
                                                                 size_t frame,
                                                                 const std::string &what) const {
  if (dataset < 0) return std::nullopt;
  std::array<double, 3> v{};
  read_rows(dataset, per_frame, frame, 0, 3, 1, H5T_NATIVE_DOUBLE, v.data(), what);
  return v;
}

// Removes the rows of a frame that hold no particle, keeping the order: with Lantern's counts
// the rows at or after the frame's count, else those id_fill or nan_position_fill marks.
void H5mdReader::Impl::drop_fill_rows(size_t index, int64_t begin, ParticleFrame *f) const {
  const int64_t count = frames[index].count;
  const auto is_fill = [&](size_t i) {
    if (has_counts) return begin + int64_t(i) >= count;
    if (id_fill) return f->id[i] == *id_fill;
    return std::isnan(f->position[3 * i]) && std::isnan(f->position[3 * i + 1]) &&
           std::isnan(f->position[3 * i + 2]);
  };
  if (!has_counts && !id_fill && !nan_position_fill) return;
  size_t kept = 0;
  const size_t rows = static_cast<size_t>(f->count());
  for (size_t i = 0; i < rows; ++i) {
    if (is_fill(i)) continue;
    for (int c = 0; c < 3; ++c) f->position[3 * kept + c] = f->position[3 * i + c];
    for (auto *v : {&f->type, &f->id})
      if (!v->empty()) (*v)[kept] = (*v)[i];
    for (auto *v : {&f->scalar, &f->radius})
      if (!v->empty()) (*v)[kept] = (*v)[i];
    ++kept;
  }
  f->position.resize(3 * kept);
  for (auto *v : {&f->type, &f->id})
    if (!v->empty()) v->resize(kept);
  for (auto *v : {&f->scalar, &f->radius})
    if (!v->empty()) v->resize(kept);
}

// The first pair list under /connectivity for this particle group; a problem with it is kept
// for read_bonds() instead of failing the file.
void H5mdReader::Impl::open_bonds() {
  if (!is_group(file.get(), h5md::kConnectivity)) return;
  const H5Handle g =
      own_group(H5Gopen2(file.get(), h5md::kConnectivity, H5P_DEFAULT), h5md::kConnectivity);
  H5G_info_t info;
  h5_check(H5Gget_info(g.get(), &info), std::string(h5md::kConnectivity) + ": list");
  for (hsize_t i = 0; i < info.nlinks && !bonds_found; ++i) {
    char name[256] = {0};
    if (H5Lget_name_by_idx(g.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof(name),
                           H5P_DEFAULT) < 0)
      continue;
    const std::string path = std::string(h5md::kConnectivity) + "/" + name;
    try {
      if (particles_group_of(file.get(), path) != group) continue;  // another group's list
      const bool per_frame = is_group(file.get(), path);
      const std::string value = per_frame ? path + "/value" : path;
      if (!link_exists(file.get(), value)) throw Hdf5Error("missing dataset " + value);
      const H5Handle dataset = own_dataset(H5Dopen2(file.get(), value.c_str(), H5P_DEFAULT), value);
      const auto dims = shape_of(dataset.get(), value);
      if (dims.size() == (per_frame ? 3u : 2u) && dims.back() != 2) continue;  // not pairs
      bonds_found = true;
      bonds = open_bond_list(path, per_frame);
    } catch (const Hdf5Error &e) {
      bonds_found = true;
      bonds_problem = e.what();
    }
  }
  if (bonds && !id) {
    bonds_problem = bonds->where +
                    ": the particle group has no id element, so its pairs are particle indices; "
                    "bonds are read by particle id only";
    bonds.reset();
  }
}

BondList H5mdReader::Impl::open_bond_list(const std::string &path, bool per_frame) const {
  BondList list;
  list.per_frame = per_frame;
  list.where = per_frame ? path + "/value" : path;
  list.value = own_dataset(H5Dopen2(file.get(), list.where.c_str(), H5P_DEFAULT), list.where);
  const auto dims = shape_of(list.value.get(), list.where);
  const std::vector<hsize_t> want =
      per_frame ? std::vector<hsize_t>{frames.size(), 0, 2} : std::vector<hsize_t>{0, 2};
  if (dims.size() != want.size() || dims.back() != 2)
    throw Hdf5Error(list.where + " has shape " + shape_text(dims) + ", expected " +
                    (per_frame ? "[frames][bonds][2]" : "[bonds][2]") + " (pairs of particle ids)");
  list.pairs = dims[dims.size() - 2];
  if (list.pairs > kMaxBonds)
    throw Hdf5Error(list.where + " has " + std::to_string(list.pairs) + " pairs (too many)");
  {
    const H5Handle type = own_type(H5Dget_type(list.value.get()), list.where + ": type");
    if (H5Tget_class(type.get()) != H5T_INTEGER)
      throw Hdf5Error(list.where + " is not of an integer type (particle ids)");
  }
  list.fill = user_fill_value<int64_t>(list.value.get(), H5T_NATIVE_INT64, list.where);
  if (per_frame) {
    const std::string step_path = path + "/step";
    if (!link_exists(file.get(), step_path)) throw Hdf5Error("missing dataset " + step_path);
    const H5Handle step =
        own_dataset(H5Dopen2(file.get(), step_path.c_str(), H5P_DEFAULT), step_path);
    const auto sdims = shape_of(step.get(), step_path);
    if (sdims.size() != 1)
      throw Hdf5Error(step_path + " has shape " + shape_text(sdims) + ", expected [frames]");
    const hsize_t n = std::min(sdims[0], dims[0]);  // a failed last frame may be longer in one
    const auto steps = read_first<int64_t>(step.get(), H5T_NATIVE_INT64, n, step_path);
    for (hsize_t f = 0; f < n; ++f) list.row_of_step.emplace(steps[f], f);
  }
  return list;
}

H5mdReader::H5mdReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
H5mdReader::~H5mdReader() = default;

const std::vector<FrameInfo> &H5mdReader::frames() const {
  return impl_->frames;
}

bool has_hdf5_signature(const std::string &path) {
  static const char kSignature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  std::ifstream in(path, std::ios::binary);
  char head[8] = {0};
  return in.read(head, 8) && std::memcmp(head, kSignature, 8) == 0;
}

Status H5mdReader::open(const std::string &path, MPI_Comm comm, std::unique_ptr<H5mdReader> *out) {
  const auto unreadable = [&path](const std::string &what) {
    return Status(StatusCode::kIo, path + ": " + what);
  };
  silence_hdf5_errors();
  // Agreed before HDF5's collective open: a rank that cannot read the file (a node-local disk,
  // a relative path in another working directory) would otherwise leave the others waiting in it.
  Status readable;
  if (!std::ifstream(path))
    readable = unreadable("cannot open the file (missing or unreadable)");
  else if (!has_hdf5_signature(path))
    readable = unreadable("not an HDF5 file (no HDF5 signature)");
  if (Status agreed = agree_on_status(comm, readable); !agreed.ok()) return agreed;
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  try {
    const H5Handle fapl = own_plist(H5Pcreate(H5P_FILE_ACCESS), "file access list");
    h5_check(H5Pset_fapl_mpio(fapl.get(), comm, MPI_INFO_NULL), "MPI-IO driver");
    impl->file = own_file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()),
                          "cannot open as HDF5 (truncated or corrupt?)");
    impl->check_h5md();
    impl->group = particle_group(impl->file.get());
    impl->find_complete_frames();
    impl->open_position();
    impl->species = impl->open_field(h5md::kSpecies);
    impl->id = impl->open_field(h5md::kId);
    impl->scalar = impl->open_field(h5md::kScalar);
    impl->radius = impl->open_field(h5md::kRadius);
    impl->open_box();
    impl->open_counts();
    impl->find_fill_values();
    impl->open_bonds();
  } catch (const Hdf5Error &e) {
    return unreadable(escaped_text(e.what()));  // may hold names read from the file
  }
  out->reset(new H5mdReader(std::move(impl)));  // private constructor: make_unique cannot
  return {};
}

Status H5mdReader::read(size_t index, int64_t begin, int64_t end, ParticleFrame *out) const {
  const Impl &m = *impl_;
  if (index >= m.frames.size())
    return {StatusCode::kInvalidArgument,
            m.path + ": frame " + std::to_string(index) + " does not exist"};
  ParticleFrame f;
  f.step = m.frames[index].step;
  f.time = m.frames[index].time;
  f.global_count = m.frames[index].count;
  const size_t rows = static_cast<size_t>(end - begin);
  try {
    f.position.resize(rows * 3);
    m.read_rows(m.position.get(), true, index, begin, end, 3, H5T_NATIVE_DOUBLE, f.position.data(),
                m.group + "/position/value");
    auto read_int = [&](const std::optional<Field> &field, const char *name,
                        std::vector<int64_t> *v) {
      if (!field || rows == 0) return;
      v->resize(rows);
      m.read_rows(field->value.get(), field->per_frame, index, begin, end, 1, H5T_NATIVE_INT64,
                  v->data(), m.group + "/" + name);
    };
    auto read_real = [&](const std::optional<Field> &field, const char *name,
                         std::vector<double> *v) {
      if (!field || rows == 0) return;
      v->resize(rows);
      m.read_rows(field->value.get(), field->per_frame, index, begin, end, 1, H5T_NATIVE_DOUBLE,
                  v->data(), m.group + "/" + name);
    };
    read_int(m.species, h5md::kSpecies, &f.type);
    read_int(m.id, h5md::kId, &f.id);
    read_real(m.scalar, h5md::kScalar, &f.scalar);
    read_real(m.radius, h5md::kRadius, &f.radius);
    if (m.edges.valid()) {
      const auto low = m.read_vec3(m.offset.get(), m.offset_per_frame, index, "box/offset");
      Box b;
      b.low = low.value_or(std::array<double, 3>{0, 0, 0});
      b.periodic = m.periodic;
      std::array<double, 3> lengths{};
      if (m.edges_matrix) {
        b.triclinic = true;
        b.tilt = m.read_tilt(index, &lengths);
      } else {
        lengths = *m.read_vec3(m.edges.get(), m.edges_per_frame, index, "box/edges");
      }
      for (int a = 0; a < 3; ++a) b.high[a] = b.low[a] + lengths[a];
      f.box = b;
    }
  } catch (const Hdf5Error &e) {
    return {StatusCode::kIo, m.path + ": " + escaped_text(e.what())};
  }
  m.drop_fill_rows(index, begin, &f);
  *out = std::move(f);
  return {};
}

}  // namespace lantern

namespace lantern {

bool H5mdReader::has_bonds() const {
  return impl_->bonds_found;
}

std::string H5mdReader::bonds_dataset(size_t index) const {
  const Impl &m = *impl_;
  if (!m.bonds) return {};
  const BondList &list = *m.bonds;
  std::string text = m.path + ": " + escaped_text(list.where);
  if (list.per_frame && index < m.frames.size())
    if (const auto found = list.row_of_step.find(m.frames[index].step);
        found != list.row_of_step.end())
      text += "[" + std::to_string(found->second) + "]";
  return text;
}

Status H5mdReader::read_bonds(size_t index, std::vector<int64_t> *first,
                              std::vector<int64_t> *second, std::vector<int64_t> *pair) const {
  const Impl &m = *impl_;
  first->clear();
  second->clear();
  if (pair) pair->clear();
  if (!m.bonds_found) return {};
  if (!m.bonds) return {StatusCode::kIo, m.path + ": " + escaped_text(m.bonds_problem)};
  if (index >= m.frames.size())
    return {StatusCode::kInvalidArgument,
            m.path + ": frame " + std::to_string(index) + " does not exist"};
  const BondList &list = *m.bonds;
  hsize_t row = 0;
  if (list.per_frame) {
    const auto found = list.row_of_step.find(m.frames[index].step);
    if (found == list.row_of_step.end())
      return {StatusCode::kInvalidArgument, m.path + ": " + escaped_text(list.where) +
                                                " records no bonds for step " +
                                                std::to_string(m.frames[index].step)};
    row = found->second;
  }
  std::vector<int64_t> pairs;
  try {
    pairs.resize(size_t(2 * list.pairs));
    if (list.pairs > 0)
      m.read_rows(list.value.get(), list.per_frame, row, 0, int64_t(list.pairs), 2,
                  H5T_NATIVE_INT64, pairs.data(), list.where);
  } catch (const Hdf5Error &e) {
    return {StatusCode::kIo, m.path + ": " + escaped_text(e.what())};
  } catch (const std::bad_alloc &) {
    return {StatusCode::kIo, m.path + ": " + escaped_text(list.where) + ": out of memory"};
  }
  const std::string at = m.path + ": " + escaped_text(list.where) +
                         (list.per_frame ? "[" + std::to_string(row) + "]" : "");
  for (size_t k = 0; k < list.pairs; ++k) {
    const int64_t a = pairs[2 * k], b = pairs[2 * k + 1];
    if (list.fill && (a == *list.fill || b == *list.fill)) continue;  // no bond (H5MD)
    const std::string where = at + "[" + std::to_string(k) + "]: ";
    if (a < 0 || b < 0)
      return {StatusCode::kIo, where + "negative particle id " + std::to_string(a < 0 ? a : b)};
    if (a == b)
      return {StatusCode::kIo, where + "a bond from particle " + std::to_string(a) + " to itself"};
    first->push_back(a);
    second->push_back(b);
    if (pair) pair->push_back(int64_t(k));
  }
  return {};
}

}  // namespace lantern
