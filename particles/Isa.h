// The instruction sets tickfx's widest loops are compiled for, chosen at run time. A loop has a
// baseline form (SSE2 on x86-64, NEON on aarch64: what the build targets) and, on x86-64, an AVX2
// clone and an AVX-512 clone; all give the same bits, because the loops use
// integer operations and IEEE arithmetic that rounds alike at any vector width (no FMA:
// -ffp-contract=off, and the clones do not enable it). Tests force each path and compare them bit
// for bit.
#pragma once

#include <optional>

/// Defined where the build can compile AVX2 and AVX-512 clones (x86-64 with GCC or Clang): the one
/// condition every dispatching loop and Isa.cpp test.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define TICKFX_AVX2_CLONES 1
#endif

namespace tickfx {

/// Ordered by width: a loop without a clone for the active Isa would take its widest one below it.
enum class Isa { Baseline = 0, Avx2 = 1, Avx512 = 2 };

/// Whether `isa` can run on this processor (Baseline always; Avx2 on an x86-64 processor with
/// AVX2, Avx512 on one with AVX2 and AVX-512 F, DQ and VL whose system saves the 512-bit registers,
/// in a build by GCC or Clang).
bool isaAvailable(Isa isa);

/// The path the loops take now: the forced one (forceIsa()), else the widest available. Cheap:
/// one relaxed atomic load after the first call.
Isa activeIsa();

/// Makes every dispatching loop run on `isa` (available here) from now on, in every thread;
/// nullopt: the widest available, the default. For tests and benches that pin each path; not
/// to be called while a loop runs.
void forceIsa(std::optional<Isa> isa);

/// "baseline", "AVX2" or "AVX-512", for messages and bench labels.
const char* isaName(Isa isa);

/// forceIsa(isa) while alive, the default (the widest) again after: a test's or a bench's path.
class ForcedIsa {
 public:
  explicit ForcedIsa(Isa isa) { forceIsa(isa); }
  ~ForcedIsa() { forceIsa(std::nullopt); }
  ForcedIsa(const ForcedIsa&) = delete;
  ForcedIsa& operator=(const ForcedIsa&) = delete;
};

}  // namespace tickfx
