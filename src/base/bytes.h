// Flat byte buffers for a render's saved state (checkpoints, and the sums processes exchange):
// plain values and vectors of plain values, in the machine's own layout, read back in the order
// they were written. A reader that runs past the end throws Error: a truncated or foreign buffer
// is refused, never read as garbage.
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "base/error.h"

namespace bpm {

class ByteWriter {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  template <class T>
  void put_vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(uint64_t(v.size()));
    const auto* p = reinterpret_cast<const uint8_t*>(v.data());
    bytes_.insert(bytes_.end(), p, p + v.size() * sizeof(T));
  }
  void reserve(size_t n) { bytes_.reserve(n); }
  // Overwrites the value written at byte `at` (a length known only later).
  template <class T>
  void patch(size_t at, const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    BPM_CHECK(at + sizeof(T) <= bytes_.size());
    std::memcpy(bytes_.data() + at, &v, sizeof(T));
  }
  const std::vector<uint8_t>& bytes() const { return bytes_; }
  std::vector<uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

class ByteReader {
 public:
  // `what` names the buffer in errors ("checkpoint out.checkpoint").
  ByteReader(const uint8_t* data, size_t size, std::string what)
      : data_(data), size_(size), what_(std::move(what)) {}
  ByteReader(const std::vector<uint8_t>& v, std::string what)
      : ByteReader(v.data(), v.size(), std::move(what)) {}
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    std::memcpy(&v, take(sizeof(T)), sizeof(T));
    return v;
  }
  template <class T>
  std::vector<T> get_vector() {
    const uint64_t n = get<uint64_t>();
    if (n > (size_ - pos_) / sizeof(T)) throw Error(what_ + " is truncated or corrupt");
    std::vector<T> v(n);
    if (n) std::memcpy(v.data(), take(n * sizeof(T)), n * sizeof(T));
    return v;
  }
  bool at_end() const { return pos_ == size_; }
  const std::string& what() const { return what_; }

 private:
  const uint8_t* take(size_t n) {
    if (n > size_ - pos_) throw Error(what_ + " is truncated or corrupt");
    const uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  const uint8_t* data_;
  size_t size_, pos_ = 0;
  std::string what_;
};

// FNV-1a, 64 bits: a checksum of saved state, and a fingerprint of scene files.
inline uint64_t fnv1a64(const void* data, size_t size, uint64_t h = 0xcbf29ce484222325ull) {
  const auto* p = static_cast<const uint8_t*>(data);
  for (size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

}  // namespace bpm
