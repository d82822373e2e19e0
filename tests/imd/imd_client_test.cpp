// lantern-imd's parts without the simulation: the IMD header codec and its checks, the spatial
// split, and the receiver against byte streams written by a server thread over loopback: well-
// formed (both byte orders, with and without IMD_ENERGIES), paused, and hostile (truncated,
// huge, changing, unexpected, not IMD at all). The real simulations (LAMMPS, GROMACS) are in
// imd_test.sh.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "frame_receiver.h"
#include "imd_protocol.h"
#include "spatial_split.h"

namespace lantern_imd {
namespace {

using Bytes = std::vector<unsigned char>;

uint32_t swapped(uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

// Appends a header, and payload words in this machine's order or reversed.
void add_header(Bytes *b, int32_t type, int32_t length) {
  const HeaderBytes h = encode_header(MessageType(type), length);
  b->insert(b->end(), h.begin(), h.end());
}
void add_word(Bytes *b, uint32_t word, bool reverse) {
  if (reverse) word = swapped(word);
  unsigned char w[4];
  std::memcpy(w, &word, 4);
  b->insert(b->end(), w, w + 4);
}
void add_floats(Bytes *b, const std::vector<float> &xyz, bool reverse = false) {
  for (const float f : xyz) {
    uint32_t w;
    std::memcpy(&w, &f, 4);
    add_word(b, w, reverse);
  }
}
Bytes handshake(uint32_t version = 2, bool reverse = false) {
  Bytes b;
  add_header(&b, int32_t(MessageType::kHandshake), 0);
  b.resize(4);  // the length is the version in the server's own byte order
  add_word(&b, version, reverse);
  return b;
}
void add_frame(Bytes *b, const std::vector<float> &xyz, bool reverse = false) {
  add_header(b, int32_t(MessageType::kCoordinates), int32_t(xyz.size() / 3));
  add_floats(b, xyz, reverse);
}
void add_energies(Bytes *b, int32_t step, bool reverse = false) {
  add_header(b, int32_t(MessageType::kEnergies), 1);
  add_word(b, uint32_t(step), reverse);
  for (int k = 0; k < 9; ++k) add_word(b, 0, reverse);
}

bool write_all(int fd, const Bytes &b) {
  size_t sent = 0;
  while (sent < b.size()) {
    const ssize_t n = send(fd, b.data() + sent, b.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return false;
    sent += size_t(n);
  }
  return true;
}

bool read_all(int fd, void *into, size_t n) {
  auto *p = static_cast<unsigned char *>(into);
  for (size_t got = 0; got < n;) {
    const ssize_t k = recv(fd, p + got, n - got, 0);
    if (k <= 0) return false;
    got += size_t(k);
  }
  return true;
}

// A one-client IMD server on 127.0.0.1: accepts, then runs `script` on the connection and closes
// it. received_go: the client's first header was IMD_GO.
class LoopbackServer {
 public:
  explicit LoopbackServer(std::function<void(int fd)> script) {
    listen_fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bind(listen_fd_, reinterpret_cast<sockaddr *>(&a), sizeof(a));
    socklen_t len = sizeof(a);
    getsockname(listen_fd_, reinterpret_cast<sockaddr *>(&a), &len);
    port_ = std::to_string(ntohs(a.sin_port));
    listen(listen_fd_, 1);
    thread_ = std::thread([this, script] {
      const int fd = accept(listen_fd_, nullptr, nullptr);
      if (fd < 0) return;
      script(fd);
      close(fd);
    });
  }
  ~LoopbackServer() {
    shutdown(listen_fd_, SHUT_RDWR);
    thread_.join();
    close(listen_fd_);
  }
  const std::string &port() const { return port_; }

 private:
  int listen_fd_ = -1;
  std::string port_;
  std::thread thread_;
};

// The server's usual start: handshake, then the client's IMD_GO.
bool greet(int fd, std::atomic<bool> *got_go, const Bytes &hello = handshake()) {
  if (!write_all(fd, hello)) return false;
  HeaderBytes h{};
  if (!read_all(fd, h.data(), h.size())) return false;
  *got_go = decode_header(h).type == int32_t(MessageType::kGo);
  return true;
}

std::atomic<bool> never{false};

std::unique_ptr<FrameReceiver> receiver_for(const LoopbackServer &server,
                                            ReceiverOptions options = {}) {
  if (options.max_atoms == 0) options.max_atoms = 178956970;
  std::unique_ptr<ImdConnection> c;
  const std::string e = ImdConnection::open("127.0.0.1", server.port(), 5.0, never, &c);
  EXPECT_EQ(e, "");
  if (!c) return nullptr;
  return std::make_unique<FrameReceiver>(std::move(c), options, never);
}

TEST(ImdProtocol, HeadersAreBigEndian) {
  const HeaderBytes h = encode_header(MessageType::kCoordinates, 256);
  EXPECT_EQ(Bytes(h.begin(), h.end()), (Bytes{0, 0, 0, 2, 0, 0, 1, 0}));
  const Header d = decode_header(h);
  EXPECT_EQ(d.type, 2);
  EXPECT_EQ(d.length, 256);
  EXPECT_EQ(type_name(2), "IMD_FCOORDS");
  EXPECT_EQ(type_name(77), "message type 77");
}

TEST(ImdProtocol, HandshakeTellsTheServersByteOrder) {
  HeaderBytes h;
  bool swap = true;
  Bytes b = handshake(2, false);
  std::copy(b.begin(), b.end(), h.begin());
  EXPECT_EQ(check_handshake(h, &swap), "");
  EXPECT_FALSE(swap);
  b = handshake(2, true);
  std::copy(b.begin(), b.end(), h.begin());
  EXPECT_EQ(check_handshake(h, &swap), "");
  EXPECT_TRUE(swap);
  b = handshake(3);
  std::copy(b.begin(), b.end(), h.begin());
  EXPECT_NE(check_handshake(h, &swap).find("IMD version 3"), std::string::npos);
  b = handshake(7);
  std::copy(b.begin(), b.end(), h.begin());
  EXPECT_NE(check_handshake(h, &swap).find("protocol version 7"), std::string::npos);
  const char http[] = "HTTP/1.1";
  std::memcpy(h.data(), http, 8);
  EXPECT_NE(check_handshake(h, &swap).find("expected the server's IMD_HANDSHAKE"),
            std::string::npos);
}

TEST(ImdProtocol, ServerHeadersAreChecked) {
  Limits limits;
  limits.max_atoms = 1000;
  const auto check = [&](int32_t type, int32_t length) {
    return check_server_header({type, length}, limits);
  };
  EXPECT_EQ(check(1, 1), "");
  EXPECT_NE(check(1, 2).find("an energy record has length 1"), std::string::npos);
  EXPECT_EQ(check(2, 1000), "");
  EXPECT_NE(check(2, 1001).find("more atoms than --max-atoms 1000"), std::string::npos);
  EXPECT_NE(check(2, 0).find("at least one atom"), std::string::npos);
  EXPECT_NE(check(2, -5).find("at least one atom"), std::string::npos);
  EXPECT_NE(check(6, 3).find("unexpected IMD_MDCOMM"), std::string::npos);
  EXPECT_NE(check(99, 0).find("unexpected message type 99"), std::string::npos);
  EXPECT_NE(check(-1, 0).find("message type -1"), std::string::npos);
  limits.expected_atoms = 10;
  EXPECT_EQ(check(2, 10), "");
  EXPECT_NE(check(2, 11).find("the first frame had 10 atoms"), std::string::npos);
}

TEST(SpatialSplit, PartsAreHalvesOfTheCurveAndBalanced) {
  std::vector<float> xyz;
  const int side = 16;
  for (int i = 0; i < side * side * side; ++i)
    xyz.insert(xyz.end(), {float(i % side), float((i / side) % side), float(i / (side * side))});
  const int64_t n = side * side * side;
  SpatialSplit split;
  split.split(xyz.data(), n, 2);
  ASSERT_EQ(split.counts(), (std::vector<int>{int(n / 2), int(n / 2)}));
  // z-order's first half of a cube is the half with the smaller x (x is each triple's top bit).
  for (int k = 0; k < n; ++k) {
    const float x = xyz[3 * size_t(split.order()[size_t(k)])];
    EXPECT_EQ(x < side / 2, k < n / 2) << "atom " << split.order()[size_t(k)];
  }
  split.split(xyz.data(), n, 3);
  EXPECT_EQ(split.counts()[0] + split.counts()[1] + split.counts()[2], n);
  for (const int c : split.counts()) EXPECT_LE(std::abs(c - int(n / 3)), 8) << "balanced";
  EXPECT_EQ(std::set<int32_t>(split.order().begin(), split.order().end()).size(), size_t(n));
  // A non-finite atom goes to part 0; one part keeps the stream's order.
  xyz[3 * 100 + 1] = std::numeric_limits<float>::quiet_NaN();
  split.split(xyz.data(), n, 4);
  const auto &o = split.order();
  EXPECT_NE(std::find(o.begin(), o.begin() + split.counts()[0], 100),
            o.begin() + split.counts()[0]);
  split.split(xyz.data(), n, 1);
  for (int k = 0; k < n; ++k) EXPECT_EQ(split.order()[size_t(k)], k);
}

TEST(FrameReceiver, ReadsFramesStepsAndTheEnd) {
  std::atomic<bool> got_go{false};
  LoopbackServer server([&](int fd) {
    if (!greet(fd, &got_go)) return;
    Bytes b;
    add_energies(&b, 700);  // GROMACS: the step before the frame
    add_frame(&b, {1, 2, 3, 4, 5, 6});
    add_frame(&b, {1.5f, 2, 3, 4, 5, -6.25f});  // LAMMPS: no step
    write_all(fd, b);
  });
  ReceiverOptions options;
  options.first_step = 10;
  options.every = 10;
  options.step_offset = -700;  // GROMACS's records carry the step after their frame's
  auto receiver = receiver_for(server, options);
  ASSERT_TRUE(receiver);
  Event e = receiver->next();
  ASSERT_EQ(e.kind, Event::Kind::kFrame) << e.message;
  EXPECT_TRUE(got_go);
  EXPECT_EQ(e.frame->step, 0);  // 700 - 700: a step 0 is a step, not "no step"
  EXPECT_EQ(e.frame->atoms, 2);
  EXPECT_EQ(e.frame->xyz, (std::vector<float>{1, 2, 3, 4, 5, 6}));
  receiver->recycle(std::move(e.frame));
  e = receiver->next();
  ASSERT_EQ(e.kind, Event::Kind::kFrame) << e.message;
  EXPECT_EQ(e.frame->step, 20);  // the second frame of a stream numbered 10, 20, ...
  EXPECT_EQ(e.frame->xyz, (std::vector<float>{1.5f, 2, 3, 4, 5, -6.25f}));
  e = receiver->next();
  EXPECT_EQ(e.kind, Event::Kind::kEnd);
  EXPECT_NE(e.message.find("closed the connection"), std::string::npos);
}

TEST(FrameReceiver, SwapsPayloadsOfTheOtherByteOrder) {
  std::atomic<bool> got_go{false};
  LoopbackServer server([&](int fd) {
    if (!greet(fd, &got_go, handshake(2, true))) return;
    Bytes b;
    add_energies(&b, 123456, true);
    add_frame(&b, {0.1f, -2e7f, 3.5f}, true);
    write_all(fd, b);
  });
  auto receiver = receiver_for(server);
  ASSERT_TRUE(receiver);
  Event e = receiver->next();
  ASSERT_EQ(e.kind, Event::Kind::kFrame) << e.message;
  EXPECT_EQ(e.frame->step, 123456);
  EXPECT_EQ(e.frame->xyz, (std::vector<float>{0.1f, -2e7f, 3.5f}));
}

// The error event a hostile stream (after a good handshake) ends in.
std::string error_for(const Bytes &stream, int64_t max_atoms = 178956970) {
  std::atomic<bool> got_go{false};
  LoopbackServer server([&](int fd) {
    if (greet(fd, &got_go)) write_all(fd, stream);
  });
  ReceiverOptions options;
  options.max_atoms = max_atoms;
  auto receiver = receiver_for(server, options);
  if (!receiver) return "no connection";
  for (;;) {
    Event e = receiver->next();
    if (e.kind == Event::Kind::kError) return e.message;
    if (e.kind == Event::Kind::kEnd) return "end: " + e.message;
  }
}

bool contains(const std::string &text, const std::string &part) {
  return text.find(part) != std::string::npos;
}

TEST(FrameReceiver, HostileStreamsAreErrors) {
  Bytes b;
  add_header(&b, 2, 100);
  b.resize(b.size() + 600);  // half of the 1200 bytes announced, then the server closes
  std::string e = error_for(b);
  EXPECT_TRUE(contains(e, "truncated")) << e;
  EXPECT_TRUE(contains(e, "received 600 of 1200 bytes")) << e;

  b.clear();
  add_frame(&b, {1, 2, 3});
  b.resize(b.size() + 3);  // a header cut short
  e = error_for(b);
  EXPECT_TRUE(contains(e, "a message header (received 3 of 8 bytes)")) << e;

  b.clear();
  add_frame(&b, {1, 2, 3});
  add_frame(&b, {1, 2, 3, 4, 5, 6});
  e = error_for(b);
  EXPECT_TRUE(contains(e, "frame 2: invalid IMD_FCOORDS of length 2")) << e;

  b.clear();
  add_header(&b, 2, 5000);
  e = error_for(b, 1000);
  EXPECT_TRUE(contains(e, "more atoms than --max-atoms 1000")) << e;

  for (const auto &[type, length, message] : std::vector<std::tuple<int32_t, int32_t, std::string>>{
           {2, -7, "at least one atom"},
           {1, 4, "an energy record has length 1"},
           {6, 1, "unexpected IMD_MDCOMM"},
           {12345, 1, "unexpected message type 12345"},
           {int32_t(0x80000000u), 0, "message type -2147483648"}}) {
    b.clear();
    add_header(&b, type, length);
    e = error_for(b);
    EXPECT_TRUE(contains(e, message)) << e;
  }
}

// A header announcing the largest frame IMD can describe (2 GiB of coordinates), followed by a
// few bytes: the receiver allocates as data arrives, never the announced size.
TEST(FrameReceiver, HugeAnnouncedFrameAllocatesOnlyWhatArrives) {
  rusage before{}, after{};
  getrusage(RUSAGE_SELF, &before);
  Bytes b;
  add_header(&b, 2, 178956970);
  b.resize(b.size() + 1000);
  const std::string e = error_for(b);
  getrusage(RUSAGE_SELF, &after);
  EXPECT_TRUE(contains(e, "received 1000 of 2147483640 bytes")) << e;
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 64 * 1024) << "KiB of peak memory added";
}

TEST(FrameReceiver, NotAnImdServerIsAnError) {
  std::atomic<bool> unused{false};
  for (const auto &[hello, message] : std::vector<std::pair<Bytes, std::string>>{
           {Bytes{'H', 'T', 'T', 'P', '/', '1', '.', '1'}, "expected the server's IMD_HANDSHAKE"},
           {handshake(3), "IMD version 3"},
           {Bytes{0, 0, 0, 4}, "closed the connection before its IMD handshake"}}) {
    LoopbackServer server([&](int fd) { write_all(fd, hello); });
    std::unique_ptr<ImdConnection> c;
    const std::string e = ImdConnection::open("127.0.0.1", server.port(), 5.0, never, &c);
    EXPECT_TRUE(contains(e, message)) << e;
    EXPECT_FALSE(c);
  }
  // Nobody listening: refused until the connect timeout.
  std::unique_ptr<ImdConnection> c;
  const auto t0 = std::chrono::steady_clock::now();
  const std::string e = ImdConnection::open("127.0.0.1", "1", 0.5, never, &c);
  EXPECT_TRUE(contains(e, "127.0.0.1:1: cannot connect")) << e;
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
}

TEST(FrameReceiver, WaitsForAPausedSimulation) {
  std::atomic<bool> got_go{false};
  LoopbackServer server([&](int fd) {
    if (!greet(fd, &got_go)) return;
    Bytes b;
    add_frame(&b, {1, 2, 3});
    write_all(fd, b);
    std::this_thread::sleep_for(std::chrono::milliseconds(1200));  // paused, between runs, ...
    write_all(fd, b);
  });
  auto receiver = receiver_for(server);
  ASSERT_TRUE(receiver);
  for (int k = 0; k < 2; ++k) {
    Event e = receiver->next();
    EXPECT_EQ(e.kind, Event::Kind::kFrame) << e.message;
  }
  EXPECT_EQ(receiver->next().kind, Event::Kind::kEnd);
}

TEST(FrameReceiver, IdleTimeoutEndsTheWait) {
  std::atomic<bool> got_go{false}, release{false};
  LoopbackServer server([&](int fd) {
    if (!greet(fd, &got_go)) return;
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  });
  ReceiverOptions options;
  options.idle_seconds = 0.3;
  auto receiver = receiver_for(server, options);
  ASSERT_TRUE(receiver);
  const Event e = receiver->next();
  release = true;
  EXPECT_EQ(e.kind, Event::Kind::kEnd);
  EXPECT_TRUE(contains(e.message, "--idle-timeout")) << e.message;
}

TEST(FrameReceiver, LeavingSendsDisconnect) {
  std::atomic<bool> got_go{false}, got_disconnect{false};
  LoopbackServer server([&](int fd) {
    if (!greet(fd, &got_go)) return;
    Bytes b;
    add_frame(&b, {1, 2, 3});
    write_all(fd, b);
    HeaderBytes h{};
    if (read_all(fd, h.data(), h.size()))
      got_disconnect = decode_header(h).type == int32_t(MessageType::kDisconnect);
  });
  {
    auto receiver = receiver_for(server);
    ASSERT_TRUE(receiver);
    EXPECT_EQ(receiver->next().kind, Event::Kind::kFrame);
  }  // the client leaves while the simulation goes on
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(got_disconnect);
}

// Five frames sent at once while nothing is rendered: kBlock keeps them all (the server waits on
// the socket), kDropOldest keeps the newest and counts the others.
TEST(FrameReceiver, BlockKeepsEveryFrameDropKeepsTheNewest) {
  for (const bool drop : {false, true}) {
    std::atomic<bool> got_go{false};
    LoopbackServer server([&](int fd) {
      if (!greet(fd, &got_go)) return;
      Bytes b;
      for (int k = 0; k < 5; ++k) {
        add_energies(&b, k);
        add_frame(&b, {float(k), 0, 0});
      }
      write_all(fd, b);
    });
    ReceiverOptions options;
    options.drop_oldest = drop;
    auto receiver = receiver_for(server, options);
    ASSERT_TRUE(receiver);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // "rendering"
    std::vector<int64_t> steps;
    for (Event e = receiver->next(); e.kind == Event::Kind::kFrame; e = receiver->next())
      steps.push_back(e.frame->step);
    if (drop) {
      EXPECT_EQ(steps, (std::vector<int64_t>{4}));
      EXPECT_EQ(receiver->dropped(), 4);
    } else {
      EXPECT_EQ(steps, (std::vector<int64_t>{0, 1, 2, 3, 4}));
      EXPECT_EQ(receiver->dropped(), 0);
    }
  }
}

}  // namespace
}  // namespace lantern_imd
