// TICKFX_ASSERT: checks of the core's invariants (row ranges within the pool, stage slots in
// range, views read at or above their base) that cost nothing in Release. They are compiled in
// where TICKFX_ENABLE_ASSERTS is 1: the sanitizer build, or any build configured with
// -DTICKFX_ASSERTS=ON (the definition is public, so a host's own inline uses of the headers
// agree with the library).
#pragma once

namespace tickfx {

/// A failed TICKFX_ASSERT: where, the condition as written, and what it protects.
struct AssertFailure {
  const char* file;
  int line;
  const char* condition;
  const char* message;
};

/// Called on a failed TICKFX_ASSERT. The default prints "FILE:LINE: tickfx assertion failed:
/// CONDITION (MESSAGE)" to stderr. A host may log it, throw, or stop a debugger; if the hook
/// returns, the process aborts.
using AssertHook = void (*)(const AssertFailure& failure);

/// Installs `hook` (nullptr: the default) for every thread; returns the previous one.
AssertHook setAssertHook(AssertHook hook) noexcept;

/// Whether this build evaluates TICKFX_ASSERT.
inline constexpr bool kAssertsEnabled =
#if defined(TICKFX_ENABLE_ASSERTS) && TICKFX_ENABLE_ASSERTS
    true;
#else
    false;
#endif

/// Reports `failure` to the hook, then aborts.
void assertFailed(const AssertFailure& failure);

}  // namespace tickfx

#if defined(TICKFX_ENABLE_ASSERTS) && TICKFX_ENABLE_ASSERTS
#define TICKFX_ASSERT(condition, message) \
  ((condition)                            \
       ? static_cast<void>(0)             \
       : ::tickfx::assertFailed(::tickfx::AssertFailure{__FILE__, __LINE__, #condition, message}))
#else
// Not evaluated, but still compiled: a condition that stops compiling is caught in Release too.
#define TICKFX_ASSERT(condition, message) static_cast<void>(sizeof(!(condition)))
#endif
