// Formulas: Reeds & Shepp 1990, §8 (numbers of the formulas in the header), in the frame of
// the start pose with lengths in units of the turning radius. Each base function solves one
// word for a goal (x, y, phi) and returns its (t, u, v); the symmetries map a goal to the
// goal of a related word:
//   time-flip  (x, y, phi) -> (-x, y, -phi):  same letters, every length negated;
//   reflect    (x, y, phi) -> (x, -y, -phi):  L and R swapped;
//   backwards  (x, y, phi) -> (x cos phi + y sin phi, x sin phi - y cos phi, phi):
//              the same word driven in reverse order.
#include "engine/motion/reeds_shepp.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dispatch::engine {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRsEps = 1e-10;

struct Word {
  int n = 0;
  char type[5] = {};
  double len[5] = {};
};

void Polar(double x, double y, double& r, double& theta) {
  r = std::hypot(x, y);
  theta = std::atan2(y, x);
}

// (8.1) L+S+L+
bool LpSpLp(double x, double y, double phi, double& t, double& u, double& v) {
  Polar(x - std::sin(phi), y - 1.0 + std::cos(phi), u, t);
  if (t < -kRsEps) return false;
  v = WrapHeading(phi - t);
  return v >= -kRsEps;
}

// (8.2) L+S+R+
bool LpSpRp(double x, double y, double phi, double& t, double& u, double& v) {
  double u1 = 0.0;
  double t1 = 0.0;
  Polar(x + std::sin(phi), y - 1.0 - std::cos(phi), u1, t1);
  u1 = u1 * u1;
  if (u1 < 4.0) return false;
  u = std::sqrt(u1 - 4.0);
  const double theta = std::atan2(2.0, u);
  t = WrapHeading(t1 + theta);
  v = WrapHeading(t - phi);
  return t >= -kRsEps && v >= -kRsEps;
}

// (8.3) L+R-L+
bool LpRmL(double x, double y, double phi, double& t, double& u, double& v) {
  double u1 = 0.0;
  double theta = 0.0;
  Polar(x - std::sin(phi), y - 1.0 + std::cos(phi), u1, theta);
  if (u1 > 4.0) return false;
  u = -2.0 * std::asin(0.25 * u1);
  t = WrapHeading(theta + 0.5 * u + kPi);
  v = WrapHeading(phi - t + u);
  return t >= -kRsEps && u <= kRsEps;
}

// Shared by (8.7) and (8.8).
void TauOmega(double u, double v, double xi, double eta, double phi, double& tau, double& omega) {
  const double delta = WrapHeading(u - v);
  const double a = std::sin(u) - std::sin(delta);
  const double b = std::cos(u) - std::cos(delta) - 1.0;
  const double t1 = std::atan2(eta * a - xi * b, xi * a + eta * b);
  const double t2 = 2.0 * (std::cos(delta) - std::cos(v) - std::cos(u)) + 3.0;
  tau = t2 < 0.0 ? WrapHeading(t1 + kPi) : WrapHeading(t1);
  omega = WrapHeading(tau - u + v - phi);
}

// (8.7) L+R+L-R-: lengths t, u, -u, v
bool LpRupLumRm(double x, double y, double phi, double& t, double& u, double& v) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  const double rho = 0.25 * (2.0 + std::hypot(xi, eta));
  if (rho > 1.0) return false;
  u = std::acos(rho);
  TauOmega(u, -u, xi, eta, phi, t, v);
  return t >= -kRsEps && v <= kRsEps;
}

// (8.8) L+R-L-R+: lengths t, u, u, v
bool LpRumLumRp(double x, double y, double phi, double& t, double& u, double& v) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  const double rho = (20.0 - xi * xi - eta * eta) / 16.0;
  if (rho < 0.0 || rho > 1.0) return false;
  u = -std::acos(rho);
  if (u < -kPi / 2.0) return false;
  TauOmega(u, u, xi, eta, phi, t, v);
  return t >= -kRsEps && v >= -kRsEps;
}

// (8.9) L+R-(pi/2)S-L-: lengths t, -pi/2, u, v
bool LpRmSmLm(double x, double y, double phi, double& t, double& u, double& v) {
  double rho = 0.0;
  double theta = 0.0;
  Polar(x - std::sin(phi), y - 1.0 + std::cos(phi), rho, theta);
  if (rho < 2.0) return false;
  const double r = std::sqrt(rho * rho - 4.0);
  u = 2.0 - r;
  t = WrapHeading(theta + std::atan2(r, -2.0));
  v = WrapHeading(phi - kPi / 2.0 - t);
  return t >= -kRsEps && u <= kRsEps && v <= kRsEps;
}

// (8.10) L+R-(pi/2)S-R-: lengths t, -pi/2, u, v
bool LpRmSmRm(double x, double y, double phi, double& t, double& u, double& v) {
  double rho = 0.0;
  double theta = 0.0;
  Polar(-(y - 1.0 - std::cos(phi)), x + std::sin(phi), rho, theta);
  if (rho < 2.0) return false;
  t = theta;
  u = 2.0 - rho;
  v = WrapHeading(t + kPi / 2.0 - phi);
  return t >= -kRsEps && u <= kRsEps && v <= kRsEps;
}

// (8.11) L+R-(pi/2)S-L-(pi/2)R+: lengths t, -pi/2, u, -pi/2, v
bool LpRmSLmRp(double x, double y, double phi, double& t, double& u, double& v) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  double rho = 0.0;
  double theta = 0.0;
  Polar(xi, eta, rho, theta);
  if (rho < 2.0) return false;
  u = 4.0 - std::sqrt(rho * rho - 4.0);
  if (u > kRsEps) return false;
  t = WrapHeading(std::atan2((4.0 - u) * xi - 2.0 * eta, -2.0 * xi + (u - 4.0) * eta));
  v = WrapHeading(t - phi);
  return t >= -kRsEps && v >= -kRsEps;
}

Word Make(std::initializer_list<char> types, std::initializer_list<double> lens) {
  Word w;
  auto ti = types.begin();
  for (double l : lens) {
    w.type[w.n] = *ti++;
    w.len[w.n] = l;
    ++w.n;
  }
  return w;
}

char Swap(char c) { return c == 'L' ? 'R' : (c == 'R' ? 'L' : c); }

using Base = bool (*)(double, double, double, double&, double&, double&);

// Adds the word solved by `base` at the four symmetric goals. `make` builds the word's
// letters (for the unreflected case) and lengths from (t, u, v).
template <class MakeWord>
void AddSymmetric(Base base, double x, double y, double phi, MakeWord make, std::vector<Word>& out) {
  double t = 0.0, u = 0.0, v = 0.0;
  for (int flip = 0; flip < 2; ++flip) {
    for (int reflect = 0; reflect < 2; ++reflect) {
      const double gx = flip ? -x : x;
      const double gy = reflect ? -y : y;
      const double gphi = (flip != reflect) ? -phi : phi;
      if (!base(gx, gy, gphi, t, u, v)) continue;
      Word w = make(t, u, v);
      for (int i = 0; i < w.n; ++i) {
        if (flip) w.len[i] = -w.len[i];
        if (reflect) w.type[i] = Swap(w.type[i]);
      }
      out.push_back(w);
    }
  }
}

std::vector<Word> AllWords(double x, double y, double phi) {
  std::vector<Word> words;
  const double xb = x * std::cos(phi) + y * std::sin(phi);
  const double yb = x * std::sin(phi) - y * std::cos(phi);
  constexpr double h = kPi / 2.0;
  // CSC
  AddSymmetric(LpSpLp, x, y, phi, [](double t, double u, double v) { return Make({'L', 'S', 'L'}, {t, u, v}); }, words);
  AddSymmetric(LpSpRp, x, y, phi, [](double t, double u, double v) { return Make({'L', 'S', 'R'}, {t, u, v}); }, words);
  // C|C|C and its backwards form
  AddSymmetric(LpRmL, x, y, phi, [](double t, double u, double v) { return Make({'L', 'R', 'L'}, {t, u, v}); }, words);
  AddSymmetric(LpRmL, xb, yb, phi, [](double t, double u, double v) { return Make({'L', 'R', 'L'}, {v, u, t}); }, words);
  // CC|CC
  AddSymmetric(LpRupLumRm, x, y, phi,
               [](double t, double u, double v) { return Make({'L', 'R', 'L', 'R'}, {t, u, -u, v}); }, words);
  AddSymmetric(LpRumLumRp, x, y, phi,
               [](double t, double u, double v) { return Make({'L', 'R', 'L', 'R'}, {t, u, u, v}); }, words);
  // C|CSC and CSC|C (backwards)
  AddSymmetric(LpRmSmLm, x, y, phi,
               [](double t, double u, double v) { return Make({'L', 'R', 'S', 'L'}, {t, -h, u, v}); }, words);
  AddSymmetric(LpRmSmRm, x, y, phi,
               [](double t, double u, double v) { return Make({'L', 'R', 'S', 'R'}, {t, -h, u, v}); }, words);
  AddSymmetric(LpRmSmLm, xb, yb, phi,
               [](double t, double u, double v) { return Make({'L', 'S', 'R', 'L'}, {v, u, -h, t}); }, words);
  AddSymmetric(LpRmSmRm, xb, yb, phi,
               [](double t, double u, double v) { return Make({'R', 'S', 'R', 'L'}, {v, u, -h, t}); }, words);
  // C|C(pi/2)SC(pi/2)|C
  AddSymmetric(LpRmSLmRp, x, y, phi,
               [](double t, double u, double v) { return Make({'L', 'R', 'S', 'L', 'R'}, {t, -h, u, -h, v}); }, words);
  return words;
}

MotionPose EndOf(const Word& w) {
  MotionPose p;
  for (int i = 0; i < w.n; ++i) {
    if (std::abs(w.len[i]) < 1e-12) continue;
    p = Advance(p, RsSegmentMode({w.type[i], w.len[i]}), std::abs(w.len[i]), 1.0);
  }
  return p;
}

}  // namespace

MotionMode RsSegmentMode(const RsSegment& segment) {
  const bool fwd = segment.length >= 0.0;
  switch (segment.type) {
    case 'L': return fwd ? MotionMode::kArcForwardLeft : MotionMode::kArcReverseLeft;
    case 'R': return fwd ? MotionMode::kArcForwardRight : MotionMode::kArcReverseRight;
    default: return fwd ? MotionMode::kForward : MotionMode::kReverse;
  }
}

std::vector<RsPath> ReedsSheppPaths(const MotionPose& start, const MotionPose& goal, double radius) {
  const double dx = (goal.x - start.x) / radius;
  const double dy = (goal.y - start.y) / radius;
  const double c = std::cos(start.theta);
  const double s = std::sin(start.theta);
  const double x = c * dx + s * dy;
  const double y = -s * dx + c * dy;
  const double phi = WrapHeading(goal.theta - start.theta);
  std::vector<RsPath> paths;
  for (const Word& w : AllWords(x, y, phi)) {
    const MotionPose end = EndOf(w);
    if (std::hypot(end.x - x, end.y - y) > 1e-6 || std::abs(WrapHeading(end.theta - phi)) > 1e-6) continue;
    RsPath path;
    for (int i = 0; i < w.n; ++i) {
      if (std::abs(w.len[i]) < 1e-9) continue;
      path.segments.push_back({w.type[i], w.len[i] * radius});
      path.length += std::abs(w.len[i]) * radius;
    }
    paths.push_back(std::move(path));
  }
  std::stable_sort(paths.begin(), paths.end(), [](const RsPath& a, const RsPath& b) { return a.length < b.length; });
  return paths;
}

RsPath ShortestReedsShepp(const MotionPose& start, const MotionPose& goal, double radius) {
  std::vector<RsPath> paths = ReedsSheppPaths(start, goal, radius);
  return paths.empty() ? RsPath{} : std::move(paths.front());
}

void SampleReedsShepp(const MotionPose& start, const RsPath& path, double radius, double spacing,
                      MotionPath& out) {
  if (out.poses.empty()) out.poses.push_back(start);
  MotionPose at = start;
  for (const RsSegment& seg : path.segments) {
    const MotionMode mode = RsSegmentMode(seg);
    const double total = std::abs(seg.length);
    const int steps = std::max(1, static_cast<int>(std::ceil(total / spacing - 1e-9)));
    for (int k = 1; k <= steps; ++k) {
      out.poses.push_back(Advance(at, mode, total * k / steps, radius));
      out.modes.push_back(mode);
    }
    at = out.poses.back();
  }
}

}  // namespace dispatch::engine
