// Columns of values that can drop their first rows without moving the rest: the storage behind
// the particle pool, whose oldest particles, at the front, are usually the first to die.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "particles/Assert.h"

namespace tickfx {

/// Uninitialised storage of `bytes` (a multiple of 64), aligned to a cache line, for std::free;
/// throws std::bad_alloc when there is none. Storage of 2 MiB or more starts on a 2 MiB boundary
/// and asks the system for huge pages where it has them (Linux: transparent huge pages by
/// madvise), so that its first writers fault a page in every 2 MiB rather than every 4 KiB.
void* allocateColumnStorage(std::size_t bytes);

/// An aligned buffer of trivially copyable T whose rows start at an offset into it: rows() rows
/// are visible from data() on, and dropFront(k) makes row k the first by moving the offset, not
/// the values. New rows are not initialised (their first writer fills them, so memory is first
/// touched by the threads that fill it). Copies hold the visible rows only.
template <class T>
class OffsetBuffer {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  /// Storage is aligned to a cache line; a dropped front leaves data() at any row.
  static constexpr std::size_t kAlignment = 64;

  OffsetBuffer() = default;
  OffsetBuffer(const OffsetBuffer& other) { copyFrom(other); }
  OffsetBuffer(OffsetBuffer&& other) noexcept { swap(other); }
  OffsetBuffer& operator=(const OffsetBuffer& other) {
    if (this != &other) copyFrom(other);
    return *this;
  }
  OffsetBuffer& operator=(OffsetBuffer&& other) noexcept {
    swap(other);
    return *this;
  }
  ~OffsetBuffer() { std::free(base_); }

  T* data() { return base_ + offset_; }
  const T* data() const { return base_ + offset_; }
  std::size_t rows() const { return rows_; }
  /// Rows dropped from the front and not yet reused: capacity() − offset to capacity().
  std::size_t offset() const { return offset_; }
  std::size_t capacity() const { return capacity_; }

  /// Makes `rows` rows visible, keeping the values of rows [0, min(keep, rows)): in place when
  /// the storage past the offset is long enough, else moved to the front of the storage when it
  /// is, else moved to new storage of exactly `rows` rows.
  void setRows(std::size_t rows, std::size_t keep) {
    keep = std::min({keep, rows, rows_});
    if (offset_ + rows <= capacity_) {
      rows_ = rows;
      return;
    }
    if (rows <= capacity_) {
      if (keep > 0) std::memmove(base_, base_ + offset_, keep * sizeof(T));
      offset_ = 0;
      rows_ = rows;
      return;
    }
    T* fresh = allocate(rows);
    if (keep > 0) std::memcpy(fresh, base_ + offset_, keep * sizeof(T));
    std::free(base_);
    base_ = fresh;
    capacity_ = rows;
    offset_ = 0;
    rows_ = rows;
  }
  /// Rows [k, rows()) become rows [0, rows() − k), in O(1).
  void dropFront(std::size_t k) {
    TICKFX_ASSERT(k <= rows_, "dropping more rows than a column holds");
    offset_ += k;
    rows_ -= k;
  }
  void swap(OffsetBuffer& other) noexcept {
    std::swap(base_, other.base_);
    std::swap(capacity_, other.capacity_);
    std::swap(offset_, other.offset_);
    std::swap(rows_, other.rows_);
  }

 private:
  static T* allocate(std::size_t rows) {
    const std::size_t bytes =
        std::max((rows * sizeof(T) + kAlignment - 1) / kAlignment * kAlignment, kAlignment);
    return static_cast<T*>(allocateColumnStorage(bytes));
  }
  void copyFrom(const OffsetBuffer& other) {
    OffsetBuffer fresh;
    fresh.setRows(other.rows_, 0);
    if (other.rows_ > 0) std::memcpy(fresh.base_, other.data(), other.rows_ * sizeof(T));
    swap(fresh);
  }

  T* base_ = nullptr;
  std::size_t capacity_ = 0;
  std::size_t offset_ = 0;
  std::size_t rows_ = 0;
};

/// One float per row: an Eigen array expression over its rows (data(), size(), segment(), head(),
/// arithmetic: everything of Eigen::Map<Eigen::ArrayXf>), owning storage that can drop its front
/// in O(1) (dropFront). Assigning an expression of another size resizes it. Contiguous; aligned
/// to a cache line until a front is dropped.
class FloatColumn : public Eigen::Map<Eigen::ArrayXf> {
  using Base = Eigen::Map<Eigen::ArrayXf>;

 public:
  FloatColumn() : Base(nullptr, 0) {}
  /// `rows` rows, not initialised.
  explicit FloatColumn(Eigen::Index rows) : Base(nullptr, 0) { resize(rows); }
  FloatColumn(const FloatColumn& other) : Base(nullptr, 0), buffer_(other.buffer_) { reseat(); }
  FloatColumn(FloatColumn&& other) noexcept : Base(nullptr, 0) {
    buffer_.swap(other.buffer_);
    reseat();
    other.reseat();
  }
  /// The values of an Eigen expression (FloatColumn::Constant(n, v), a Map of other storage, …).
  template <class Derived>
  FloatColumn(const Eigen::DenseBase<Derived>& values) : Base(nullptr, 0) {  // NOLINT: implicit
    resize(values.size());
    Base::operator=(values);
  }
  FloatColumn& operator=(const FloatColumn& other) {
    if (this != &other) {
      buffer_ = other.buffer_;
      reseat();
    }
    return *this;
  }
  FloatColumn& operator=(FloatColumn&& other) noexcept {
    buffer_.swap(other.buffer_);
    reseat();
    other.reseat();
    return *this;
  }
  template <class Derived>
  FloatColumn& operator=(const Eigen::DenseBase<Derived>& values) {
    if (values.size() != size()) {
      // Evaluated first: the expression may read this column.
      const Eigen::ArrayXf evaluated = values;
      resize(evaluated.size());
      Base::operator=(evaluated);
    } else {
      Base::operator=(values);
    }
    return *this;
  }
  ~FloatColumn() = default;

  /// `rows` rows; the values of the rows both sizes have are kept, the others not initialised.
  void resize(Eigen::Index rows) { conservativeResize(rows); }
  void conservativeResize(Eigen::Index rows) {
    TICKFX_ASSERT(rows >= 0, "a negative row count");
    const auto n = static_cast<std::size_t>(rows);
    buffer_.setRows(n, n);
    reseat();
  }
  /// `rows` rows keeping the values of rows [0, keep) (no more are copied when it moves).
  void setRows(std::size_t rows, std::size_t keep) {
    buffer_.setRows(rows, keep);
    reseat();
  }
  /// Drops rows [0, k): row k becomes row 0, with nothing moved.
  void dropFront(std::size_t k) {
    buffer_.dropFront(k);
    reseat();
  }

 private:
  // Points the Map at the buffer's rows (Eigen's documented way to change a Map's array).
  void reseat() {
    new (static_cast<Base*>(this)) Base(buffer_.data(), static_cast<Eigen::Index>(buffer_.rows()));
  }

  OffsetBuffer<float> buffer_;
};

/// One value of integer type T per row, with a small part of std::vector's interface (data,
/// size, indexing, iteration) over the visible rows and the pool's growth and dropFront.
template <class T>
class RowColumn {
 public:
  T* data() { return buffer_.data(); }
  const T* data() const { return buffer_.data(); }
  std::size_t size() const { return buffer_.rows(); }
  bool empty() const { return size() == 0; }
  T& operator[](std::size_t i) { return data()[i]; }
  const T& operator[](std::size_t i) const { return data()[i]; }
  /// Row `i`, checked: std::out_of_range past size().
  const T& at(std::size_t i) const {
    if (i >= size()) throw std::out_of_range("row past the end of a column");
    return data()[i];
  }
  T* begin() { return data(); }
  T* end() { return data() + size(); }
  const T* begin() const { return data(); }
  const T* end() const { return data() + size(); }
  /// See FloatColumn: kept values, new rows not initialised.
  void resize(std::size_t rows) { buffer_.setRows(rows, rows); }
  void setRows(std::size_t rows, std::size_t keep) { buffer_.setRows(rows, keep); }
  void dropFront(std::size_t k) { buffer_.dropFront(k); }

 private:
  OffsetBuffer<T> buffer_;
};

}  // namespace tickfx
