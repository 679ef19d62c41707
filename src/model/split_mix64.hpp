// The generator randomConfiguration draws from (include/zwang/configuration.hpp).
// Not installed: the tests draw from it to reproduce a configuration's draws.
#pragma once

#include <cstdint>

namespace zwang::internal {

// One step of SplitMix64 (state += 0x9E3779B97F4A7C15, then two
// xor-shift-multiply rounds): a uniform 64-bit number from any state, the same
// on every platform.
std::uint64_t splitMix64(std::uint64_t& state) noexcept;

}  // namespace zwang::internal
