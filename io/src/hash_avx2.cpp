// XXH3 built for AVX2 (this file only is compiled with -mavx2): sidecar.cpp calls these where
// the processor has AVX2, the default build (SSE2) elsewhere. XXH3's values do not depend on
// the instructions that compute them, so a sidecar written on one machine checks on another.
#include <cstddef>
#include <cstdint>

#define XXH_INLINE_ALL
#include <xxhash.h>

namespace loci::io::detail {

std::uint64_t hash_bytes_avx2(const void* data, std::size_t size, std::uint64_t seed) {
  return XXH3_64bits_withSeed(data, size, seed);
}

void hash_update_avx2(XXH3_state_t* state, const void* data, std::size_t size) {
  XXH3_64bits_update(state, data, size);
}

}  // namespace loci::io::detail
