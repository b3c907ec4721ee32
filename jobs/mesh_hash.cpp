#include "jobs/mesh_hash.h"

#define XXH_STATIC_LINKING_ONLY
#include <xxhash.h>

#include <cstdio>

namespace rivulet {
namespace {
static_assert(sizeof(XXH3_state_t) <= 576, "Hasher::state_ too small for XXH3_state_t");
XXH3_state_t* state(unsigned char* s) {
    return reinterpret_cast<XXH3_state_t*>(s);
}
const XXH3_state_t* state(const unsigned char* s) {
    return reinterpret_cast<const XXH3_state_t*>(s);
}
}  // namespace

Hasher::Hasher() {
    XXH3_INITSTATE(state(state_));
    reset();
}
Hasher::~Hasher() = default;
void Hasher::reset() {
    XXH3_64bits_reset(state(state_));
}
void Hasher::add(const void* data, std::size_t bytes) {
    if (bytes) XXH3_64bits_update(state(state_), data, bytes);
}
std::uint64_t Hasher::digest() const {
    return XXH3_64bits_digest(state(state_));
}

std::uint64_t hash_bytes(const void* data, std::size_t bytes) {
    return XXH3_64bits(data, bytes);
}

std::string hash_hex(std::uint64_t h) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
}

}  // namespace rivulet
