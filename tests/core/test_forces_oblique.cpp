// Every force module against its closed form on all three axes, with directions along no axis:
// gravity, drag, periodic wind, the anchor spring, a spring between two particles, and vector
// fields (uniform, in force and drag mode, sampled from a baked grid and in closed form through
// AnalyticForce, and a linear shear), each under all six integrators.
//
// Three checks, so that neither the library nor the test's own arithmetic is trusted alone:
//  1. the float run follows the scheme's recurrence, every tick and coordinate, within the
//     round-off bound of ObliqueTestSupport.h, and that bound is under a tenth of what the force
//     did on every axis (a dropped, swapped or negated component cannot pass);
//  2. where the scheme's recurrence has a closed form (constant acceleration; drag, whose
//     velocity follows w_n = R(k·dt)^n·w_0 with R the scheme's own factor), the float run is held
//     to that closed form, and the double recurrence is checked against it too, which validates
//     the recurrence used for the other forces;
//  3. the RK4 recurrence in double meets the closed form of the motion itself (the wind's time
//     integral, the damped oscillators, the cubic of a shear) within RK4's truncation bound.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "ObliqueTestSupport.h"
#include "fields/AnchorSpring.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/PeriodicWind.h"
#include "fields/SpringNetwork.h"
#include "fields/vdb/AnalyticField.h"
#include "fields/vdb/VectorField.h"
#include "particles/ParallelFor.h"

namespace tickfx::oblique {
namespace {

// One second at 60 Hz: long enough for every force to move every axis by decimetres, short
// enough that position Verlet's k² round-off stays a hundredth of that.
constexpr std::int64_t kRate = 60;
constexpr std::int64_t kTicks = 60;

using States = std::pair<std::vector<Vec>, std::vector<Vec>>;  // p and v of every particle

struct ForceCase {
  std::function<ForceSet()> forces;  // the module under test, as the library builds it
  Accel accel;                       // its documented formula, in double
  std::vector<Body> bodies;
  /// F of the round-off budget: the largest term the module adds up, before any cancellation.
  double forceTerms = 0.0;
  /// The closed form of the motion (the ODE's solution) at t seconds.
  std::function<States(double t)> motion;
  /// The closed form of the scheme's own recurrence, where it has one.
  std::function<Trajectory(const std::string& scheme)> schemeClosedForm;
  /// RK4's local truncation error per tick, for each coordinate of its flattened state (p, v);
  /// empty: the bound for an autonomous affine system (rk4LocalErrorAutonomous).
  std::function<Eigen::VectorXd()> rk4LocalError;
};

// ---- closed forms of the schemes' recurrences -----------------------------------------------

// Constant acceleration a from (p0, v0): the exact schemes give p0 + v0·t + a·t²/2; explicit
// Euler moves with the velocity at the start of each tick, a·dt²·n(n−1)/2, half a step of
// velocity behind; semi-implicit Euler with the one at the end, a·dt²·n(n+1)/2, as far ahead.
// Position Verlet's velocity, a backward difference, is the one at t − dt/2.
Trajectory constantAccelerationClosedForm(const std::string& scheme, const Body& b, const Vec& a) {
  const double h = stepOf(kRate);
  Trajectory out;
  for (std::int64_t n = 0; n <= kTicks; ++n) {
    const double t = static_cast<double>(n) * h;
    double offset = 0.0;
    if (scheme == "explicit_euler") offset = -h * t / 2.0;
    if (scheme == "semi_implicit_euler") offset = h * t / 2.0;
    const double lag = (scheme == "position_verlet" && n > 0) ? h / 2.0 : 0.0;
    out.p.push_back({b.p + b.v * t + a * (t * t / 2.0 + offset)});
    out.v.push_back({b.v + a * (t - lag)});
  }
  return out;
}

// Drag a = k·(u − v): every scheme maps w = v − u linearly, by its own factor R(z), z = k·dt, and
// moves the position by h·(u + Q·w) for its own Q (both read off the specifications):
//   explicit Euler     R = 1 − z,                      p moves with w_n;
//   semi-implicit      R = 1 − z,                      p moves with w_{n+1};
//   midpoint           R = 1 − z + z²/2,               p moves with (1 − z/2)·w_n;
//   position Verlet    w_1 = (1 − z/2)·w_0, then R = 1 − z, p moves with w_{n+1};
//   velocity Verlet    (w, h·a) ← [[1 − z/2, (1 − z)/2], [−z, −z]]·(w, h·a), a_0 = −k·w_0,
//                      p moves with w_n + h·a_n/2 (a is the kept, predicted acceleration);
//   RK4                R = 1 − z + z²/2 − z³/6 + z⁴/24, p moves with (1 − z/2 + z²/6 − z³/24)·w_n.
Trajectory dragClosedForm(const std::string& scheme, const Body& b, double k, const Vec& u) {
  const double h = stepOf(kRate);
  const double z = k * h;
  Trajectory out{{{b.p}}, {{b.v}}};
  Vec p = b.p;
  Vec w = b.v - u;
  Vec ha = -z * w;  // velocity Verlet's h·a
  for (std::int64_t n = 0; n < kTicks; ++n) {
    Vec next = w;
    Vec moved = w;
    if (scheme == "explicit_euler") {
      next = (1.0 - z) * w;
    } else if (scheme == "semi_implicit_euler") {
      next = (1.0 - z) * w;
      moved = next;
    } else if (scheme == "midpoint") {
      next = (1.0 - z + z * z / 2.0) * w;
      moved = (1.0 - z / 2.0) * w;
    } else if (scheme == "position_verlet") {
      next = (n == 0 ? 1.0 - z / 2.0 : 1.0 - z) * w;
      moved = next;
    } else if (scheme == "velocity_verlet") {
      moved = w + ha / 2.0;
      next = (1.0 - z / 2.0) * w + (1.0 - z) / 2.0 * ha;
      ha = -z * (w + ha);
    } else if (scheme == "rk4") {
      next = (1.0 - z + z * z / 2.0 - z * z * z / 6.0 + z * z * z * z / 24.0) * w;
      moved = (1.0 - z / 2.0 + z * z / 6.0 - z * z * z / 24.0) * w;
    }
    p += h * (u + moved);
    w = next;
    out.p.push_back({p});
    out.v.push_back({u + w});
  }
  return out;
}

// ---- the cases --------------------------------------------------------------------------------

double maxAbs(const Vec& v) { return v.cwiseAbs().maxCoeff(); }

ForceCase gravityCase() {
  const Vec g = floats(2.25f, -9.81f, 3.5f);
  ForceCase c;
  c.forces = [g] {
    ForceSet f;
    f.add(std::make_unique<Gravity>(narrow(g)));
    return f;
  };
  c.accel = [g](const std::vector<Vec>& p, const std::vector<Vec>&, double) {
    return std::vector<Vec>(p.size(), g);
  };
  c.bodies = {{floats(0.25f, 1.5f, -0.75f), floats(1.25f, 2.5f, -0.5f), 1.0}};
  c.forceTerms = maxAbs(g);
  const Body b = c.bodies[0];
  c.motion = [b, g](double t) {
    return States{{b.p + b.v * t + g * (t * t / 2.0)}, {b.v + g * t}};
  };
  c.schemeClosedForm = [b, g](const std::string& s) {
    return constantAccelerationClosedForm(s, b, g);
  };
  return c;
}

ForceCase dragCase() {
  const double k = 0.8f;
  const Vec air = floats(1.5f, -0.75f, 2.25f);
  ForceCase c;
  c.forces = [k, air] {
    ForceSet f;
    f.add(std::make_unique<LinearDrag>(static_cast<float>(k), narrow(air)));
    return f;
  };
  c.accel = [k, air](const std::vector<Vec>&, const std::vector<Vec>& v, double) {
    return std::vector<Vec>{k * (air - v[0])};
  };
  c.bodies = {{floats(0.5f, -0.25f, 1.0f), floats(-1.0f, 2.0f, 0.5f), 1.0}};
  c.forceTerms = k * (maxAbs(air) + 3.0);  // |v| stays below 3 m/s
  const Body b = c.bodies[0];
  c.motion = [b, k, air](double t) {
    const double decay = std::exp(-k * t);
    return States{{b.p + air * t + (b.v - air) * ((1.0 - decay) / k)}, {air + (b.v - air) * decay}};
  };
  c.schemeClosedForm = [b, k, air](const std::string& s) { return dragClosedForm(s, b, k, air); };
  return c;
}

struct WindParameters {
  Vec direction;  // as given; the module normalises it
  double base, amplitude, frequency, phase;
};

ForceCase windCase() {
  const WindParameters w{floats(0.6f, -0.45f, 0.8f), 0.75f, 1.875f, 1.5, 0.4};
  const Vec dir = w.direction.normalized();
  const double omega = 2.0 * std::numbers::pi * w.frequency;
  ForceCase c;
  c.forces = [w] {
    PeriodicWind::Settings s;
    s.direction = narrow(w.direction);
    s.base = static_cast<float>(w.base);
    s.amplitude = static_cast<float>(w.amplitude);
    s.frequency = w.frequency;
    s.phase = w.phase;
    ForceSet f;
    f.add(std::make_unique<PeriodicWind>(s));
    return f;
  };
  c.accel = [w, dir, omega](const std::vector<Vec>& p, const std::vector<Vec>&, double t) {
    return std::vector<Vec>(p.size(), dir * (w.base + w.amplitude * std::sin(omega * t + w.phase)));
  };
  c.bodies = {{floats(-0.5f, 0.75f, 0.25f), floats(0.5f, 1.0f, -1.5f), 1.0}};
  c.forceTerms = std::abs(w.base) + std::abs(w.amplitude);
  const Body b = c.bodies[0];
  // The time integrals of a(t) = d̂·(base + A·sin(ωt + φ)).
  c.motion = [b, w, dir, omega](double t) {
    const double a = w.amplitude, phi = w.phase;
    const double dv = w.base * t + a / omega * (std::cos(phi) - std::cos(omega * t + phi));
    const double dp = w.base * t * t / 2.0 + a / omega * t * std::cos(phi) -
                      a / (omega * omega) * (std::sin(omega * t + phi) - std::sin(phi));
    return States{{b.p + b.v * t + dir * dp}, {b.v + dir * dv}};
  };
  // RK4 on a force of time alone is a quadrature. Its velocity step is Simpson's rule, off by at
  // most h⁵·max|a⁗|/2880; its position step h·v + h²/6·(a(t) + 2a(t + h/2)) weighs a with
  // (h − s) exactly up to quadratics, so it is off by at most h⁵·max|a'''|·(1/120 + 1/144) (the
  // cubic remainder under the integral and under the rule), plus h times the velocity's error,
  // which the propagator carries.
  c.rk4LocalError = [w, dir, omega] {
    const double h = stepOf(kRate);
    const double h5 = std::pow(h, 5.0);
    const double a = std::abs(w.amplitude);
    Eigen::VectorXd e(6);
    for (int i = 0; i < 3; ++i) {
      e[i] = h5 * a * std::pow(omega, 3.0) * (1.0 / 120.0 + 1.0 / 144.0) * std::abs(dir[i]);
      e[3 + i] = h5 * a * std::pow(omega, 4.0) / 2880.0 * std::abs(dir[i]);
    }
    return e;
  };
  return c;
}

// A damped oscillator about `rest`, ω0² = k/m, γ = c/(2m), the same on every axis; oblique
// because the start offset and velocity point along no axis and not along each other.
ForceCase anchorCase() {
  const Vec rest = floats(0.5f, -1.0f, 0.75f);
  const double k = 3.0f, damping = 0.625f, mass = 1.5f;
  ForceCase c;
  c.forces = [rest, k, damping] {
    ForceSet f;
    f.add(std::make_unique<AnchorSpring>(narrow(rest), static_cast<float>(k),
                                         static_cast<float>(damping)));
    return f;
  };
  c.accel = [rest, k, damping, mass](const std::vector<Vec>& p, const std::vector<Vec>& v, double) {
    return std::vector<Vec>{-(k * (p[0] - rest) + damping * v[0]) / mass};
  };
  c.bodies = {{floats(1.5f, 0.25f, -0.5f), floats(0.5f, 1.0f, -1.5f), mass}};
  c.forceTerms = (k * 3.0 + damping * 3.0) / mass;  // |p − rest| and |v| stay below 3
  const Body b = c.bodies[0];
  c.motion = [b, rest, k, damping, mass](double t) {
    const double gamma = damping / (2.0 * mass);
    const double wd = std::sqrt(k / mass - gamma * gamma);
    const Vec x0 = b.p - rest;
    const Vec s0 = (b.v + gamma * x0) / wd;
    const double e = std::exp(-gamma * t), cs = std::cos(wd * t), sn = std::sin(wd * t);
    const Vec x = e * (x0 * cs + s0 * sn);
    const Vec v = e * ((s0 * wd - gamma * x0) * cs - (x0 * wd + gamma * s0) * sn);
    return States{{rest + x}, {v}};
  };
  return c;
}

// Two particles of 1 and 2 kg on one damped spring, stretched along an oblique line and moving
// together across it. Their relative motion stays on the line, where s = |p2 − p1| is a damped
// oscillator: s'' = −(k·(s − L) + c·s')·(1/m1 + 1/m2); the centre of mass moves uniformly.
ForceCase springPairCase() {
  const double k = 12.0f, damping = 0.375f, rest = 1.0f, m1 = 1.0, m2 = 2.0;
  const Vec p1 = floats(0.125f, 0.25f, -0.375f), p2 = floats(0.5f, 0.8125f, 0.75f);  // 1.3764 m
  const Vec drift = floats(0.25f, -0.5f, 0.375f);  // both the same: no relative velocity across
  ForceCase c;
  c.forces = [k, damping, rest] {
    auto springs = std::make_unique<SpringNetwork>();
    Spring s;
    s.a = 0;
    s.b = 1;
    s.restLength = static_cast<float>(rest);
    s.stiffness = static_cast<float>(k);
    s.damping = static_cast<float>(damping);
    springs->add(s);
    ForceSet f;
    f.add(std::move(springs));
    return f;
  };
  c.accel = [k, damping, rest, m1, m2](const std::vector<Vec>& p, const std::vector<Vec>& v,
                                       double) {
    const Vec d = p[1] - p[0];
    const Vec u = d / d.norm();
    const double f = k * (d.norm() - rest) + damping * (v[1] - v[0]).dot(u);
    return std::vector<Vec>{f * u / m1, -f * u / m2};
  };
  c.bodies = {{p1, drift, m1}, {p2, drift, m2}};
  c.forceTerms = k * 3.0 + damping * 3.0;  // |d| + L and the closing speed stay below 3
  const std::vector<Body> bodies = c.bodies;
  c.motion = [bodies, k, damping, rest, m1, m2](double t) {
    const double mu = 1.0 / m1 + 1.0 / m2, total = m1 + m2;
    const double gamma = damping * mu / 2.0;
    const double wd = std::sqrt(k * mu - gamma * gamma);
    const Vec d0 = bodies[1].p - bodies[0].p;
    const Vec u = d0 / d0.norm();
    const double x0 = d0.norm() - rest;
    const double e = std::exp(-gamma * t), cs = std::cos(wd * t), sn = std::sin(wd * t);
    const double s = rest + x0 * e * (cs + gamma / wd * sn);
    const double ds = -x0 * e * (wd + gamma * gamma / wd) * sn;
    const Vec centre = (m1 * bodies[0].p + m2 * bodies[1].p) / total + bodies[0].v * t;
    const Vec v = bodies[0].v;
    return States{{centre - (m2 / total) * s * u, centre + (m1 / total) * s * u},
                  {v - (m2 / total) * ds * u, v + (m1 / total) * ds * u}};
  };
  return c;
}

// Vector fields baked in memory (the bits of a baked .vdb file) over a box that holds the whole
// motion, sampled trilinearly: exact for an affine field up to float rounding.
std::unique_ptr<VectorField> bakedField(const AnalyticField& field, VectorField::Mode mode,
                                        float scale) {
  BakeSettings bake;
  bake.voxelSize = 0.25;
  bake.min = Eigen::Vector3d::Constant(-4.0);
  bake.max = Eigen::Vector3d::Constant(4.0);
  VectorField::Settings s;
  s.file = "baked";
  s.mode = mode;
  s.scale = scale;
  return bakeVectorField(field, bake, s);
}

// A field's force module: sampled from a baked grid (what effects use) or evaluated in closed form
// (AnalyticForce, the oracle the field tests compare grids with).
enum class FieldSource { Baked, Analytic };

std::unique_ptr<ForceModule> fieldForce(FieldSource source, const AnalyticField& field,
                                        VectorField::Mode mode, float scale) {
  if (source == FieldSource::Baked) return bakedField(field, mode, scale);
  return std::make_unique<AnalyticForce>(
      field,
      mode == VectorField::Mode::Drag ? AnalyticForce::Mode::Drag : AnalyticForce::Mode::Force,
      scale);
}

// A uniform field in force mode is a constant acceleration scale·u.
ForceCase uniformFieldForceCase(FieldSource source) {
  const Vec u = floats(0.75f, -1.5f, 1.25f);
  const double scale = 1.5f;
  ForceCase c;
  c.forces = [u, scale, source] {
    ForceSet f;
    f.add(fieldForce(source, AnalyticField::uniform(u), VectorField::Mode::Force,
                     static_cast<float>(scale)));
    return f;
  };
  const Vec a = scale * u;
  c.accel = [a](const std::vector<Vec>& p, const std::vector<Vec>&, double) {
    return std::vector<Vec>(p.size(), a);
  };
  c.bodies = {{floats(-0.25f, 0.5f, 0.125f), floats(-0.75f, 1.25f, 0.5f), 1.0}};
  c.forceTerms = scale * maxAbs(u);
  const Body b = c.bodies[0];
  c.motion = [b, a](double t) {
    return States{{b.p + b.v * t + a * (t * t / 2.0)}, {b.v + a * t}};
  };
  c.schemeClosedForm = [b, a](const std::string& s) {
    return constantAccelerationClosedForm(s, b, a);
  };
  return c;
}

// A uniform field in drag mode is drag toward u at rate k = scale.
ForceCase uniformFieldDragCase(FieldSource source) {
  const Vec u = floats(-1.25f, 0.5f, 1.75f);
  const double k = 1.25f;
  ForceCase c;
  c.forces = [u, k, source] {
    ForceSet f;
    f.add(fieldForce(source, AnalyticField::uniform(u), VectorField::Mode::Drag,
                     static_cast<float>(k)));
    return f;
  };
  c.accel = [u, k](const std::vector<Vec>&, const std::vector<Vec>& v, double) {
    return std::vector<Vec>{k * (u - v[0])};
  };
  c.bodies = {{floats(0.5f, 0.25f, -0.5f), floats(0.75f, -1.0f, -0.25f), 1.0}};
  c.forceTerms = k * (maxAbs(u) + 3.0);
  const Body b = c.bodies[0];
  c.motion = [b, k, u](double t) {
    const double decay = std::exp(-k * t);
    return States{{b.p + u * t + (b.v - u) * ((1.0 - decay) / k)}, {u + (b.v - u) * decay}};
  };
  c.schemeClosedForm = [b, k, u](const std::string& s) { return dragClosedForm(s, b, k, u); };
  return c;
}

// A linear field at an oblique angle in force mode: the shear u(x) = r·(n̂·(x − o))·d̂ with d̂ ⊥ n̂.
// Then n̂·x moves uniformly, α(t) = α0 + α1·t, and d̂·x'' = s·r·α(t): the motion is the cubic
// x(t) = x0 + v0·t + s·r·(α0·t²/2 + α1·t³/6)·d̂.
ForceCase shearFieldCase() {
  const Vec origin = floats(0.25f, -0.5f, 0.125f);
  const Vec flow(1.0, 2.0, 2.0), gradient(2.0, 1.0, -2.0);  // perpendicular
  const double rate = 1.25, scale = 1.5f;
  const Vec d = flow.normalized(), n = gradient.normalized();
  ForceCase c;
  c.forces = [origin, flow, gradient, rate, scale] {
    ForceSet f;
    f.add(bakedField(AnalyticField::shear(origin, flow, gradient, rate), VectorField::Mode::Force,
                     static_cast<float>(scale)));
    return f;
  };
  c.accel = [origin, d, n, rate, scale](const std::vector<Vec>& p, const std::vector<Vec>&,
                                        double) {
    return std::vector<Vec>{scale * rate * n.dot(p[0] - origin) * d};
  };
  c.bodies = {{floats(0.5f, 0.75f, -1.0f), floats(0.5f, -0.375f, 0.75f), 1.0}};
  // |u| below r·4 m inside the motion; the sample's index transform rounds x/voxel, which moves
  // the sample by u·|x| and the value by r·u·|x|, |x| < 4 m: inside the same F.
  c.forceTerms = scale * rate * 4.0 * 3.0;
  const Body b = c.bodies[0];
  c.motion = [b, origin, d, n, rate, scale](double t) {
    const double sr = scale * rate;
    const double a0 = n.dot(b.p - origin), a1 = n.dot(b.v);
    return States{{b.p + b.v * t + sr * (a0 * t * t / 2.0 + a1 * t * t * t / 6.0) * d},
                  {b.v + sr * (a0 * t + a1 * t * t / 2.0) * d}};
  };
  return c;
}

ForceCase forceCase(const std::string& name) {
  if (name == "gravity") return gravityCase();
  if (name == "drag") return dragCase();
  if (name == "wind") return windCase();
  if (name == "anchor_spring") return anchorCase();
  if (name == "spring_pair") return springPairCase();
  if (name == "field_uniform_force") return uniformFieldForceCase(FieldSource::Baked);
  if (name == "field_uniform_drag") return uniformFieldDragCase(FieldSource::Baked);
  if (name == "analytic_uniform_force") return uniformFieldForceCase(FieldSource::Analytic);
  if (name == "analytic_uniform_drag") return uniformFieldDragCase(FieldSource::Analytic);
  if (name == "field_shear_force") return shearFieldCase();
  throw std::invalid_argument("no force case " + name);
}

const std::vector<std::string> kForces{"gravity",
                                       "drag",
                                       "wind",
                                       "anchor_spring",
                                       "spring_pair",
                                       "field_uniform_force",
                                       "field_uniform_drag",
                                       "field_shear_force",
                                       "analytic_uniform_force",
                                       "analytic_uniform_drag"};
const std::vector<std::string> kClosedFormForces{"gravity",
                                                 "drag",
                                                 "field_uniform_force",
                                                 "field_uniform_drag",
                                                 "analytic_uniform_force",
                                                 "analytic_uniform_drag"};

// ---- 1 and 2: the float run on every axis ------------------------------------------------------

struct ForceRun {
  std::string force, scheme;
};

void PrintTo(const ForceRun& r, std::ostream* os) { *os << r.force << " under " << r.scheme; }

std::vector<ForceRun> runs(const std::vector<std::string>& forces) {
  std::vector<ForceRun> out;
  for (const std::string& f : forces) {
    for (const std::string& s : integratorNames()) out.push_back({f, s});
  }
  return out;
}

std::string runName(const ::testing::TestParamInfo<ForceRun>& info) {
  return info.param.force + "_" + info.param.scheme;
}

class ObliqueForce : public ::testing::TestWithParam<ForceRun> {};

TEST_P(ObliqueForce, FloatRunFollowsTheSchemeOnEveryAxis) {
  const ForceRun& r = GetParam();
  const ForceCase c = forceCase(r.force);
  ForceSet forces = c.forces();
  const Trajectory got = runFloat(r.scheme, forces, c.bodies, kRate, kTicks);
  const Trajectory want = c.schemeClosedForm
                              ? c.schemeClosedForm(r.scheme)
                              : runReference(r.scheme, c.accel, c.bodies, kRate, kTicks);
  const Tolerances tol =
      roundOffTolerances(r.scheme, c.accel, c.bodies, kRate, kTicks, c.forceTerms);
  const double seconds = static_cast<double>(kTicks) * stepOf(kRate);
  const auto [p, v] = c.motion(seconds);
  ASSERT_TRUE(toleranceBelowEffect(tol, effectOf(c.bodies, p, v, seconds), 0.1));
  EXPECT_TRUE(followsWithin(got, want, tol));
}

INSTANTIATE_TEST_SUITE_P(AllSchemes, ObliqueForce, ::testing::ValuesIn(runs(kForces)), runName);

// The double recurrence of ObliqueTestSupport.h is what the other forces are held to: here it
// meets the independent closed forms, within double round-off (the float bound scaled from
// u = 2^-24 to 2^-53).
class ObliqueForceClosedForm : public ::testing::TestWithParam<ForceRun> {};

TEST_P(ObliqueForceClosedForm, ReferenceRecurrenceIsTheSchemesClosedForm) {
  const ForceRun& r = GetParam();
  const ForceCase c = forceCase(r.force);
  const Trajectory recurrence = runReference(r.scheme, c.accel, c.bodies, kRate, kTicks);
  Tolerances tol = roundOffTolerances(r.scheme, c.accel, c.bodies, kRate, kTicks, c.forceTerms);
  for (auto* part : {&tol.p, &tol.v}) {
    for (auto& tick : *part) {
      for (Vec& x : tick) x *= 0x1p-29;
    }
  }
  EXPECT_TRUE(followsWithin(recurrence, c.schemeClosedForm(r.scheme), tol));
}

INSTANTIATE_TEST_SUITE_P(AllSchemes, ObliqueForceClosedForm,
                         ::testing::ValuesIn(runs(kClosedFormForces)), runName);

// ---- 3: the recurrence meets the closed form of the motion --------------------------------------

// For an autonomous affine system y' = A·y + b, y = (p, v), RK4's step is the Taylor polynomial
// of degree 4 of the exact flow, so its local error is Σ_{j≥5} h^j·A^{j−1}·y'/j!, at most
// h⁵·‖A‖⁴·‖y'‖/120·e^{h‖A‖} in any norm. The norm weighs velocities by 1/σ, σ² = the largest
// row sum of ∂a/∂p (so an oscillator's ‖A‖ is ω + damping rather than ω²): ‖A‖ = max(σ,
// ‖∂a/∂p‖/σ + ‖∂a/∂v‖), ‖y'‖ = max(|v|, |a|/σ), both the largest along the exact motion, the
// derivatives by finite differences of the formula. Back in metres and m/s, a position is off by
// at most the bound and a velocity by σ times it.
Eigen::VectorXd rk4LocalErrorAutonomous(const ForceCase& c) {
  const double h = stepOf(kRate);
  const std::size_t n = c.bodies.size();
  double byPosition = 0.0, byVelocity = 0.0, speed = 0.0, acceleration = 0.0;
  for (std::int64_t k = 0; k <= kTicks; ++k) {
    const double t = static_cast<double>(k) * h;
    auto [p, v] = c.motion(t);
    const std::vector<Vec> a = c.accel(p, v, t);
    for (std::size_t i = 0; i < n; ++i) {
      speed = std::max(speed, maxAbs(v[i]));
      acceleration = std::max(acceleration, maxAbs(a[i]));
    }
    for (int which = 0; which < 2; ++which) {
      std::vector<double> rowSums(3 * n, 0.0);
      for (std::size_t j = 0; j < n; ++j) {
        for (int cj = 0; cj < 3; ++cj) {
          std::vector<Vec> pp = p, vv = v;
          const double delta = 1e-6;
          (which == 0 ? pp : vv)[j][cj] += delta;
          const std::vector<Vec> ad = c.accel(pp, vv, t);
          for (std::size_t i = 0; i < n; ++i) {
            for (int ci = 0; ci < 3; ++ci) {
              rowSums[3 * i + static_cast<std::size_t>(ci)] +=
                  std::abs(ad[i][ci] - a[i][ci]) / delta;
            }
          }
        }
      }
      double& largest = which == 0 ? byPosition : byVelocity;
      for (double s : rowSums) largest = std::max(largest, s);
    }
  }
  // The finite differences are the derivatives to 1e-6 relative: 1 % more covers them.
  byPosition *= 1.01;
  byVelocity *= 1.01;
  const double sigma = std::max(1.0, std::sqrt(byPosition));
  const double norm = std::max(sigma, byPosition / sigma + byVelocity);
  const double slope = std::max(speed, acceleration / sigma);
  const double bound = std::pow(h, 5.0) * std::pow(norm, 4.0) * slope / 120.0 * std::exp(h * norm);
  Eigen::VectorXd local(static_cast<Eigen::Index>(6 * n));
  local.head(static_cast<Eigen::Index>(3 * n)).setConstant(bound);
  local.tail(static_cast<Eigen::Index>(3 * n)).setConstant(sigma * bound);
  return local;
}

class ObliqueMotion : public ::testing::TestWithParam<std::string> {};

TEST_P(ObliqueMotion, Rk4RecurrenceMeetsTheClosedFormOfTheMotion) {
  const ForceCase c = forceCase(GetParam());
  const Trajectory rk4 = runReference("rk4", c.accel, c.bodies, kRate, kTicks);
  const Eigen::VectorXd local = c.rk4LocalError ? c.rk4LocalError() : rk4LocalErrorAutonomous(c);
  const std::vector<Eigen::MatrixXd> phi = propagators("rk4", c.accel, c.bodies, kRate, kTicks);
  const std::size_t n = c.bodies.size();
  const double h = stepOf(kRate);
  // The schemes step by h, 1/rate rounded to float, while a force of time reads the exact clock
  // k/rate. An autonomous motion is simply compared at n·h. The wind's is compared at n/rate:
  // stepping by h = (1 + δ)/rate instead scales every velocity increment by 1 + δ and every
  // displacement by at most (1 + δ)², so the scheme is further off by δ·|v − v0| and
  // δ·|v0|·t + 2.0001·δ·|p − p0 − v0·t|.
  const double delta = std::abs(h * kRate - 1.0);
  Trajectory exact;
  Tolerances tol;
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(local.size());
  for (std::int64_t k = 0; k <= kTicks; ++k) {
    const double t = c.rk4LocalError ? static_cast<double>(k) / kRate : static_cast<double>(k) * h;
    const auto [p, v] = c.motion(t);
    exact.p.push_back(p);
    exact.v.push_back(v);
    if (k > 0) sum += phi[static_cast<std::size_t>(k - 1)].cwiseAbs() * local;
    std::vector<Vec> tp(n), tv(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec clockP =
          c.rk4LocalError ? (delta * (c.bodies[i].v * t).cwiseAbs() +
                             2.0001 * delta * (p[i] - c.bodies[i].p - c.bodies[i].v * t).cwiseAbs())
                                .eval()
                          : Vec::Zero().eval();
      const Vec clockV =
          c.rk4LocalError ? (delta * (v[i] - c.bodies[i].v).cwiseAbs()).eval() : Vec::Zero().eval();
      for (int ci = 0; ci < 3; ++ci) {
        const auto row = static_cast<Eigen::Index>(3 * i + static_cast<std::size_t>(ci));
        // Plus the double rounding of both sides: 1e-12 of the motion's metres.
        tp[i][ci] = sum[row] + clockP[ci] + 1e-12;
        tv[i][ci] = sum[static_cast<Eigen::Index>(3 * n) + row] + clockV[ci] + 1e-12;
      }
    }
    tol.p.push_back(tp);
    tol.v.push_back(tv);
  }
  const double seconds = static_cast<double>(kTicks) * h;
  ASSERT_TRUE(
      toleranceBelowEffect(tol, effectOf(c.bodies, exact.p.back(), exact.v.back(), seconds), 0.1));
  EXPECT_TRUE(followsWithin(rk4, exact, tol));
}

INSTANTIATE_TEST_SUITE_P(EveryForce, ObliqueMotion, ::testing::ValuesIn(kForces),
                         [](const ::testing::TestParamInfo<std::string>& force) {
                           return force.param;
                         });

}  // namespace
}  // namespace tickfx::oblique

namespace tickfx {
namespace {

// ForceSet adds a leading run of uniform modules once per evaluation (uniformAcceleration) and
// any later one per row (accumulate): gravity after drag takes the per-row path, which must add
// the same vector on every axis.
TEST(GravityPerRow, AddsTheUniformVectorOnEveryAxis) {
  const Eigen::Vector3f g(1.5f, -9.81f, 2.25f);
  const Gravity gravity(g);
  ParticlePool pool(4);
  for (int i = 0; i < 3; ++i) pool.spawn(ParticleInit{}, 0);
  const ForceInput in{pool, Vec3View::of(pool.position()), Vec3View::of(pool.velocity()), {}};
  Eigen::Vector3f uniform;
  ASSERT_TRUE(gravity.uniformAcceleration(in, uniform));
  EXPECT_EQ(uniform, g);
  Vec3Column a;
  a.resize(3);
  a.x << 0.5f, 0.0f, -1.0f;
  a.y << 0.0f, 1.0f, 0.0f;
  a.z << -0.25f, 0.0f, 4.0f;
  const Vec3Column before = a;
  const RowRange rows{0, 3};
  Vec3Rows out = Vec3Rows::of(a, rows);
  gravity.accumulate(in, rows, out);
  for (int c = 0; c < 3; ++c) {
    for (Eigen::Index i = 0; i < 3; ++i) EXPECT_EQ(a[c][i], before[c][i] + g[c]) << c << ", " << i;
  }
}

// A pinned particle holds still wherever it sits in a pool of many parallel blocks: ForceSet
// looks for pins over the whole pool each tick (beginTick), in blocks, and holds them per row.
TEST(ForceSetPins, APinnedParticleInAnyBlockOfALargePoolGetsNoAcceleration) {
  constexpr std::size_t kRows = 3 * kParallelBlockRows + 5;
  for (const std::size_t pinnedRow : {std::size_t{0}, 2 * kParallelBlockRows + 3, kRows - 1}) {
    ParticlePool pool(kRows);
    for (std::size_t r = 0; r < kRows; ++r) {
      ParticleInit init;
      if (r == pinnedRow) init.mass = std::numeric_limits<float>::infinity();
      pool.spawn(init, 0);
    }
    ForceSet forces;
    forces.add(std::make_unique<Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f)));
    forces.beginTick(pool, 0);
    const ForceInput in{pool, Vec3View::of(pool.position()), Vec3View::of(pool.velocity()), {}};
    Vec3Column a;
    a.resize(static_cast<Eigen::Index>(kRows));
    const RowRange rows{0, kRows};
    Vec3Rows out = Vec3Rows::of(a, rows);
    forces.evaluate(in, rows, out);
    for (std::size_t r = 0; r < kRows; ++r) {
      const float expected = r == pinnedRow ? 0.0f : -9.81f;
      ASSERT_EQ(a.y[static_cast<Eigen::Index>(r)], expected)
          << "row " << r << ", pin " << pinnedRow;
    }
  }
}
}  // namespace
}  // namespace tickfx
