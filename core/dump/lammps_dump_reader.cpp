#include "core/dump/lammps_dump_reader.h"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/common/quoted_text.h"

namespace lantern {
namespace {

std::vector<std::string> split(const std::string &line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

bool starts_with(const std::string &s, const std::string &prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

template <typename T>
bool parse_number(const char *begin, const char *end, T *out) {
  const auto r = std::from_chars(begin, end, *out);
  return r.ec == std::errc() && r.ptr == end;
}

template <typename T>
bool parse_number(const std::string &s, T *out) {
  return parse_number(s.data(), s.data() + s.size(), out);
}

// Reads the file line by line, counting lines, for the header scan of open().
class LineReader {
 public:
  explicit LineReader(const std::string &path) : in_(path, std::ios::binary) {}
  bool good() const { return bool(in_); }
  bool next(std::string *line) {
    if (!std::getline(in_, *line)) return false;
    if (!line->empty() && line->back() == '\r') line->pop_back();
    ++number_;
    return true;
  }
  int64_t line_number() const { return number_; }
  std::streamoff offset() { return in_.tellg(); }
  // Skips n lines; returns how many existed.
  int64_t skip(int64_t n) {
    for (int64_t i = 0; i < n; ++i) {
      if (in_.peek() == std::char_traits<char>::eof()) return i;
      in_.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
      ++number_;
    }
    return n;
  }

 private:
  std::ifstream in_;
  int64_t number_ = 0;
};

struct ParseError {
  int64_t line;
  std::string what;
};

// The first complete coordinate triple among the column names; throws ParseError otherwise.
void choose_position(const std::vector<std::string> &names, int64_t line,
                     LammpsDumpReader::Columns *c) {
  struct Triple {
    const char *x, *y, *z;
    bool scaled;
  };
  static const Triple kTriples[] = {{"x", "y", "z", false},
                                    {"xu", "yu", "zu", false},
                                    {"xs", "ys", "zs", true},
                                    {"xsu", "ysu", "zsu", true}};
  auto index = [&](const char *name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1 : int(it - names.begin());
  };
  std::string partial;
  for (const Triple &t : kTriples) {
    const std::array<int, 3> idx{index(t.x), index(t.y), index(t.z)};
    const int found = (idx[0] >= 0) + (idx[1] >= 0) + (idx[2] >= 0);
    if (found == 3) {
      c->position = idx;
      c->scaled = t.scaled;
      return;
    }
    if (found > 0 && partial.empty())
      for (int a = 0; a < 3; ++a)
        if (idx[a] < 0)
          partial = std::string(" (column '") +
                    (a == 0   ? t.x
                     : a == 1 ? t.y
                              : t.z) +
                    "' is missing)";
  }
  throw ParseError{line, "ITEM: ATOMS has no complete set of position columns" + partial +
                             "; need x y z, xu yu zu, xs ys zs or xsu ysu zsu"};
}

LammpsDumpReader::Columns parse_columns(const std::vector<std::string> &tokens, int64_t line) {
  LammpsDumpReader::Columns c;
  c.names.assign(tokens.begin() + 2, tokens.end());  // after "ITEM:" "ATOMS"
  choose_position(c.names, line, &c);
  auto index = [&](const char *name) {
    const auto it = std::find(c.names.begin(), c.names.end(), name);
    return it == c.names.end() ? -1 : int(it - c.names.begin());
  };
  c.type = index("type");
  c.id = index("id");
  c.radius = index("radius");
  if (c.radius < 0 && (c.radius = index("diameter")) >= 0) c.diameter = true;
  c.needed = 1 + std::max({c.position[0], c.position[1], c.position[2], c.type, c.id, c.radius});
  return c;
}

// "ITEM: BOX BOUNDS [xy xz yz] pp pp pp" and its three lines.
void parse_box(const std::vector<std::string> &header, LineReader &in, LammpsDumpReader::Frame *f) {
  const bool triclinic = header.size() > 3 && header[3] == "xy";
  const size_t flags_at = triclinic ? 6 : 3;
  std::array<double, 3> lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    std::string line;
    if (!in.next(&line))
      throw ParseError{in.line_number(), "file ends inside ITEM: BOX BOUNDS (truncated?)"};
    const auto t = split(line);
    const size_t want = triclinic ? 3 : 2;
    if (t.size() < want)
      throw ParseError{in.line_number(), "ITEM: BOX BOUNDS line has " + std::to_string(t.size()) +
                                             " numbers, expected " + std::to_string(want)};
    for (size_t k = 0; k < want; ++k) {
      double v = 0;
      if (!parse_number(t[k], &v))
        throw ParseError{in.line_number(),
                         "ITEM: BOX BOUNDS: " + quoted_text(t[k]) + " is not a number"};
      (k == 0 ? lo[a] : k == 1 ? hi[a] : f->tilt[a]) = v;
    }
    const size_t flag = flags_at + a;
    f->box.periodic[a] = header.size() > flag && header[flag] == "pp";
  }
  f->box.low = lo;
  f->box.high = hi;
  // Triclinic bounds enclose the tilted box; recover the box's own origin and lengths.
  const double xy = f->tilt[0], xz = f->tilt[1], yz = f->tilt[2];
  const double xmin = std::min({0.0, xy, xz, xy + xz}), xmax = std::max({0.0, xy, xz, xy + xz});
  f->origin = {lo[0] - xmin, lo[1] - std::min(0.0, yz), lo[2]};
  f->length = {(hi[0] - xmax) - f->origin[0], (hi[1] - std::max(0.0, yz)) - f->origin[1],
               hi[2] - lo[2]};
  if (triclinic) {  // the box itself, not the bounds that enclose it
    f->box.triclinic = true;
    f->box.tilt = f->tilt;
    for (int a = 0; a < 3; ++a)
      f->box.low[size_t(a)] = f->origin[size_t(a)],
      f->box.high[size_t(a)] = f->origin[size_t(a)] + f->length[size_t(a)];
  }
  f->has_box = true;
}

int64_t read_integer_line(LineReader &in, const char *item) {
  std::string line;
  if (!in.next(&line))
    throw ParseError{in.line_number(), std::string("file ends after ITEM: ") + item};
  const auto t = split(line);
  int64_t v = 0;
  if (t.size() != 1 || !parse_number(t[0], &v))
    throw ParseError{in.line_number(), std::string("ITEM: ") + item +
                                           ": expected one integer, found " + quoted_text(line)};
  return v;
}

double read_real_line(LineReader &in, const char *item) {
  std::string line;
  if (!in.next(&line))
    throw ParseError{in.line_number(), std::string("file ends after ITEM: ") + item};
  const auto t = split(line);
  double v = 0;
  if (t.size() != 1 || !parse_number(t[0], &v))
    throw ParseError{in.line_number(), std::string("ITEM: ") + item +
                                           ": expected one number, found " + quoted_text(line)};
  return v;
}

// Other ITEM sections (UNITS, ...) hold one value line, which Lantern does not need.
void skip_value_line(LineReader &in, const std::string &item) {
  std::string value;
  if (!in.next(&value)) throw ParseError{in.line_number(), "file ends after " + quoted_text(item)};
}

// Scans one frame's header after its "ITEM: TIMESTEP" line, up to and over its atom lines.
LammpsDumpReader::Frame scan_frame(LineReader &in) {
  LammpsDumpReader::Frame f;
  f.info.step = read_integer_line(in, "TIMESTEP");
  f.info.time = static_cast<double>(f.info.step);
  bool have_count = false;
  std::string line;
  while (in.next(&line)) {
    if (line.empty()) continue;
    const auto t = split(line);
    if (starts_with(line, "ITEM: NUMBER OF ATOMS")) {
      f.info.count = read_integer_line(in, "NUMBER OF ATOMS");
      if (f.info.count < 0) throw ParseError{in.line_number(), "ITEM: NUMBER OF ATOMS is negative"};
      have_count = true;
    } else if (starts_with(line, "ITEM: TIME") && !starts_with(line, "ITEM: TIMESTEP")) {
      f.info.time = read_real_line(in, "TIME");
    } else if (starts_with(line, "ITEM: BOX BOUNDS")) {
      parse_box(t, in, &f);
    } else if (starts_with(line, "ITEM: ATOMS")) {
      if (!have_count)
        throw ParseError{in.line_number(), "ITEM: ATOMS before ITEM: NUMBER OF ATOMS"};
      f.columns = parse_columns(t, in.line_number());
      if (f.columns.scaled && !f.has_box)
        throw ParseError{in.line_number(),
                         "scaled coordinates but no ITEM: BOX BOUNDS to unscale them with"};
      f.atoms_offset = in.offset();
      f.atoms_line = in.line_number() + 1;
      const int64_t found = in.skip(f.info.count);
      if (found < f.info.count)
        throw ParseError{in.line_number(), "file ends after " + std::to_string(found) + " of " +
                                               std::to_string(f.info.count) +
                                               " atom lines (truncated?)"};
      return f;
    } else if (starts_with(line, "ITEM: TIMESTEP")) {
      throw ParseError{in.line_number(), "ITEM: TIMESTEP before the previous frame's ITEM: ATOMS"};
    } else if (starts_with(line, "ITEM:")) {
      skip_value_line(in, line);
    } else {
      throw ParseError{in.line_number(), "unexpected line " + quoted_text(line)};
    }
  }
  throw ParseError{in.line_number(), "file ends before ITEM: ATOMS (truncated?)"};
}

// Splits one atom line into at most `needed` tokens; returns how many there were.
int tokenize(const std::string &line, int needed,
             std::array<std::pair<const char *, const char *>, 64> *tok,
             std::vector<std::pair<const char *, const char *>> *more) {
  const char *p = line.data(), *end = p + line.size();
  int n = 0;
  while (n < needed) {
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    if (p == end) break;
    const char *s = p;
    while (p < end && *p != ' ' && *p != '\t') ++p;
    if (n < 64)
      (*tok)[n] = {s, p};
    else
      more->push_back({s, p});
    ++n;
  }
  return n;
}

}  // namespace

Status LammpsDumpReader::open(const std::string &path, std::unique_ptr<LammpsDumpReader> *out) {
  const auto unreadable = [&path](const std::string &what) {
    return Status(StatusCode::kIo, path + what);
  };
  LineReader in(path);
  if (!in.good()) return unreadable(": cannot open the file (missing or unreadable)");
  auto reader = std::make_unique<LammpsDumpReader>();
  reader->path_ = path;
  try {
    std::string line;
    bool has_time = false;  // LAMMPS writes UNITS and TIME before TIMESTEP
    double time = 0.0;
    while (in.next(&line)) {
      if (line.find_first_not_of(" \t") == std::string::npos) continue;
      if (starts_with(line, "ITEM: TIMESTEP")) {
        reader->frames_.push_back(scan_frame(in));
        if (has_time) reader->frames_.back().info.time = time;
        has_time = false;
        reader->infos_.push_back(reader->frames_.back().info);
      } else if (starts_with(line, "ITEM: TIME")) {
        time = read_real_line(in, "TIME");
        has_time = true;
      } else if (starts_with(line, "ITEM:")) {
        skip_value_line(in, line);  // e.g. ITEM: UNITS
      } else {
        throw ParseError{in.line_number(), "expected 'ITEM: TIMESTEP', found " + quoted_text(line) +
                                               " (not a LAMMPS text dump?)"};
      }
    }
  } catch (const ParseError &e) {
    return unreadable(":" + std::to_string(e.line) + ": " + e.what);
  }
  if (reader->frames_.empty())
    return unreadable(": no frames (empty file or not a LAMMPS text dump)");
  *out = std::move(reader);
  return {};
}

Status LammpsDumpReader::read(size_t index, int64_t begin, int64_t end, ParticleFrame *out) const {
  if (index >= frames_.size())
    return {StatusCode::kInvalidArgument,
            path_ + ": frame " + std::to_string(index) + " does not exist"};
  const Frame &fr = frames_[index];
  const Columns &c = fr.columns;
  ParticleFrame f;
  f.step = fr.info.step;
  f.time = fr.info.time;
  f.global_count = fr.info.count;
  if (fr.has_box) f.box = fr.box;
  const size_t rows = static_cast<size_t>(end - begin);
  f.position.resize(rows * 3);
  if (c.type >= 0) f.type.resize(rows);
  if (c.id >= 0) f.id.resize(rows);
  if (c.radius >= 0) f.radius.resize(rows);

  std::ifstream in(path_, std::ios::binary);
  in.seekg(fr.atoms_offset);
  for (int64_t i = 0; i < begin; ++i) in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  std::string line;
  std::array<std::pair<const char *, const char *>, 64> tok;
  std::vector<std::pair<const char *, const char *>> more;
  auto token = [&](int k) { return k < 64 ? tok[k] : more[k - 64]; };
  for (size_t r = 0; r < rows; ++r) {
    const int64_t line_no = fr.atoms_line + begin + static_cast<int64_t>(r);
    const auto bad_line = [&](const std::string &what) {
      return Status(StatusCode::kIo, path_ + ":" + std::to_string(line_no) + ": " + what);
    };
    if (!std::getline(in, line)) return bad_line("cannot read the atom line (file changed?)");
    // As the header scan does (LineReader::next): a file with CRLF line ends kept the '\r' in its
    // last column, "0.5\r", which is not a number.
    if (!line.empty() && line.back() == '\r') line.pop_back();
    more.clear();
    const int n = tokenize(line, c.needed, &tok, &more);
    if (n < c.needed)
      return bad_line("short line: " + std::to_string(n) + " columns, ITEM: ATOMS needs at least " +
                      std::to_string(c.needed) + " (" + name_text(c.names[n]) + " is missing)");
    auto real = [&](int col, double *v) -> Status {
      const auto [s, e] = token(col);
      if (parse_number(s, e, v)) return {};
      return bad_line("column " + quoted_text(c.names[col]) + ": " +
                      quoted_text(std::string_view(s, size_t(e - s))) + " is not a number");
    };
    auto integer = [&](int col, int64_t *v) -> Status {
      const auto [s, e] = token(col);
      if (parse_number(s, e, v)) return {};
      return bad_line("column " + quoted_text(c.names[col]) + ": " +
                      quoted_text(std::string_view(s, size_t(e - s))) + " is not an integer");
    };
    double p[3];
    for (int a = 0; a < 3; ++a)
      if (Status s = real(c.position[a], &p[a]); !s.ok()) return s;
    if (c.scaled) {  // unscale: x = xlo + xs lx + ys xy + zs xz, ...
      const double xs = p[0], ys = p[1], zs = p[2];
      p[0] = fr.origin[0] + xs * fr.length[0] + ys * fr.tilt[0] + zs * fr.tilt[1];
      p[1] = fr.origin[1] + ys * fr.length[1] + zs * fr.tilt[2];
      p[2] = fr.origin[2] + zs * fr.length[2];
    }
    std::copy(p, p + 3, f.position.begin() + 3 * r);
    if (c.type >= 0)
      if (Status s = integer(c.type, &f.type[r]); !s.ok()) return s;
    if (c.id >= 0)
      if (Status s = integer(c.id, &f.id[r]); !s.ok()) return s;
    if (c.radius >= 0) {
      if (Status s = real(c.radius, &f.radius[r]); !s.ok()) return s;
      if (c.diameter) f.radius[r] *= 0.5;
    }
  }
  *out = std::move(f);
  return {};
}

}  // namespace lantern
