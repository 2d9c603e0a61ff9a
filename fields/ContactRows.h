// Internal to the colliders (not installed): the contact loop of ColliderSet::collideRows(), over
// the rows the screen flagged, written once as a template over how a path's first contact is
// found and answered. A set of one collider runs it through Collider::contactRows(), which a
// shape collider overrides with its own test and response inlined (a heap resting on the ground
// makes a contact a row every tick); a set of several runs it through their virtual calls.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "fields/Collider.h"
#include "fields/ColliderSet.h"
#include "fields/ColliderShapes.h"

namespace tickfx::collide {

// One block's rows [begin, begin + count), as collideRows() prepared them. The flags and the
// starts are the block's (row begin + k at index k); the pool's columns are whole (row i at i).
struct RowsJob {
  std::size_t begin = 0, count = 0;
  const std::uint8_t* flagged = nullptr;  // the screen's flags, one a row
  std::array<const float*, 3> starts{};   // where each row's path starts
  std::array<float*, 3> position{}, velocity{}, previous{};
  std::uint8_t* dead = nullptr;  // null unless a collider kills
  const std::uint64_t* ids = nullptr;
  float dt = 0.0f;     // s
  float start = 0.0f;  // s: the tick's start, for hittime
  bool history = false;
  std::array<float*, kHitColumns.size()> hits{};  // the pool's hit columns, or null
  float* counts = nullptr;                        // the contact count column, or null
  std::vector<CollisionPath>* found = nullptr;    // the block's paths, appended in row order
  std::vector<ContactRecord>* records = nullptr;  // the block's contacts, or null
};

// Collider::respond(): `v` after contact `c` with a collider of this response, restitution and
// friction (see there), inline for the contact loop.
[[gnu::always_inline]] inline V3 respondWith(ColliderResponse response, float restitution,
                                             float friction, const Contact& c, const V3& v) {
  const V3 u = c.surfaceVelocity;
  const V3 relative = v - u;
  const float approach = dot(relative, c.normal);
  if (!(approach < 0.0f)) return v;
  if (response == ColliderResponse::Stick || response == ColliderResponse::Kill) return u;
  const float e = response == ColliderResponse::Bounce ? restitution : 0.0f;
  const V3 normalPart = c.normal * approach;
  V3 tangential = relative - normalPart;
  const float speed = length(tangential);
  const float loss = friction * ((1.0f + e) * -approach);
  if (speed > 0.0f)
    tangential = loss >= speed ? V3::Zero() : V3(tangential * ((speed - loss) / speed));
  return u + tangential - normalPart * e;
}

// Row k's path from its start to its end, contact after contact; returns the contacts made.
// The colliders, as `Colliders`:
//   first(a, from, b, out): the collider with the earliest contact on the path from `a` at
//     fraction `from` of the tick to `b` (earlier colliders winning ties), `out` its contact;
//     or null;
//   respond(hit, c, v): hit.respond(c, v).
template <class Colliders>
int contactRow(const RowsJob& job, std::size_t k, const Colliders& colliders) {
  const std::size_t i = job.begin + k;
  const float dt = job.dt;
  V3 a(job.starts[0][k], job.starts[1][k], job.starts[2][k]);
  V3 b(job.position[0][i], job.position[1][i], job.position[2][i]);
  V3 v(job.velocity[0][i], job.velocity[1][i], job.velocity[2][i]);
  CollisionPath path;
  float from = 0.0f;
  int recorded = 0;
  Contact lastHit;
  V3 hitVelocity = V3::Zero();
  while (path.contacts < kMaxContactsPerTick) {
    Contact best;
    const Collider* const hit = colliders.first(a, from, b, best);
    if (hit == nullptr) break;
    if (path.contacts == 0) path.start = a;
    path.fraction[static_cast<std::size_t>(path.contacts)] = best.fraction;
    path.point[static_cast<std::size_t>(path.contacts)] = best.point;
    ++path.contacts;
    if (job.records != nullptr) {
      job.records->push_back(ContactRecord{
          static_cast<std::uint32_t>(i),
          static_cast<std::uint32_t>(job.counts[i]) + static_cast<std::uint32_t>(path.contacts - 1),
          best.point, best.normal, v});
    }
    if (job.hits[0] != nullptr && hit->settings().recordHits) {
      ++recorded;
      lastHit = best;
      hitVelocity = v;
    }
    v = colliders.respond(*hit, best, v);
    a = best.point;
    from = best.fraction;
    if (hit->settings().response == ColliderResponse::Kill) {
      job.dead[i] = static_cast<std::uint8_t>(job.dead[i] | 1);
      b = a;
      break;
    }
    // The rest of the tick at the new velocity; after the last contact allowed, carried along
    // with the collider.
    b = path.contacts < kMaxContactsPerTick ? V3(a + v * ((1.0f - from) * dt)) : hit->carried(best);
  }
  if (path.contacts == 0) return 0;
  if (job.counts != nullptr) job.counts[i] += static_cast<float>(path.contacts);
  for (std::size_t c = 0; c < 3; ++c) {
    const auto axis = static_cast<Eigen::Index>(c);
    job.position[c][i] = b[axis];
    job.velocity[c][i] = v[axis];
    if (job.history) job.previous[c][i] = b[axis] - v[axis] * dt;
  }
  if (recorded > 0) {
    const float values[kHitColumns.size()] = {job.hits[0][i] + static_cast<float>(recorded),
                                              job.start + lastHit.fraction * dt,
                                              lastHit.point.x(),
                                              lastHit.point.y(),
                                              lastHit.point.z(),
                                              lastHit.normal.x(),
                                              lastHit.normal.y(),
                                              lastHit.normal.z(),
                                              hitVelocity.x(),
                                              hitVelocity.y(),
                                              hitVelocity.z()};
    for (std::size_t h = 0; h < kHitColumns.size(); ++h) job.hits[h][i] = values[h];
  }
  path.id = job.ids[i];
  job.found->push_back(path);
  return path.contacts;
}

// The colliders [begin, end) through their virtual calls, as contactRow() takes them: a path's
// earliest contact among them (an earlier collider winning a tie), answered by the collider hit.
// `Iterator` dereferences to a pointer to a Collider (raw or owning).
template <class Iterator>
struct VirtualColliders {
  Iterator begin, end;

  const Collider* first(const V3& a, float from, const V3& b, Contact& best) const {
    const Collider* hit = nullptr;
    Contact contact;
    for (Iterator c = begin; c != end; ++c) {
      const Collider& collider = **c;
      if (collider.firstContact(a, from, b, contact) &&
          (hit == nullptr || contact.fraction < best.fraction)) {
        best = contact;
        hit = &collider;
      }
    }
    return hit;
  }
  V3 respond(const Collider& hit, const Contact& c, const V3& v) const { return hit.respond(c, v); }
};

// Rows of flags contactRows() tests at once.
inline constexpr std::size_t kScanRows = 64;

// Whether none of flags[0, kScanRows) is set: their words or'ed, no branch a row.
inline bool noneFlagged(const std::uint8_t* flags) {
  std::uint64_t any = 0;
  for (std::size_t w = 0; w < kScanRows; w += sizeof any) {
    std::uint64_t word = 0;
    std::memcpy(&word, flags + w, sizeof word);
    any |= word;
  }
  return any == 0;
}

// contactRow() for every flagged row of the block, in row order; returns the contacts made.
template <class Colliders>
std::uint64_t contactRows(const RowsJob& job, const Colliders& colliders) {
  std::uint64_t contacts = 0;
  for (std::size_t k = 0; k < job.count; ++k) {
    // Most rows are screened out: skipped 64 at a time.
    if (k % kScanRows == 0 && k + kScanRows <= job.count && noneFlagged(job.flagged + k)) {
      k += kScanRows - 1;
      continue;
    }
    if (job.flagged[k] != 0) contacts += static_cast<std::uint64_t>(contactRow(job, k, colliders));
  }
  return contacts;
}

}  // namespace tickfx::collide
