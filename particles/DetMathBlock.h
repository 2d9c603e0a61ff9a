// det::sincos, det::cbrt and a clamped square root over arrays: the same bits as the scalar
// functions, element by element, in loops the compiler vectorises (SSE2 on x86-64, NEON on
// aarch64). Internal: the emitter's batch sampler uses them; not installed.
#pragma once

#include <cstddef>

namespace tickfx::det {

/// sine[i], cosine[i] = det::sincos(x[i]) for i < n, bit for bit (any x: arguments past the
/// vectorised range, |x| >= 2^19 or not finite, go through det::sincos itself). The arrays may
/// not overlap.
void sincosBlock(const double* x, double* sine, double* cosine, std::size_t n);

/// root[i] = det::cbrt(x[i]) for i < n, bit for bit (any x: zero, subnormal, negative and
/// non-finite arguments go through det::cbrt itself). The arrays may not overlap.
void cbrtBlock(const double* x, double* root, std::size_t n);

/// x[i] = std::sqrt(std::max(0.0, x[i])) for i < n, bit for bit (the square root is correctly
/// rounded everywhere), two at a time where the vector unit has it.
void sqrtClampedBlock(double* x, std::size_t n);

}  // namespace tickfx::det
