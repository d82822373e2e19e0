// The scenes mini_md can start from. Each defines the box and creates, on each rank, the atoms
// of its subdomain from a global, rank-independent description (lattice sites or hashed random
// positions with global indices), so every rank count starts from the same state.
//
//   lattice      fcc at density 0.8442, T 1.44, periodic: the classic LJ melt (LAMMPS in.lj).
//   void_impact  fcc crystal slab (density 1.07, T 0.05) with five spherical voids (three of them
//                centred on the plane y = Ly/2, for cross-sections), struck along
//                -z by a flyer plate at --impact-speed; reflecting walls in z, far enough from
//                the free surfaces that they only catch spall; periodic in x and y.
//                Types: 1 target, 2 flyer.
//   droplet      a dense liquid drop (fcc sphere at 0.8442 that melts at T 0.8) in a dilute gas
//                (density 0.02, simple cubic start), periodic. Types: 1 liquid, 2 gas.
//   random       4 N^3 atoms at uniformly random positions at density 0.8442: overlapping
//                atoms, the stiff start that needs --relax.
#pragma once

#include <string>

#include "atoms.h"
#include "box.h"
#include "domain_decomposition.h"
#include "run_config.h"

namespace mini_md {

struct SceneSetup {
  Box box;
  double density = 0.8442;    // lattice density used to build it
  double temperature = 1.44;  // initial thermal temperature
  std::string description;    // one line for the run header
};

// The box and defaults of cfg's scene (pure; the same on every rank).
SceneSetup define_scene(const RunConfig &cfg);

// Creates this rank's owned atoms (positions, ids, types; zero velocities).
void create_scene_atoms(const RunConfig &cfg, const SceneSetup &setup,
                        const DomainDecomposition &dd, Atoms &atoms);

// Thermal velocities at setup.temperature, then scene motion (the flyer). Collective.
void assign_scene_velocities(const RunConfig &cfg, const SceneSetup &setup, Atoms &atoms,
                             MPI_Comm comm);

const char *scene_name(SceneKind kind);

}  // namespace mini_md
