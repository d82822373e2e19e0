// The camera of one scene in double precision, as the culling passes need it: world -> view
// space, the pixel rectangle a sphere can touch, the ray through a pixel centre, and the length
// tolerance that separates "certainly" from "maybe" when the GPU computes the same thing in float.
//
// Conventions: view space looks down -z; "depth" is the view-space distance along the view axis
// (d = -z), linear for both projections and ordered like the window depth. Pixels are counted as
// the Frame counts them: column x from the left, row y from the TOP; pixel (x, y) is sampled at
// its centre (x + 0.5, y + 0.5), exactly where the impostor shader casts its ray.
// Thread-safety: immutable value type.
#pragma once

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "core/camera/camera.h"

namespace lantern {

// Inclusive pixel rectangle; empty when x0 > x1 or y0 > y1.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool empty() const { return x0 > x1 || y0 > y1; }
  int64_t area() const { return empty() ? 0 : int64_t(x1 - x0 + 1) * (y1 - y0 + 1); }
  void unite(const PixelRect &o) {
    if (o.empty()) return;
    if (empty()) {
      *this = o;
      return;
    }
    x0 = std::min(x0, o.x0), y0 = std::min(y0, o.y0);
    x1 = std::max(x1, o.x1), y1 = std::max(y1, o.y1);
  }
};

struct ViewGeometry {
  glm::dmat4 view{1.0};  // world -> view
  bool orthographic = false;
  double near_plane = 0.01, far_plane = 100.0;
  int width = 1, height = 1;
  // Projection of a symmetric frustum / box (what make_camera builds):
  //   perspective: x_ndc = sx * x / d,  y_ndc = sy * y / d
  //   orthographic: x_ndc = sx * x + tx, y_ndc = sy * y + ty
  double sx = 1, sy = 1, tx = 0, ty = 0;
  double p22 = -1, p32 = 0;  // projection[2][2], projection[3][2]: depth -> NDC z
  // Length tolerance covering the float rounding of positions, matrices and the shader's ray
  // (about 150 float ulps of the scene's scale): anything closer than this to a decision
  // boundary is treated as "maybe".
  double eps = 0.0;

  // `scale` is a length that bounds |position - camera.origin| and |eye - origin|.
  static ViewGeometry from_camera(const Camera &camera, double scale);

  glm::dvec3 to_view(const glm::dvec3 &world) const {
    return glm::dvec3(view * glm::dvec4(world, 1.0));
  }
  static double depth_of(const glm::dvec3 &v) { return -v.z; }

  // Pixels per length unit at view depth d (1 / d folded in for perspective).
  double pixels_per_unit(double d) const {
    const double s = 0.5 * height * sy;
    return orthographic ? s : s / std::max(d, near_plane);
  }

  // Window depth (what the Frame stores) of view depth d.
  double window_depth(double d) const {
    const double z_ndc = orthographic ? (-p22 * d + p32) : (-p22 * d + p32) / d;
    return 0.5 * z_ndc + 0.5;
  }

  // The projected position of view-space point c in pixels (x right, y down from the image's
  // top-left corner; pixel k spans [k, k + 1)). False when c is not beyond the near plane
  // (perspective).
  bool pixel_position(const glm::dvec3 &c, double *x, double *y) const {
    double xn, yn;
    if (orthographic) {
      xn = sx * c.x + tx, yn = sy * c.y + ty;
    } else {
      const double d = -c.z;
      if (d <= near_plane) return false;
      xn = sx * c.x / d, yn = sy * c.y / d;
    }
    *x = (xn + 1.0) * 0.5 * width, *y = (1.0 - yn) * 0.5 * height;
    return true;
  }

  // Every pixel whose centre the sphere (view-space centre c, radius r) could cover, clamped to
  // the image. A sphere reaching behind the near plane gets the whole image.
  PixelRect sphere_rect(const glm::dvec3 &c, double r) const;
  // The pixels whose centres lie within `slack` pixels of the sphere's projected outline (the
  // outline computed in double for radius r + eps), clamped to the image: for the CPU raster,
  // whose own per-pixel test errs far less than `slack`. Empty when no centre is that close.
  // Inline: the CPU raster asks it once per candidate particle.
  PixelRect sphere_rect_tight(const glm::dvec3 &c, double r, double slack) const {
    double x_lo, x_hi, y_lo, y_hi;
    if (!sphere_ndc(c, r, &x_lo, &x_hi, &y_lo, &y_hi))
      return PixelRect{0, 0, width - 1, height - 1};
    return ndc_rect_tight(x_lo, x_hi, y_lo, y_hi, slack);
  }
  // sphere_rect_tight of n spheres: sphere k's view-space centre and radius are
  // spheres[k * stride + 0, 1, 2, 3] (x, y, z, r; `stride` in doubles, at least 4), its rectangle
  // out[k]. The same rectangles bit for bit. Why: the CPU raster works out a depth bucket's
  // rectangles together, and with AVX2 two spheres share each vector instruction, so the
  // divider (two divisions and a square root a sphere, most of the time of a rectangle) handles
  // two at once.
  void sphere_rects_tight(const double *spheres, size_t stride, int n, double slack,
                          PixelRect *out) const;
  // The same for a view-space box given by its 8 corners' bounds (already expanded by radius).
  PixelRect box_rect(const glm::dvec3 corners[8]) const;
  // box_rect of the axis-aligned box [lo, hi]'s corners (box_corners' order), the same rectangle
  // bit for bit with fewer divisions: 8 (the corners share two depths, x and y), or where the
  // bounds are finite 4 in two paired instructions (the extremes are among 4 of the quotients).
  PixelRect box_rect(const glm::dvec3 &lo, const glm::dvec3 &hi) const;

  // Unnormalised ray direction (perspective) or ray origin x/y (orthographic) through the centre
  // of pixel column x / row y: perspective dir = (ray_x(x), ray_y(y), -1).
  double ray_x(int x) const {
    const double ndc = (x + 0.5) / width * 2.0 - 1.0;
    return orthographic ? (ndc - tx) / sx : ndc / sx;
  }
  double ray_y(int y) const {
    const double ndc = 1.0 - (y + 0.5) / height * 2.0;
    return orthographic ? (ndc - ty) / sy : ndc / sy;
  }

 private:
  PixelRect ndc_rect(double x_lo, double x_hi, double y_lo, double y_hi) const;
  // The centres in [lo, hi] widened by `slack` pixels. NaN bounds give the whole range.
  PixelRect ndc_rect_tight(double x_lo, double x_hi, double y_lo, double y_hi, double slack) const {
    const auto first = [slack](double p, int n) {
      const double f = std::ceil(p - slack);
      return f > 0.0 ? int(std::min(f, double(n))) : 0;
    };
    const auto last = [slack](double p, int n) {
      const double f = std::floor(p + slack);
      return p != p ? n - 1 : f < double(n - 1) ? int(std::max(f, -1.0)) : n - 1;
    };
    return pixels_of(x_lo, x_hi, y_lo, y_hi, first, last);
  }
  // The pixel rectangle of NDC bounds, each edge mapped to continuous pixel coordinates (pixel
  // column x is sampled at NDC (x + 0.5) / W * 2 - 1) and rounded by `first` / `last`.
  template <typename First, typename Last>
  PixelRect pixels_of(double x_lo, double x_hi, double y_lo, double y_hi, First first,
                      Last last) const {
    const double hw = 0.5 * width, hh = 0.5 * height;
    PixelRect r;
    r.x0 = first((x_lo + 1.0) * hw - 0.5, width);
    r.x1 = last((x_hi + 1.0) * hw - 0.5, width);
    r.y0 = first((1.0 - y_hi) * hh - 0.5, height);
    r.y1 = last((1.0 - y_lo) * hh - 0.5, height);
    return r;
  }
  // NDC bounds of the sphere's outline for radius + eps (tangent lines from the eye, or the
  // orthographic box); false when the sphere reaches behind half the near plane.
  bool sphere_ndc(const glm::dvec3 &c, double radius, double *x_lo, double *x_hi, double *y_lo,
                  double *y_hi) const {
    const double r = radius + eps;
    if (orthographic) {
      *x_lo = sx * (c.x - r) + tx, *x_hi = sx * (c.x + r) + tx;
      *y_lo = sy * (c.y - r) + ty, *y_hi = sy * (c.y + r) + ty;
      return true;
    }
    if (-c.z - r <= 0.5 * near_plane) return false;
    // Tangent lines from the eye to the circle in the xz (yz) plane: slopes m = x / d with
    // m^2 (d^2 - r^2) - 2 x d m + x^2 - r^2 = 0.
    const double d = -c.z, dd = d * d - r * r;
#if defined(__SSE2__)
    // x and y side by side: the same IEEE operations, two divisions and one square root fewer.
    // max(0, q) is std::max(q, 0.0) (a NaN q stays NaN).
    const __m128d xy = _mm_set_pd(c.y, c.x);
    const __m128d q = _mm_add_pd(_mm_mul_pd(xy, xy), _mm_set1_pd(dd));
    const __m128d root = _mm_mul_pd(_mm_set1_pd(r), _mm_sqrt_pd(_mm_max_pd(_mm_setzero_pd(), q)));
    const __m128d xd = _mm_mul_pd(xy, _mm_set1_pd(d)), den = _mm_set1_pd(dd);
    const __m128d scale = _mm_set_pd(sy, sx);
    const __m128d lo = _mm_mul_pd(scale, _mm_div_pd(_mm_sub_pd(xd, root), den));
    const __m128d hi = _mm_mul_pd(scale, _mm_div_pd(_mm_add_pd(xd, root), den));
    *x_lo = _mm_cvtsd_f64(lo), *y_lo = _mm_cvtsd_f64(_mm_unpackhi_pd(lo, lo));
    *x_hi = _mm_cvtsd_f64(hi), *y_hi = _mm_cvtsd_f64(_mm_unpackhi_pd(hi, hi));
#else
    const auto slopes = [&](double x, double scale, double *lo, double *hi) {
      const double root = r * std::sqrt(std::max(x * x + dd, 0.0));
      *lo = scale * ((x * d - root) / dd);
      *hi = scale * ((x * d + root) / dd);
    };
    slopes(c.x, sx, x_lo, x_hi);
    slopes(c.y, sy, y_lo, y_hi);
#endif
    return true;
  }
};

}  // namespace lantern
