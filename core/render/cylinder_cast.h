// The CPU raster's ray cast of a closed cylinder (a half-bond), per pixel, and the columns of each
// row worth casting: CylinderCast decides a pixel in double (cylinders reaching behind the eye
// plane; centred_cylinder_cast.h casts the others in float), CylinderRows bounds the pixels
// either cast can accept, so that draw_bond casts only those and its image is that of casting
// every pixel.
// Thread-safety: immutable values. Units: view space of ViewGeometry.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/view/pixel_rays.h"
#include "core/view/view_geometry.h"

namespace lantern {

// The ray of one pixel against a closed cylinder (view-space end a, unit axis u, length, radius
// r): where it enters (the view depth t, which is the ray parameter for D = (rx, ry, -1) from the
// eye or from (rx, ry, 0)), and the outward unit normal there. With w = o - a and the parts of D
// and w across the axis (Dp, wp), the curved side is |wp + t Dp| = r: qa t^2 + 2 qb t + (|wp|^2 -
// r^2) = 0, whose discriminant is qa r^2 - (u . (D x w))^2 without cancellation (the triple
// product is the distance between the ray and the axis times |Dp|). The solid is the curved
// side's interval cut by the end slab 0 <= (w + t D) . u <= length; the ray enters at the larger
// of the two entries. What does not change along the pixels - w, wp and u . w in perspective (the
// rays leave the eye), D, Dp, qa and u . D in orthographic (they are parallel) - is computed once,
// and each pixel divides twice (by qa and u . D), so a pixel's result depends only on the pixel
// and the cylinder.
struct CylinderHit {
  double t;
  glm::dvec3 normal;
};

class CylinderCast {
 public:
  CylinderCast(bool orthographic, const glm::dvec3 &a, const glm::dvec3 &u, double length, double r)
      : orthographic_(orthographic), a_(a), u_(u), length_(length), r2_(r * r), inv_r_(1.0 / r) {
    if (orthographic_) {
      d_ = glm::dvec3(0.0, 0.0, -1.0);
      d_u_ = -u.z;
      dp_ = d_ - d_u_ * u;
      qa_ = glm::dot(dp_, dp_);
      inv_qa_ = qa_ > 0.0 ? 1.0 / qa_ : 0.0;
      inv_du_ = d_u_ != 0.0 ? 1.0 / d_u_ : 0.0;
    } else {
      w_ = -a;
      w_u_ = glm::dot(w_, u);
      wp_ = w_ - w_u_ * u;
      m_ = glm::cross(w_, u);  // u . (D x w) = D . (w x u)
    }
  }

  bool cast(double rx, double ry, CylinderHit *hit) const {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    glm::dvec3 d, dp, wp;
    double d_u, w_u, qa, inv_qa, inv_du, cross;
    if (orthographic_) {
      const glm::dvec3 w(rx - a_.x, ry - a_.y, -a_.z);
      d = d_, d_u = d_u_, dp = dp_, qa = qa_, inv_qa = inv_qa_, inv_du = inv_du_;
      w_u = glm::dot(w, u_);
      wp = w - w_u * u_;
      cross = u_.x * w.y - u_.y * w.x;  // u . (D x w) with D = -z
    } else {
      d = glm::dvec3(rx, ry, -1.0);
      d_u = glm::dot(d, u_), w_u = w_u_, wp = wp_;
      dp = d - d_u * u_;
      qa = glm::dot(dp, dp);
      inv_qa = 0.0, inv_du = 0.0;  // set below where used
      cross = glm::dot(d, m_);
    }
    double side0 = -kInf, side1 = kInf;
    if (qa > 0.0) {
      const double h2 = qa * r2_ - cross * cross;
      if (!(h2 > 0.0)) return false;
      if (!orthographic_) inv_qa = 1.0 / qa;
      const double qb = glm::dot(dp, wp), s = std::sqrt(h2);
      side0 = (-qb - s) * inv_qa, side1 = (-qb + s) * inv_qa;
    } else if (!(glm::dot(wp, wp) < r2_)) {
      return false;  // along the axis, outside the curved side
    }
    double slab0 = -kInf, slab1 = kInf;
    if (d_u != 0.0) {
      if (!orthographic_) inv_du = 1.0 / d_u;
      const double t_a = -w_u * inv_du, t_b = (length_ - w_u) * inv_du;
      slab0 = std::min(t_a, t_b), slab1 = std::max(t_a, t_b);
    } else if (!(w_u >= 0.0 && w_u <= length_)) {
      return false;  // parallel to the end discs, beside the slab
    }
    const double enter = std::max(side0, slab0);
    if (!(enter <= std::min(side1, slab1))) return false;
    hit->t = enter;
    if (slab0 > side0)
      hit->normal = d_u > 0.0 ? -u_ : u_;  // through an end disc
    else
      hit->normal = (wp + enter * dp) * inv_r_;  // on the curved side, |wp + t Dp| = r
    return true;
  }

  // The squared Lambert factor of the headlight (light along the ray) at a hit of pixel ray
  // (rx, ry): max(n . -D, 0)^2 / |D|^2.
  double lambert2(double rx, double ry, const glm::dvec3 &n) const {
    const double c = orthographic_ ? n.z : n.z - n.x * rx - n.y * ry;
    if (!(c > 0.0)) return 0.0;
    return orthographic_ ? c * c : c * c / (rx * rx + ry * ry + 1.0);
  }
  // The unit vector towards the eye along pixel ray (rx, ry).
  glm::dvec3 towards_eye(double rx, double ry) const {
    if (orthographic_) return glm::dvec3(0.0, 0.0, 1.0);
    return glm::dvec3(-rx, -ry, 1.0) / std::sqrt(rx * rx + ry * ry + 1.0);
  }

 private:
  bool orthographic_;
  glm::dvec3 a_, u_;
  double length_, r2_, inv_r_;
  // perspective: w = -a and its parts; orthographic: the ray direction and its parts
  glm::dvec3 w_{0.0}, wp_{0.0}, m_{0.0}, d_{0.0}, dp_{0.0};
  double w_u_ = 0.0, d_u_ = 0.0, qa_ = 0.0, inv_qa_ = 0.0, inv_du_ = 0.0;
};

// The columns of each row of a rectangle whose rays may meet the curved side of a cylinder (view-
// space point a, unit axis u, radius r): a superset of the pixels cast_cylinder can hit, so that
// draw_bond casts only those and its image stays that of casting the whole rectangle. Along a
// row the ray is (rx, ry, -1) from the eye (perspective) or (0, 0, -1) from (rx, ry, 0), and
// cast_cylinder's h2 = r^2 |Dp|^2 - (u . (D x w))^2 is a quadratic A rx^2 + B rx + C:
//   |Dp|^2 = q2 rx^2 + q1 rx + q0,   u . (D x w) = kx rx + k0,
// perspective (w = -a, m = w x u, c1 = ry uy - uz): q2 = 1 - ux^2, q1 = -2 ux c1,
//   q0 = ry^2 + 1 - c1^2, kx = mx, k0 = ry my - mz;
// orthographic: q2 = q1 = 0, q0 = 1 - uz^2, kx = -uy, k0 = ax uy + (ry - ay) ux.
// A pixel is kept where the quadratic is >= -tol, widened by a column on each side; where A >= 0
// the set is not an interval and the whole row is kept. tol holds 1e-5 of the terms' scale (far
// above the rounding of either cast's evaluation of h2, double or float) plus what h2 can change
// by when the ray moves by `slack`: the float cast (centred_cylinder_cast.h) builds its ray from
// float steps, within about 1e-7 of its distance from the cylinder's reference ray of the double
// ray (rays.x, rays.y), and slack is a hundredth of a pixel plus 1e-6 of that distance. Near
// h2 = 0, |u . (D x w)| <= r |D|, so h2's gradient in the ray is at most 2 r |D| (r + |m|)
// (perspective, m = w x u) or 2 r (orthographic), and its second derivatives 2 (r^2 + |m|^2).
// So every pixel either cast accepts (h2 > 0, or a ray along the axis, where h2 = 0) is kept.
class CylinderRows {
 public:
  CylinderRows(const ViewGeometry &g, const PixelRays &rays, const glm::dvec3 &a,
               const glm::dvec3 &u, double r, const PixelRect &rect)
      : orthographic_(g.orthographic), a_(a), u_(u), r2_(r * r), x0_(rect.x0), x1_(rect.x1) {
    m_ = glm::cross(-a, u);
    if (rect.empty()) return;  // no column to read the rays of (cylinder_rect's empty answer)
    const double rx0 = rays.x(rect.x0), rx1 = rays.x(rect.x1);
    rx2_ = std::max(rx0 * rx0, rx1 * rx1);
  }

  // Columns [*lo, *hi] of `row` (within the rectangle) to cast; false when none.
  bool span(const PixelRays &rays, int row, int *lo, int *hi) const {
    const double ry = rays.y(row);
    double q2, q1, q0, kx, k0;
    if (orthographic_) {
      q2 = 0.0, q1 = 0.0, q0 = 1.0 - u_.z * u_.z;
      kx = -u_.y, k0 = a_.x * u_.y + (ry - a_.y) * u_.x;
    } else {
      const double c1 = ry * u_.y - u_.z;
      q2 = 1.0 - u_.x * u_.x, q1 = -2.0 * u_.x * c1, q0 = ry * ry + 1.0 - c1 * c1;
      kx = m_.x, k0 = ry * m_.y - m_.z;
    }
    const double qa = r2_ * q2 - kx * kx, qb = r2_ * q1 - 2.0 * kx * k0, qc = r2_ * q0 - k0 * k0;
    *lo = x0_, *hi = x1_;
    if (!(qa < 0.0)) return true;  // not a bounded interval (or NaN): the whole row
    // Scale of the terms of h2 over the rectangle: r^2 |D|^2, the triple product squared, and
    // (|D| |w|)^2 for the rounding of that product near zero.
    const double d2 = orthographic_ ? 1.0 : rx2_ + ry * ry + 1.0;
    const double w2 =
        orthographic_ ? 2.0 * (rx2_ + ry * ry) + 2.0 * glm::dot(a_, a_) : glm::dot(a_, a_);
    const double scale = r2_ * d2 + kx * kx * rx2_ + k0 * k0 + 1e-7 * d2 * w2;
    const double pixel = std::abs(rays.x(1) - rays.x(0)) + std::abs(rays.y(1) - rays.y(0));
    const double reference = orthographic_ ? std::abs(a_.x) + std::abs(a_.y)
                                           : (std::abs(a_.x) + std::abs(a_.y)) / std::abs(a_.z);
    const double slack = 0.01 * pixel + 1e-6 * (std::sqrt(rx2_) + std::abs(ry) + reference);
    const double mm = orthographic_ ? 1.0 : glm::length(m_), r = std::sqrt(r2_);
    const double tol =
        1e-5 * scale + 2.0 * r * std::sqrt(d2) * (r + mm) * slack + (r2_ + mm * mm) * slack * slack;
    const double disc = qb * qb - 4.0 * qa * (qc + tol);
    if (!(disc >= 0.0)) return !(disc < 0.0);  // no ray of the row comes near the axis
    const double sq = std::sqrt(disc);
    const double ra = (-qb + sq) / (2.0 * qa), rb = (-qb - sq) / (2.0 * qa);  // qa < 0: ra <= rb
    // ray_x is affine in the column: ray_x(x) = ray_x(0) + x * step.
    const double x0 = rays.x(0), step = rays.x(1) - x0;
    double f0 = (std::min(ra, rb) - x0) / step, f1 = (std::max(ra, rb) - x0) / step;
    if (f0 > f1) std::swap(f0, f1);  // a negative step
    f0 = std::ceil(f0 - 1.0), f1 = std::floor(f1 + 1.0);
    if (!(f0 <= double(x1_)) || !(f1 >= double(x0_))) return false;
    *lo = std::max(x0_, int(std::max(f0, double(x0_))));
    *hi = std::min(x1_, int(std::min(f1, double(x1_))));
    return *lo <= *hi;
  }

 private:
  bool orthographic_;
  glm::dvec3 a_, u_, m_;
  double r2_, rx2_ = 0.0;
  int x0_, x1_;
};

}  // namespace lantern
