// TBB's parallel algorithms as the io library calls them, each marked as a parallel loop for
// `tickfx run --profile` (profile::ParallelScope): a cache encoded on the thread that drives the
// run (--no-overlap) then shows which part of its time ran on one thread. Internal to io/.
#pragma once

#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <utility>

#include "particles/PhaseProfile.h"

namespace tickfx::io::par {

template <typename... Args>
void parallel_for(Args&&... args) {
  const profile::ParallelScope parallel;
  tbb::parallel_for(std::forward<Args>(args)...);
}

template <typename... Args>
auto parallel_reduce(Args&&... args) {
  const profile::ParallelScope parallel;
  return tbb::parallel_reduce(std::forward<Args>(args)...);
}

template <typename... Args>
void parallel_sort(Args&&... args) {
  const profile::ParallelScope parallel;
  tbb::parallel_sort(std::forward<Args>(args)...);
}

template <typename... Args>
void parallel_pipeline(Args&&... args) {
  const profile::ParallelScope parallel;
  tbb::parallel_pipeline(std::forward<Args>(args)...);
}

}  // namespace tickfx::io::par
