/// @file track.cpp
/// @brief Track (track.h).

#include "view/track.h"

#include <algorithm>
#include <stdexcept>

namespace meshnav::view {

Track::Track(size_t width, size_t capacity, Overflow overflow)
    : width_(width), capacity_(std::max<size_t>(capacity, 2)), overflow_(overflow) {
  if (width == 0) throw std::invalid_argument("Track: width must be positive");
}

void Track::append(const std::vector<double>& row) {
  if (row.size() != width_) throw std::invalid_argument("Track::append: row of the wrong width");
  if (size() >= capacity_) {
    const size_t n = size();
    std::vector<double> kept;
    kept.reserve(data_.size());
    if (overflow_ == Overflow::Thin) {
      // Every second row, and always the newest one.
      for (size_t i = 0; i < n; ++i)
        if (i % 2 == 0 || i + 1 == n) kept.insert(kept.end(), data_.begin() + i * width_, data_.begin() + (i + 1) * width_);
    } else {
      kept.assign(data_.begin() + (n / 2) * width_, data_.end());
    }
    data_.swap(kept);
    ++epoch_;
  }
  data_.insert(data_.end(), row.begin(), row.end());
}

void Track::write(JsonWriter& w, int64_t client_epoch, size_t since, int digits) const {
  const size_t n = size();
  const size_t start = (client_epoch == epoch_ && since <= n) ? since : 0;
  w.beginObject().field("epoch", epoch_).field("start", static_cast<int64_t>(start)).key("rows").beginArray();
  for (size_t i = start; i < n; ++i) {
    w.beginArray();
    for (size_t j = 0; j < width_; ++j) w.number(at(i, j), digits);
    w.endArray();
  }
  w.endArray().endObject();
}

}  // namespace meshnav::view
