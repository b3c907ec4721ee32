#pragma once
// 64-bit content hashes (XXH3) for determinism checks and replay: the same bytes give the same hash on
// every run and thread count.
#include <cstdint>
#include <span>
#include <string>

namespace rivulet {

class Hasher {
  public:
    Hasher();
    ~Hasher();
    Hasher(const Hasher&) = delete;
    Hasher& operator=(const Hasher&) = delete;
    void reset();
    void add(const void* data, std::size_t bytes);
    template <class T>
    void add(std::span<const T> s) {
        add(s.data(), s.size_bytes());
    }
    std::uint64_t digest() const;

  private:
    alignas(64) unsigned char state_[576];  // XXH3_state_t, kept inline so hashing never allocates
};

std::uint64_t hash_bytes(const void* data, std::size_t bytes);
std::string hash_hex(std::uint64_t h);  // 16 lowercase hex digits

}  // namespace rivulet
