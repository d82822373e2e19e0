#include "cli.h"

#include <cstdlib>
#include <sstream>

#include "md_error.h"

namespace mini_md {

namespace {

double to_double(const std::string &opt, const std::string &text) {
  char *end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') throw MdError(opt + " expects a number, got '" + text + "'");
  return value;
}

long long to_int(const std::string &opt, const std::string &text) {
  char *end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0') throw MdError(opt + " expects an integer, got '" + text + "'");
  return value;
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

}  // namespace

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
    if (opt == "--help" || opt == "-h")
      cl.help = true;
    else if (opt == "--scene")
      r.scene = to_scene(value());
    else if (opt == "--cells")
      r.cells = static_cast<int>(to_int(opt, value()));
    else if (opt == "--steps")
      r.steps = to_int(opt, value());
    else if (opt == "--dt")
      r.dt = to_double(opt, value());
    else if (opt == "--temp")
      r.temperature = to_double(opt, value());
    else if (opt == "--density")
      r.density = to_double(opt, value());
    else if (opt == "--seed")
      r.seed = static_cast<uint64_t>(to_int(opt, value()));
    else if (opt == "--cutoff")
      r.cutoff = to_double(opt, value());
    else if (opt == "--shift")
      r.shift_energy = to_bool(opt, value());
    else if (opt == "--skin")
      r.skin = to_double(opt, value());
    else if (opt == "--neigh-every")
      r.neigh_every = static_cast<int>(to_int(opt, value()));
    else if (opt == "--neigh-check")
      r.neigh_check = to_bool(opt, value());
    else if (opt == "--sort-every")
      r.sort_every = static_cast<int>(to_int(opt, value()));
    else if (opt == "--thermo")
      r.thermo_every = to_int(opt, value());
    else if (opt == "--boundary")
      r.boundary = value();
    else if (opt == "--impact-speed")
      r.impact_speed = to_double(opt, value());
    else if (opt == "--random-start")
      r.random_start = true;
    else if (opt == "--relax")
      r.relax = true;
    else if (opt == "--relax-steps")
      r.relax_steps = static_cast<int>(to_int(opt, value()));
    else if (opt == "--relax-fmax")
      r.relax_fmax = to_double(opt, value());
    else if (opt == "--langevin")
      r.langevin_temp = to_double(opt, value());
    else if (opt == "--langevin-damp")
      r.langevin_damp = to_double(opt, value());
    else if (opt == "--blowup-energy")
      r.blowup_energy = to_double(opt, value());
    else if (opt == "--render")
      r.render_config = value();
    else if (opt == "--dt-sweep")
      cl.dt_sweep = true;
    else if (opt == "--sweep-time")
      cl.sweep_time = to_double(opt, value());
    else if (opt == "--csv")
      cl.csv_path = value();
    else
      throw MdError("unknown option '" + opt + "' (see --help)");
  }
  if (r.steps < 0) throw MdError("--steps must be >= 0");
  if (r.thermo_every < 0) throw MdError("--thermo must be >= 0");
  if (r.langevin_temp && !(r.langevin_damp > 0)) throw MdError("--langevin-damp must be > 0");
  return cl;
}

}  // namespace mini_md
