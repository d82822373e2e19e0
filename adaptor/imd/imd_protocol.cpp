#include "imd_protocol.h"

#include <cstring>

namespace lantern_imd {
namespace {

uint32_t big_endian(const unsigned char *p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

uint32_t native(const unsigned char *p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

uint32_t reversed(uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

}  // namespace

HeaderBytes encode_header(MessageType type, int32_t length) {
  HeaderBytes b{};
  const uint32_t words[2] = {uint32_t(type), uint32_t(length)};
  for (int w = 0; w < 2; ++w)
    for (int k = 0; k < 4; ++k) b[size_t(4 * w + k)] = (words[w] >> (24 - 8 * k)) & 0xffu;
  return b;
}

Header decode_header(const HeaderBytes &bytes) {
  return {int32_t(big_endian(bytes.data())), int32_t(big_endian(bytes.data() + 4))};
}

std::string type_name(int32_t type) {
  static const char *const names[] = {"IMD_DISCONNECT", "IMD_ENERGIES", "IMD_FCOORDS", "IMD_GO",
                                      "IMD_HANDSHAKE",  "IMD_KILL",     "IMD_MDCOMM",  "IMD_PAUSE",
                                      "IMD_TRATE",      "IMD_IOERROR"};
  if (type >= 0 && type < int32_t(sizeof(names) / sizeof(names[0]))) return names[type];
  return "message type " + std::to_string(type);
}

std::string check_handshake(const HeaderBytes &bytes, bool *swap) {
  const Header h = decode_header(bytes);
  if (h.type != int32_t(MessageType::kHandshake))
    return "expected the server's IMD_HANDSHAKE, received " + type_name(h.type) +
           " (is this port an IMD server?)";
  // The version is written in the server's byte order: read as this machine's or reversed.
  const uint32_t raw = native(bytes.data() + 4);
  for (const bool swapped : {false, true}) {
    const uint32_t version = swapped ? reversed(raw) : raw;
    if (version == uint32_t(kProtocolVersion)) {
      *swap = swapped;
      return {};
    }
    if (version == 3)
      return "the server speaks IMD version 3, which lantern-imd does not read; use version 2 "
             "(LAMMPS: fix imd ... version 2)";
  }
  return "the server's IMD_HANDSHAKE announces protocol version " + std::to_string(raw) +
         " (bytes " + std::to_string(bytes[4]) + " " + std::to_string(bytes[5]) + " " +
         std::to_string(bytes[6]) + " " + std::to_string(bytes[7]) +
         "); lantern-imd reads version 2";
}

std::string check_server_header(const Header &header, const Limits &limits) {
  const std::string what = type_name(header.type) + " of length " + std::to_string(header.length);
  if (header.type == int32_t(MessageType::kEnergies)) {
    if (header.length != 1) return "unexpected " + what + " (an energy record has length 1)";
    return {};
  }
  if (header.type != int32_t(MessageType::kCoordinates))
    return "unexpected " + what + " from the server (expected IMD_FCOORDS or IMD_ENERGIES)";
  if (header.length < 1) return "invalid " + what + ": a frame holds at least one atom";
  if (header.length > limits.max_atoms)
    return "invalid " + what + ": more atoms than --max-atoms " + std::to_string(limits.max_atoms);
  if (limits.expected_atoms != 0 && header.length != limits.expected_atoms)
    return "invalid " + what + ": the first frame had " + std::to_string(limits.expected_atoms) +
           " atoms, and an IMD server sends the same atoms in every frame";
  return {};
}

void swap_words(void *words, int64_t n) {
  auto *p = static_cast<unsigned char *>(words);
  for (int64_t i = 0; i < n; ++i, p += 4) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    v = reversed(v);
    std::memcpy(p, &v, 4);
  }
}

int32_t energies_step(const unsigned char *payload, bool swap) {
  const uint32_t raw = native(payload);
  return int32_t(swap ? reversed(raw) : raw);
}

}  // namespace lantern_imd
