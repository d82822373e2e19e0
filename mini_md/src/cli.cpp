#include "cli.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "md_error.h"

namespace mini_md {

namespace {

// A value outside the option's range, or not a number at all: the message names the option, the
// text given and the range, so every numeric option fails the same way.
[[noreturn]] void reject(const NumericOption &o, const std::string &text) {
  throw MdError(o.name + " must be " + (o.integer() ? "an integer" : "a number") + " in " +
                range_text(o) + ", got '" + text + "'");
}

int64_t parse_integer(const NumericOption &o, const std::string &text) {
  char *end = nullptr;
  errno = 0;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE) reject(o, text);
  // Compared as integers: as doubles, 1e18 + 1 would pass a limit of 1e18. Integer limits in the
  // table are exact in a double.
  if (value < static_cast<long long>(o.min) || value > static_cast<long long>(o.max)) {
    reject(o, text);
  }
  return value;
}

double parse_real(const NumericOption &o, const std::string &text) {
  char *end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') reject(o, text);
  // Written so that NaN fails every comparison and lands in reject(); inf is never allowed.
  const bool above_min = o.min_exclusive ? value > o.min : value >= o.min;
  const bool below_max = std::isinf(o.max) ? std::isfinite(value) : value <= o.max;
  if (!(above_min && below_max)) reject(o, text);
  return value;
}

const NumericOption *find_numeric(const std::string &name) {
  for (const NumericOption &o : numeric_options()) {
    if (o.name == name) return &o;
  }
  return nullptr;
}

bool to_bool(const std::string &opt, const std::string &text) {
  if (text == "yes" || text == "true" || text == "1") return true;
  if (text == "no" || text == "false" || text == "0") return false;
  throw MdError(opt + " expects yes or no, got '" + text + "'");
}

SceneKind to_scene(const std::string &text) {
  if (text == "lattice") return SceneKind::kLattice;
  if (text == "void_impact") return SceneKind::kVoidImpact;
  if (text == "droplet") return SceneKind::kDroplet;
  if (text == "random") return SceneKind::kRandom;
  throw MdError("--scene must be lattice, void_impact, droplet or random, got '" + text + "'");
}

std::string number_text(double v) {
  if (std::isinf(v)) return "inf";
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

const std::vector<NumericOption> &numeric_options() {
  constexpr double kAnyFinite = std::numeric_limits<double>::infinity();
  // Ranges: what the physics or the program can mean, in LJ units. Upper limits sit orders of
  // magnitude beyond any useful run and exist to catch typos and overflow (an int option never
  // wraps), not to police experiments.
  static const std::vector<NumericOption> table = {
      // 4 * 10000^3 = 4e12 atoms is beyond any machine; keeps 4 N^3 far from int64 overflow.
      {"--cells", 1, false, 1e4,
       [](CommandLine &c, int64_t v) { c.run.cells = static_cast<int>(v); }},
      {"--steps", 0, false, 1e15, [](CommandLine &c, int64_t v) { c.run.steps = v; }},
      // The stable LJ step is ~0.005; 1 is already 200 times that.
      {"--dt", 0, true, 1, nullptr, [](CommandLine &c, double v) { c.run.dt = v; }},
      // T = 1e4 is ~1e4 times the LJ melting temperature.
      {"--temp", 0, false, 1e4, nullptr, [](CommandLine &c, double v) { c.run.temperature = v; }},
      // Density 10 puts neighbours at 0.5 sigma (pair energy ~1e4); 0 has no lattice.
      {"--density", 0, true, 10, nullptr, [](CommandLine &c, double v) { c.run.density = v; }},
      {"--seed", 0, false, 1e18,
       [](CommandLine &c, int64_t v) { c.run.seed = static_cast<uint64_t>(v); }},
      {"--cutoff", 0, true, 100, nullptr, [](CommandLine &c, double v) { c.run.cutoff = v; }},
      {"--skin", 0, false, 100, nullptr, [](CommandLine &c, double v) { c.run.skin = v; }},
      {"--neigh-every", 1, false, 1e9,
       [](CommandLine &c, int64_t v) { c.run.neigh_every = static_cast<int>(v); }},
      {"--sort-every", 0, false, 1e9,
       [](CommandLine &c, int64_t v) { c.run.sort_every = static_cast<int>(v); }},
      {"--thermo", 0, false, 1e15, [](CommandLine &c, int64_t v) { c.run.thermo_every = v; }},
      // Speed 1000 is ~100 times the LJ sound speed; negative would fly away from the target.
      {"--impact-speed", 0, false, 1e3, nullptr,
       [](CommandLine &c, double v) { c.run.impact_speed = v; }},
      {"--relax-steps", 0, false, 1e9,
       [](CommandLine &c, int64_t v) { c.run.relax_steps = static_cast<int>(v); }},
      {"--relax-fmax", 0, true, kAnyFinite, nullptr,
       [](CommandLine &c, double v) { c.run.relax_fmax = v; }},
      {"--langevin", 0, false, 1e4, nullptr,
       [](CommandLine &c, double v) { c.run.langevin_temp = v; }},
      {"--langevin-damp", 0, true, kAnyFinite, nullptr,
       [](CommandLine &c, double v) { c.run.langevin_damp = v; }},
      // Any finite limit: a huge one switches the check off (the runaway warning stays).
      {"--blowup-energy", 0, true, kAnyFinite, nullptr,
       [](CommandLine &c, double v) { c.run.blowup_energy = v; }},
      {"--sweep-time", 0, true, 1e6, nullptr, [](CommandLine &c, double v) { c.sweep_time = v; }},
  };
  return table;
}

std::string range_text(const NumericOption &o) {
  return (o.min_exclusive ? "(" : "[") + number_text(o.min) + ", " + number_text(o.max) +
         (std::isinf(o.max) ? ")" : "]");
}

std::string usage_text() {
  return R"(usage: mini_md [options]
  --scene lattice|void_impact|droplet|random   (default lattice)
  --cells N            fcc cells per box edge; 4 N^3 lattice atoms (default 20)
  --steps S            time steps (default 100)
  --dt DT              time step, LJ units (default 0.005)
  --temp T             initial temperature (default per scene: 1.44 lattice)
  --density RHO        lattice density (default per scene: 0.8442 lattice)
  --seed S             velocities, random placement, Langevin noise (default 87287)
  --cutoff RC          LJ cutoff, potential not shifted (default 2.5)
  --shift yes|no       energies with U shifted to 0 at the cutoff (default no, as LAMMPS)
  --skin S             neighbour skin (default 0.3)
  --neigh-every K      rebuild at least every K steps (default 20)
  --neigh-check yes|no also rebuild when an atom moved skin/2 (default yes)
  --sort-every K       sort atoms by bin every K rebuilds, 0 = never (default 1)
  --thermo K           thermo line every K steps, 0 = first and last only (default 100)
  --boundary XYZ       p = periodic, f = reflecting wall, per axis (default per scene)
  --impact-speed V     flyer speed for void_impact (default 3)
  --random-start       random positions (same as --scene random)
  --relax              force-capped steepest descent before the dynamics
  --relax-steps N      iteration limit of --relax (default 2000)
  --relax-fmax F       stop relaxing when every |f| < F (default 10)
  --langevin T         Langevin thermostat at T (default off: NVE)
  --langevin-damp D    thermostat relaxation time (default 1)
  --blowup-energy E    stop when |E/atom - E0/atom| > E in NVE (default 1)
  --render CONFIG      render in situ with Lantern (YAML file or inline document)
  --dt-sweep           NVE energy drift and wall time for dt in 0.001 .. 0.02
  --sweep-time T       simulated time per dt in the sweep (default 5)
  --csv FILE           write the sweep table as CSV too
  --help               this text (also -h)
  --version            mini_md's and Lantern's version
)";
}

CommandLine parse_command_line(int argc, const char *const *argv) {
  CommandLine cl;
  RunConfig &r = cl.run;
  for (int k = 1; k < argc; ++k) {
    const std::string opt = argv[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= argc) throw MdError(opt + " needs a value");
      return argv[++k];
    };
    if (const NumericOption *numeric = find_numeric(opt)) {
      const std::string text = value();
      if (numeric->integer()) {
        numeric->store_integer(cl, parse_integer(*numeric, text));
      } else {
        numeric->store_real(cl, parse_real(*numeric, text));
      }
      continue;
    }
    if (opt == "--help" || opt == "-h")
      cl.help = true;
    else if (opt == "--version")
      cl.version = true;
    else if (opt == "--scene")
      r.scene = to_scene(value());
    else if (opt == "--shift")
      r.shift_energy = to_bool(opt, value());
    else if (opt == "--neigh-check")
      r.neigh_check = to_bool(opt, value());
    else if (opt == "--boundary")
      r.boundary = value();
    else if (opt == "--random-start")
      r.random_start = true;
    else if (opt == "--relax")
      r.relax = true;
    else if (opt == "--render")
      r.render_config = value();
    else if (opt == "--dt-sweep")
      cl.dt_sweep = true;
    else if (opt == "--csv")
      cl.csv_path = value();
    else
      throw MdError("unknown option '" + opt + "' (see --help)");
  }
  return cl;
}

}  // namespace mini_md
