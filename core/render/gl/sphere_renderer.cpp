#include "core/render/gl/sphere_renderer.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <vector>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/common/ms_since.h"
#include "core/render/gl/bond_shaders.h"
#include "core/render/gl/gl_functions.h"
#include "core/render/gl/gl_objects.h"
#include "core/render/gl/sphere_shaders.h"

namespace lantern {
namespace {

// Instances uploaded per draw call: bounds the streaming buffer at 20 MiB.
constexpr size_t kChunkInstances = size_t(1) << 20;

Status compile(GLenum kind, const char *source, GlShader *out) {
  const char *what = kind == GL_VERTEX_SHADER ? "vertex" : "fragment";
  GlShader shader(gl().glCreateShader(kind));
  gl().glShaderSource(shader.get(), 1, &source, nullptr);
  gl().glCompileShader(shader.get());
  GLint ok = GL_FALSE;
  gl().glGetShaderiv(shader.get(), GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::vector<char> log(4096);
    gl().glGetShaderInfoLog(shader.get(), GLsizei(log.size()), nullptr, log.data());
    return {StatusCode::kGl,
            std::string("impostor ") + what + " shader failed to compile: " + log.data()};
  }
  *out = std::move(shader);
  return {};
}

// The two impostors: spheres and bonds' cylinders.
enum class Primitive { kSphere, kBond };

Status link_program(Primitive primitive, const Lighting &lighting, GlProgram *out) {
  GlShader vs, fs;
  const bool sphere = primitive == Primitive::kSphere;
  if (Status s =
          compile(GL_VERTEX_SHADER, sphere ? shaders::kSphereVertex : shaders::kBondVertex, &vs);
      !s.ok())
    return s;
  const std::string fragment =
      sphere ? shaders::sphere_fragment_source(lighting) : shaders::bond_fragment_source(lighting);
  if (Status s = compile(GL_FRAGMENT_SHADER, fragment.c_str(), &fs); !s.ok()) return s;
  GlProgram program(gl().glCreateProgram());
  gl().glAttachShader(program.get(), vs.get());
  gl().glAttachShader(program.get(), fs.get());
  gl().glLinkProgram(program.get());
  GLint ok = GL_FALSE;
  gl().glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (!ok) {
    std::vector<char> log(4096);
    gl().glGetProgramInfoLog(program.get(), GLsizei(log.size()), nullptr, log.data());
    return {StatusCode::kGl,
            std::string(sphere ? "sphere" : "bond") + " program failed to link: " + log.data()};
  }
  *out = std::move(program);
  return {};
}

// Maps the full image's clip space onto one tile's: NDC x' = x * W/tw + (W - 2 tx - tw)/tw.
glm::mat4 tile_projection(const RenderView &v, int tx, int ty, int tw, int th) {
  glm::mat4 m(1.0f);
  m[0][0] = float(v.width) / float(tw);
  m[1][1] = float(v.height) / float(th);
  m[3][0] = float(v.width - 2 * tx - tw) / float(tw);
  m[3][1] = float(v.height - 2 * ty - th) / float(th);
  return m * v.projection;
}

// The shader's color key of an RGB8 color is R * 65536 + G * 256 + B, exact in a float and ordered
// as compositing orders colors (R, then G, then B). The key buffer is cleared to kNoKey, above
// every key, so that the background competes (below) only at background depth.
constexpr float kNoKey = 16777216.0f;  // 2^24

// The word R<<24 | G<<16 | B<<8 | A of compositing (packed_pixel.h), from 4 bytes.
uint32_t color_word(const uint8_t rgba[4]) {
  return uint32_t(rgba[0]) << 24 | uint32_t(rgba[1]) << 16 | uint32_t(rgba[2]) << 8 | rgba[3];
}

// The far-plane distance of the view's projection (glm::perspective or glm::ortho, OpenGL
// conventions): perspective p22 = -(f + n) / (f - n), p32 = -2 f n / (f - n); orthographic
// p22 = -2 / (f - n), p32 = -(f + n) / (f - n).
float far_plane(const RenderView &v) {
  const float p22 = v.projection[2][2], p32 = v.projection[3][2];
  return v.orthographic ? (p32 - 1.0f) / p22 : p32 / (p22 + 1.0f);
}

}  // namespace

namespace {

// Uniform locations of one linked program.
struct UniformLocations {
  GLint view, tile_proj, ortho, near_plane, far_plane, slack, proj, inv_proj, image_size,
      tile_origin, depth_only;
};

// A program for one primitive and lighting: the default one, or a variant with that lighting's
// constants.
struct LitProgram {
  Primitive primitive = Primitive::kSphere;
  Lighting lighting;
  GlProgram program;
  UniformLocations loc{};
};

Status make_lit_program(Primitive primitive, const Lighting &lighting, LitProgram *out) {
  if (Status s = link_program(primitive, lighting, &out->program); !s.ok()) return s;
  out->primitive = primitive;
  const GLuint p = out->program.get();
  const auto uniform = [p](const char *name) { return gl().glGetUniformLocation(p, name); };
  out->lighting = lighting;
  out->loc = {uniform("u_view"),        uniform("u_tile_proj"), uniform("u_ortho"),
              uniform("u_near"),        uniform("u_far"),       uniform("u_slack"),
              uniform("u_proj"),        uniform("u_inv_proj"),  uniform("u_image_size"),
              uniform("u_tile_origin"), uniform("u_depth_only")};
  return {};
}

// Variant programs kept besides the default sphere program; beyond that the oldest is dropped (a
// scene's lighting rarely changes, and a few scenes may each have their own).
constexpr size_t kMaxLightingVariants = 8;

// The uniforms every program of a render shares, set on `loc`'s program (in use).
void set_view_uniforms(const UniformLocations &loc, const RenderView &view, const glm::mat4 &inv) {
  gl().glUniformMatrix4fv(loc.view, 1, GL_FALSE, glm::value_ptr(view.view));
  gl().glUniformMatrix4fv(loc.proj, 1, GL_FALSE, glm::value_ptr(view.projection));
  gl().glUniformMatrix4fv(loc.inv_proj, 1, GL_FALSE, glm::value_ptr(inv));
  gl().glUniform1i(loc.ortho, view.orthographic ? 1 : 0);
  gl().glUniform1f(loc.near_plane, view.near_plane);
  gl().glUniform1f(loc.far_plane, far_plane(view));
  // A twentieth of a pixel, as a view-space length (ortho) or slope (perspective): x_ndc =
  // projection[0][0] * x (/ -z) for the symmetric frusta and boxes cameras build.
  gl().glUniform2f(loc.slack, 0.05f * 2.0f / (float(view.width) * view.projection[0][0]),
                   0.05f * 2.0f / (float(view.height) * view.projection[1][1]));
  gl().glUniform2f(loc.image_size, float(view.width), float(view.height));
}

}  // namespace

struct SphereRenderer::Impl {
  // [0]: spheres under the default lighting; then the others (bonds, variants), oldest first
  std::vector<LitProgram> programs;
  GlVertexArray vao, bond_vao;
  GlBuffer instances, bond_instances;
  GlFramebuffer fbo;
  GlRenderbuffer key_rb, depth_rb;  // color keys (R32F, see sphere_shaders.h), window depth
  int fbo_w = 0, fbo_h = 0;
  int tile_limit = kMaxTileSize;
  int gl_limit = kMaxTileSize;  // min(kMaxTileSize, GL renderbuffer and viewport limits)
  std::vector<float> tile_key;
  std::vector<float> tile_depth;

  // The program for `primitive` under `lighting`, linked on first use. Pointers into
  // `programs` stay valid until the next call.
  Status program_for(Primitive primitive, const Lighting &lighting, size_t *out) {
    for (size_t k = 0; k < programs.size(); ++k)
      if (programs[k].primitive == primitive && programs[k].lighting == lighting)
        return *out = k, Status();
    LitProgram p;
    if (Status s = make_lit_program(primitive, lighting, &p); !s.ok()) return s;
    // The oldest other lighting's program goes: the programs of this lighting (spheres and
    // bonds of one render) stay together.
    if (programs.size() > kMaxLightingVariants)
      for (size_t k = 1; k < programs.size(); ++k)
        if (!(programs[k].lighting == lighting)) {
          programs.erase(programs.begin() + std::ptrdiff_t(k));
          break;
        }
    programs.push_back(std::move(p));
    *out = programs.size() - 1;
    return {};
  }

  Status ensure_framebuffer(int w, int h) {
    if (w == fbo_w && h == fbo_h) return {};
    GLuint name = 0;
    gl().glGenRenderbuffers(1, &name);
    key_rb = GlRenderbuffer(name);
    gl().glBindRenderbuffer(GL_RENDERBUFFER, key_rb.get());
    gl().glRenderbufferStorage(GL_RENDERBUFFER, GL_R32F, w, h);
    gl().glGenRenderbuffers(1, &name);
    depth_rb = GlRenderbuffer(name);
    gl().glBindRenderbuffer(GL_RENDERBUFFER, depth_rb.get());
    gl().glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, w, h);
    gl().glBindFramebuffer(GL_FRAMEBUFFER, fbo.get());
    gl().glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                   key_rb.get());
    gl().glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                   depth_rb.get());
    if (gl().glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      return {StatusCode::kGl,
              "framebuffer of " + std::to_string(w) + "x" + std::to_string(h) + " is incomplete"};
    fbo_w = w;
    fbo_h = h;
    return {};
  }

  // Draws `count` instances of `size` bytes each from `data` through `vao` (whose attributes
  // read `buffer`).
  static void draw_all(const GlVertexArray &vao, const GlBuffer &buffer, const void *data,
                       size_t size, size_t count, bool reupload) {
    gl().glBindVertexArray(vao.get());
    gl().glBindBuffer(GL_ARRAY_BUFFER, buffer.get());
    const auto *bytes = static_cast<const unsigned char *>(data);
    for (size_t first = 0; first < count; first += kChunkInstances) {
      const size_t n = std::min(kChunkInstances, count - first);
      if (reupload) {
        // A new store of exactly this chunk's size, filled in the same call: llvmpipe need not
        // wait for the previous chunk's draw, and nothing larger is allocated or cleared.
        gl().glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * size), bytes + first * size,
                          GL_STREAM_DRAW);
      }
      gl().glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(n));
    }
  }

  // Copies the tile whose lower-left pixel is (tx, gl_ty), GL rows bottom-up, into the frame
  // (rows top-down), color keys turned back into opaque RGBA8. At background depth the background
  // is a contender too, as it is in compositing: the smaller word of the two wins.
  void read_tile(const uint8_t background[4], Frame *frame, int tx, int gl_ty, int tw, int th) {
    tile_key.resize(size_t(tw) * th);
    tile_depth.resize(size_t(tw) * th);
    gl().glPixelStorei(GL_PACK_ALIGNMENT, 1);
    gl().glReadPixels(0, 0, tw, th, GL_RED, GL_FLOAT, tile_key.data());
    gl().glReadPixels(0, 0, tw, th, GL_DEPTH_COMPONENT, GL_FLOAT, tile_depth.data());
    const uint32_t background_word = color_word(background);
    for (int row = 0; row < th; ++row) {
      const int y = frame->height - 1 - (gl_ty + row);
      const size_t dst = frame->index(tx, y);
      const float *key = &tile_key[size_t(row) * tw];
      const float *depth = &tile_depth[size_t(row) * tw];
      uint8_t *rgba = &frame->rgba[dst * 4];
      for (int k = 0; k < tw; ++k, rgba += 4) {
        const uint32_t word = key[k] < kNoKey ? uint32_t(key[k]) << 8 | 0xFFu : 0xFFFFFFFFu;
        if (depth[k] == kBackgroundDepth && background_word <= word) {
          std::memcpy(rgba, background, 4);
          continue;
        }
        rgba[0] = uint8_t(word >> 24), rgba[1] = uint8_t(word >> 16), rgba[2] = uint8_t(word >> 8);
        rgba[3] = 255;
      }
      std::memcpy(&frame->depth[dst], depth, size_t(tw) * sizeof(float));
    }
  }
};

SphereRenderer::SphereRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SphereRenderer::~SphereRenderer() = default;

int SphereRenderer::max_tile_size() const {
  return impl_->tile_limit;
}

void SphereRenderer::set_max_tile_size(int pixels) {
  impl_->tile_limit = std::clamp(pixels, 16, impl_->gl_limit);
}

Status SphereRenderer::create(std::unique_ptr<SphereRenderer> *out) {
  auto impl = std::make_unique<Impl>();
  impl->programs.emplace_back();
  if (Status s = make_lit_program(Primitive::kSphere, Lighting(), &impl->programs.back()); !s.ok())
    return s;
  GLint rb_limit = 0, viewport_limit[2] = {0, 0};
  gl().glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &rb_limit);
  gl().glGetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport_limit);
  impl->gl_limit = std::min({kMaxTileSize, int(rb_limit), viewport_limit[0], viewport_limit[1]});
  impl->tile_limit = impl->gl_limit;

  GLuint name = 0;
  gl().glGenVertexArrays(1, &name);
  impl->vao = GlVertexArray(name);
  gl().glGenBuffers(1, &name);
  impl->instances = GlBuffer(name);
  gl().glGenFramebuffers(1, &name);
  impl->fbo = GlFramebuffer(name);

  gl().glBindVertexArray(impl->vao.get());
  gl().glBindBuffer(GL_ARRAY_BUFFER, impl->instances.get());
  gl().glEnableVertexAttribArray(0);
  gl().glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, sizeof(SphereInstance), nullptr);
  gl().glVertexAttribDivisor(0, 1);
  gl().glEnableVertexAttribArray(1);
  gl().glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(SphereInstance),
                             reinterpret_cast<const void *>(offsetof(SphereInstance, rgba)));
  gl().glVertexAttribDivisor(1, 1);
  // Bonds: start (vec3), end and radius (vec4), color.
  gl().glGenVertexArrays(1, &name);
  impl->bond_vao = GlVertexArray(name);
  gl().glGenBuffers(1, &name);
  impl->bond_instances = GlBuffer(name);
  gl().glBindVertexArray(impl->bond_vao.get());
  gl().glBindBuffer(GL_ARRAY_BUFFER, impl->bond_instances.get());
  gl().glEnableVertexAttribArray(0);
  gl().glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(BondInstance), nullptr);
  gl().glVertexAttribDivisor(0, 1);
  gl().glEnableVertexAttribArray(1);
  gl().glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(BondInstance),
                             reinterpret_cast<const void *>(offsetof(BondInstance, end)));
  gl().glVertexAttribDivisor(1, 1);
  gl().glEnableVertexAttribArray(2);
  gl().glVertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(BondInstance),
                             reinterpret_cast<const void *>(offsetof(BondInstance, rgba)));
  gl().glVertexAttribDivisor(2, 1);
  if (const GLenum err = gl().glGetError(); err != GL_NO_ERROR)
    return {StatusCode::kGl,
            "OpenGL error " + std::to_string(err) + " while setting up the sphere renderer"};
  out->reset(new SphereRenderer(std::move(impl)));  // private constructor: make_unique cannot
  return {};
}

Status SphereRenderer::render(const RenderView &view, const SphereInstance *spheres, size_t count,
                              Frame *frame, RenderTimings *timings) {
  return render(view, spheres, count, nullptr, 0, frame, timings);
}

Status SphereRenderer::render(const RenderView &view, const SphereInstance *spheres, size_t count,
                              const BondInstance *bonds, size_t bond_count, Frame *frame,
                              RenderTimings *timings) {
  Impl &m = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  frame->reset(view.width, view.height);
  const int tile_w = std::min(view.width, m.tile_limit);
  const int tile_h = std::min(view.height, m.tile_limit);
  if (Status s = m.ensure_framebuffer(tile_w, tile_h); !s.ok()) return s;

  // The programs of the primitives drawn (indices into m.programs, which may grow).
  size_t sphere_program = 0, bond_program = 0;
  if (bond_count > 0)
    if (Status s = m.program_for(Primitive::kBond, view.lighting, &bond_program); !s.ok()) return s;
  if (Status s = m.program_for(Primitive::kSphere, view.lighting, &sphere_program); !s.ok())
    return s;
  // Linking the sphere program may have dropped an older program: find the bond program again
  // (its lighting is this one, which eviction spares).
  if (bond_count > 0)
    if (Status s = m.program_for(Primitive::kBond, view.lighting, &bond_program); !s.ok()) return s;
  const glm::mat4 inv = glm::inverse(view.projection);
  struct Pass {
    const LitProgram *program;
    const GlVertexArray *vao;
    const GlBuffer *buffer;
    const void *data;
    size_t size, count;
  };
  std::vector<Pass> passes;
  if (count > 0)
    passes.push_back({&m.programs[sphere_program], &m.vao, &m.instances, spheres,
                      sizeof(SphereInstance), count});
  if (bond_count > 0)
    passes.push_back({&m.programs[bond_program], &m.bond_vao, &m.bond_instances, bonds,
                      sizeof(BondInstance), bond_count});
  for (const Pass &p : passes) {
    gl().glUseProgram(p.program->program.get());
    set_view_uniforms(p.program->loc, view, inv);
  }
  gl().glEnable(GL_DEPTH_TEST);
  gl().glDisable(GL_CULL_FACE);
  gl().glBlendEquation(GL_MIN);  // factors are ignored by GL_MIN
  gl().glClearColor(kNoKey, 0.0f, 0.0f, 0.0f);
  gl().glClearDepth(1.0);

  RenderTimings t;
  std::vector<bool> uploaded(passes.size(), false);
  for (int ty = 0; ty < view.height; ty += tile_h) {
    for (int tx = 0; tx < view.width; tx += tile_w) {
      const int tw = std::min(tile_w, view.width - tx);
      const int th = std::min(tile_h, view.height - ty);
      // Tile rows are counted from the bottom of the image, as GL counts them.
      const int gl_ty = view.height - ty - th;
      gl().glBindFramebuffer(GL_FRAMEBUFFER, m.fbo.get());
      gl().glViewport(0, 0, tw, th);
      gl().glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      const glm::mat4 tp = tile_projection(view, tx, gl_ty, tw, th);
      for (const Pass &p : passes) {
        gl().glUseProgram(p.program->program.get());
        gl().glUniformMatrix4fv(p.program->loc.tile_proj, 1, GL_FALSE, glm::value_ptr(tp));
        gl().glUniform2f(p.program->loc.tile_origin, float(tx), float(gl_ty));
      }
      if (!passes.empty()) {
        // Pass 1: the nearest depth of every pixel. Pass 2: the smallest color key among the
        // fragments at exactly that depth (read_tile lets the background compete at its depth).
        // Each pass draws every primitive: spheres and bonds settle depth and ties together.
        gl().glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        gl().glDepthMask(GL_TRUE);
        gl().glDepthFunc(GL_LESS);
        gl().glDisable(GL_BLEND);
        for (size_t k = 0; k < passes.size(); ++k) {
          const Pass &p = passes[k];
          const bool single_chunk = p.count <= kChunkInstances;
          gl().glUseProgram(p.program->program.get());
          gl().glUniform1i(p.program->loc.depth_only, 1);
          Impl::draw_all(*p.vao, *p.buffer, p.data, p.size, p.count,
                         !(single_chunk && uploaded[k]));
          uploaded[k] = true;
        }
        gl().glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        gl().glDepthMask(GL_FALSE);
        gl().glDepthFunc(GL_EQUAL);
        gl().glEnable(GL_BLEND);
        for (const Pass &p : passes) {
          gl().glUseProgram(p.program->program.get());
          gl().glUniform1i(p.program->loc.depth_only, 0);
          Impl::draw_all(*p.vao, *p.buffer, p.data, p.size, p.count, p.count > kChunkInstances);
        }
        gl().glDepthMask(GL_TRUE);  // for the next tile's clear
      }
      gl().glFinish();
      const auto r0 = std::chrono::steady_clock::now();
      m.read_tile(view.background, frame, tx, gl_ty, tw, th);
      t.readback_ms += ms_since(r0);
      ++t.tiles;
    }
  }
  if (const GLenum err = gl().glGetError(); err != GL_NO_ERROR)
    return {StatusCode::kGl, "OpenGL error " + std::to_string(err) + " while drawing spheres"};
  t.draw_ms = ms_since(t0) - t.readback_ms;
  if (timings) *timings = t;
  return {};
}

}  // namespace lantern
