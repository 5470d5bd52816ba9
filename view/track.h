#pragma once
/// @file track.h
/// @brief Rows of numbers appended in time order (the vehicle's path, the truth, the range
/// residuals) that a page fetches incrementally: it sends the epoch and the number of rows it
/// holds, and gets only the rows after those. When the track is full it makes room by thinning
/// (every second row dropped: the whole path stays, coarser) or by dropping its oldest half (a
/// window of the newest rows); either starts a new epoch, and a page holding an older epoch gets
/// every row again.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "view/json_writer.h"

namespace meshnav::view {

class Track {
 public:
  enum class Overflow { Thin, DropOldest };

  /// `width` numbers per row; at most `capacity` rows (≥ 2) are kept.
  Track(size_t width, size_t capacity, Overflow overflow);

  /// Appends a row of width() numbers.
  void append(const std::vector<double>& row);

  size_t width() const { return width_; }
  size_t size() const { return data_.size() / width_; }
  int64_t epoch() const { return epoch_; }
  /// Row `i`, number `j`.
  double at(size_t i, size_t j) const { return data_[i * width_ + j]; }

  /// Writes {"epoch":E,"start":S,"rows":[[…],…]}: the rows from `since` on when `client_epoch` is
  /// epoch() and `since` ≤ size(), else every row with start 0.
  void write(JsonWriter& w, int64_t client_epoch, size_t since, int digits = 6) const;

 private:
  size_t width_;
  size_t capacity_;
  Overflow overflow_;
  int64_t epoch_ = 0;
  std::vector<double> data_;
};

}  // namespace meshnav::view
