// GlContext back end: EGL without a window (libglvnd's libEGL, any vendor behind it): a GPU
// through EGL_EXT_device_enumeration, else Mesa's software device (llvmpipe), else the
// surfaceless platform. OpenGL 3.3 core; Lantern renders into its own framebuffer objects, so
// the context needs no surface.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/render/gl/gl_context.h"
#include "core/render/gl/gl_functions.h"

namespace lantern {
namespace {

template <typename F>
F egl_proc(const char *name) {
  return reinterpret_cast<F>(eglGetProcAddress(name));
}

void *lookup_gl(const char *name) {
  // EGL_KHR_get_all_proc_addresses (every Mesa and NVIDIA libEGL): core functions too.
  return reinterpret_cast<void *>(eglGetProcAddress(name));
}

bool has_extension(const char *list, const char *name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char *p = std::strstr(list, name); p; p = std::strstr(p + n, name))
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

std::string egl_error(const char *what) {
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", unsigned(eglGetError()));
  return std::string(what) + " failed (EGL error " + code + ")";
}

class EglContext final : public GlContext {
 public:
  EglContext(EGLDisplay display, EGLContext context, std::string where)
      : display_(display), context_(context), where_(std::move(where)) {}
  ~EglContext() override {
    if (&gl() == &functions_) set_current_gl_functions(nullptr);
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    // No eglTerminate: EGL displays are per device and not reference counted, and another
    // context of the process may still use this one.
  }

  Status load() { return load_gl_functions(lookup_gl, &functions_); }

  Status make_current() override {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      return {StatusCode::kGl, egl_error("eglMakeCurrent")};
    set_current_gl_functions(&functions_);
    return {};
  }

  const char *backend() const override { return "egl"; }

  std::string description() const override {
    return "EGL (" + where_ + ") / " + gl_driver_text(functions_);
  }

 private:
  EGLDisplay display_;
  EGLContext context_;
  std::string where_;
  GlFunctions functions_;
};

struct Candidate {
  EGLDisplay display = EGL_NO_DISPLAY;
  std::string where;
};

// The displays to try, best first: the chosen device, or hardware devices (spread by
// `local_rank`), then Mesa's software device, then the surfaceless platform.
std::vector<Candidate> candidates(const EglOptions &options) {
  std::vector<Candidate> out;
  const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const auto get_display = egl_proc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
  if (!get_display) return out;
  const auto query_devices = egl_proc<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
  const auto query_string = egl_proc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
  if (has_extension(client, "EGL_EXT_device_enumeration") &&
      has_extension(client, "EGL_EXT_platform_device") && query_devices && query_string) {
    EGLint count = 0;
    query_devices(0, nullptr, &count);
    std::vector<EGLDeviceEXT> devices(size_t(std::max(count, 0)));
    if (count > 0 && query_devices(count, devices.data(), &count)) {
      devices.resize(size_t(count));
      std::vector<int> hardware, software;
      for (int i = 0; i < count; ++i) {
        const char *ext = query_string(devices[size_t(i)], EGL_EXTENSIONS);
        (has_extension(ext, "EGL_MESA_device_software") ? software : hardware).push_back(i);
      }
      const auto add = [&](int i, const char *kind) {
        const EGLDisplay d = get_display(EGL_PLATFORM_DEVICE_EXT, devices[size_t(i)], nullptr);
        if (d != EGL_NO_DISPLAY) out.push_back({d, "device " + std::to_string(i) + ", " + kind});
      };
      if (options.device >= 0) {
        if (options.device < count)
          add(options.device,
              std::find(software.begin(), software.end(), options.device) != software.end()
                  ? "software"
                  : "hardware");
        return out;  // a device asked for by number: that one or none
      }
      for (size_t k = 0; k < hardware.size(); ++k)  // rank r starts at device r mod n
        add(hardware[(size_t(std::max(options.local_rank, 0)) + k) % hardware.size()], "hardware");
      for (const int i : software) add(i, "software");
    }
  }
  if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
    const EGLDisplay d = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d != EGL_NO_DISPLAY) out.push_back({d, "surfaceless platform"});
  }
  return out;
}

// An OpenGL 3.3 core context on `display`, or a message saying why not.
Status context_on(const Candidate &c, std::unique_ptr<GlContext> *out) {
  EGLint major = 0, minor = 0;
  if (!eglInitialize(c.display, &major, &minor))
    return {StatusCode::kGl, c.where + ": " + egl_error("eglInitialize")};
  const char *ext = eglQueryString(c.display, EGL_EXTENSIONS);
  if (!has_extension(ext, "EGL_KHR_surfaceless_context"))
    return {StatusCode::kGl, c.where + ": no EGL_KHR_surfaceless_context"};
  if (!eglBindAPI(EGL_OPENGL_API))
    return {StatusCode::kGl, c.where + ": " + egl_error("eglBindAPI")};
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!has_extension(ext, "EGL_KHR_no_config_context")) {
    const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint n = 0;
    if (!eglChooseConfig(c.display, want, &config, 1, &n) || n < 1)
      return {StatusCode::kGl, c.where + ": no EGL config for desktop OpenGL"};
  }
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                            3,
                            EGL_CONTEXT_MINOR_VERSION,
                            3,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK,
                            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                            EGL_NONE};
  const EGLContext context = eglCreateContext(c.display, config, EGL_NO_CONTEXT, attribs);
  if (context == EGL_NO_CONTEXT)
    return {StatusCode::kGl, c.where + ": " + egl_error("eglCreateContext (OpenGL 3.3 core)")};
  auto ctx = std::make_unique<EglContext>(c.display, context, c.where);
  if (Status s = ctx->load(); !s.ok()) return {s.code, c.where + ": " + s.message};
  if (Status s = ctx->make_current(); !s.ok()) return {s.code, c.where + ": " + s.message};
  *out = std::move(ctx);
  return {};
}

}  // namespace

Status create_egl_context(const EglOptions &options, std::unique_ptr<GlContext> *out) {
  const std::vector<Candidate> displays = candidates(options);
  if (displays.empty())
    return {StatusCode::kGl,
            options.device >= 0 ? "EGL device " + std::to_string(options.device) + " does not exist"
                                : std::string("EGL offers no device and no surfaceless platform")};
  std::string tried;
  for (const Candidate &c : displays) {
    const Status s = context_on(c, out);
    if (s.ok()) return s;
    tried += (tried.empty() ? "" : "; ") + s.message;
  }
  return {StatusCode::kGl, "no EGL context: " + tried};
}

}  // namespace lantern
