// A 128-bit non-cryptographic hash of byte strings, for telling whether a
// unit's input or configuration changed since its result was stored.
//
// Two 64-bit lanes with different multipliers absorb every 8-byte word
// (h = rotl(h ^ w, r) * k); each Add() is framed by its length, so
// Add("ab"), Add("c") and Add("a"), Add("bc") differ. The lanes are
// finished with the murmur3 64-bit finaliser and cross-mixed.
#ifndef GRAVCAL_SRC_CONTENT_HASH_H_
#define GRAVCAL_SRC_CONTENT_HASH_H_

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

namespace gravcal {

class ContentHash {
 public:
  void Add(std::string_view bytes) {
    Absorb(static_cast<uint64_t>(bytes.size()));
    const char* p = bytes.data();
    size_t left = bytes.size();
    while (left >= 8) {
      uint64_t w;
      std::memcpy(&w, p, 8);
      Absorb(w);
      p += 8;
      left -= 8;
    }
    if (left > 0) {
      uint64_t w = 0;
      std::memcpy(&w, p, left);
      Absorb(w);
    }
  }

  // 32 lower-case hex digits.
  std::string Hex() const {
    uint64_t a = Finish(a_ ^ (b_ >> 1));
    uint64_t b = Finish(b_ + a);
    char out[33];
    std::snprintf(out, sizeof(out), "%016llx%016llx", static_cast<unsigned long long>(a),
                  static_cast<unsigned long long>(b));
    return std::string(out, 32);
  }

 private:
  static uint64_t Rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }
  static uint64_t Finish(uint64_t x) {
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ULL;
    x ^= x >> 33;
    return x;
  }
  void Absorb(uint64_t w) {
    a_ = Rotl(a_ ^ w, 29) * 0x9e3779b97f4a7c15ULL;
    b_ = Rotl(b_ ^ w, 37) * 0xc2b2ae3d27d4eb4fULL;
  }

  uint64_t a_ = 0x243f6a8885a308d3ULL;
  uint64_t b_ = 0x13198a2e03707344ULL;
};

}  // namespace gravcal

#endif  // GRAVCAL_SRC_CONTENT_HASH_H_
