// Shared by the oblique physics tests (test_forces_oblique, test_integrators_oblique): the six
// schemes written again in double from their specifications (the comments of integrators/*.h,
// not their code), a float run of the library itself, and the round-off bound that separates the
// two.
//
// Why a bound and not a fitted number: a float run differs from the same recurrence in double
// only by rounding. Each tick every float operation rounds its result by at most u = 2^-24 of its
// size; those local errors are then carried to later ticks by the recurrence itself. For the
// systems tested here (affine in the state, or followed along a line on which they are affine)
// the carried error is exactly Σ_j Φ(k − j)·ε_j to first order, with Φ(m) the recurrence's own
// propagator over m ticks. Φ is measured on the double recurrence (finite differences, exact for
// an affine map up to double rounding), so the bound follows the scheme: it grows like k for
// damped systems and like k² for position Verlet, whose velocity is a difference of positions.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fields/ForceSet.h"
#include "integrators/Integrator.h"
#include "particles/ParticlePool.h"

namespace tickfx::oblique {

using Vec = Eigen::Vector3d;

/// Unit round-off of float.
inline constexpr double kU = 0x1p-24;

/// The step the integrators take: 1/rate rounded to float once (StepTime::dt()).
inline double stepOf(std::int64_t rate) { return static_cast<double>(StepTime{0, rate}.dt()); }

/// A vector of floats, widened: the test's inputs are the very values the float run starts from.
inline Vec floats(float x, float y, float z) {
  return {static_cast<double>(x), static_cast<double>(y), static_cast<double>(z)};
}
inline Eigen::Vector3f narrow(const Vec& v) { return v.cast<float>(); }

/// One particle's start. Every value must be a float (see floats()).
struct Body {
  Vec p = Vec::Zero();
  Vec v = Vec::Zero();
  double mass = 1.0;
};

/// The accelerations of every particle at positions p, velocities v and time t (seconds), in
/// double, written from the force's documented formula.
using Accel =
    std::function<std::vector<Vec>(const std::vector<Vec>& p, const std::vector<Vec>& v, double t)>;

/// What a scheme's recurrence carries from one tick to the next, in double. Velocity Verlet also
/// carries its acceleration, position Verlet the previous position (its velocity is derived).
struct RefState {
  std::vector<Vec> p, v, a, prev;
};

inline bool carriesAcceleration(const std::string& scheme) { return scheme == "velocity_verlet"; }
inline bool carriesHistory(const std::string& scheme) { return scheme == "position_verlet"; }

inline RefState startState(const std::vector<Body>& bodies) {
  RefState s;
  for (const Body& b : bodies) {
    s.p.push_back(b.p);
    s.v.push_back(b.v);
    s.a.push_back(Vec::Zero());
    s.prev.push_back(b.p);
  }
  return s;
}

/// One tick of `scheme` from tick `tick` at `rate` Hz, from the specifications in
/// integrators/*.h. Stage times are exact (tick + halves/2)/rate, the step h the float dt.
/// `first`: the particles' first tick, where the self-starting schemes start.
inline void referenceStep(const std::string& scheme, RefState& s, const Accel& f, std::int64_t tick,
                          std::int64_t rate, bool first) {
  const double h = stepOf(rate);
  const double r = static_cast<double>(rate);
  const double t0 = static_cast<double>(tick) / r;
  const double tHalf = (static_cast<double>(tick) + 0.5) / r;
  const double t1 = static_cast<double>(tick + 1) / r;
  const std::size_t n = s.p.size();
  auto combine = [n](const std::vector<Vec>& x, const std::vector<Vec>& y, double w) {
    std::vector<Vec> out(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = x[i] + w * y[i];
    return out;
  };
  if (scheme == "explicit_euler") {
    // p ← p + v·dt, then v ← v + a(p, v, t)·dt, both from the state at the start of the tick.
    const std::vector<Vec> a = f(s.p, s.v, t0);
    s.prev = s.p;
    s.p = combine(s.p, s.v, h);
    s.v = combine(s.v, a, h);
  } else if (scheme == "semi_implicit_euler") {
    // v ← v + a(p, v, t)·dt, then p ← p + v_new·dt.
    const std::vector<Vec> a = f(s.p, s.v, t0);
    s.prev = s.p;
    s.v = combine(s.v, a, h);
    s.p = combine(s.p, s.v, h);
  } else if (scheme == "midpoint") {
    // v_mid = v + a(p, v, t)·dt/2; p ← p + v_mid·dt; v ← v + a(p_new, v_mid, t + dt/2)·dt.
    const std::vector<Vec> a = f(s.p, s.v, t0);
    const std::vector<Vec> vMid = combine(s.v, a, h / 2.0);
    s.prev = s.p;
    s.p = combine(s.p, vMid, h);
    s.v = combine(s.v, f(s.p, vMid, tHalf), h);
  } else if (scheme == "position_verlet") {
    // p_new = 2p − p_prev + a(p, v, t)·dt², v = (p_new − p)/dt; started with
    // p_prev = p − v·dt + a·dt²/2.
    const std::vector<Vec> a = f(s.p, s.v, t0);
    for (std::size_t i = 0; i < n; ++i) {
      if (first) s.prev[i] = s.p[i] - s.v[i] * h + a[i] * (h * h / 2.0);
      const Vec next = 2.0 * s.p[i] - s.prev[i] + a[i] * (h * h);
      s.prev[i] = s.p[i];
      s.p[i] = next;
      s.v[i] = (s.p[i] - s.prev[i]) / h;
    }
  } else if (scheme == "velocity_verlet") {
    // p ← p + v·dt + a·dt²/2; a_new = a(p_new, v + a·dt, t + dt); v ← v + (a + a_new)·dt/2;
    // a is kept for the next tick (evaluated on a particle's first tick).
    if (first) s.a = f(s.p, s.v, t0);
    s.prev = s.p;
    for (std::size_t i = 0; i < n; ++i) s.p[i] += s.v[i] * h + s.a[i] * (h * h / 2.0);
    const std::vector<Vec> aNew = f(s.p, combine(s.v, s.a, h), t1);
    for (std::size_t i = 0; i < n; ++i) s.v[i] += (s.a[i] + aNew[i]) * (h / 2.0);
    s.a = aNew;
  } else if (scheme == "rk4") {
    // The classic four stages at t, t + dt/2, t + dt/2, t + dt, weights 1/6, 1/3, 1/3, 1/6.
    const std::vector<Vec> k1 = f(s.p, s.v, t0);
    const std::vector<Vec> p2 = combine(s.p, s.v, h / 2.0), v2 = combine(s.v, k1, h / 2.0);
    const std::vector<Vec> k2 = f(p2, v2, tHalf);
    const std::vector<Vec> p3 = combine(s.p, v2, h / 2.0), v3 = combine(s.v, k2, h / 2.0);
    const std::vector<Vec> k3 = f(p3, v3, tHalf);
    const std::vector<Vec> p4 = combine(s.p, v3, h), v4 = combine(s.v, k3, h);
    const std::vector<Vec> k4 = f(p4, v4, t1);
    s.prev = s.p;
    for (std::size_t i = 0; i < n; ++i) {
      s.p[i] += (s.v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]) * (h / 6.0);
      s.v[i] += (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) * (h / 6.0);
    }
  } else {
    throw std::invalid_argument("no reference for " + scheme);
  }
}

/// Positions and velocities of every particle after every tick; entry 0 is the start.
struct Trajectory {
  std::vector<std::vector<Vec>> p, v;
  std::size_t ticks() const { return p.size() - 1; }
};

inline Trajectory runReference(const std::string& scheme, const Accel& f,
                               const std::vector<Body>& bodies, std::int64_t rate,
                               std::int64_t ticks) {
  RefState s = startState(bodies);
  Trajectory out{{s.p}, {s.v}};
  for (std::int64_t k = 0; k < ticks; ++k) {
    referenceStep(scheme, s, f, k, rate, k == 0);
    out.p.push_back(s.p);
    out.v.push_back(s.v);
  }
  return out;
}

/// The library itself: `scheme` in float on a pool of `bodies`, every tick begun and ended on the
/// forces as ParticleSystem does (springs build their links in beginTick).
inline Trajectory runFloat(const std::string& scheme, ForceSet& forces,
                           const std::vector<Body>& bodies, std::int64_t rate, std::int64_t ticks) {
  ParticlePool pool(bodies.size());
  for (const Body& b : bodies) {
    ParticleInit init;
    init.position = narrow(b.p);
    init.velocity = narrow(b.v);
    init.mass = static_cast<float>(b.mass);
    pool.spawn(init, 0);
  }
  std::unique_ptr<Integrator> integrator = makeIntegrator(scheme);
  auto read = [&pool](const Vec3Column& c) {
    std::vector<Vec> out(pool.size());
    for (std::size_t i = 0; i < pool.size(); ++i) {
      const auto row = static_cast<Eigen::Index>(i);
      out[i] = floats(c.x[row], c.y[row], c.z[row]);
    }
    return out;
  };
  Trajectory out{{read(pool.position())}, {read(pool.velocity())}};
  for (std::int64_t k = 0; k < ticks; ++k) {
    const StepTime time{k, rate};
    forces.beginTick(pool, k);
    integrator->step(pool, forces, time);
    pool.markAllStepped();
    forces.endTick(pool, time.stage(2));
    out.p.push_back(read(pool.position()));
    out.v.push_back(read(pool.velocity()));
  }
  return out;
}

// ---- the round-off bound ----------------------------------------------------------------------

/// The scheme's state as one vector: p then v (v then a for velocity Verlet), or p then the
/// previous position for position Verlet.
inline Eigen::VectorXd flatten(const std::string& scheme, const RefState& s) {
  std::vector<const std::vector<Vec>*> parts{&s.p};
  parts.push_back(carriesHistory(scheme) ? &s.prev : &s.v);
  if (carriesAcceleration(scheme)) parts.push_back(&s.a);
  Eigen::VectorXd out(static_cast<Eigen::Index>(3 * s.p.size() * parts.size()));
  Eigen::Index i = 0;
  for (const auto* part : parts) {
    for (const Vec& x : *part) {
      for (int c = 0; c < 3; ++c) out[i++] = x[c];
    }
  }
  return out;
}

/// The inverse of flatten(); position Verlet's velocity is derived again from its history.
inline void unflatten(const std::string& scheme, const Eigen::VectorXd& x, double h, RefState& s) {
  std::vector<std::vector<Vec>*> parts{&s.p};
  parts.push_back(carriesHistory(scheme) ? &s.prev : &s.v);
  if (carriesAcceleration(scheme)) parts.push_back(&s.a);
  Eigen::Index i = 0;
  for (auto* part : parts) {
    for (Vec& v : *part) {
      for (int c = 0; c < 3; ++c) v[c] = x[i++];
    }
  }
  if (carriesHistory(scheme)) {
    for (std::size_t j = 0; j < s.p.size(); ++j) s.v[j] = (s.p[j] - s.prev[j]) / h;
  }
}

/// Largest |component| over a trajectory's positions, velocities, and accelerations.
struct Magnitudes {
  double p = 0.0, v = 0.0, a = 0.0;
};

inline Magnitudes magnitudesOf(const Trajectory& t, const Accel& f, std::int64_t rate) {
  Magnitudes m;
  for (std::size_t k = 0; k < t.p.size(); ++k) {
    const std::vector<Vec> a =
        f(t.p[k], t.v[k], static_cast<double>(k) / static_cast<double>(rate));
    for (std::size_t i = 0; i < t.p[k].size(); ++i) {
      m.p = std::max(m.p, t.p[k][i].cwiseAbs().maxCoeff());
      m.v = std::max(m.v, t.v[k][i].cwiseAbs().maxCoeff());
      m.a = std::max(m.a, a[i].cwiseAbs().maxCoeff());
    }
  }
  return m;
}

/// The propagators Φ(0) = I, Φ(1), ..., Φ(ticks − 1) of `scheme`'s recurrence on its flattened
/// state, measured from the state after the first tick. Exact for an affine recurrence whose
/// linear part does not change in time (every system tested here: the wind only adds a term of
/// time); the linearisation otherwise.
inline std::vector<Eigen::MatrixXd> propagators(const std::string& scheme, const Accel& f,
                                                const std::vector<Body>& bodies, std::int64_t rate,
                                                std::int64_t ticks) {
  RefState start = startState(bodies);
  referenceStep(scheme, start, f, 0, rate, true);
  const Eigen::VectorXd base = flatten(scheme, start);
  const auto dim = base.size();
  std::vector<Eigen::MatrixXd> phi(static_cast<std::size_t>(std::max<std::int64_t>(ticks, 1)),
                                   Eigen::MatrixXd::Identity(dim, dim));
  // The unperturbed run, tick by tick, to difference against.
  std::vector<Eigen::VectorXd> reference{base};
  RefState s = start;
  for (std::int64_t m = 1; m < ticks; ++m) {
    referenceStep(scheme, s, f, m, rate, false);
    reference.push_back(flatten(scheme, s));
  }
  for (Eigen::Index i = 0; i < dim; ++i) {
    // A perturbation small enough for the linearisation, large enough that double rounding of
    // the difference (1e-16 of the state) stays 1e-8 of it.
    const double delta = 1e-7 * std::max(1.0, std::abs(base[i]));
    Eigen::VectorXd x = base;
    x[i] += delta;
    RefState p = start;
    unflatten(scheme, x, stepOf(rate), p);
    for (std::int64_t m = 1; m < ticks; ++m) {
      referenceStep(scheme, p, f, m, rate, false);
      phi[static_cast<std::size_t>(m)].col(i) =
          (flatten(scheme, p) - reference[static_cast<std::size_t>(m)]) / delta;
    }
  }
  return phi;
}

/// Bounds on the rounding one float tick makes in each coordinate of the scheme's state, from
/// the sizes of what it rounds. A rounding is at most u of its result. Counted from the schemes'
/// specifications: the longest, RK4, rounds a component of p or v at most 13 times between one
/// state and the next outside its force evaluations (three stage advances of 2, a weighted sum of
/// 4 operations, the += and its h/6), every value it rounds at most P (positions) or V
/// (velocities); kSteps = 16 covers every scheme. A force evaluation rounds at most kForce = 24
/// times (a spring: differences, length, direction, closing speed, force, its products; a field
/// sample: the index transform and the trilinear weights), each at most u of F, the largest
/// term the force adds up before cancellation; the scheme multiplies an acceleration by at most h
/// before it reaches a velocity and h² before a position.
struct RoundOffBudget {
  double p = 0.0, v = 0.0, a = 0.0;
};

inline int evaluationsPerTick(const std::string& scheme) {
  if (scheme == "rk4") return 4;
  if (scheme == "midpoint" || scheme == "velocity_verlet") return 2;  // VV: 2 on the first tick
  return 1;
}

inline RoundOffBudget budgetFor(const std::string& scheme, const Magnitudes& m, double forceTerms,
                                std::int64_t rate) {
  constexpr double kSteps = 16.0, kForce = 24.0;
  const double h = stepOf(rate);
  const double e = evaluationsPerTick(scheme);
  const double bigP = m.p + h * m.v + h * h * m.a;
  const double bigV = m.v + h * m.a;
  const double f = std::max(forceTerms, m.a);
  RoundOffBudget b;
  b.v = kU * (kSteps * bigV + kForce * e * h * f);
  // A velocity rounded within the tick reaches the position through at most h of it.
  b.p = kU * (kSteps * bigP + kForce * e * h * h * f) + h * b.v;
  b.a = kU * kForce * f;
  return b;
}

/// Per tick and coordinate, how far the float run may be from the double recurrence.
struct Tolerances {
  std::vector<std::vector<Vec>> p, v;  // [tick][particle]
};

/// Σ_{m<k} |Φ(m)|·ε_{k−m} for every tick k: the rounding of tick j carried to tick k. Position
/// Verlet's history coordinates are exact copies of the position except on the first tick, where
/// its start step rounds them (the position budget), and its velocity is the functional
/// (p − p_prev)/dt of the state, carried as such (the two errors are correlated, not added).
inline Tolerances roundOffTolerances(const std::string& scheme, const Accel& f,
                                     const std::vector<Body>& bodies, std::int64_t rate,
                                     std::int64_t ticks, double forceTerms) {
  const Trajectory ref = runReference(scheme, f, bodies, rate, ticks);
  const RoundOffBudget b = budgetFor(scheme, magnitudesOf(ref, f, rate), forceTerms, rate);
  const std::vector<Eigen::MatrixXd> phi = propagators(scheme, f, bodies, rate, ticks);
  const std::size_t n = bodies.size();
  const bool history = carriesHistory(scheme);
  const auto block = static_cast<Eigen::Index>(3 * n);
  const double h = stepOf(rate);
  Eigen::VectorXd eps(phi[0].rows());
  eps.segment(0, block).setConstant(b.p);
  eps.segment(block, block).setConstant(history ? 0.0 : b.v);
  if (carriesAcceleration(scheme)) eps.segment(2 * block, block).setConstant(b.a);
  Eigen::VectorXd epsFirst = eps;
  if (history) epsFirst.segment(block, block).setConstant(b.p);

  // The rows observed: positions, and velocities (position Verlet: (p − p_prev)/dt).
  Eigen::MatrixXd observe = Eigen::MatrixXd::Zero(2 * block, phi[0].cols());
  observe.topLeftCorner(block, block).setIdentity();
  if (history) {
    observe.block(block, 0, block, block) = Eigen::MatrixXd::Identity(block, block) / h;
    observe.block(block, block, block, block) = -Eigen::MatrixXd::Identity(block, block) / h;
  } else {
    observe.block(block, block, block, block).setIdentity();
  }
  std::vector<Eigen::MatrixXd> carried;  // |observe·Φ(m)|
  for (const Eigen::MatrixXd& m : phi) carried.push_back((observe * m).cwiseAbs());

  Tolerances out;
  out.p.assign(1, std::vector<Vec>(n, Vec::Zero()));
  out.v.assign(1, std::vector<Vec>(n, Vec::Zero()));
  Eigen::VectorXd later = Eigen::VectorXd::Zero(2 * block);  // ticks 2..k
  for (std::int64_t k = 1; k <= ticks; ++k) {
    if (k >= 2) later += carried[static_cast<std::size_t>(k - 2)] * eps;
    const Eigen::VectorXd sum = later + carried[static_cast<std::size_t>(k - 1)] * epsFirst;
    std::vector<Vec> p(n), v(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        const auto row = static_cast<Eigen::Index>(3 * i + static_cast<std::size_t>(c));
        p[i][c] = sum[row];
        // Position Verlet rounds its velocity three more times, each at most u·V (the
        // difference, the product by the rate, the rate against 1/dt): inside the budget.
        v[i][c] = sum[block + row] + (history ? b.v : 0.0);
      }
    }
    out.p.push_back(p);
    out.v.push_back(v);
  }
  return out;
}

// ---- checks -----------------------------------------------------------------------------------

inline const char* axisName(int c) { return c == 0 ? "x" : (c == 1 ? "y" : "z"); }

/// Every coordinate of every tick of `got` within `tol` of `want`; on failure, the coordinate
/// furthest outside its tolerance, with both values.
inline ::testing::AssertionResult followsWithin(const Trajectory& got, const Trajectory& want,
                                                const Tolerances& tol) {
  if (got.p.size() != want.p.size() || tol.p.size() != want.p.size()) {
    return ::testing::AssertionFailure() << "trajectories of different lengths";
  }
  double worst = 0.0;
  std::string where;
  for (std::size_t k = 0; k < got.p.size(); ++k) {
    for (std::size_t i = 0; i < got.p[k].size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        const struct {
          const char* what;
          double got, want, tol;
        } checks[] = {{"p", got.p[k][i][c], want.p[k][i][c], tol.p[k][i][c]},
                      {"v", got.v[k][i][c], want.v[k][i][c], tol.v[k][i][c]}};
        for (const auto& x : checks) {
          const double excess = std::abs(x.got - x.want) - x.tol;
          if (excess > worst || (!(excess <= 0.0) && where.empty())) {
            worst = excess;
            where = "tick " + std::to_string(k) + ", particle " + std::to_string(i) + ", " +
                    x.what + "." + axisName(c) + ": " + std::to_string(x.got) + " (run) vs " +
                    std::to_string(x.want) + " (expected), |difference| " +
                    std::to_string(std::abs(x.got - x.want)) + " > bound " + std::to_string(x.tol);
          }
        }
      }
    }
  }
  if (where.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << where;
}

/// What the forces did by the end of a motion that starts at (p0, v0): |p(T) − p0 − v0·T| and
/// |v(T) − v0| per coordinate. A tolerance must stay well below it, or the test could not tell a
/// force that acts from one that does not.
struct Effect {
  std::vector<Vec> p, v;
};

inline Effect effectOf(const std::vector<Body>& bodies, const std::vector<Vec>& p,
                       const std::vector<Vec>& v, double seconds) {
  Effect e;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    e.p.push_back((p[i] - bodies[i].p - bodies[i].v * seconds).cwiseAbs());
    e.v.push_back((v[i] - bodies[i].v).cwiseAbs());
  }
  return e;
}

/// Every coordinate's final tolerance below `fraction` of its effect.
inline ::testing::AssertionResult toleranceBelowEffect(const Tolerances& tol, const Effect& effect,
                                                       double fraction) {
  for (std::size_t i = 0; i < effect.p.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double tp = tol.p.back()[i][c], tv = tol.v.back()[i][c];
      if (!(tp < fraction * effect.p[i][c]) || !(tv < fraction * effect.v[i][c])) {
        return ::testing::AssertionFailure()
               << "particle " << i << ", axis " << axisName(c) << ": bounds " << tp << " m, " << tv
               << " m/s against effects " << effect.p[i][c] << " m, " << effect.v[i][c]
               << " m/s: the test could not see this axis";
      }
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace tickfx::oblique
