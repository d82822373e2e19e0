// The IMD (Interactive Molecular Dynamics) wire protocol, version 2, as VMD, NAMD, GROMACS
// (`mdrun -imdport`) and LAMMPS (`fix imd`) speak it (Stone et al., "A system for interactive
// molecular dynamics simulation", ACM Symposium on Interactive 3D Graphics, 2001).
//
// Every message starts with an 8-byte header: two 32-bit integers, the message type and a length,
// in network (big-endian) byte order. The simulation is the server: on accepting a client it
// sends IMD_HANDSHAKE whose length field is the protocol version (2) written in the server's own
// byte order, so the client learns the byte order of the payloads that follow; the client
// answers IMD_GO within a second. The server then sends, every N steps, IMD_FCOORDS (length: the
// atom count; payload: 3 float32 per atom, in Angstrom for GROMACS and NAMD, in LAMMPS's units
// for LAMMPS), GROMACS and NAMD preceded by IMD_ENERGIES (length 1; payload: the int32 step and
// nine float32 energies). Clients may send IMD_TRATE (length: the new rate in steps),
// IMD_PAUSE, IMD_DISCONNECT (the simulation goes on) and IMD_KILL (it stops; never sent here).
//
// This file only encodes and checks bytes: no sockets, no state. Every function that reads a
// header from the network validates it against what this client accepts, so a hostile stream
// fails here with a message, before anything is allocated for it.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace lantern_imd {

enum class MessageType : int32_t {
  kDisconnect = 0,
  kEnergies = 1,
  kCoordinates = 2,  // IMD_FCOORDS
  kGo = 3,
  kHandshake = 4,
  kKill = 5,
  kForces = 6,  // IMD_MDCOMM: forces from the client
  kPause = 7,
  kTransferRate = 8,
  kIoError = 9,
};

inline constexpr int kHeaderBytes = 8;
inline constexpr int kEnergiesBytes = 40;  // int32 step + 9 float32
inline constexpr int32_t kProtocolVersion = 2;
using HeaderBytes = std::array<unsigned char, kHeaderBytes>;

// A header as sent, with the type and length in network byte order.
HeaderBytes encode_header(MessageType type, int32_t length);

// The type and length of a header received (decoded from network byte order; not validated).
struct Header {
  int32_t type = 0;
  int32_t length = 0;
};
Header decode_header(const HeaderBytes &bytes);

// "IMD_FCOORDS" for a known type, "message type 77" for another.
std::string type_name(int32_t type);

// The server's handshake. "" and *swap (true when the server's byte order differs from this
// machine's, so payloads must be byte-swapped), or an error: not a handshake, or a version other
// than 2 (IMD version 3 is named as such).
std::string check_handshake(const HeaderBytes &bytes, bool *swap);

// What a header that announces a frame's data may say. The first IMD_FCOORDS fixes the atom
// count; every later one must repeat it (IMD servers send one fixed group of atoms).
struct Limits {
  int64_t max_atoms = 0;       // the largest count accepted
  int64_t expected_atoms = 0;  // 0 until the first frame, then its count
};

// Checks a header from the server: IMD_ENERGIES of length 1, or IMD_FCOORDS with
// 1 <= length <= max_atoms (and == expected_atoms once known). Anything else is an error naming
// the type and length received.
std::string check_server_header(const Header &header, const Limits &limits);

// Reverses the bytes of each 32-bit word of `words` (n words), in place.
void swap_words(void *words, int64_t n);

// The step of an IMD_ENERGIES payload (its first int32, in the server's byte order).
int32_t energies_step(const unsigned char *payload, bool swap);

}  // namespace lantern_imd
