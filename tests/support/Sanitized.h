// Whether a test runs in a sanitizer build (scripts/test's ASan/UBSan and TSan stages).
#pragma once

namespace tickfx::test {

// Tests that repeat one path many times, for statistics or for more schedules of the same code,
// run fewer repetitions there: a sanitizer checks a path's memory or threads once it has run,
// and at 10 to 30 times the Release time the repetitions would be most of CI's budget. Release
// runs them all.
#ifdef TICKFX_TEST_SANITIZED
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

}  // namespace tickfx::test
