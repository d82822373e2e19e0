// RunConfig: every knob of a mini_md run, with the in.lj defaults. cli.cpp fills it from the
// command line; tests fill it directly.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace mini_md {

enum class SceneKind { kLattice, kVoidImpact, kDroplet, kRandom };

struct RunConfig {
  SceneKind scene = SceneKind::kLattice;
  int cells = 20;                     // --cells: fcc unit cells per box edge (4 N^3 lattice atoms)
  int64_t steps = 100;                // --steps
  double dt = 0.005;                  // --dt (LJ time units)
  std::optional<double> temperature;  // --temp: initial T; default per scene (1.44 for lattice)
  std::optional<double> density;      // --density: lattice density; default per scene
  uint64_t seed = 87287;              // --seed: initial velocities, voids, random placement, noise
  double cutoff = 2.5;                // --cutoff: LJ cutoff
  // --shift yes: report energies with U shifted to 0 at the cutoff. Forces are the same either
  // way; only the energy bookkeeping changes (no jump when a pair crosses the cutoff). Default
  // no, as LAMMPS pair lj/cut, so step-0 energies match in.lj.
  bool shift_energy = false;
  double skin = 0.3;           // --skin: neighbour-list skin
  int neigh_every = 20;        // --neigh-every: rebuild at least this often
  bool neigh_check = true;     // --neigh-check yes|no: also rebuild when an atom moved skin/2
  int sort_every = 1;          // --sort-every: sort atoms by bin every K rebuilds (0 = never)
  int64_t thermo_every = 100;  // --thermo: thermo line every K steps (0 = first and last)
  // Boundaries per axis: 'p' periodic, 'f' reflecting wall. Empty = scene default.
  std::string boundary;       // --boundary, e.g. ppp or ppf
  double impact_speed = 3.0;  // --impact-speed: flyer speed (void_impact), LJ velocity units
  bool random_start = false;  // --random-start: random positions instead of the lattice
  bool relax = false;         // --relax: capped steepest descent before the dynamics
  int relax_steps = 2000;     // --relax-steps: iteration limit of --relax
  double relax_fmax = 10.0;   // --relax-fmax: stop relaxing when every |f| is below this
  std::optional<double> langevin_temp;  // --langevin T: Langevin thermostat target
  double langevin_damp = 1.0;           // --langevin-damp: relaxation time (1/gamma)
  double blowup_energy = 1.0;  // --blowup-energy: max |E/atom - E0/atom| in NVE before stopping
  bool print_thermo = true;    // thermo lines on rank 0 (tests switch them off)
  std::string render_config;   // --render CONFIG.yaml
};

}  // namespace mini_md
