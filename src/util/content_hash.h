// A 128-bit non-cryptographic hash of byte strings, for telling whether a
// unit's input or configuration changed since its result was stored.
//
// Four 64-bit lanes absorb the 8-byte words in turn (h = rotl(h ^ w, r) * k,
// independent chains, so the CPU runs them in parallel: several GB/s); each
// Add() is framed by its length, so Add("ab"), Add("c") and Add("a"),
// Add("bc") differ. The lanes are finished with the murmur3 64-bit finaliser
// and folded into two 64-bit halves.
#ifndef GRAVCAL_SRC_UTIL_CONTENT_HASH_H_
#define GRAVCAL_SRC_UTIL_CONTENT_HASH_H_

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

namespace gravcal {
namespace internal {

class ContentHash {
 public:
  void Add(std::string_view bytes) {
    Begin(bytes.size());
    Append(bytes);
    End();
  }

  // The same as Add(bytes) for bytes that come in pieces (a file read block
  // by block): Begin with their total size, Append the pieces in order, End.
  void Begin(uint64_t size) {
    Absorb(0, size);
    pending_size_ = 0;
  }
  void Append(std::string_view bytes) {
    const char* p = bytes.data();
    size_t left = bytes.size();
    if (pending_size_ > 0) {
      const size_t n = left < 32 - pending_size_ ? left : 32 - pending_size_;
      std::memcpy(pending_ + pending_size_, p, n);
      pending_size_ += n;
      p += n;
      left -= n;
      if (pending_size_ < 32) return;
      AbsorbBlock(pending_);
      pending_size_ = 0;
    }
    for (; left >= 32; p += 32, left -= 32) AbsorbBlock(p);
    if (left > 0) std::memcpy(pending_, p, left);
    pending_size_ = left;
  }
  void End() {
    const char* p = pending_;
    size_t left = pending_size_;
    for (int lane = 0; left > 0; ++lane) {
      uint64_t w = 0;
      const size_t n = left < 8 ? left : 8;
      std::memcpy(&w, p, n);
      Absorb(lane, w);
      p += n;
      left -= n;
    }
    pending_size_ = 0;
  }

  // 32 lower-case hex digits.
  std::string Hex() const {
    const uint64_t a = Finish(h_[0] ^ Finish(h_[1]));
    const uint64_t b = Finish(h_[2] ^ Finish(h_[3] + a));
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
  void AbsorbBlock(const char* p) {
    uint64_t w[4];
    std::memcpy(w, p, 32);
    for (int lane = 0; lane < 4; ++lane) Absorb(lane, w[lane]);
  }
  void Absorb(int lane, uint64_t w) {
    static constexpr uint64_t kMultiplier[4] = {0x9e3779b97f4a7c15ULL, 0xc2b2ae3d27d4eb4fULL,
                                                0x165667b19e3779f9ULL, 0x27d4eb2f165667c5ULL};
    static constexpr int kRotation[4] = {29, 31, 37, 41};
    h_[lane] = Rotl(h_[lane] ^ w, kRotation[lane]) * kMultiplier[lane];
  }

  uint64_t h_[4] = {0x243f6a8885a308d3ULL, 0x13198a2e03707344ULL, 0xa4093822299f31d0ULL,
                    0x082efa98ec4e6c89ULL};
  // Bytes of an Append not yet absorbed (fewer than 32).
  char pending_[32];
  size_t pending_size_ = 0;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_CONTENT_HASH_H_
