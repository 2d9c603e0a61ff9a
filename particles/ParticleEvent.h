// A moment of a particle's life that sub-emitters answer: its birth, its death, a contact.
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace tickfx {

/// What a sub-emitter emits on (EmitterSettings::on).
enum class EmitterEvent : std::uint8_t {
  None,       // not a sub-emitter
  Birth,      // the parent's birth: children born in the same tick
  Death,      // its lifetime running out, a kill contact, a kill region (not a non-finite kill)
  Collision,  // each contact with a collider
};

/// One event of one particle, as its children are made from it. Children of a death or contact
/// found in tick k, which covers (t_k, t_{k+1}], are born at t_{k+1} (the first tick at or after
/// the event, as a burst at that time would be); children of a birth at tick k are born at tick k.
struct ParticleEvent {
  std::uint64_t parentId = 0;
  std::uint32_t parentEmitter = 0;
  EmitterEvent kind = EmitterEvent::None;
  /// The parent's events of this kind before this one: 0 for a birth and a death, the contacts
  /// before this one over the particle's life for a collision.
  std::uint32_t ordinal = 0;
  Eigen::Vector3f position = Eigen::Vector3f::Zero();  // m: where the children are born
  Eigen::Vector3f velocity = Eigen::Vector3f::Zero();  // m/s: the parent's, at the event
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();    // a contact's unit normal; else 0
};

/// A contact the colliders found, for collision events. `velocity` is the one just before the
/// contact's response (Houdini's hitv); `point` the particle's centre at it (hitpos).
struct ContactRecord {
  std::uint32_t row = 0;      // the pool row, before the tick's removal
  std::uint32_t ordinal = 0;  // the particle's contacts before this one, over its life
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  Eigen::Vector3f velocity = Eigen::Vector3f::Zero();
};

}  // namespace tickfx
