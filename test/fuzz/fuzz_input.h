// Reading fuzzer bytes as numbers (libFuzzer targets only).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <opencv2/core/types.hpp>

namespace mono_plane_detection {

class FuzzInput {
 public:
  FuzzInput(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  size_t left() const { return pos_ < size_ ? size_ - pos_ : 0; }
  // Any float bit pattern, NaN and infinities included; 0 when the bytes run out.
  double nextFloat() {
    float f = 0;
    if (left() >= sizeof f) {
      std::memcpy(&f, data_ + pos_, sizeof f);
      pos_ += sizeof f;
    } else {
      pos_ = size_;
    }
    return f;
  }
  // Two floats as a point, x first (function arguments have no set evaluation order).
  cv::Point2d nextPoint() {
    const double x = nextFloat();
    return {x, nextFloat()};
  }
  uint8_t nextByte() { return pos_ < size_ ? data_[pos_++] : 0; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

}  // namespace mono_plane_detection
