#include "particles/ParticlePool.h"

#include <algorithm>
#include <cmath>

namespace tickfx {
namespace {

template <typename Column>
void compact(Column& column, const std::vector<std::uint32_t>& keep) {
  for (std::size_t w = 0; w < keep.size(); ++w) column[w] = column[keep[w]];
}

void compact(Vec3Column& column, const std::vector<std::uint32_t>& keep) {
  compact(column.x, keep);
  compact(column.y, keep);
  compact(column.z, keep);
}

}  // namespace

void Vec3Column::resize(Eigen::Index rows) {
  x.resize(rows);
  y.resize(rows);
  z.resize(rows);
}

void Vec3Column::conservativeResize(Eigen::Index rows) {
  x.conservativeResize(rows);
  y.conservativeResize(rows);
  z.conservativeResize(rows);
}

void Vec3Column::assignRows(const Vec3Column& from, Eigen::Index begin, Eigen::Index end) {
  const Eigen::Index n = end - begin;
  x.segment(begin, n) = from.x.segment(begin, n);
  y.segment(begin, n) = from.y.segment(begin, n);
  z.segment(begin, n) = from.z.segment(begin, n);
}

ParticlePool::ParticlePool(std::size_t maxParticles) : maxParticles_(maxParticles) {
  if (maxParticles >= (std::size_t{1} << 32)) {
    // Row indices are 32-bit in the compaction and in the spring tables.
    maxParticles_ = (std::size_t{1} << 32) - 1;
  }
}

void ParticlePool::reserve(std::size_t rows) {
  if (rows > storageRows_) grow(std::min(rows, maxParticles_));
}

void ParticlePool::grow(std::size_t rows) {
  const auto n = static_cast<Eigen::Index>(rows);
  for (Vec3Column* c : {&position_, &velocity_, &previous_, &acceleration_}) c->conservativeResize(n);
  for (FloatColumn* c : {&age_, &lifetime_, &mass_, &inverseMass_}) c->conservativeResize(n);
  id_.resize(rows);
  birthTick_.resize(rows);
  dead_.resize(rows);
  for (NamedColumn& a : attributes_) a.values.conservativeResize(n);
  storageRows_ = rows;
}

std::size_t ParticlePool::spawn(const ParticleInit& init, std::int64_t tick) {
  if (size_ >= maxParticles_) {
    ++droppedSpawns_;
    return npos;
  }
  if (size_ == storageRows_) {
    grow(std::min(maxParticles_, std::max<std::size_t>(1024, storageRows_ * 2)));
  }
  const std::size_t i = size_++;
  const auto r = static_cast<Eigen::Index>(i);
  position_.x[r] = init.position.x();
  position_.y[r] = init.position.y();
  position_.z[r] = init.position.z();
  velocity_.x[r] = init.velocity.x();
  velocity_.y[r] = init.velocity.y();
  velocity_.z[r] = init.velocity.z();
  previous_.x[r] = init.position.x();
  previous_.y[r] = init.position.y();
  previous_.z[r] = init.position.z();
  acceleration_.x[r] = 0.0f;
  acceleration_.y[r] = 0.0f;
  acceleration_.z[r] = 0.0f;
  age_[r] = 0.0f;
  lifetime_[r] = init.lifetime;
  mass_[r] = init.mass;
  inverseMass_[r] = std::isinf(init.mass) ? 0.0f : 1.0f / init.mass;
  id_[i] = nextId_++;
  birthTick_[i] = tick;
  dead_[i] = 0;
  for (NamedColumn& a : attributes_) a.values[r] = a.initial;
  return i;
}

void ParticlePool::updateAges(std::int64_t tick, std::int64_t stepRateHz) {
  const double rate = static_cast<double>(stepRateHz);
  for (std::size_t i = 0; i < size_; ++i) {
    age_[static_cast<Eigen::Index>(i)] = static_cast<float>(static_cast<double>(tick - birthTick_[i]) / rate);
  }
}

std::size_t ParticlePool::removeDead() {
  std::vector<std::uint32_t> keep;
  keep.reserve(size_);
  for (std::size_t i = 0; i < size_; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    if (dead_[i] == 0 && !(age_[r] >= lifetime_[r])) keep.push_back(static_cast<std::uint32_t>(i));
  }
  const std::size_t removed = size_ - keep.size();
  if (removed == 0) return 0;
  for (Vec3Column* c : {&position_, &velocity_, &previous_, &acceleration_}) compact(*c, keep);
  for (FloatColumn* c : {&age_, &lifetime_, &mass_, &inverseMass_}) compact(*c, keep);
  compact(id_, keep);
  compact(birthTick_, keep);
  compact(dead_, keep);
  for (NamedColumn& a : attributes_) compact(a.values, keep);
  size_ = keep.size();
  firstUnstepped_ = std::min(firstUnstepped_, size_);
  return removed;
}

std::size_t ParticlePool::addAttribute(const std::string& name, float initial) {
  const std::size_t existing = findAttribute(name);
  if (existing != npos) return existing;
  NamedColumn column{name, initial, FloatColumn::Constant(static_cast<Eigen::Index>(storageRows_), initial)};
  attributes_.push_back(std::move(column));
  return attributes_.size() - 1;
}

std::size_t ParticlePool::findAttribute(const std::string& name) const {
  for (std::size_t i = 0; i < attributes_.size(); ++i) {
    if (attributes_[i].name == name) return i;
  }
  return npos;
}

void ParticlePool::resizeForRestore(std::size_t size, std::uint64_t nextId,
                                    std::uint64_t droppedSpawns) {
  reserve(size);
  size_ = std::min(size, storageRows_);
  firstUnstepped_ = size_;
  nextId_ = nextId;
  droppedSpawns_ = droppedSpawns;
}

}  // namespace tickfx
